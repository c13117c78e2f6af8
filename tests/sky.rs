//! Rainbow sky models (heron::sky): the Aristotelian bow of the seed, Descartes' geometric
//! optics, Airy theory, Lorenz–Mie, and a Monte Carlo check of the bows with heron's own
//! tracer.
use heron::sky::aristotle::{self, AristotleSky};

/// spectra/aristotle_bow.csv is what `aristotle::derive_texture_csv` writes. Regenerate
/// with `HERON_REGENERATE=1 cargo test --release --test sky aristotle_texture`.
#[test]
fn aristotle_texture_is_derived() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/spectra/aristotle_bow.csv");
    let want = aristotle::derive_texture_csv();
    if std::env::var_os("HERON_REGENERATE").is_some() {
        std::fs::write(path, &want).unwrap();
    }
    let have = std::fs::read_to_string(path).unwrap();
    assert!(
        have == want,
        "{path} is stale: regenerate it (see this test)"
    );
    let _ = AristotleSky::new(0.01, heron::spectrum::DenseSpectrum::constant(0.0));
}
