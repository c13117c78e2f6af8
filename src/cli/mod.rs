//! The command line's pieces: one file per subcommand (its flags and its `run`), and
//! here the parser, the flags several subcommands share, and their helpers.
use anyhow::Result;
use clap::{Parser, Subcommand};
use heron::scene::load_scene;
use heron::spectrum::display::{DisplayMode, DisplayTransform};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::path::{Path, PathBuf};

pub(crate) mod bench;
pub(crate) mod color;
pub(crate) mod compare;
pub(crate) mod converge;
pub(crate) mod convert;
pub(crate) mod display;
pub(crate) mod halo;
pub(crate) mod info;
pub(crate) mod lens;
pub(crate) mod merge;
pub(crate) mod render;
pub(crate) mod sky;
pub(crate) mod stress;
pub(crate) mod trace;
pub(crate) mod view;

#[derive(Parser)]
#[command(
    name = "heron",
    version = heron::provenance::LONG_VERSION,
    about = "A physically faithful spectral ray tracer for optics research"
)]
pub(crate) struct Cli {
    #[command(subcommand)]
    pub(crate) command: Command,
}

// Parsed once per run: the size of the largest variant costs nothing.
#[allow(clippy::large_enum_variant)]
#[derive(Subcommand)]
pub(crate) enum Command {
    /// Render a scene file to OpenEXR (linear sRGB) and an sRGB PNG preview, or (with -o
    /// FILE.heronfilm, e.g. one shard of a render) to a film file for heron merge.
    Render(render::RenderArgs),
    /// Convert a Mitsuba 3 (.xml) or pbrt-v4 (.pbrt) scene to heron's TOML: the scene heron renders from it,
    /// opened by a comment listing what was not carried over as written (also printed as
    /// warnings).
    Convert(convert::ConvertArgs),
    /// Merge the film files of a sharded render (heron render --shard K/N -o
    /// part-K.heronfilm) into its EXR and PNG: byte-identical to one heron render with all
    /// the samples, whatever the number of shards and the order of the parts.
    Merge(merge::MergeArgs),
    /// Follow one ray at one wavelength through a scene and print its events as JSON.
    Trace(trace::TraceArgs),
    /// Run time against error: render a reference, then each (lanes, spp) setting, and
    /// print CSV of wall time, time per sample and relative RMSE.
    Converge(converge::ConvergeArgs),
    /// Measure throughput.
    #[command(subcommand)]
    Bench(bench::BenchCommand),
    /// Print the CIE XYZ, xy and linear sRGB of a spectral distribution CSV as JSON.
    Color(color::ColorArgs),
    /// Are two renders the same image up to noise? A z-test of the mean difference per
    /// region and channel (R, G, B), with standard errors from the EXRs' variance
    /// channels (heron render --variance) or from the spread within each region. Exits 0
    /// (same), 1 (different) or 2 (cannot compare).
    Compare(compare::CompareArgs),
    /// Encode linear colours for display as the PNG preview does: an EXR's R, G, B (linear
    /// sRGB, as heron render writes them) into a PNG, or the X, Y, Z columns of a CSV into
    /// encoded sRGB rows (sR,sG,sB), e.g. for figures.
    Display(display::DisplayCmdArgs),
    /// Print the provenance heron wrote into an EXR: version, scene and input hashes,
    /// integrator, sampler, spp, seed, lanes, wavelengths (one `key: value` per line).
    Info {
        /// An EXR written by heron render.
        exr: PathBuf,
    },
    /// Random rays at the numerical edge cases of a scene's materials (grazing incidence,
    /// the edge of total internal reflection) and shapes (grazing hits, continuations
    /// leaving them); counts non-finite values, non-unit directions, self-intersections
    /// and light leaks, and exits with status 3 if there is any.
    Stress(stress::StressArgs),
    /// Rainbow skies: radiance profiles of the sky models (heron::sky).
    #[command(subcommand)]
    Sky(sky::SkyCommand),
    /// Ice-crystal halos: profiles of the halo sky (heron::sky::halo).
    #[command(subcommand)]
    Halo(halo::HaloCommand),
    /// A lens prescription's optics from heron's own lens code: first order (EFL, BFL,
    /// f-number, pupils) at F, d and C, the chromatic focal shift over 400–700 nm and
    /// real-ray spot diagrams per field angle and wavelength; with --out, as CSV files
    /// and PNG plots.
    Lens(lens::LensArgs),
    /// Look at EXRs in the browser: exposure, display transform, channels (RGB, spectral
    /// bins, S0–S3, DoLP/AoLP, standard error), a pixel's values and spectrum, A/B flip,
    /// heron compare's z-map and the provenance; served on 127.0.0.1 only.
    View(view::ViewArgs),
    /// The scene's spectra (reflectances, emissions, indices) on heron's 1 nm grid as
    /// JSON, for tests/python/test_mitsuba.py.
    #[command(hide = true)]
    Spectra {
        /// Scene file (TOML).
        scene: PathBuf,
    },
}

/// How a scene in another renderer's format is imported (heron render, heron convert).
#[derive(clap::Args, Clone, Default)]
pub(crate) struct ImportArgs {
    /// Scenes in another renderer's format (.xml, .pbrt): fail on the first element or parameter
    /// heron does not carry over, instead of warning.
    #[arg(long)]
    strict: bool,
    /// Mitsuba 3 XML: set the parameter $NAME (as Mitsuba's -D NAME=VALUE), overriding the
    /// file's <default>. Repeatable.
    #[arg(short = 'D', long = "define", value_name = "NAME=VALUE", value_parser = parse_define)]
    define: Vec<(String, String)>,
}

pub(crate) fn parse_define(s: &str) -> Result<(String, String), String> {
    match s.split_once('=') {
        Some((k, v)) if !k.is_empty() => Ok((k.to_string(), v.to_string())),
        _ => Err(format!("expected NAME=VALUE, got {s:?}")),
    }
}

impl ImportArgs {
    pub(crate) fn options(&self) -> heron::scene::import::ImportOptions {
        heron::scene::import::ImportOptions {
            strict: self.strict,
            defines: self.define.iter().cloned().collect(),
        }
    }
}

/// The scene at `path`: heron's TOML, or a converted scene of another format (its
/// warnings printed).
pub(crate) fn load_any_scene(
    path: &Path,
    import: &ImportArgs,
) -> anyhow::Result<heron::scene::Scene> {
    use heron::scene::import::{import_scene, Format};
    if Format::of(path) == Format::Heron {
        if import.strict || !import.define.is_empty() {
            anyhow::bail!("--strict and --define apply to scenes in another renderer's format (.xml, .pbrt), not to heron's TOML");
        }
        return Ok(load_scene(path)?);
    }
    let imported = import_scene(path, &import.options())?;
    for w in &imported.warnings {
        eprintln!("warning: {w}");
    }
    let scene = heron::scene::load::load_imported(&imported)?;
    for w in &scene.warnings {
        eprintln!("warning: {w}");
    }
    Ok(scene)
}

pub(crate) fn parse_vec3(s: &str) -> std::result::Result<[f32; 3], String> {
    let v: Vec<&str> = s.split(',').collect();
    if v.len() != 3 {
        return Err(format!("expected X,Y,Z (three numbers), got {s:?}"));
    }
    let mut out = [0.0; 3];
    for (o, t) in out.iter_mut().zip(v) {
        *o = t
            .trim()
            .parse::<f32>()
            .ok()
            .filter(|x| x.is_finite())
            .ok_or_else(|| format!("expected a finite number, got {t:?}"))?;
    }
    Ok(out)
}

pub(crate) fn parse_size(s: &str) -> std::result::Result<(u32, u32), String> {
    let bad = || format!("expected W,H (two positive integers), got {s:?}");
    let (w, h) = s.split_once(',').ok_or_else(bad)?;
    let w: u32 = w.trim().parse().map_err(|_| bad())?;
    let h: u32 = h.trim().parse().map_err(|_| bad())?;
    if w == 0 || h == 0 || w > 16384 || h > 16384 {
        return Err(bad());
    }
    Ok((w, h))
}

/// How linear colours become the PNG's (heron::spectrum::display).
#[derive(clap::Args)]
pub(crate) struct DisplayFlags {
    /// How colours outside the sRGB gamut are shown: hue (colours inside stay as they
    /// are; the others get white added until no channel is negative, which keeps their
    /// dominant wavelength, then, if still over range, are moved at constant Oklab hue
    /// toward mid-grey until they fit, Ottosson 2021) or clip (each channel clipped to
    /// [0, 1]).
    #[arg(long, default_value = "hue", value_parser = clap::builder::PossibleValuesParser::new(DisplayMode::NAMES))]
    display: String,
    /// Exposure in stops: linear values are multiplied by 2^EV before the display
    /// transform (0: as rendered).
    #[arg(
        long,
        value_name = "EV",
        default_value_t = 0.0,
        allow_hyphen_values = true
    )]
    exposure: f64,
}

impl DisplayFlags {
    pub(crate) fn transform(&self) -> Result<DisplayTransform> {
        let mode =
            DisplayMode::parse(&self.display).map_err(|e| anyhow::anyhow!("--display: {e}"))?;
        DisplayTransform::new(mode, self.exposure).map_err(|e| anyhow::anyhow!("--exposure: {e}"))
    }
}

pub(crate) fn display(p: &Path) -> String {
    p.display().to_string()
}

pub(crate) fn progress_bar(quiet: bool) -> Option<ProgressBar> {
    if quiet {
        return None;
    }
    let bar = ProgressBar::with_draw_target(Some(1), ProgressDrawTarget::stderr());
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {bar:40} {pos}/{len} tiles, ETA {eta}",
        )
        .ok()?,
    );
    Some(bar)
}
