//! Exact shadows on decoded scenes and lights: the fast path's fragments
//! tile every face and carry the ray oracle's flags, and Chin & Feiner's
//! give the same exact area per face and flags. The case and the oracle
//! are svbsp's test suite's own files, included by path.
#![no_main]

use libfuzzer_sys::fuzz_target;

#[allow(dead_code)]
#[path = "../../svbsp/tests/suite/oracle.rs"]
mod oracle;
#[allow(dead_code)]
#[path = "../../svbsp/tests/suite/harness.rs"]
mod harness;
#[allow(dead_code)]
#[path = "../../svbsp/tests/suite/scenes.rs"]
mod scenes;
#[path = "../../svbsp/tests/suite/fuzzcase.rs"]
mod fuzzcase;

fuzz_target!(|data: &[u8]| {
    fuzzcase::shadows_case(data);
});
