//! Base colours of faces: one per group, with two refinements for the
//! built-in room (books get a colour each; the arrows of the axis object
//! are red, green and blue along x, y and z).

use glam::DVec3;
use shadow_scene::Mesh;

/// Linear-ish RGB in `[0, 1]`.
pub(crate) type Rgb = DVec3;

const fn rgb(r: f64, g: f64, b: f64) -> Rgb {
    DVec3::new(r, g, b)
}

const BOOKS: [Rgb; 8] = [
    rgb(0.66, 0.13, 0.14),
    rgb(0.14, 0.30, 0.60),
    rgb(0.86, 0.68, 0.18),
    rgb(0.16, 0.46, 0.28),
    rgb(0.50, 0.22, 0.52),
    rgb(0.88, 0.44, 0.14),
    rgb(0.22, 0.23, 0.28),
    rgb(0.86, 0.82, 0.70),
];

/// Colours for groups without a known name, picked by group index.
const OTHERS: [Rgb; 6] = [
    rgb(0.80, 0.74, 0.64),
    rgb(0.45, 0.60, 0.75),
    rgb(0.75, 0.50, 0.42),
    rgb(0.55, 0.70, 0.48),
    rgb(0.70, 0.62, 0.80),
    rgb(0.85, 0.72, 0.45),
];

const AXIS: [Rgb; 3] = [
    rgb(0.86, 0.12, 0.10),
    rgb(0.12, 0.66, 0.20),
    rgb(0.14, 0.30, 0.90),
];

fn group_color(name: &str, index: u32) -> Rgb {
    match name {
        "floor" => rgb(0.72, 0.54, 0.34),
        "walls" => rgb(0.92, 0.89, 0.82),
        "rug" => rgb(0.42, 0.48, 0.56),
        "chair" => rgb(0.12, 0.48, 0.52),
        "chair_frame" => rgb(0.24, 0.24, 0.26),
        "bookshelf" => rgb(0.52, 0.33, 0.18),
        "pot" => rgb(0.78, 0.38, 0.22),
        "soil" => rgb(0.28, 0.19, 0.12),
        "plant" => rgb(0.24, 0.58, 0.20),
        "flower" => rgb(0.95, 0.78, 0.15),
        "decor" => rgb(0.66, 0.64, 0.60),
        "axes" => rgb(0.62, 0.62, 0.64),
        _ => OTHERS[index as usize % OTHERS.len()],
    }
}

fn find(parent: &mut [u32], mut x: u32) -> u32 {
    while parent[x as usize] != x {
        parent[x as usize] = parent[parent[x as usize] as usize];
        x = parent[x as usize];
    }
    x
}

/// The base colour of every face of `mesh`.
pub(crate) fn face_colors(mesh: &Mesh) -> Vec<Rgb> {
    // connected parts (faces sharing a vertex), numbered in face order
    let mut parent: Vec<u32> = (0..mesh.positions.len() as u32).collect();
    for f in &mesh.faces {
        for w in f.vertices.windows(2) {
            let (a, b) = (find(&mut parent, w[0]), find(&mut parent, w[1]));
            parent[a.max(b) as usize] = a.min(b);
        }
    }
    let mut part_of_root = std::collections::HashMap::new();
    let parts: Vec<usize> = mesh
        .faces
        .iter()
        .map(|f| {
            let root = f.vertices.first().map_or(0, |&v| find(&mut parent, v));
            let next = part_of_root.len();
            *part_of_root.entry(root).or_insert(next)
        })
        .collect();
    let mut lo = vec![DVec3::splat(f64::INFINITY); part_of_root.len()];
    let mut hi = vec![DVec3::splat(f64::NEG_INFINITY); part_of_root.len()];
    for (f, &part) in mesh.faces.iter().zip(&parts) {
        for &v in &f.vertices {
            lo[part] = lo[part].min(mesh.positions[v as usize]);
            hi[part] = hi[part].max(mesh.positions[v as usize]);
        }
    }
    // parts of the "books" group numbered from 0
    let books = mesh.group_index("books");
    let first_book = mesh
        .faces
        .iter()
        .zip(&parts)
        .find(|(f, _)| Some(f.group) == books)
        .map_or(0, |(_, &p)| p);

    mesh.faces
        .iter()
        .zip(&parts)
        .enumerate()
        .map(|(i, (f, &part))| match mesh.group_name(i) {
            "books" => BOOKS[(part - first_book) % BOOKS.len()],
            "axes" => {
                // a long thin part is an arrow: colour it by its direction
                let size = hi[part] - lo[part];
                let mut order = [0, 1, 2];
                order.sort_by(|&a, &b| size[b].total_cmp(&size[a]));
                if size[order[0]] > 3.0 * size[order[1]] {
                    AXIS[order[0]]
                } else {
                    group_color("axes", f.group)
                }
            }
            name => group_color(name, f.group),
        })
        .collect()
}

/// `#rrggbb` of a colour scaled by `intensity`.
pub(crate) fn hex(c: Rgb, intensity: f64) -> String {
    let v = (c * intensity).clamp(DVec3::ZERO, DVec3::ONE) * 255.0;
    format!(
        "#{:02x}{:02x}{:02x}",
        v.x.round() as u8,
        v.y.round() as u8,
        v.z.round() as u8
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arrows_are_red_green_blue_and_books_differ() {
        let room = shadow_scene::room();
        let colors = face_colors(&room);
        let axes = room.group_index("axes").unwrap();
        let used: std::collections::HashSet<String> = room
            .faces
            .iter()
            .zip(&colors)
            .filter(|(f, _)| f.group == axes)
            .map(|(_, c)| hex(*c, 1.0))
            .collect();
        for c in AXIS {
            assert!(used.contains(&hex(c, 1.0)));
        }
        assert_eq!(used.len(), 4, "three arrows and the grey pedestal");
        let books = room.group_index("books").unwrap();
        let book_colors: std::collections::HashSet<String> = room
            .faces
            .iter()
            .zip(&colors)
            .filter(|(f, _)| f.group == books)
            .map(|(_, c)| hex(*c, 1.0))
            .collect();
        assert_eq!(book_colors.len(), BOOKS.len());
    }

    #[test]
    fn hex_clamps() {
        assert_eq!(hex(rgb(1.0, 0.5, 0.0), 1.0), "#ff8000");
        assert_eq!(hex(rgb(1.0, 0.5, 0.0), 4.0), "#ffff00");
        assert_eq!(hex(rgb(0.2, 0.2, 0.2), -1.0), "#000000");
    }
}
