//! `heron compare`: are two renders the same image up to noise?
use super::display;
use anyhow::Result;
use std::path::PathBuf;

#[derive(clap::Args)]
pub(crate) struct CompareArgs {
    /// The first image (OpenEXR with R, G, B).
    a: PathBuf,
    /// The second image, the reference of the relative errors.
    b: PathBuf,
    /// Region edge in pixels (the last region of a row or column takes the remainder).
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u32).range(1..))]
    region: u32,
    /// Family-wise significance level: the chance that two renders of one image are
    /// called different.
    #[arg(long, default_value_t = 0.01)]
    alpha: f64,
    /// How alpha is split among the tests: sidak (1 − (1 − alpha)^(1/m)) or bonferroni
    /// (alpha/m).
    #[arg(long, default_value = "sidak", value_parser = clap::builder::PossibleValuesParser::new(heron::compare::Correction::NAMES))]
    correction: String,
    /// An equivalence margin: mean differences within this fraction of the two images'
    /// means are allowed and only the excess is held to the noise (0: the plain
    /// z-test). For an estimator biased by a stated bound, e.g. 0.05 for sppm (tests/agree.rs).
    #[arg(long, default_value_t = 0.0, value_name = "FRACTION")]
    tolerance: f64,
    /// Write a PNG heat map of the regions' z-scores (red: A brighter, blue: B brighter;
    /// failing regions outlined).
    #[arg(long, value_name = "PNG")]
    heatmap: Option<PathBuf>,
    /// List at most this many failing tests.
    #[arg(long, default_value_t = 20)]
    max_listed: usize,
}

/// `heron compare`: prints the report; status 0 (same), 1 (different), and errors
/// (status 2) through `main`.
pub(crate) fn run(a: CompareArgs) -> Result<()> {
    use heron::compare::{compare, Correction, Image, Options};
    let opts = Options {
        region: a.region,
        alpha: a.alpha,
        correction: Correction::parse(&a.correction).map_err(anyhow::Error::msg)?,
        mask: None,
        tolerance: a.tolerance,
    };
    opts.check().map_err(anyhow::Error::msg)?;
    if let Some(h) = &a.heatmap {
        heron::session::check_output(h, &["png"]).map_err(|e| {
            anyhow::anyhow!("{}", e.to_string().replacen("--output", "--heatmap", 1))
        })?;
    }
    let (ia, ib) = (Image::read_exr(&a.a)?, Image::read_exr(&a.b)?);
    let c = compare(&ia, &ib, &opts)
        .map_err(|e| anyhow::anyhow!("{} and {}: {e}", display(&a.a), display(&a.b)))?;
    print!("{}", c.report(&display(&a.a), &display(&a.b), a.max_listed));
    if let Some(h) = &a.heatmap {
        c.write_heat_map(h, None)?;
    }
    if !c.same() {
        std::process::exit(1);
    }
    Ok(())
}
