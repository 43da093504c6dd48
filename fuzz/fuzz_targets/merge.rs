//! Merges two decoded solids with a decoded operation and checks the result
//! exactly; see `bsp_testkit::merge_case`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| bsp_testkit::merge_case(data));
