//! The palette: a base colour for every face of a mesh, one per group,
//! with two refinements for the built-in room (books get a colour each;
//! the arrows of the axis object are red, green and blue along x, y and
//! z).

use crate::Mesh;
use glam::DVec3;

/// Linear-ish RGB in `[0, 1]`.
pub type Rgb = DVec3;

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

/// The base colour of every face of `mesh`.
pub fn face_colors(mesh: &Mesh) -> Vec<Rgb> {
    // connected parts (faces sharing a vertex), numbered in face order
    let parts = mesh.parts();
    let count = parts.iter().max().map_or(0, |&p| p + 1);
    let mut lo = vec![DVec3::splat(f64::INFINITY); count];
    let mut hi = vec![DVec3::splat(f64::NEG_INFINITY); count];
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A colour's bits, to compare colours exactly.
    fn hex(c: Rgb, _intensity: f64) -> [u64; 3] {
        c.to_array().map(f64::to_bits)
    }

    #[test]
    fn arrows_are_red_green_blue_and_books_differ() {
        let room = crate::room();
        let colors = face_colors(&room);
        let axes = room.group_index("axes").unwrap();
        let used: std::collections::HashSet<[u64; 3]> = room
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
        let book_colors: std::collections::HashSet<[u64; 3]> = room
            .faces
            .iter()
            .zip(&colors)
            .filter(|(f, _)| f.group == books)
            .map(|(_, c)| hex(*c, 1.0))
            .collect();
        assert_eq!(book_colors.len(), BOOKS.len());
    }
}
