//! Booleans of decoded unions of integer boxes (overlapping, nested, touching, inward, sheared), checked cell by cell and by exact volume, and of UV spheres (overlapping, copied, moved below the grid step, nested), checked by exact volume identities and probe windings; see `bsp_testkit::mesh_boolean_case`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    bsp_testkit::mesh_boolean_case(data);
});
