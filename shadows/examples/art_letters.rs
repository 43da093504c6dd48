//! Writes a shadow-art job: three block letters (G, E, B, as in Mitra &
//! Pauly's *Gödel, Escher, Bach*) as PGM images, each cast by a sun along
//! one axis onto a wall or the floor of a unit box, and the SPEC naming
//! them.
//!
//! ```text
//! cargo run --release -p bsp-shadows --example art_letters -- DIR [SIZE]
//! shadow art DIR/spec.json -o geb.obj --report geb_report.json --images DIR/views
//! ```

use std::fmt::Write;

/// The letters on a 5 × 7 grid of cells, `#` dark.
const LETTERS: [(&str, [&str; 7]); 3] = [
    (
        "G",
        [
            ".###.", "#...#", "#....", "#.###", "#...#", "#...#", ".###.",
        ],
    ),
    (
        "E",
        [
            "#####", "#....", "#....", "####.", "#....", "#....", "#####",
        ],
    ),
    (
        "B",
        [
            "####.", "#...#", "#...#", "####.", "#...#", "#...#", "####.",
        ],
    ),
];

/// A `size²` binary PGM of `cells`, the letter's 5 × 7 cells centred on an
/// 8 × 8 grid.
fn pgm(cells: &[&str; 7], size: usize) -> Vec<u8> {
    let mut out = format!("P5\n{size} {size}\n255\n").into_bytes();
    for r in 0..size {
        for c in 0..size {
            let (gc, gr) = (c * 8 / size, r * 8 / size);
            let dark = (1..6).contains(&gc) && gr < 7 && cells[gr].as_bytes()[gc - 1] == b'#';
            out.push(if dark { 0 } else { 255 });
        }
    }
    out
}

fn main() -> std::io::Result<()> {
    let mut args = std::env::args().skip(1);
    let dir = std::path::PathBuf::from(args.next().unwrap_or_else(|| "geb".into()));
    let size: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(512);
    std::fs::create_dir_all(&dir)?;
    for (name, cells) in LETTERS {
        std::fs::write(dir.join(format!("{name}.pgm")), pgm(&cells, size))?;
    }
    // the unit box; each image covers one side, one pixel 1/size wide,
    // its rows running down (or along -y on the floor), a quarter away
    let p = 1.0 / size as f64;
    let mut spec = String::from("{\"views\": [\n");
    let views = [
        (
            "G",
            "[1, 0, 0]",
            "[-0.25, 0, 1]",
            format!("[0, {p}, 0]"),
            format!("[0, 0, -{p}]"),
        ),
        (
            "E",
            "[0, -1, 0]",
            "[0, 1.25, 1]",
            format!("[{p}, 0, 0]"),
            format!("[0, 0, -{p}]"),
        ),
        (
            "B",
            "[0, 0, 1]",
            "[0, 1, -0.25]",
            format!("[{p}, 0, 0]"),
            format!("[0, -{p}, 0]"),
        ),
    ];
    for (i, (name, sun, origin, u, v)) in views.iter().enumerate() {
        let _ = write!(
            spec,
            "  {{\"image\": \"{name}.pgm\", \"light\": {{\"sun\": {sun}}},\n   \"plane\": {{\"origin\": {origin}, \"u\": {u}, \"v\": {v}}}}}{}\n",
            if i < 2 { "," } else { "" }
        );
    }
    spec += " ],\n \"bounds\": [[0, 0, 0], [1, 1, 1]]}\n";
    std::fs::write(dir.join("spec.json"), spec)?;
    println!(
        "wrote {}/spec.json and G.pgm, E.pgm, B.pgm ({size}x{size})",
        dir.display()
    );
    Ok(())
}
