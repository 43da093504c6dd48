//! The `shadows` fuzz target's case, shared with this suite (the target
//! includes these files by path, so the fuzzer runs the very oracle the
//! tests do): bytes decoded into a small scene and its lights
//! ([`crate::scenes`]), checked by [`crate::harness::check`]: the fast
//! path's fragments tile every face exactly and carry the ray oracle's
//! flags, and Chin & Feiner's fragments on two scene trees give exactly
//! the same area per face and set of flags. `cargo test` replays the
//! corpus in `fuzz/corpus/shadows`.

use bsp_fixtures::corpus::ByteReader;

use crate::harness::{Opts, check, polygons, scene_of};
use crate::scenes::{FaceGen, LightGen, P3, Transform, make_faces, make_lights};

/// The decoder's reads on top of [`ByteReader`].
struct Reader<'a>(ByteReader<'a>);

impl Reader<'_> {
    fn below(&mut self, n: u32) -> u32 {
        self.0.below(n)
    }

    fn int(&mut self, lo: i32, hi: i32) -> i32 {
        lo + self.below((hi - lo + 1) as u32) as i32
    }

    fn pt(&mut self, lo: i32, hi: i32) -> P3 {
        [(); 3].map(|()| self.int(lo, hi))
    }

    fn index(&mut self) -> usize {
        usize::from(self.0.byte())
    }
}

/// One face, weighted as the random tests weigh them.
fn face(b: &mut Reader) -> FaceGen {
    match b.below(10) {
        0..=2 => FaceGen::Triangle(b.pt(0, 6), b.pt(0, 6), b.pt(0, 6)),
        3..=4 => FaceGen::Parallelogram(b.pt(0, 6), b.pt(-3, 3), b.pt(-3, 3)),
        5..=6 => FaceGen::SharedEdge(b.index(), b.below(4) as usize, b.pt(0, 6)),
        7 => FaceGen::Coplanar(b.index(), [(); 3].map(|()| (b.int(-2, 2), b.int(-2, 2)))),
        8 => FaceGen::Copy(b.index()),
        _ => FaceGen::Flipped(b.index()),
    }
}

fn light(b: &mut Reader) -> LightGen {
    match b.below(9) {
        0..=2 => LightGen::Point(b.pt(-2, 8)),
        3 => LightGen::Far(b.pt(-3, 3)),
        4..=5 => LightGen::OnPlane(b.index(), b.int(-2, 3), b.int(-2, 3)),
        6..=7 => LightGen::Sun(b.pt(-3, 3)),
        _ => LightGen::SunAlong(b.index(), b.int(-2, 2), b.int(-2, 2)),
    }
}

fn transform(b: &mut Reader) -> Transform {
    let t = |scale: i32, offset: P3| Transform { scale, offset };
    match b.below(7) {
        0..=3 => t(1, [0, 0, 0]),
        4 => t(1, [-(1 << 25), 1 << 24, 12_345]),
        5 => t((1 << 20) + 1, [-(1 << 25), 3, 1 << 24]),
        _ => t(1_234_567, [5_000_000, -(1 << 25), 0]),
    }
}

/// Decodes a scene and its lights from `data` and checks both shadow
/// algorithms against the oracle, panicking with the scene on any
/// disagreement. Returns whether a scene with faces came out.
pub(crate) fn shadows_case(data: &[u8]) -> bool {
    let mut b = Reader(ByteReader(data));
    let faces: Vec<FaceGen> = (0..3 + b.below(10)).map(|_| face(&mut b)).collect();
    let lights: Vec<LightGen> = (0..1 + b.below(3)).map(|_| light(&mut b)).collect();
    let t = transform(&mut b);
    let loops = make_faces(&faces, &t);
    if loops.is_empty() {
        return false;
    }
    let lights = make_lights(&lights, &loops, &t);
    let polys = polygons(&loops).unwrap_or_else(|e| panic!("{e}: {loops:?}"));
    let opts = Opts {
        seeds: vec![1, 2],
        ..Opts::default()
    };
    if let Err(e) = check(&polys, &scene_of(&loops), &lights, &opts) {
        panic!("{e}\nloops: {loops:?}\nlights: {lights:?}");
    }
    true
}

#[cfg(test)]
mod tests {
    use bsp_fixtures::corpus::{replay, seed_bytes, write_seeds};

    use super::*;

    fn seeds() -> Vec<Vec<u8>> {
        seed_bytes(0x5eed_5ad0_0ca5_e5e5, 24, |i| 32 + 4 * i)
    }

    /// Rewrites `fuzz/corpus/shadows/seed-*`:
    /// `cargo test -p svbsp --release --test lib write_shadows_seeds -- --ignored`.
    #[test]
    #[ignore = "writes fuzz/corpus/shadows; run by hand after changing the decoder"]
    fn write_shadows_seeds() {
        write_seeds("shadows", &seeds());
    }

    /// Every file of the corpus (the seeds and what fuzzing kept) passes,
    /// and most of them are scenes.
    #[test]
    fn the_shadows_corpus_replays() {
        let (files, scenes) = replay("shadows", shadows_case);
        assert!(files >= seeds().len(), "{files} files");
        assert!(scenes * 4 >= files * 3, "{scenes} scenes of {files} files");
    }
}
