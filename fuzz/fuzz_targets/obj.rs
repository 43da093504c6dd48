//! The OBJ reader on arbitrary bytes: no panic, faces index their own positions, errors name the file; see `bsp_testkit::obj_case`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    bsp_testkit::obj_case(data);
});
