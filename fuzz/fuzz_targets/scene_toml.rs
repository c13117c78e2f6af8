//! The scene loader on TOML text (heron::fuzzing::scene), files read from fuzz/fixtures.
#![no_main]
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    heron::fuzzing::scene(
        data,
        Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/fixtures")),
    );
});
