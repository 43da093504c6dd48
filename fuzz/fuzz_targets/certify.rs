//! The culling certificate on decoded folded, crossing and nested
//! surfaces: a certified one never has a negative winding number; see
//! `bsp_testkit::certify_case`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    bsp_testkit::certify_case(data);
});
