//! The Rust side of `scripts/python_bench.py`: the seconds of
//! `bsp_shadows::union` on two meshes already in memory, `REPS` times.
//!
//! ```sh
//! cargo run --release -p bsp-shadows --example union_time -- A.obj B.obj 5
//! ```

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let [_, a, b, reps] = &args[..] else {
        return Err("usage: union_time A.obj B.obj REPS".into());
    };
    let (a, b) = (bsp_shadows::read_mesh(a)?, bsp_shadows::read_mesh(b)?);
    for _ in 0..reps.parse::<usize>()? {
        let t = std::time::Instant::now();
        let u = bsp_shadows::union(&a, &b)?;
        println!("{} {}", t.elapsed().as_secs_f64(), u.faces.len());
    }
    Ok(())
}
