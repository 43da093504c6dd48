use glam::DVec3;

use super::*;

const BLOCK: &str = include_str!("../../../data/city/block.city.json");

fn block() -> Mesh {
    parse_cityjson(BLOCK, "block.city.json").unwrap()
}

/// The area of a group's faces (fans: the fixture's faces are convex).
fn area(mesh: &Mesh, group: &str) -> f64 {
    let g = mesh.group_index(group).unwrap();
    mesh.faces
        .iter()
        .filter(|f| f.group == g)
        .map(|f| {
            let p: Vec<DVec3> = f
                .vertices
                .iter()
                .map(|&v| mesh.positions[v as usize])
                .collect();
            (1..p.len() - 1)
                .map(|i| (p[i] - p[0]).cross(p[i + 1] - p[0]))
                .sum::<DVec3>()
                .length()
                / 2.0
        })
        .sum()
}

#[test]
fn every_object_with_a_surface_is_a_group_named_by_its_id() {
    let mesh = block();
    // the tower has only a child, the lamp only a point
    assert_eq!(mesh.groups, ["house", "tower-part", "tree-1", "yard"]);
    let origin = DVec3::new(85_000.0, 446_000.0, 0.0);
    let (lo, hi) = mesh.bounds().unwrap();
    assert_eq!(lo, origin);
    assert_eq!(hi, origin + DVec3::new(60.0, 60.0, 20.0));
}

#[test]
fn the_most_detailed_geometry_is_read_and_solids_stay_closed() {
    let mesh = block();
    let (_, house) = mesh.split_off_group("house").unwrap();
    // LoD 2.2 (floor, 2 walls, 2 gables, 2 roof faces), not the LoD 1 block too
    assert_eq!(house.faces.len(), 7);
    assert!(house.is_closed_oriented());
    assert!((house.signed_volume() - 750.0).abs() < 1e-6);
    let (_, tower) = mesh.split_off_group("tower-part").unwrap();
    assert!(
        tower.is_closed_oriented(),
        "the window's hole is filled by the window"
    );
    assert!((tower.signed_volume() - 1280.0).abs() < 1e-6);
}

#[test]
fn a_surface_with_holes_becomes_triangles_turning_as_its_outer_ring() {
    let mesh = block();
    assert!((area(&mesh, "yard") - 3500.0).abs() < 1e-6);
    let yard = mesh.group_index("yard").unwrap();
    for f in mesh.faces.iter().filter(|f| f.group == yard) {
        assert_eq!(f.vertices.len(), 3);
        let [a, b, c] = [0, 1, 2].map(|k| mesh.positions[f.vertices[k] as usize]);
        assert!((b - a).cross(c - a).z > 0.0, "facing up, as the ring");
    }
}

#[test]
fn a_template_is_placed_by_its_matrix_at_its_reference_point() {
    let mesh = block();
    let (_, tree) = mesh.split_off_group("tree-1").unwrap();
    assert!(tree.is_closed_oriented());
    assert!((tree.signed_volume() - 32.0).abs() < 1e-6);
    let (lo, hi) = tree.bounds().unwrap();
    let at = DVec3::new(85_045.0, 446_020.0, 0.0);
    assert_eq!(
        (lo, hi),
        (
            at - DVec3::new(2.0, 2.0, 0.0),
            at + DVec3::new(2.0, 2.0, 6.0)
        )
    );
}

#[test]
fn load_reads_json_as_cityjson() {
    let dir = std::env::temp_dir().join(format!("cityjson-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("block.CITY.JSON");
    std::fs::write(&path, BLOCK).unwrap();
    assert_eq!(crate::load(&path).unwrap(), block());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `BLOCK` with `from` replaced by `to` once (which must change it).
fn broken(from: &str, to: &str) -> String {
    assert!(BLOCK.contains(from), "{from}");
    BLOCK.replacen(from, to, 1)
}

#[test]
fn malformed_files_are_refused_with_the_place_in_the_file() {
    let cases = [
        (
            broken(
                r#""boundaries":[[[0,1,2,3]"#,
                r#""boundaries":[[[0,1,2,99]"#,
            ),
            "/CityObjects/yard/geometry/0/boundaries/0/0/3: vertex 99 out of range (0..=39)",
        ),
        (
            broken(r#""type":"CityJSON""#, r#""type":"FeatureCollection""#),
            "/type: `FeatureCollection`, not a CityJSON document",
        ),
        (
            broken(r#""scale":[0.001,0.001,0.001]"#, r#""scale":[0.001,0.001]"#),
            "/transform/scale: three finite numbers expected",
        ),
        (
            broken(
                r#""type":"Solid","lod":"2""#,
                r#""type":"Solidd","lod":"2""#,
            ),
            "/CityObjects/tower-part/geometry/0/type: unknown geometry type `Solidd`",
        ),
        (
            broken(r#""lod":"2.2""#, r#""lod":"LoD2""#),
            "/CityObjects/house/geometry/1/lod: `LoD2` is not a level of detail",
        ),
        (
            broken(r#""template":0"#, r#""template":3"#),
            "/CityObjects/tree-1/geometry/0/template: template 3 out of range (0..1)",
        ),
        (
            broken(r#"[[[0,1,4]]"#, r#"[[[0,1]]"#),
            "/geometry-templates/templates/0/boundaries/0/0: a ring of 2 vertices",
        ),
        (
            broken(r#""CityObjects":{"#, r#""CityObjectz":{"#),
            "/CityObjects: missing",
        ),
    ];
    for (text, message) in cases {
        let e = parse_cityjson(&text, "b.json").unwrap_err();
        assert_eq!(e.to_string(), format!("b.json: {message}"));
    }
    let e = parse_cityjson("{\"type\": \"CityJSON\",\n  \"vertices\": [1,}", "b.json").unwrap_err();
    assert_eq!(e.line(), Some(2));
    assert!(e.to_string().starts_with("b.json:2: not JSON: "), "{e}");
    let none = r#"{"type":"CityJSON","vertices":[],"CityObjects":{"a":{"type":"Building"}}}"#;
    let e = parse_cityjson(none, "b.json").unwrap_err();
    assert_eq!(e.to_string(), "b.json: no city object has a surface");
}

#[test]
fn a_byte_order_mark_is_read_past() {
    let bom = format!("\u{feff}{BLOCK}");
    assert_eq!(parse_cityjson(&bom, "block.city.json").unwrap(), block());
}
