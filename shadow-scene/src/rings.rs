//! A planar polygon with holes as triangles.

/// Triangles covering the planar polygon whose rings (the outer one,
/// then the holes) are `points` in turn, `lens[i]` corners each: indices
/// into `points`, each triangle turning as the outer ring does (earcut in
/// the polygon's plane). None where the outer ring has no area.
pub fn triangulate_rings(points: &[[f64; 3]], lens: &[usize]) -> Vec<[usize; 3]> {
    let Some(&outer) = lens.first() else {
        return Vec::new();
    };
    let mut flat = Vec::new();
    if !earcut::utils3d::project3d_to_2d(points, outer, &mut flat) {
        return Vec::new();
    }
    let mut holes = Vec::new();
    let mut start = 0;
    for r in &lens[..lens.len() - 1] {
        start += r;
        holes.push(start as u32);
    }
    let mut triangles: Vec<u32> = Vec::new();
    earcut::Earcut::new().earcut(flat.iter().copied(), &holes, &mut triangles);
    let area2 = |t: [usize; 3]| {
        let [a, b, c] = t.map(|i| flat[i]);
        (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    };
    let turn: f64 = (0..outer)
        .map(|i| {
            let (a, b) = (flat[i], flat[(i + 1) % outer]);
            a[0] * b[1] - a[1] * b[0]
        })
        .sum();
    (triangles.chunks(3))
        .map(|t| [t[0] as usize, t[1] as usize, t[2] as usize])
        .map(|t| match (area2(t) > 0.0) == (turn > 0.0) {
            true => t,
            false => [t[0], t[2], t[1]],
        })
        .collect()
}
