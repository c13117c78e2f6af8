//! The Mitsuba 3 XML importer and the scene it becomes (heron::fuzzing::mitsuba_xml).
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    heron::fuzzing::mitsuba_xml(
        data,
        std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/fixtures")),
    );
});
