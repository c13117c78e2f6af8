//! `heron color`: CIE XYZ, xy and linear sRGB of a spectral distribution.
use anyhow::Result;
use std::path::PathBuf;

/// `heron color`; the formulas are in the heron::colorimetry documentation.
#[derive(clap::Args)]
pub(crate) struct ColorArgs {
    /// CSV of rows `wavelength_nm,value` (optional header line, # comments).
    file: PathBuf,
    /// D65, D50, A or E: the file is a reflectance, XYZ = Σ R·I·x̄ / Σ I·ȳ (white has
    /// Y = 1); none: the file is emitted, XYZ = Σ S·x̄ / Σ ȳ (the constant 1 has Y = 1).
    #[arg(long, default_value = "D65")]
    illuminant: heron::colorimetry::Illuminant,
    /// CIE standard observer: 1931 (2°) or 1964 (10°).
    #[arg(long, default_value = "1931")]
    observer: heron::colorimetry::StandardObserver,
    /// How the rows go onto the 1 nm grid: cie167 (Sprague for uniform rows, a cubic
    /// spline otherwise, as colour-science by default) or linear (straight lines, as
    /// colour-science interpolates the illuminants of its SDS_ILLUMINANTS).
    #[arg(long, default_value = "cie167")]
    interpolation: heron::spectrum::interp::Interpolation,
}

pub(crate) fn run(a: ColorArgs) -> Result<()> {
    let report =
        heron::colorimetry::color_file(&a.file, a.observer, a.illuminant, a.interpolation)?;
    println!("{}", serde_json::to_string_pretty(&report)?);
    for note in &report.notes {
        eprintln!("note: {note}");
    }
    Ok(())
}
