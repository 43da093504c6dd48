//! Integration tests of `svbsp`, one binary: every fragment's flags
//! against an exact ray-casting oracle, and the exact tiling of every face,
//! on hand-made degenerate scenes (`special`), random scenes (`random`,
//! proptest) and real meshes (`meshes`). The oracle (`oracle`) is written
//! from scratch on big integers and rationals; `harness` runs a scene
//! through the tree build and the shadows and applies every check.
//!
//! The modules live in `suite/` rather than next to this file because
//! Cargo would build every `tests/*.rs` as a test binary of its own.

#[path = "suite/area.rs"]
mod area;
#[path = "suite/fuzzcase.rs"]
mod fuzzcase;
#[path = "suite/harness.rs"]
mod harness;
#[path = "suite/meshes.rs"]
mod meshes;
#[path = "suite/oracle.rs"]
mod oracle;
#[path = "suite/random.rs"]
mod random;
#[path = "suite/scenes.rs"]
mod scenes;
#[path = "suite/special.rs"]
mod special;
