//! Splits a decoded convex polygon by decoded planes and checks every
//! piece exactly; see `bsp_core::check::split_case`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| bsp_core::check::split_case(data));
