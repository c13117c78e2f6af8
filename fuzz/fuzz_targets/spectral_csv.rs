//! The spectral CSV readers and the interpolation onto the 1 nm grid
//! (heron::fuzzing::spectral_csv).
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    heron::fuzzing::spectral_csv(data);
});
