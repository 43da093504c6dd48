//! Builds a BSP tree of a decoded polygon soup or box and checks the tree,
//! its traversals and point membership; see `bsp_testkit::build_case`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| bsp_testkit::build_case(data));
