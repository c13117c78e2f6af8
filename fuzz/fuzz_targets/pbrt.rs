//! The pbrt-v4 importer and the scene it becomes (heron::fuzzing::pbrt).
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    heron::fuzzing::pbrt(
        data,
        std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/fixtures")),
    );
});
