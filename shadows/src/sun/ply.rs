//! Sun studies as PLY: the heat maps of [`super::hours_obj`],
//! [`super::regions_obj`] and [`super::sensors_obj`] with the colour as
//! `red`, `green`, `blue` and the hours as a `sun_hours` property of each
//! face (or point), for tools that read PLY (`MeshLab`, `Open3D`, `trimesh`).

use glam::DVec3;

use super::{FaceHours, RegionCell, heat};

/// Every face with its own corners, coloured by its sun-hours, its hours
/// a property.
pub fn hours_ply(mesh: &crate::Mesh, hours: &[FaceHours]) -> String {
    let faces = (mesh.faces.iter().zip(hours)).map(|(f, h)| {
        let ring = f.vertices.iter().map(|&v| mesh.positions[v as usize]);
        (ring.collect(), h.sun_hours)
    });
    heat_ply(faces.collect())
}

/// The region's cells, coloured by their hours, the hours a property:
/// each cell as triangles ([`RegionCell::triangles`]: a cell need not be
/// convex, and may have holes).
pub fn regions_ply(cells: &[RegionCell]) -> String {
    heat_ply(
        (cells.iter())
            .flat_map(|c| c.triangles().into_iter().map(|t| (t.to_vec(), c.hours)))
            .collect(),
    )
}

/// Sensors as coloured points, their hours a property.
pub fn sensors_ply(points: &[DVec3], hours: &[f64]) -> String {
    let most = hours.iter().copied().fold(0.0, f64::max);
    let mut s = header(most, points.len());
    s += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
    s += "property double sun_hours\nend_header\n";
    for (p, &h) in points.iter().zip(hours) {
        let [r, g, b] = bytes(heat(h, most));
        s += &format!("{} {} {} {r} {g} {b} {h}\n", p.x, p.y, p.z);
    }
    s
}

/// Polygons with their hours as PLY faces (a face's corners its own).
fn heat_ply(faces: Vec<(Vec<DVec3>, f64)>) -> String {
    let most = faces.iter().map(|f| f.1).fold(0.0, f64::max);
    let corners: usize = faces.iter().map(|f| f.0.len()).sum();
    let count = if faces.iter().all(|f| f.0.len() <= 255) {
        "uchar"
    } else {
        "uint"
    };
    let mut s = header(most, corners);
    s += &format!(
        "element face {}\nproperty list {count} int vertex_indices\n",
        faces.len()
    );
    s += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
    s += "property double sun_hours\nend_header\n";
    for p in faces.iter().flat_map(|f| &f.0) {
        s += &format!("{} {} {}\n", p.x, p.y, p.z);
    }
    let mut next = 0;
    for (ring, h) in &faces {
        let ids: Vec<String> = (next..next + ring.len()).map(|i| i.to_string()).collect();
        let [r, g, b] = bytes(heat(*h, most));
        s += &format!("{} {} {r} {g} {b} {h}\n", ring.len(), ids.join(" "));
        next += ring.len();
    }
    s
}

/// The header up to the vertices' coordinates.
fn header(most: f64, vertices: usize) -> String {
    format!(
        "ply\nformat ascii 1.0\ncomment sun-hours: viridis from 0 (dark blue) to {most} hours \
         (yellow)\nelement vertex {vertices}\nproperty double x\nproperty double y\nproperty \
         double z\n"
    )
}

/// A colour in `[0, 1]` as bytes.
fn bytes(c: [f64; 3]) -> [u8; 3] {
    c.map(|x| (x.clamp(0.0, 1.0) * 255.0).round() as u8)
}
