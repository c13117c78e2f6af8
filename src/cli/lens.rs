//! `heron lens`: a lens prescription's first-order optics, focal shift and spots.
use anyhow::Result;
use std::path::PathBuf;

#[derive(clap::Args)]
pub(crate) struct LensArgs {
    /// The prescription: heron's TOML (lenses/*.toml) or a pbrt-v4 lens file (*.dat).
    prescription: PathBuf,
    /// Folder for paraxial.csv, focal_shift.csv, spots.csv, spot_points.csv,
    /// focal_shift.png and spots.png.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Field angles of the spot diagrams (degrees, comma-separated).
    // heron::lensdesign::DEFAULT_FIELDS, written as text so that the help shows it
    // comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "0,14,20")]
    fields: Vec<f64>,
    /// Points across the pupil's diameter of the spot diagrams' square grid.
    #[arg(long, default_value_t = heron::lensdesign::DEFAULT_RAYS)]
    rays: usize,
    /// The reference wavelength (nm) of the focus and the focal shift; default the
    /// prescription's (587.5618, the d line, unless it says otherwise).
    #[arg(long)]
    reference_wavelength: Option<f64>,
}

pub(crate) fn run(a: LensArgs) -> Result<()> {
    let sys = heron::scene::load::lens::read_prescription(&a.prescription)
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    let report = heron::lensdesign::analyse(&sys, &a.fields, a.rays, a.reference_wavelength)?;
    if let Some(dir) = &a.out {
        report.write(dir)?;
    }
    print!("{}", report.summary());
    Ok(())
}
