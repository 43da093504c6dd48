//! The `pipeline` fuzz target's case, shared with the tests (the target
//! includes this file and `scratch.rs` by path): bytes decoded into a
//! ground with blocks, a moving object (a tetrahedron, or two tetrahedra
//! touching along an edge whose faces through it cross, which the
//! culling certificate must refuse), lights and a motion; every frame
//! must give every face exactly the lit area per set of flags that the
//! answer from scratch gives ([`crate::scratch::check_motion`]).
//! `cargo test` replays the corpus in `fuzz/corpus/pipeline`.

use bsp_fixtures::corpus::ByteReader;
use glam::DVec3;
use svbsp::LightSpec;
use tiling::{Motion, Strategy};

use crate::scratch::{check_motion, crossing, ground, tetra};

/// The decoder's reads on top of [`ByteReader`].
struct Reader<'a>(ByteReader<'a>);

impl Reader<'_> {
    fn byte(&mut self) -> u8 {
        self.0.byte()
    }

    /// A number in `lo..=hi` in 256 steps.
    fn num(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * f64::from(self.byte()) / 255.0
    }

    fn vec(&mut self, lo: f64, hi: f64) -> DVec3 {
        DVec3::new(self.num(lo, hi), self.num(lo, hi), self.num(lo, hi))
    }
}

/// Decodes a scene, its lights and a motion from `data` and checks every
/// frame against the answer from scratch (panicking on a difference).
pub(crate) fn pipeline_case(data: &[u8]) {
    let mut b = Reader(ByteReader(data));
    let mut statics = vec![ground()];
    for _ in 0..1 + b.byte() % 4 {
        let lo = b.vec(-4.0, 4.0) * DVec3::new(1.0, 1.0, 0.0) + DVec3::Z * b.num(0.0, 2.0);
        statics.extend(bsp_fixtures::cuboid(lo, lo + b.vec(0.2, 1.5)));
    }
    let at = b.vec(-2.0, 2.0) * DVec3::new(1.0, 1.0, 0.0) + DVec3::Z * b.num(0.3, 2.3);
    let object = match b.byte() % 3 {
        0 => crossing(at, b.num(0.1, 0.4)),
        _ => tetra(at, 0.7),
    };
    let light = b.vec(-3.0, 3.0) * DVec3::new(1.0, 1.0, 0.0) + DVec3::Z * b.num(4.0, 7.0);
    let mut lights = vec![LightSpec::Point(light)];
    if b.byte() % 2 == 1 {
        lights.push(LightSpec::Sun(DVec3::new(0.4, -0.3, 1.0)));
    }
    let motion = Motion {
        axis: b.vec(-1.0, 1.0) + DVec3::Z * 1e-3,
        degrees: b.num(-90.0, 90.0),
        centre: DVec3::new(at.x, at.y, 1.0),
        step: b.vec(-0.8, 0.8) * DVec3::new(1.0, 1.0, 0.3),
    };
    let strategy = match b.byte() % 2 {
        0 => Strategy::Fast,
        _ => Strategy::Paper,
    };
    let tiles = [None, Some(1), Some(3), Some(17)][usize::from(b.byte() % 4)];
    check_motion(&statics, &object, &lights, &motion, 3, strategy, tiles);
}

#[cfg(test)]
mod tests {
    use bsp_fixtures::corpus::{replay, seed_bytes, write_seeds};

    use super::*;

    fn seeds() -> Vec<Vec<u8>> {
        seed_bytes(0x0b1e_c7ed_5eed_0001, 12, |_| 40)
    }

    /// Rewrites `fuzz/corpus/pipeline/seed-*`:
    /// `cargo test -p tiling --release --test lib write_pipeline_seeds -- --ignored`.
    #[test]
    #[ignore = "writes fuzz/corpus/pipeline; run by hand after changing the decoder"]
    fn write_pipeline_seeds() {
        write_seeds("pipeline", &seeds());
    }

    /// Every file of the corpus (the seeds and what fuzzing kept) passes.
    #[test]
    fn the_pipeline_corpus_replays() {
        let (files, _) = replay("pipeline", |data| {
            pipeline_case(data);
            true
        });
        assert!(files >= seeds().len(), "{files} files");
    }
}
