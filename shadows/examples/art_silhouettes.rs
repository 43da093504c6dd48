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
use bsp_shadows::art::{ArtLight, axis_silhouettes};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let (Some(mesh), Some(dir)) = (args.next(), args.next()) else {
        return Err("usage: art_silhouettes MESH DIR [SIZE]".into());
    };
    let n: u32 = args.next().and_then(|s| s.parse().ok()).unwrap_or(512);
    let dir = std::path::PathBuf::from(dir);
    std::fs::create_dir_all(&dir)?;
    let mesh = bsp_shadows::read_mesh(&mesh)?;
    let views = axis_silhouettes(&mesh, n)?;
    let mut spec = String::from("{\"views\": [\n");
    let v3 = |v: DVec3| format!("[{}, {}, {}]", v.x, v.y, v.z);
    for (i, view) in views.views.iter().enumerate() {
        let name = view.image.display().to_string();
        let mut pgm = format!("P5\n{n} {n}\n255\n").into_bytes();
        pgm.extend(view.mask.wanted.iter().map(|&w| if w { 0u8 } else { 255 }));
        std::fs::write(dir.join(&name), pgm)?;
        let (ArtLight::Sun(sun) | ArtLight::Point(sun)) = view.light;
        let p = view.plane;
        spec += &format!(
            "  {{\"image\": \"{name}\", \"light\": {{\"sun\": {}}},\n   \"plane\": {{\"origin\": {}, \"u\": {}, \"v\": {}}}}}{}\n",
            v3(sun),
            v3(p.origin),
            v3(p.u),
            v3(p.v),
            if i < 2 { "," } else { "" }
        );
    }
    let [a, b] = views.bounds;
    spec += &format!(" ],\n \"bounds\": [{}, {}]}}\n", v3(a), v3(b));
    std::fs::write(dir.join("spec.json"), spec)?;
    println!(
        "wrote {}/spec.json and x.pgm, y.pgm, z.pgm ({n}x{n})",
        dir.display()
    );
    Ok(())
}
