#![deny(unsafe_code)]
//! The heron command line.
use anyhow::{bail, Result};
use clap::{Parser, Subcommand};
use heron::film::{exr::stage_exr, png::stage_png};
use heron::render::{render_state, RenderOptions};
use heron::scene::load_scene;
use heron::settings::SettingsArgs;
use heron::spectrum::display::{DisplayMode, DisplayTransform};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::path::{Path, PathBuf};
use std::sync::Arc;

#[derive(Parser)]
#[command(
    name = "heron",
    version = heron::provenance::LONG_VERSION,
    about = "A physically faithful spectral ray tracer for optics research"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

// Parsed once per run: the size of the largest variant costs nothing.
#[allow(clippy::large_enum_variant)]
#[derive(Subcommand)]
enum Command {
    /// Render a scene file to OpenEXR (linear sRGB) and an sRGB PNG preview, or (with -o
    /// FILE.heronfilm, e.g. one shard of a render) to a film file for heron merge.
    Render(RenderArgs),
    /// Convert a Mitsuba 3 (.xml) or pbrt-v4 (.pbrt) scene to heron's TOML: the scene heron renders from it,
    /// opened by a comment listing what was not carried over as written (also printed as
    /// warnings).
    Convert(ConvertArgs),
    /// Merge the film files of a sharded render (heron render --shard K/N -o
    /// part-K.heronfilm) into its EXR and PNG: byte-identical to one heron render with all
    /// the samples, whatever the number of shards and the order of the parts.
    Merge(MergeArgs),
    /// Follow one ray at one wavelength through a scene and print its events as JSON.
    Trace(TraceArgs),
    /// Run time against error: render a reference, then each (lanes, spp) setting, and
    /// print CSV of wall time, time per sample and relative RMSE.
    Converge(ConvergeArgs),
    /// Measure throughput.
    #[command(subcommand)]
    Bench(BenchCommand),
    /// Print the CIE XYZ, xy and linear sRGB of a spectral distribution CSV as JSON.
    Color(ColorArgs),
    /// Are two renders the same image up to noise? A z-test of the mean difference per
    /// region and channel (R, G, B), with standard errors from the EXRs' variance
    /// channels (heron render --variance) or from the spread within each region. Exits 0
    /// (same), 1 (different) or 2 (cannot compare).
    Compare(CompareArgs),
    /// Encode linear colours for display as the PNG preview does: an EXR's R, G, B (linear
    /// sRGB, as heron render writes them) into a PNG, or the X, Y, Z columns of a CSV into
    /// encoded sRGB rows (sR,sG,sB), e.g. for figures.
    Display(DisplayCmdArgs),
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
    Stress(StressArgs),
    /// Rainbow skies: radiance profiles of the sky models (heron::sky).
    #[command(subcommand)]
    Sky(SkyCommand),
    /// A lens prescription's optics from heron's own lens code: first order (EFL, BFL,
    /// f-number, pupils) at F, d and C, the chromatic focal shift over 400–700 nm and
    /// real-ray spot diagrams per field angle and wavelength; with --out, as CSV files
    /// and PNG plots.
    Lens(LensArgs),
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
struct ImportArgs {
    /// Scenes in another renderer's format (.xml, .pbrt): fail on the first element or parameter
    /// heron does not carry over, instead of warning.
    #[arg(long)]
    strict: bool,
    /// Mitsuba 3 XML: set the parameter $NAME (as Mitsuba's -D NAME=VALUE), overriding the
    /// file's <default>. Repeatable.
    #[arg(short = 'D', long = "define", value_name = "NAME=VALUE", value_parser = parse_define)]
    define: Vec<(String, String)>,
}

fn parse_define(s: &str) -> Result<(String, String), String> {
    match s.split_once('=') {
        Some((k, v)) if !k.is_empty() => Ok((k.to_string(), v.to_string())),
        _ => Err(format!("expected NAME=VALUE, got {s:?}")),
    }
}

impl ImportArgs {
    fn options(&self) -> heron::scene::import::ImportOptions {
        heron::scene::import::ImportOptions {
            strict: self.strict,
            defines: self.define.iter().cloned().collect(),
        }
    }
}

/// The scene at `path`: heron's TOML, or a converted scene of another format (its
/// warnings printed).
fn load_any_scene(path: &Path, import: &ImportArgs) -> anyhow::Result<heron::scene::Scene> {
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
    Ok(heron::scene::load::load_imported(&imported)?)
}

#[derive(clap::Args)]
struct ConvertArgs {
    /// The scene: Mitsuba 3 XML (.xml) or pbrt-v4 (.pbrt).
    scene: PathBuf,
    /// The TOML file to write (mesh paths are written relative to its folder).
    #[arg(short, long)]
    output: PathBuf,
    #[command(flatten)]
    import: ImportArgs,
}

fn cmd_convert(a: ConvertArgs) -> anyhow::Result<()> {
    use heron::scene::import::{import_scene, Format};
    if Format::of(&a.scene) == Format::Heron {
        anyhow::bail!(
            "{}: expected a Mitsuba 3 (.xml) or pbrt-v4 (.pbrt) scene; heron's TOML needs no conversion",
            a.scene.display()
        );
    }
    let imported = import_scene(&a.scene, &a.import.options())?;
    for w in &imported.warnings {
        eprintln!("warning: {w}");
    }
    // The conversion must be a scene heron renders; its errors are found before writing.
    heron::scene::load::load_imported(&imported)?;
    let dir = match a.output.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let text = imported.to_toml(&dir);
    heron::files::write_atomically(&a.output, |tmp| {
        std::fs::write(tmp, &text).map_err(|e| e.to_string())
    })?;
    eprintln!(
        "{}: written, {} warning{}",
        a.output.display(),
        imported.warnings.len(),
        if imported.warnings.len() == 1 {
            ""
        } else {
            "s"
        }
    );
    Ok(())
}

#[derive(clap::Args)]
struct StressArgs {
    /// Scene file (TOML).
    scene: PathBuf,
    /// Rays per case (each material in each incidence regime, each shape).
    #[arg(long, default_value_t = 1_000_000, value_parser = clap::value_parser!(u64).range(1..))]
    rays: u64,
    /// Random seed.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Worker threads (default: one per core). The counts do not depend on it.
    #[arg(long, value_parser = clap::value_parser!(u16).range(1..))]
    threads: Option<u16>,
    /// The ray offsets of a render by this integrator (whitted, path, lighttrace, bdpt);
    /// default: the scene's.
    #[arg(long, value_parser = ["whitted", "path", "lighttrace", "bdpt"])]
    integrator: Option<String>,
    /// auto, epsilon or robust (as render --offset); default: the scene's render.offset.
    #[arg(long, value_parser = clap::builder::PossibleValuesParser::new(heron::settings::OffsetMode::NAMES))]
    offset: Option<String>,
}

#[derive(clap::Args)]
struct LensArgs {
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

fn cmd_lens(a: LensArgs) -> Result<()> {
    let sys = heron::scene::load::lens::read_prescription(&a.prescription)
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    let report = heron::lensdesign::analyse(&sys, &a.fields, a.rays, a.reference_wavelength)?;
    if let Some(dir) = &a.out {
        report.write(dir)?;
    }
    print!("{}", report.summary());
    Ok(())
}

#[derive(Subcommand)]
enum SkyCommand {
    /// CSV of radiance against the angle from the antisolar point (degrees), one column
    /// per wavelength. Units: dσ/dΩ/(πa²) per sr for descartes, airy and mie (see
    /// heron::sky); the texture's radiance for aristotle.
    Profile(Box<SkyProfileArgs>),
    /// Lee diagram: the bow's colour against drop radius (log-spaced) and angle from the
    /// antisolar point, from Lorenz–Mie theory under a D65 sun averaged over its disk, as
    /// CSV radius_mm,theta_deg,X,Y,Z,R,G,B (see heron::sky::lee).
    Lee(SkyLeeArgs),
    /// Mie amplitudes S1, S2 (Bohren & Huffman) of a sphere, for tests/python/test_mie.py.
    #[command(hide = true)]
    MiePhase {
        /// Real relative refractive index.
        #[arg(long)]
        m: f64,
        /// Size parameter 2πa/λ.
        #[arg(long)]
        x: f64,
        /// Scattering angles (degrees): from, to, step.
        #[arg(long, default_value_t = 0.0)]
        from: f64,
        #[arg(long, default_value_t = 180.0)]
        to: f64,
        #[arg(long, default_value_t = 1.0, allow_hyphen_values = true)]
        step: f64,
    },
    /// The phase table (p and F12, F33, F34 over F11) of a medium of one drop radius at
    /// one wavelength node, for tests/python/test_mie.py.
    #[command(hide = true)]
    MieMatrix {
        /// Drop radius, μm.
        #[arg(long, allow_hyphen_values = true)]
        radius_um: f64,
        /// Wavelength node, nm (360 to 830 in steps of 10).
        #[arg(long, allow_hyphen_values = true)]
        lambda: f64,
        /// With water's absorption (its imaginary index).
        #[arg(long)]
        absorption: bool,
    },
}

#[derive(clap::Args)]
struct SkyLeeArgs {
    /// Smallest drop radius, mm.
    #[arg(long, default_value_t = 0.01, allow_hyphen_values = true)]
    radius_from: f64,
    /// Largest drop radius, mm.
    #[arg(long, default_value_t = 1.0, allow_hyphen_values = true)]
    radius_to: f64,
    /// Number of radii, log-spaced.
    #[arg(long, default_value_t = 40)]
    radii: usize,
    /// First angle from the antisolar point, degrees.
    #[arg(long, default_value_t = 36.0, allow_hyphen_values = true)]
    from: f64,
    /// Last angle, degrees.
    #[arg(long, default_value_t = 44.0, allow_hyphen_values = true)]
    to: f64,
    /// Angle step, degrees.
    #[arg(long, default_value_t = 0.05, allow_hyphen_values = true)]
    step: f64,
    /// Wavelength step of the colour sums over 380–780 nm.
    #[arg(long, default_value_t = 10.0, allow_hyphen_values = true)]
    lambda_step: f64,
    /// Sun angular radius in degrees.
    #[arg(long, default_value_t = 0.2666, allow_hyphen_values = true)]
    sun_radius: f64,
    /// Output CSV (written atomically); default: standard output.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// How the R, G, B columns are encoded (the X, Y, Z columns do not change).
    #[command(flatten)]
    display: DisplayFlags,
}

#[derive(clap::Args)]
struct SkyProfileArgs {
    /// constant, aristotle, descartes, airy or mie.
    #[arg(long)]
    model: String,
    /// Sun angular radius in degrees.
    #[arg(long, default_value_t = 0.2666, allow_hyphen_values = true)]
    sun_radius: f64,
    /// Drop radius in mm (airy, mie; descartes does not depend on it).
    #[arg(long, allow_hyphen_values = true)]
    droplet_radius: Option<f64>,
    /// Wavelengths in nm, comma-separated.
    #[arg(long)]
    lambda: String,
    /// First angle from the antisolar point, degrees.
    #[arg(long, allow_hyphen_values = true)]
    from: f64,
    /// Last angle, degrees.
    #[arg(long, allow_hyphen_values = true)]
    to: f64,
    /// Angle step, degrees.
    #[arg(long, allow_hyphen_values = true)]
    step: f64,
    /// Internal reflections: 1, 2 or both (descartes, airy); descartes also 0 (external
    /// reflection) or all (0, 1 and 2).
    #[arg(long)]
    k: Option<String>,
    /// unpolarised, s or p (descartes, airy, mie).
    #[arg(long)]
    polarisation: Option<String>,
    /// Background radiance (constant: default 1; aristotle: default 0).
    #[arg(long, allow_hyphen_values = true)]
    background: Option<f64>,
    /// Drop-size distribution (airy, mie): monodisperse (radius --droplet-radius),
    /// lognormal (--median-mm, --sigma), gamma (--mode-mm, --mu) or marshall-palmer
    /// (--rain-rate-mm-h); see heron::drops.
    #[arg(long)]
    distribution: Option<String>,
    /// Log-normal: median radius, mm.
    #[arg(long, allow_hyphen_values = true)]
    median_mm: Option<f64>,
    /// Log-normal: standard deviation of ln a.
    #[arg(long, allow_hyphen_values = true)]
    sigma: Option<f64>,
    /// Gamma: mode radius, mm.
    #[arg(long, allow_hyphen_values = true)]
    mode_mm: Option<f64>,
    /// Gamma: shape μ (≥ 1).
    #[arg(long, allow_hyphen_values = true)]
    mu: Option<f64>,
    /// Marshall–Palmer: rain rate, mm/h.
    #[arg(long, allow_hyphen_values = true)]
    rain_rate_mm_h: Option<f64>,
    /// Quadrature nodes of the distribution (default 48; 16 for mie).
    #[arg(long, allow_hyphen_values = true)]
    nodes: Option<i64>,
    /// Only the Debye-series term p (mie): 0 external reflection and diffraction, 1
    /// direct transmission, 2 the primary bow, 3 the secondary, …
    #[arg(long)]
    debye: Option<u32>,
    /// Also draw the profile as a PNG chart (960×600, one line per wavelength), written
    /// atomically; the CSV still goes to standard output.
    #[arg(long)]
    plot: Option<PathBuf>,
}

/// The distribution flags as the scene table they mirror; a parameter without
/// `--distribution` is an error naming it.
fn drops_from_flags(
    distribution: Option<String>,
    [median_mm, sigma, mode_mm, mu, rain_rate_mm_h]: [Option<f64>; 5],
    nodes: Option<i64>,
) -> Result<Option<heron::drops::DropsFile>> {
    let Some(distribution) = distribution else {
        for (flag, v) in [
            ("--median-mm", median_mm),
            ("--sigma", sigma),
            ("--mode-mm", mode_mm),
            ("--mu", mu),
            ("--rain-rate-mm-h", rain_rate_mm_h),
        ] {
            if v.is_some() {
                anyhow::bail!("{flag}: needs --distribution");
            }
        }
        if nodes.is_some() {
            anyhow::bail!("--nodes: needs --distribution");
        }
        return Ok(None);
    };
    Ok(Some(heron::drops::DropsFile {
        distribution,
        radius_mm: None,
        median_mm,
        sigma,
        mode_mm,
        mu,
        rain_rate_mm_h,
        nodes,
    }))
}

fn cmd_sky(c: SkyCommand) -> Result<()> {
    let csv = match c {
        SkyCommand::Profile(a) => {
            let a = *a;
            if let Some(p) = &a.plot {
                heron::plot::check_path(p, "--plot")?;
            }
            let mut title = format!("heron sky profile: {}", a.model);
            if let Some(r) = a.droplet_radius {
                title += &format!(", drop radius {r} mm");
            }
            if let Some(d) = &a.distribution {
                title += &format!(", {d} drops");
            }
            title += &format!(", sun radius {}°", a.sun_radius);
            let model = a.model.clone();
            let profile = heron::sky::profile::profile(&heron::sky::profile::ProfileRequest {
                model: a.model,
                sun_radius_deg: a.sun_radius,
                droplet_radius_mm: a.droplet_radius,
                lambdas: a.lambda,
                from_deg: a.from,
                to_deg: a.to,
                step_deg: a.step,
                k: a.k,
                polarisation: a.polarisation,
                background: a.background,
                drops: drops_from_flags(
                    a.distribution,
                    [a.median_mm, a.sigma, a.mode_mm, a.mu, a.rain_rate_mm_h],
                    a.nodes,
                )?,
                debye: a.debye,
            })?;
            if let Some(p) = &a.plot {
                let chart = heron::plot::sky::chart(&title, &model, &profile);
                heron::plot::write_png(p, &chart, "--plot")?;
            }
            profile.csv()
        }
        SkyCommand::Lee(a) => {
            let csv = heron::sky::lee::lee_csv(&heron::sky::lee::LeeRequest {
                radius_from_mm: a.radius_from,
                radius_to_mm: a.radius_to,
                radii: a.radii,
                from_deg: a.from,
                to_deg: a.to,
                step_deg: a.step,
                lambda_step_nm: a.lambda_step,
                sun_radius_deg: a.sun_radius,
                display: a.display.transform()?,
            })?;
            match a.output {
                Some(path) => {
                    heron::sky::lee::write_csv(&path, &csv)?;
                    return Ok(());
                }
                None => csv,
            }
        }
        SkyCommand::MiePhase {
            m,
            x,
            from,
            to,
            step,
        } => heron::sky::profile::mie_phase_csv(m, x, from, to, step)?,
        SkyCommand::MieMatrix {
            radius_um,
            lambda,
            absorption,
        } => heron::medium::homogeneous::matrix_csv(radius_um, lambda, absorption)?,
    };
    print!("{csv}");
    Ok(())
}

#[derive(Subcommand)]
enum BenchCommand {
    /// Embree traversal throughput (Mrays/s) for primary and incoherent secondary rays
    /// on an OBJ, with a camera like Embree's `viewer --benchmark`.
    Traversal(TraversalArgs),
    /// Write the deterministic procedural test mesh (a bumpy sphere of 2·N² triangles,
    /// the one the criterion traversal bench uses) as OBJ, for side-by-side runs with
    /// Embree's own viewer.
    /// Record every query a render sends to Embree (rendered on one thread, so in the
    /// render's own order) to a ray log, for `heron bench replay`.
    Record(RecordArgs),
    /// Replay a ray log through a raw-Embree C program and through heron's wrapper,
    /// interleaved, checking that both find what the render found.
    Replay {
        /// The ray log (`heron bench record`).
        log: PathBuf,
        /// Timed replays of each (after one warm-up); the table reports medians.
        #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..))]
        rounds: u32,
    },
    /// Record a render's rays, then time the render (one thread) against the raw-Embree
    /// replay of those rays, interleaved: how far heron is from Embree's own speed.
    Limit(LimitArgs),
    Mesh {
        /// Grid resolution N; 708 gives about one million triangles.
        #[arg(long, default_value_t = 708, value_parser = clap::value_parser!(u32).range(4..=8192))]
        n: u32,
        /// Output OBJ path.
        #[arg(short, long)]
        output: PathBuf,
    },
}

/// The render a ray log records.
#[derive(clap::Args)]
struct RecordedRender {
    /// Scene file (TOML).
    scene: PathBuf,
    /// Samples per pixel (overrides the scene's render.spp).
    #[arg(long)]
    spp: Option<u32>,
    /// Random seed (overrides the scene's render.seed).
    #[arg(long)]
    seed: Option<u64>,
    /// Integrator (overrides the scene's render.integrator).
    #[arg(long, value_parser = ["whitted", "path", "lighttrace", "bdpt"])]
    integrator: Option<String>,
}

#[derive(clap::Args)]
struct RecordArgs {
    #[command(flatten)]
    render: RecordedRender,
    /// Output ray log (.rays).
    #[arg(short, long)]
    output: PathBuf,
}

#[derive(clap::Args)]
struct LimitArgs {
    #[command(flatten)]
    render: RecordedRender,
    /// Timed rounds of the render and the replays (after one warm-up); the table reports
    /// medians.
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..))]
    rounds: u32,
    /// Keep the ray log in this file (.rays; default: a temporary file, removed).
    #[arg(long)]
    keep: Option<PathBuf>,
}

#[derive(clap::Args)]
struct TraversalArgs {
    /// OBJ mesh; every object is loaded into one triangle mesh.
    #[arg(long)]
    mesh: PathBuf,
    /// Camera position X,Y,Z (Embree viewer: --vp).
    #[arg(long, value_parser = parse_vec3)]
    eye: [f32; 3],
    /// Point looked at X,Y,Z (Embree viewer: --vi).
    #[arg(long, value_parser = parse_vec3)]
    look_at: [f32; 3],
    /// Up vector X,Y,Z (Embree viewer: --vu).
    #[arg(long, value_parser = parse_vec3, default_value = "0,1,0")]
    up: [f32; 3],
    /// Vertical field of view in degrees (Embree viewer: --fov).
    #[arg(long, default_value_t = 90.0)]
    fov: f32,
    /// Image size W,H (Embree viewer: --size W H).
    #[arg(long, value_parser = parse_size, default_value = "1024,1024")]
    size: (u32, u32),
    /// How rays go to Embree, comma-separated: 1 (rtcIntersect1), 4, 8, 16 (packets) or
    /// stream (rtcIntersect1M, Embree 3 only).
    #[arg(long, default_value = "1,4,8,16,stream", value_delimiter = ',', value_parser = heron::bench::Width::parse)]
    widths: Vec<heron::bench::Width>,
    /// Timed passes per ray set and width (after one warm-up pass); the table reports
    /// medians.
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..))]
    rounds: u32,
    /// Also build (with gcc) and time a C program that traces the same rays through
    /// Embree's C API, interleaved with heron's passes; adds the raw-Embree column and
    /// heron's throughput as a fraction of it.
    #[arg(long)]
    raw: bool,
}

#[derive(clap::Args)]
struct ConvergeArgs {
    /// Scene file (TOML).
    scene: PathBuf,
    /// Samples per pixel of the reference (rendered with 8 lanes, independent numbers and
    /// seed + 1, as two halves whose difference estimates its own error).
    #[arg(long, default_value_t = 1024, value_parser = clap::value_parser!(u32).range(1..))]
    reference_spp: u32,
    /// The reference's integrator [default: the runs']: e.g. bdpt for a caustic that the
    /// measured integrator finds rarely.
    #[arg(long, value_name = "INTEGRATOR", value_parser = clap::builder::PossibleValuesParser::new(heron::settings::IntegratorKind::NAMES))]
    reference_integrator: Option<String>,
    /// Also measure the errors over this pixel rectangle: X0,Y0,X1,Y1, from the top-left,
    /// X0 <= x < X1 and Y0 <= y < Y1 (after --size).
    #[arg(long, value_name = "X0,Y0,X1,Y1", value_parser = heron::converge::Roi::parse)]
    roi: Option<heron::converge::Roi>,
    /// Write one error heat map per setting into this existing folder, as
    /// INTEGRATOR-lanesL-sppN.png: each pixel's relative squared error, white at 1e-4 or
    /// less to full red (brighter than the reference) or blue (darker) at 1e2 or more,
    /// log scale; the --roi rectangle's border black.
    #[arg(long, value_name = "DIR")]
    heatmap: Option<PathBuf>,
    /// Comma-separated spp values to measure.
    #[arg(long, default_value = "1,4,16,64", value_delimiter = ',', value_parser = clap::value_parser!(u32).range(1..))]
    spp: Vec<u32>,
    /// Comma-separated lane counts (each 1, 4 or 8).
    #[arg(long, default_value = "1,4,8", value_delimiter = ',', value_parser = parse_lanes)]
    lanes: Vec<usize>,
    /// Override the scene's resolution, W,H (smaller is faster to converge).
    #[arg(long, value_parser = parse_size)]
    size: Option<(u32, u32)>,
    /// Also draw error against time as a PNG chart (960×600, log–log, one line per lane
    /// count, the 1/√t slope), written atomically; the CSV still goes to standard output.
    #[arg(long)]
    plot: Option<PathBuf>,
    /// Worker threads (default: one per core).
    #[arg(long, value_parser = clap::value_parser!(u16).range(1..))]
    threads: Option<u16>,
    /// Random seed of the measured runs.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// How hero wavelengths are drawn in the measured runs: uniform or visible.
    #[arg(long, default_value = "visible", value_parser = ["uniform", "visible"])]
    wavelengths: String,
    /// The measured runs' integrator (whitted, path, lighttrace, bdpt, …); default: the
    /// scene's.
    #[arg(long, value_parser = clap::builder::PossibleValuesParser::new(heron::settings::IntegratorKind::NAMES))]
    integrator: Option<String>,
    /// sobol or independent for the measured runs [default: sobol]; the reference always
    /// uses independent numbers.
    #[arg(long, value_parser = ["sobol", "independent"])]
    sampler: Option<String>,
    /// forced or collision (as heron render --medium-nee), for the reference and the
    /// measured runs; default: the scene's.
    #[arg(long, value_name = "HOW")]
    medium_nee: Option<String>,
    /// As heron render --sun-guide, for the reference and the measured runs.
    #[arg(long, value_name = "FRACTION")]
    sun_guide: Option<f64>,
}

#[derive(clap::Args)]
struct TraceArgs {
    /// Scene file (TOML).
    scene: PathBuf,
    /// Ray origin X,Y,Z.
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    origin: [f32; 3],
    /// Ray direction X,Y,Z (normalised here).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    dir: [f32; 3],
    /// Wavelength in nm (360–830).
    #[arg(long)]
    lambda: f32,
    /// At the k-th dielectric event, R reflects and T transmits (default T; total
    /// internal reflection forces R), e.g. TRT for the primary rainbow ray.
    #[arg(long, default_value = "")]
    path: String,
    /// Also report the light's Stokes vector after each event, starting from S0,S1,S2,S3
    /// (e.g. 1,0,0,0, unpolarised) in a frame of the ray's choosing, which the first
    /// event's output names; `stokes_x` is each output's frame (x̂; S1 > 0 along it).
    #[arg(long, value_name = "S0,S1,S2,S3", value_parser = parse_stokes, allow_hyphen_values = true)]
    stokes: Option<[f64; 4]>,
}

fn parse_stokes(s: &str) -> std::result::Result<[f64; 4], String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|t| t.trim().parse::<f64>())
        .collect::<std::result::Result<_, _>>()
        .map_err(|_| format!("expected S0,S1,S2,S3 (four numbers), got {s:?}"))?;
    <[f64; 4]>::try_from(v).map_err(|_| format!("expected S0,S1,S2,S3 (four numbers), got {s:?}"))
}

fn parse_vec3(s: &str) -> std::result::Result<[f32; 3], String> {
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

fn parse_size(s: &str) -> std::result::Result<(u32, u32), String> {
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
struct DisplayFlags {
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
    fn transform(&self) -> Result<DisplayTransform> {
        let mode =
            DisplayMode::parse(&self.display).map_err(|e| anyhow::anyhow!("--display: {e}"))?;
        DisplayTransform::new(mode, self.exposure).map_err(|e| anyhow::anyhow!("--exposure: {e}"))
    }
}

#[derive(clap::Args)]
struct DisplayCmdArgs {
    /// An EXR (R, G, B in linear sRGB) or a CSV with a header naming columns X, Y, Z (CIE
    /// 1931, D65 white at Y = 1, heron's film convention; other columns are ignored).
    input: PathBuf,
    /// The PNG to write for an EXR (required); the CSV to write for a CSV (default:
    /// standard output). Written atomically.
    #[arg(short, long)]
    output: Option<PathBuf>,
    #[command(flatten)]
    display: DisplayFlags,
}

#[derive(clap::Args)]
struct RenderArgs {
    /// Scene file: heron's TOML, or Mitsuba 3 XML (.xml) or pbrt-v4 (.pbrt), converted as
    /// heron convert does.
    scene: PathBuf,
    #[command(flatten)]
    import: ImportArgs,
    /// Output EXR path; the PNG preview goes next to it with the extension .png. A path
    /// ending in .heronfilm writes the film's unnormalised sums instead (for heron merge).
    #[arg(short, long)]
    output: PathBuf,
    /// Render shard K of N (0 ≤ K < N): sample indices ⌊K·spp/N⌋ to ⌊(K+1)·spp/N⌋ − 1 of
    /// every pixel, into a .heronfilm file; heron merge adds the N parts up.
    #[arg(long, value_name = "K/N", value_parser = heron::checkpoint::Shard::parse)]
    shard: Option<heron::checkpoint::Shard>,
    /// Samples per pixel (overrides the scene's render.spp).
    #[arg(long)]
    spp: Option<u32>,
    /// Worker threads (default: one per core). The image does not depend on it.
    #[arg(long)]
    threads: Option<usize>,
    /// Random seed (overrides the scene's render.seed).
    #[arg(long)]
    seed: Option<u64>,
    /// Wavelengths carried per path: 1, 4 or 8.
    #[arg(long, default_value_t = 8, value_parser = parse_lanes)]
    lanes: usize,
    /// How rays go to Embree: paths (the paths of 8 pixel samples advance together, their
    /// closest-hit and shadow rays sent as 8-wide packets; whitted and path), camera
    /// (camera rays in packets, every later ray alone: the one-path-at-a-time engine) or
    /// off (every ray alone). They agree up to the last bits of Embree's hits. Default
    /// auto: paths under whitted, camera otherwise (off under lighttrace, which traces
    /// no camera rays): the faster here (BENCHMARKS.md). Under lighttrace and bdpt,
    /// paths sends each sample's connection shadow rays 8 at a time.
    #[arg(long, value_name = "HOW")]
    packets: Option<String>,
    /// Every ray alone: the same as --packets off.
    #[arg(long, conflicts_with = "packets")]
    no_packets: bool,
    /// Where the path tracer samples lights from a segment through a medium: forced
    /// (default: one light sample per segment, at a point drawn within it, collided or
    /// not) or collision (at free-flight collisions only, the estimator before 0.21).
    /// Overrides the scene's render.medium_nee.
    #[arg(long, value_name = "HOW")]
    medium_nee: Option<String>,
    /// The fraction of phase samples at medium vertices drawn about the direction
    /// toward the sun, in [0, 1) (default 0.25; 0: phase sampling alone). Overrides the
    /// scene's render.sun_guide.
    #[arg(long, value_name = "FRACTION")]
    sun_guide: Option<f64>,
    /// sppm: photons traced per iteration (default: one per pixel). Overrides the
    /// scene's render.sppm_photons.
    #[arg(long, value_name = "N", allow_hyphen_values = true)]
    sppm_photons: Option<i64>,
    /// sppm: the share α of each iteration's photons a pixel keeps, in (0, 1) (default
    /// 2/3): smaller shrinks the radii faster. Overrides the scene's render.sppm_alpha.
    #[arg(long, value_name = "FRACTION", allow_hyphen_values = true)]
    sppm_alpha: Option<f64>,
    /// sppm: the initial gather radius in scene units (default 0: four pixel footprints
    /// at each pixel's first visible point). Overrides the scene's render.sppm_radius.
    #[arg(long, value_name = "RADIUS", allow_hyphen_values = true)]
    sppm_radius: Option<f64>,
    /// Do not write the PNG preview.
    #[arg(long)]
    no_png: bool,
    #[command(flatten)]
    display: DisplayFlags,
    /// Rewrite the PNG preview (atomically) with the samples so far at the first pass
    /// boundary after every SECONDS, to watch a long render converge; the final EXR and
    /// PNG do not change.
    #[arg(long, value_name = "SECONDS", allow_hyphen_values = true)]
    preview_every: Option<f64>,
    /// Add the CIE XYZ channels X, Y, Z to the EXR.
    #[arg(long)]
    xyz: bool,
    /// Polarised transport: Stokes vectors along every path, Mueller matrices at every
    /// event; the EXR gains S1.R … S3.B (R, G, B are S0) and the previews OUT.dolp.png
    /// and OUT.aolp.png (default: the scene's [render] polarization).
    #[arg(long)]
    polarization: bool,
    /// An ideal linear analyser in front of the camera at DEG from the image's
    /// horizontal, counter-clockwise as the photographer sees it (overrides the scene's
    /// [camera] polarizer; needs --polarization or [render] polarization = true).
    #[arg(long, value_name = "DEG", allow_hyphen_values = true)]
    polarizer: Option<f64>,
    /// Add N spectral channels (equal bins over 360–830 nm, the layout of Fichet et al.
    /// 2021, readable by colour.read_spectral_image_Fichet2021).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..=470))]
    spectral_bins: Option<u16>,
    /// How hero wavelengths are drawn: uniform or visible (pdf ∝ 1/cosh²(0.0072(λ − 538))).
    #[arg(long, default_value = "visible", value_parser = ["uniform", "visible"])]
    wavelengths: String,
    /// whitted (the seed's tracer), path (path tracing with MIS), lighttrace (paths from
    /// the lights, splatted), bdpt (bidirectional) or sppm (stochastic progressive photon
    /// mapping; --spp is then its iterations); default: the scene's [render]
    /// integrator, else whitted.
    #[arg(long, value_parser = clap::builder::PossibleValuesParser::new(heron::settings::IntegratorKind::NAMES))]
    integrator: Option<String>,
    /// Where random numbers come from: sobol (Owen-scrambled Sobol' points along a Morton
    /// curve) or independent [default: sobol].
    #[arg(long, value_parser = ["sobol", "independent"])]
    sampler: Option<String>,
    /// auto: the kernel compiled for what the scene uses (no shadow rays, specular
    /// paths, area lights or escaping radiance where it has none); general: the kernel
    /// with all of them. Both give the same image.
    #[arg(long, default_value = "auto", value_parser = ["auto", "general"])]
    kernel: String,
    /// Maximum number of scattering events per path (overrides the scene's
    /// render.max_depth).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    max_depth: Option<u32>,
    /// How rays leave surfaces: epsilon (the seed's fixed ε, the scene's render.epsilon),
    /// robust (offset by the hit point's floating-point error bound, pbrt-v4 §6.8.6) or
    /// auto (epsilon for whitted, robust for path, lighttrace and bdpt); default: the
    /// scene's render.offset, else auto.
    #[arg(long, value_parser = clap::builder::PossibleValuesParser::new(heron::settings::OffsetMode::NAMES))]
    offset: Option<String>,
    /// Write the film's state to FILE (atomically) during the render, so that a killed
    /// render can continue with --resume FILE.
    #[arg(long, value_name = "FILE")]
    checkpoint: Option<PathBuf>,
    /// Seconds between checkpoints (written at the first pass boundary after this long;
    /// 0: after every pass).
    #[arg(
        long,
        value_name = "SECONDS",
        default_value_t = 60.0,
        requires = "checkpoint"
    )]
    checkpoint_every: f64,
    /// Continue the render a checkpoint holds (same scene and settings); the image is
    /// byte-identical to an uninterrupted render.
    #[arg(long, value_name = "FILE")]
    resume: Option<PathBuf>,
    /// Exit with status 3 (after writing the image) if any sample was NaN or infinite;
    /// the count and the first pixel and sample are printed either way.
    #[arg(long)]
    check_finite: bool,
    /// Stop at the first pass boundary after this many seconds and write the image of
    /// the samples so far.
    #[arg(long, value_name = "SECONDS")]
    time_limit: Option<f64>,
    /// Do not draw the progress bar.
    #[arg(long)]
    quiet: bool,
    /// Also estimate each pixel's variance (of its mean, from the sums of its samples'
    /// squares) and write it as the EXR channels variance.R, variance.G, variance.B, for
    /// heron compare. Needs at least 2 spp.
    #[arg(long)]
    variance: bool,
}

#[derive(clap::Args)]
struct CompareArgs {
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
    /// Write a PNG heat map of the regions' z-scores (red: A brighter, blue: B brighter;
    /// failing regions outlined).
    #[arg(long, value_name = "PNG")]
    heatmap: Option<PathBuf>,
    /// List at most this many failing tests.
    #[arg(long, default_value_t = 20)]
    max_listed: usize,
}

#[derive(clap::Args)]
struct MergeArgs {
    /// The film files of every shard K/N of one render, in any order.
    #[arg(required = true, num_args = 1..)]
    parts: Vec<PathBuf>,
    /// Output EXR path; the PNG preview goes next to it with the extension .png.
    #[arg(short, long)]
    output: PathBuf,
    /// Do not write the PNG preview.
    #[arg(long)]
    no_png: bool,
    #[command(flatten)]
    display: DisplayFlags,
}

fn parse_lanes(s: &str) -> std::result::Result<usize, String> {
    match s {
        "1" => Ok(1),
        "4" => Ok(4),
        "8" => Ok(8),
        _ => Err(format!("expected 1, 4 or 8, got {s}")),
    }
}

/// `heron color`; the formulas are in the heron::colorimetry documentation.
#[derive(clap::Args)]
struct ColorArgs {
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

fn cmd_display(a: DisplayCmdArgs) -> Result<()> {
    let t = a.display.transform()?;
    let ext = a
        .input
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("exr") => {
            let Some(out) = &a.output else {
                bail!("--output: expected the PNG to write (heron display IN.exr -o OUT.png)");
            };
            check_output(out, &["png"])?;
            let (w, h, rgb) = heron::film::exr::read_linear_srgb(&a.input)?;
            heron::film::png::stage_png_rgb(w, h, &rgb, out, &t)?.commit()?;
        }
        Some("csv") => {
            let text = std::fs::read_to_string(&a.input)
                .map_err(|e| anyhow::anyhow!("{}: {e}", a.input.display()))?;
            if let Some(out) = &a.output {
                check_output(out, &["csv"])?;
            }
            let csv = heron::spectrum::display::map_xyz_csv(&text, &display(&a.input), &t)
                .map_err(anyhow::Error::msg)?;
            match &a.output {
                Some(out) => heron::files::write_atomically(out, |tmp| {
                    std::fs::write(tmp, &csv).map_err(|e| e.to_string())
                })?,
                None => print!("{csv}"),
            }
        }
        _ => bail!(
            "{}: expected an .exr (to a PNG) or a .csv with columns X, Y, Z",
            a.input.display()
        ),
    }
    Ok(())
}

fn cmd_color(a: ColorArgs) -> Result<()> {
    let report =
        heron::colorimetry::color_file(&a.file, a.observer, a.illuminant, a.interpolation)?;
    println!("{}", serde_json::to_string_pretty(&report)?);
    for note in &report.notes {
        eprintln!("note: {note}");
    }
    Ok(())
}

/// `heron compare`: prints the report; status 0 (same), 1 (different), and errors
/// (status 2) through `main`.
fn cmd_compare(a: CompareArgs) -> Result<()> {
    use heron::compare::{compare, Correction, Image, Options};
    let opts = Options {
        region: a.region,
        alpha: a.alpha,
        correction: Correction::parse(&a.correction).map_err(anyhow::Error::msg)?,
        mask: None,
    };
    opts.check().map_err(anyhow::Error::msg)?;
    if let Some(h) = &a.heatmap {
        check_output(h, &["png"]).map_err(|e| {
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

fn main() {
    // Usage errors get one line and status 1 like every other error (status 2 for
    // heron compare, whose 1 means "different", as diff and cmp do); --help and
    // --version print as usual.
    let compare = std::env::args().nth(1).as_deref() == Some("compare");
    let fail = if compare { 2 } else { 1 };
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) if !e.use_stderr() => e.exit(),
        Err(e) => {
            let text = e.to_string();
            let first = text.lines().next().unwrap_or("invalid arguments");
            eprintln!("{}", first.trim_end());
            std::process::exit(fail);
        }
    };
    let result = match cli.command {
        Command::Render(args) => cmd_render(args),
        Command::Convert(args) => cmd_convert(args),
        Command::Merge(args) => cmd_merge(args),
        Command::Trace(args) => cmd_trace(args),
        Command::Converge(args) => cmd_converge(args),
        Command::Bench(BenchCommand::Traversal(args)) => cmd_bench_traversal(args),
        Command::Bench(BenchCommand::Record(args)) => cmd_bench_record(args),
        Command::Bench(BenchCommand::Replay { log, rounds }) => cmd_bench_replay(&log, rounds),
        Command::Bench(BenchCommand::Limit(args)) => cmd_bench_limit(args),
        Command::Bench(BenchCommand::Mesh { n, output }) => {
            heron::bench::write_obj(&heron::bench::procedural_mesh(n), &output).map_err(Into::into)
        }
        Command::Color(args) => cmd_color(args),
        Command::Compare(args) => cmd_compare(args),
        Command::Display(args) => cmd_display(args),
        Command::Info { exr } => cmd_info(&exr),
        Command::Stress(args) => cmd_stress(args),
        Command::Sky(c) => cmd_sky(c),
        Command::Lens(args) => cmd_lens(args),
        Command::Spectra { scene } => load_scene(&scene)
            .map_err(Into::into)
            .map(|s| println!("{}", heron::scene::export::spectra_json(&s))),
    };
    if let Err(e) = result {
        eprintln!("error: {e:#}");
        std::process::exit(fail);
    }
}

/// Checks that `path` ends in one of `exts` and that its folder exists; returns the
/// extension.
fn check_output(path: &Path, exts: &[&str]) -> Result<String> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    if !exts.contains(&ext) {
        let want: Vec<String> = exts.iter().map(|e| format!(".{e}")).collect();
        bail!(
            "--output {}: expected a path ending in {}",
            path.display(),
            want.join(" or ")
        );
    }
    let dir = path.parent().filter(|p| !p.as_os_str().is_empty());
    if let Some(d) = dir {
        if !d.is_dir() {
            bail!(
                "--output {}: folder {} does not exist",
                path.display(),
                d.display()
            );
        }
    }
    Ok(ext.to_string())
}

fn cmd_render(args: RenderArgs) -> Result<()> {
    let exr_path = args.output;
    let to_film = check_output(&exr_path, &["exr", "heronfilm"])? == "heronfilm";
    if let Some(s) = args.shard {
        if !to_film {
            bail!(
                "--shard {s}: expected --output to end in .heronfilm (a shard is a part for heron merge, not an image)"
            );
        }
    }
    if args.threads == Some(0) {
        bail!("--threads: expected at least 1");
    }
    let shown = args.display.transform()?;
    let preview_every = match args.preview_every {
        None => None,
        Some(v) => {
            let every = match std::time::Duration::try_from_secs_f64(v) {
                Ok(d) if v.is_finite() && v > 0.0 => d,
                _ => bail!("--preview-every: expected a finite number of seconds > 0, got {v}"),
            };
            if to_film {
                bail!(
                    "--preview-every: a .heronfilm output has no PNG preview (render to an .exr)"
                );
            }
            if args.no_png {
                bail!("--preview-every: rewrites the PNG preview, which --no-png turns off");
            }
            Some(every)
        }
    };
    let settings_args = SettingsArgs {
        spp: args.spp.map(i64::from),
        seed: args.seed,
        lanes: Some(args.lanes as i64),
        integrator: args.integrator.as_deref(),
        sampler: args.sampler.as_deref(),
        wavelengths: Some(&args.wavelengths),
        // Absent, the scene's `[render] spectral_bins` (default none) stands.
        spectral_bins: args.spectral_bins.map(i64::from),
        max_depth: args.max_depth.map(i64::from),
        offset: args.offset.as_deref(),
        kernel: Some(&args.kernel),
        packets: args.packets.as_deref(),
        no_packets: args.no_packets,
        medium_nee: args.medium_nee.as_deref(),
        sun_guide: args.sun_guide,
        sppm_photons: args.sppm_photons,
        sppm_alpha: args.sppm_alpha,
        sppm_radius: args.sppm_radius,
        polarization: args.polarization.then_some(true),
        polarizer: args.polarizer,
    };
    // Before the scene loads, which may take seconds (sky and medium tables).
    settings_args.check().map_err(anyhow::Error::msg)?;
    let scene = load_any_scene(&args.scene, &args.import)?;
    let mut opts = RenderOptions::from_scene(&scene);
    opts.settings
        .apply(&settings_args)
        .map_err(anyhow::Error::msg)?;
    opts.threads = args.threads.unwrap_or(0);
    if args.variance && opts.settings.spp < 2 {
        bail!(
            "--variance: needs at least 2 samples per pixel to estimate a variance, got {}",
            opts.settings.spp
        );
    }
    opts.variance = args.variance;
    let seconds = |flag: &str, v: f64| -> Result<std::time::Duration> {
        match std::time::Duration::try_from_secs_f64(v) {
            Ok(d) if v.is_finite() => Ok(d),
            _ => bail!("{flag}: expected a finite number of seconds >= 0, got {v}"),
        }
    };
    if let Some(c) = &args.checkpoint {
        if c.extension().and_then(|e| e.to_str()) == Some("exr") {
            bail!(
                "--checkpoint {}: expected a file other than an EXR",
                c.display()
            );
        }
        opts.checkpoint = Some((
            c.clone(),
            seconds("--checkpoint-every", args.checkpoint_every)?,
        ));
    }
    if let Some(t) = args.time_limit {
        opts.time_limit = Some(seconds("--time-limit", t)?);
    }
    if let Some(r) = &args.resume {
        opts.resume = Some(Arc::new(heron::checkpoint::Checkpoint::read(r)?));
    }
    opts.shard = args.shard;
    // Ctrl-C finishes the current pass and writes what it has (status 130); a second
    // Ctrl-C exits at once.
    let stop = Arc::new(std::sync::atomic::AtomicBool::new(false));
    {
        let stop = stop.clone();
        ctrlc::set_handler(move || {
            if stop.swap(true, std::sync::atomic::Ordering::SeqCst) {
                std::process::exit(130);
            }
        })
        .map_err(|e| anyhow::anyhow!("cannot install the Ctrl-C handler: {e}"))?;
    }
    opts.stop = Some(stop.clone());
    if let Some(every) = preview_every {
        let png = exr_path.with_extension("png");
        opts.preview = Some((
            every,
            Arc::new(move |state: &heron::checkpoint::Checkpoint| {
                // A preview that cannot be written is not worth the render: say so and go on.
                if let Err(e) =
                    stage_png(&state.film.image(), &png, &shown).and_then(|s| s.commit())
                {
                    eprintln!("warning: --preview-every: {e}");
                }
            }),
        ));
    }
    let bar = progress_bar(args.quiet);
    if let Some(bar) = &bar {
        let b = bar.clone();
        opts.progress = Some(Arc::new(move |done, all| {
            b.set_length(all);
            b.set_position(done);
        }));
    }
    let (mut state, stats) = render_state(&scene, &opts)?;
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    state.xyz_channels = args.xyz;
    let film = state.film.image();
    if to_film {
        // The sums as they are: heron merge (or --resume, if the render stopped early)
        // carries on from them.
        state.write(&exr_path)?;
    } else {
        // From the settings key, as heron merge does: the same header either way (the
        // key records what ran, e.g. no packets for light tracing).
        let provenance = heron::provenance::Provenance::from_key(&state.key.provenance, stats.spp)
            .expect("the settings key holds the provenance");
        let png = (!args.no_png).then_some(&shown);
        write_image(&film, &exr_path, &state, &provenance, png)?;
    }
    let shard = args
        .shard
        .map_or(String::new(), |s| format!(" (shard {s})"));
    eprintln!(
        "{}{shard}: {}x{} at {} spp, {} lanes, {}, {} (kernel {}) in {:.3} s: {} rays ({} camera/continued, {} shadow), {:.2} Mrays/s, {} non-finite samples",
        display(&exr_path),
        film.width,
        film.height,
        stats.spp,
        opts.settings.lanes,
        opts.settings.sampler.name(),
        opts.settings.integrator.name(),
        heron::settings::flag_names(stats.kernel),
        stats.wall.as_secs_f64(),
        stats.total_rays(),
        stats.counters.rays,
        stats.counters.shadow_rays,
        stats.mrays_per_s(),
        stats.nonfinite
    );
    if stats.nonfinite > 0 {
        let at = match stats.first_nonfinite {
            Some((x, y, s)) => format!("; the first at pixel ({x}, {y}), sample {s}"),
            None => " (in splats)".to_string(),
        };
        eprintln!(
            "non-finite: {} samples were NaN or infinite and left out of the image{at}",
            stats.nonfinite
        );
    }
    if let Some(from) = stats.resumed_from {
        eprintln!(
            "resumed from {from} spp ({})",
            display(args.resume.as_deref().unwrap_or(Path::new("")))
        );
    }
    if stats.stopped {
        let why = if stop.load(std::sync::atomic::Ordering::SeqCst) {
            "interrupted"
        } else {
            "time limit reached"
        };
        let want = opts.shard.map_or(opts.settings.spp, |s| {
            s.samples(opts.settings.spp).len() as u32
        });
        // A film file is a checkpoint too.
        let resume = match &opts.checkpoint {
            Some((c, _)) => Some(c.as_path()),
            None if to_film => Some(exr_path.as_path()),
            None => None,
        };
        eprintln!(
            "{why}: the {} holds {} of {want} spp per pixel{}",
            if to_film { "film" } else { "image" },
            stats.spp,
            match resume {
                Some(c) => format!("; continue with --resume {}", display(c)),
                None => String::new(),
            }
        );
        if why == "interrupted" {
            std::process::exit(130);
        }
    }
    if args.check_finite && stats.nonfinite > 0 {
        std::process::exit(3);
    }
    Ok(())
}

/// Writes the EXR and (given a display transform) the PNG of `film`. Both files are
/// staged first and renamed into place together: an error in either leaves neither
/// behind.
fn write_image(
    film: &heron::film::Film,
    exr_path: &Path,
    state: &heron::checkpoint::Checkpoint,
    provenance: &heron::provenance::Provenance,
    png: Option<&DisplayTransform>,
) -> Result<()> {
    let channels = heron::film::exr::ExrChannels {
        xyz: state.xyz_channels,
        spectral: film.spectral.is_some(),
    };
    let exr = stage_exr(film, exr_path, channels, provenance)?;
    let png = match png {
        None => None,
        Some(d) => Some(stage_png(film, &exr_path.with_extension("png"), d)?),
    };
    exr.commit()?;
    if let Some(p) = png {
        p.commit()?;
        if film.stokes.is_some() {
            // A polarised render's previews of its degree and angle of polarisation.
            heron::plot::stokes::write_previews(
                film,
                &exr_path.with_extension("dolp.png"),
                &exr_path.with_extension("aolp.png"),
            )?;
        }
    }
    Ok(())
}

fn cmd_merge(args: MergeArgs) -> Result<()> {
    check_output(&args.output, &["exr"])?;
    let shown = args.display.transform()?;
    let parts = args
        .parts
        .iter()
        .map(|p| {
            Ok((
                p.clone(),
                heron::checkpoint::Checkpoint::read_as(p, "film file")?,
            ))
        })
        .collect::<Result<Vec<_>>>()?;
    let total = heron::checkpoint::merge(&parts)?;
    let provenance =
        heron::provenance::Provenance::from_key(&total.key.provenance, total.film.spp_done)
            .ok_or_else(|| {
                anyhow::anyhow!(
                    "{}: not a heron film file: its settings lack the provenance",
                    display(&parts[0].0)
                )
            })?;
    let film = total.film.image();
    let png = (!args.no_png).then_some(&shown);
    write_image(&film, &args.output, &total, &provenance, png)?;
    eprintln!(
        "{}: merged {} part{}: {}x{} at {} spp, {} rays ({} camera/continued, {} shadow), {} non-finite samples",
        display(&args.output),
        parts.len(),
        if parts.len() == 1 { "" } else { "s" },
        film.width,
        film.height,
        total.film.spp_done,
        total.film.rays + total.film.shadow_rays,
        total.film.rays,
        total.film.shadow_rays,
        total.film.nonfinite
    );
    Ok(())
}

fn cmd_converge(a: ConvergeArgs) -> Result<()> {
    // Bad output paths and a bad --roi fail before the renders, not after.
    if let Some(p) = &a.plot {
        heron::plot::check_path(p, "--plot")?;
    }
    if let Some(d) = &a.heatmap {
        if !d.is_dir() {
            bail!(
                "--heatmap {}: expected an existing folder to write the heat maps into",
                d.display()
            );
        }
    }
    let mut scene = load_scene(&a.scene)?;
    if let Some((w, h)) = a.size {
        let c = &scene.camera;
        scene.camera = c
            .resized(w, h)
            .map_err(|e| anyhow::anyhow!("--size: {e}"))?;
    }
    let (w, h) = (scene.camera.width, scene.camera.height);
    if let Some(r) = &a.roi {
        r.check(w, h).map_err(|e| anyhow::anyhow!("--roi {e}"))?;
    }
    let mut base = RenderOptions::from_scene(&scene);
    base.settings
        .apply(&SettingsArgs {
            seed: Some(a.seed),
            integrator: a.integrator.as_deref(),
            sampler: a.sampler.as_deref(),
            wavelengths: Some(&a.wavelengths),
            medium_nee: a.medium_nee.as_deref(),
            sun_guide: a.sun_guide,
            ..SettingsArgs::default()
        })
        .map_err(anyhow::Error::msg)?;
    base.threads = a.threads.map_or(0, usize::from);
    let reference_integrator = a
        .reference_integrator
        .as_deref()
        .map(|k| {
            heron::settings::IntegratorKind::parse(k)
                .map_err(|e| anyhow::anyhow!("--reference-integrator: {e}"))
        })
        .transpose()?;
    let plan = heron::converge::Plan {
        reference_spp: a.reference_spp,
        reference_integrator,
        lanes: a.lanes.clone(),
        spps: a.spp.clone(),
        roi: a.roi,
        heat_maps: a.heatmap.clone(),
    };
    let result = heron::converge::converge(&scene, &base, &plan)?;
    let reference = &result.reference;
    println!(
        "# {}: {w}x{h}, {}, {} wavelengths, reference {} spp x 8 lanes with {} ({:.1} s)",
        a.scene.display(),
        base.settings.integrator.name(),
        a.wavelengths,
        reference.spp,
        reference.integrator,
        reference.wall_s
    );
    let own = |e: Option<heron::compare::Errors>| {
        e.map_or("not estimated (1 spp)".to_string(), |e| {
            format!("rel_rmse {:.4e}, rel_mse {:.4e}", e.rel_rmse, e.rel_mse)
        })
    };
    println!(
        "# the reference's own error, from its two halves (added to every row's squared error): {}",
        own(reference.own)
    );
    if let Some(r) = &a.roi {
        println!(
            "# region of interest {r} ({} pixels), the reference's own error there: {}",
            r.area(),
            own(reference.own_roi)
        );
    }
    println!(
        "# rel_mse: mean over pixels and channels of (x - r)^2 / (r^2 + {})",
        heron::compare::REL_MSE_EPSILON
    );
    let roi_header = if a.roi.is_some() {
        ",roi_rel_rmse,roi_rel_mse"
    } else {
        ""
    };
    println!("lanes,spp,wall_s,ns_per_sample,rel_rmse,rmse_sqrt_time,rel_mse{roi_header}");
    for r in &result.rows {
        let roi = match (r.roi_rel_rmse, r.roi_rel_mse) {
            (Some(a), Some(b)) => format!(",{a:.4e},{b:.4e}"),
            _ => String::new(),
        };
        println!(
            "{},{},{:.4},{:.1},{:.5},{:.5},{:.4e}{roi}",
            r.lanes, r.spp, r.wall_s, r.ns_per_sample, r.rel_rmse, r.rmse_sqrt_time, r.rel_mse
        );
    }
    if let Some(p) = &a.plot {
        let title = format!(
            "{}: {w}×{h}, {}, reference {} spp",
            a.scene.display(),
            base.settings.integrator.name(),
            a.reference_spp
        );
        heron::plot::write_png(
            p,
            &heron::plot::converge::chart(&title, &result.rows),
            "--plot",
        )?;
    }
    Ok(())
}

fn cmd_trace(a: TraceArgs) -> Result<()> {
    let choices = heron::trace::parse_path(&a.path)?;
    let scene = load_scene(&a.scene)?;
    let renderer = heron::render::Renderer::new(&scene)?;
    let report = heron::trace::trace(
        &scene,
        renderer.accel(),
        a.origin.into(),
        a.dir.into(),
        a.lambda,
        &choices,
        a.stokes,
    )?;
    println!("{}", serde_json::to_string_pretty(&report)?);
    Ok(())
}

/// The scene and render options of a recorded render.
fn recorded_render(r: &RecordedRender) -> Result<(heron::scene::Scene, RenderOptions)> {
    let settings_args = SettingsArgs {
        spp: r.spp.map(i64::from),
        seed: r.seed,
        integrator: r.integrator.as_deref(),
        ..Default::default()
    };
    settings_args.check().map_err(anyhow::Error::msg)?;
    let scene = load_scene(&r.scene)?;
    let mut opts = RenderOptions::from_scene(&scene);
    opts.settings
        .apply(&settings_args)
        .map_err(anyhow::Error::msg)?;
    opts.threads = 1;
    Ok((scene, opts))
}

fn recorded_title(r: &RecordedRender, opts: &RenderOptions) -> String {
    format!(
        "{}, {}, {} spp, one thread, Embree {}",
        r.scene.display(),
        opts.settings.integrator.name(),
        opts.settings.spp,
        heron::accel::embree::Device::new("")
            .map(|d| {
                let (a, b, c) = d.version();
                format!("{a}.{b}.{c}")
            })
            .unwrap_or_else(|_| "?".into())
    )
}

fn cmd_bench_record(a: RecordArgs) -> Result<()> {
    check_output(&a.output, &["rays"])?;
    let (scene, opts) = recorded_render(&a.render)?;
    let (file, counted) = heron::bench::limit::record(&scene, &opts)?;
    file.write(&a.output)?;
    let t = file.log.tally;
    println!("# {}", recorded_title(&a.render, &opts));
    println!(
        "rays {} (the render counted {counted}), calls {}, hits {}, occluded {}: {}",
        t.rays,
        t.calls,
        t.hits,
        t.occluded,
        a.output.display()
    );
    Ok(())
}

fn cmd_bench_replay(log: &Path, rounds: u32) -> Result<()> {
    let r = heron::bench::limit::replay(log, rounds)?;
    println!(
        "# ray log {}, replayed on one thread, median of {rounds} rounds",
        log.display()
    );
    print!("{}", r.text());
    Ok(())
}

fn cmd_bench_limit(a: LimitArgs) -> Result<()> {
    if let Some(k) = &a.keep {
        if k.extension().and_then(|e| e.to_str()) != Some("rays") {
            bail!("--keep {}: expected a path ending in .rays", k.display());
        }
    }
    let (scene, opts) = recorded_render(&a.render)?;
    let r = heron::bench::limit::limit(&scene, &opts, a.keep.as_deref(), a.rounds)?;
    println!(
        "# {}, median of {} rounds; the render counted {} rays",
        recorded_title(&a.render, &opts),
        a.rounds,
        r.counted_rays
    );
    print!("{}", r.text());
    Ok(())
}

fn cmd_bench_traversal(a: TraversalArgs) -> Result<()> {
    let mesh = heron::bench::load_obj_mesh(&a.mesh)?;
    let opts = heron::bench::TraversalOptions {
        eye: a.eye.into(),
        look_at: a.look_at.into(),
        up: a.up.into(),
        fov_deg: a.fov,
        width: a.size.0,
        height: a.size.1,
        widths: a.widths,
        rounds: a.rounds,
        raw: a.raw,
    };
    let r = heron::bench::run_traversal(&mesh, &opts)?;
    let (ma, mi, pa) = r.embree_version;
    println!(
        "# mesh {} ({} triangles), {}x{}, Embree {ma}.{mi}.{pa}, BVH build {:.1} ms, one thread, median of {} rounds",
        a.mesh.display(),
        r.triangles,
        opts.width,
        opts.height,
        r.build.as_secs_f64() * 1e3,
        opts.rounds
    );
    println!("rays,width,count,hit_percent,heron_mrays,raw_embree_mrays,heron_over_raw");
    for row in &r.rows {
        let cell = |v: f64, ok: bool| {
            if ok {
                format!("{v:.3}")
            } else {
                "-".to_string()
            }
        };
        let has_raw = !row.raw_ns.is_empty();
        let has_heron = !row.heron_ns.is_empty();
        println!(
            "{},{},{},{},{},{},{}",
            heron::bench::SETS[row.set],
            row.width.name(),
            row.rays,
            if has_heron {
                format!("{:.1}", 100.0 * row.hits as f64 / row.rays.max(1) as f64)
            } else {
                "-".to_string()
            },
            cell(row.heron_mrays(), has_heron),
            cell(row.raw_mrays(), has_raw),
            cell(row.ratio(), has_raw),
        );
    }
    Ok(())
}

fn cmd_info(path: &Path) -> Result<()> {
    let attrs = heron::film::exr::read_provenance(path)?;
    if attrs.is_empty() {
        anyhow::bail!(
            "{}: no heron provenance in this EXR (expected heron.* header attributes)",
            path.display()
        );
    }
    for (k, v) in attrs {
        // Multi-line values (the input files) are indented under their key.
        println!("{k}: {}", v.replace('\n', "\n  "));
    }
    Ok(())
}

fn cmd_stress(args: StressArgs) -> Result<()> {
    let scene = load_scene(&args.scene)?;
    let mut settings = scene.settings.clone();
    settings
        .apply(&SettingsArgs {
            integrator: args.integrator.as_deref(),
            offset: args.offset.as_deref(),
            ..SettingsArgs::default()
        })
        .map_err(anyhow::Error::msg)?;
    let offset = settings.ray_offset(settings.integrator);
    let device = heron::accel::embree::Device::new("")?;
    let accel = heron::render::build_accel(&scene, &device)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads.map_or(0, usize::from))
        .build()?;
    let start = std::time::Instant::now();
    let reports = pool.install(|| heron::stress::run(&scene, &accel, offset, args.rays, args.seed));
    let failures: u64 = reports.iter().map(|r| r.failures()).sum();
    let rays: u64 = reports.iter().map(|r| r.rays).sum();
    print!("{}", heron::stress::format_table(&reports));
    println!(
        "{}: {} cases, {rays} rays, offsets {offset}, {failures} failures in {:.1} s",
        display(&args.scene),
        reports.len(),
        start.elapsed().as_secs_f64()
    );
    if failures > 0 && !offset.is_robust() {
        println!(
            "note: these are the seed's fixed ε offsets (the default of the whitted \
             integrator); --offset robust checks the offsets of path, lighttrace and bdpt"
        );
    }
    if failures > 0 {
        std::process::exit(3);
    }
    Ok(())
}

fn display(p: &Path) -> String {
    p.display().to_string()
}

fn progress_bar(quiet: bool) -> Option<ProgressBar> {
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
