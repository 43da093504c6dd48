//! Splits a decoded convex polygon by decoded planes and checks every
//! piece exactly; see `bsp_testkit::split_case`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| bsp_testkit::split_case(data));
