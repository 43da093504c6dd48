//! The real-time pipeline on decoded scenes, objects (some crossing
//! themselves) and motions: every frame equals the answer from scratch,
//! face by face and flag by flag, as exact rationals. The case and the
//! check are tiling's test files, included by path.
#![no_main]

use libfuzzer_sys::fuzz_target;

#[allow(dead_code)]
#[path = "../../tiling/tests/scratch.rs"]
mod scratch;
#[path = "../../tiling/tests/fuzzcase.rs"]
mod fuzzcase;

fuzz_target!(|data: &[u8]| {
    fuzzcase::pipeline_case(data);
});
