//! The PLY reader and a mesh entry's triangles (heron::fuzzing::ply).
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    heron::fuzzing::ply(data);
});
