//! Writes a shadow-art job from a closed mesh: its silhouettes under
//! three suns along the axes (the pixels its exact shadow covers at least
//! half of), as PGM images on three walls around it, and the SPEC. Their
//! hull gives each silhouette back but for boundary pixels.
//!
//! ```text
//! cargo run --release -p bsp-shadows --example art_silhouettes -- MESH DIR [SIZE]
//! shadow art DIR/spec.json -o hull.obj --report hull.json
//! ```

use bsp_shadows::DVec3;
use bsp_shadows::art::{ArtLight, ArtView, Mask, ViewPlane, shadow_coverage};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let (Some(mesh), Some(dir)) = (args.next(), args.next()) else {
        return Err("usage: art_silhouettes MESH DIR [SIZE]".into());
    };
    let n: u32 = args.next().and_then(|s| s.parse().ok()).unwrap_or(512);
    let dir = std::path::PathBuf::from(dir);
    std::fs::create_dir_all(&dir)?;
    let mesh = bsp_shadows::read_mesh(&mesh)?;
    let (lo, hi) = mesh.bounds().ok_or("an empty mesh")?;
    let side = (hi - lo).max_element() * 1.1;
    let px = side / f64::from(n);
    let c = (lo + hi) * 0.5 - DVec3::splat(side / 2.0);
    let gap = 0.1 * side;
    let walls = [
        (
            "x",
            DVec3::X,
            DVec3::new(lo.x - gap, c.y, c.z),
            DVec3::Y,
            DVec3::Z,
        ),
        (
            "y",
            DVec3::Y,
            DVec3::new(c.x, lo.y - gap, c.z),
            DVec3::Z,
            DVec3::X,
        ),
        (
            "z",
            DVec3::Z,
            DVec3::new(c.x, c.y, lo.z - gap),
            DVec3::X,
            DVec3::Y,
        ),
    ];
    let mut spec = String::from("{\"views\": [\n");
    for (i, (name, sun, origin, u, v)) in walls.into_iter().enumerate() {
        let plane = ViewPlane {
            origin,
            u: u * px,
            v: v * px,
        };
        let blank = Mask {
            width: n,
            height: n,
            wanted: vec![false; (n * n) as usize],
        };
        let view = ArtView {
            image: dir.join(name),
            light: ArtLight::Sun(sun),
            plane,
            mask: blank,
        };
        let cover = shadow_coverage(&mesh, &view)?;
        let mut pgm = format!("P5\n{n} {n}\n255\n").into_bytes();
        pgm.extend(cover.iter().map(|&c| if c >= 0.5 { 0u8 } else { 255 }));
        std::fs::write(dir.join(format!("{name}.pgm")), pgm)?;
        let v3 = |v: DVec3| format!("[{}, {}, {}]", v.x, v.y, v.z);
        spec += &format!(
            "  {{\"image\": \"{name}.pgm\", \"light\": {{\"sun\": {}}},\n   \"plane\": {{\"origin\": {}, \"u\": {}, \"v\": {}}}}}{}\n",
            v3(sun),
            v3(origin),
            v3(plane.u),
            v3(plane.v),
            if i < 2 { "," } else { "" }
        );
    }
    let (a, b) = (lo - DVec3::splat(gap / 2.0), hi + DVec3::splat(gap / 2.0));
    spec += &format!(
        " ],\n \"bounds\": [[{}, {}, {}], [{}, {}, {}]]}}\n",
        a.x, a.y, a.z, b.x, b.y, b.z
    );
    std::fs::write(dir.join("spec.json"), spec)?;
    println!(
        "wrote {}/spec.json and x.pgm, y.pgm, z.pgm ({n}x{n})",
        dir.display()
    );
    Ok(())
}
