//! The OBJ reader and a mesh entry's triangles (heron::fuzzing::obj).
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    heron::fuzzing::obj(data);
});
