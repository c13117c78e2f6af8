//! `heron render`: flags into a [`heron::session::Session`], the progress bar and
//! Ctrl-C, then the session's output and stop report.
use super::{display, load_any_scene, progress_bar, DisplayFlags, ImportArgs};
use anyhow::{bail, Result};
use heron::film::png::stage_png;
use heron::session::{Output, Report, Request, Session, Stopped};
use heron::settings::SettingsArgs;
use heron::view::ViewImage;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

#[derive(clap::Args)]
pub(crate) struct RenderArgs {
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
    #[arg(long, default_value = "8", value_parser = heron::settings::Lanes::parse)]
    lanes: heron::settings::Lanes,
    /// How rays go to Embree: paths (the paths of 8 pixel samples advance together, their
    /// closest-hit and shadow rays sent as 8-wide packets; whitted and path), camera
    /// (camera rays in packets, every later ray alone: the one-path-at-a-time engine) or
    /// off (every ray alone). They agree up to the last bits of Embree's hits. Default
    /// auto: paths under whitted, camera otherwise (off under lighttrace, which traces
    /// no camera rays): the faster here (BENCHMARKS.md). Under lighttrace, bdpt and sppm
    /// (and polarised renders), paths runs camera packets (none under lighttrace).
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
    /// Emitters seen directly by the camera contribute nothing: area lights hit by a
    /// camera ray, and the background, environment map, sky and sun's disk behind
    /// escaping camera rays are black; light through any reflection or refraction and
    /// the lighting of surfaces are unchanged (Mitsuba 3's hide_emitters; default: the
    /// scene's [render] hide_emitters).
    #[arg(long)]
    hide_emitters: bool,
    /// The pixel reconstruction filter: box, tent (or triangle), gaussian or mitchell,
    /// optionally with parameters, e.g. gaussian:radius=1.5,stddev=0.5 or
    /// mitchell:b=0.333,c=0.333 (default: the scene's [render] filter, else a box of
    /// radius 0.5). Camera samples are drawn from the filter and weighted by f/p.
    #[arg(long, value_name = "NAME[:radius=R,stddev=S,b=B,c=C]")]
    filter: Option<String>,
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
    /// Watch the render in heron view: the viewer shows the samples so far at the first
    /// pass boundary after every second (or every --preview-every), then the finished
    /// EXR, and stays open until Ctrl-C.
    #[arg(long)]
    view: bool,
    #[command(flatten)]
    server: super::view::ServerFlags,
}

pub(crate) fn run(args: RenderArgs) -> Result<()> {
    let mut output = Output::new(&args.output, args.shard)?;
    if args.threads == Some(0) {
        bail!("--threads: expected at least 1");
    }
    let shown = args.display.transform()?;
    output.png = (!args.no_png).then_some(shown);
    output.xyz = args.xyz;
    let preview_every = preview_every(&args, &output)?;
    let request = Request {
        settings: settings_args(&args),
        variance: args.variance,
        threads: args.threads.unwrap_or(0),
    };
    // Before the scene loads, which may take seconds (sky and medium tables).
    request.check()?;
    let scene = load_any_scene(&args.scene, &args.import)?;
    let mut session = request.session(&scene)?;
    run_options(&args, &mut session)?;
    let stop = ctrl_c(&mut session)?;
    let viewer = if args.view {
        if output.film {
            bail!("--view: a .heronfilm output is not an image to look at (render to an .exr)");
        }
        Some(super::view::start(Vec::new(), &args.server, false)?)
    } else {
        None
    };
    let every = preview_every.or(viewer.as_ref().map(|_| Duration::from_secs(1)));
    if let Some(every) = every {
        let png = preview_every.map(|_| args.output.with_extension("png"));
        let (watch, name) = (viewer.clone(), display(&args.output));
        session.opts.preview = Some((
            every,
            Arc::new(move |state: &heron::checkpoint::Checkpoint| {
                let film = state.film.image();
                // A preview that cannot be written is not worth the render: say so and go on.
                if let Some(png) = &png {
                    if let Err(e) = stage_png(&film, png, &shown).and_then(|s| s.commit()) {
                        eprintln!("warning: --preview-every: {e}");
                    }
                }
                if let Some(v) = &watch {
                    v.replace(0, ViewImage::from_film(&name, &film));
                }
            }),
        ));
    }
    let bar = progress_bar(args.quiet);
    if let Some(bar) = &bar {
        let b = bar.clone();
        session.opts.progress = Some(Arc::new(move |done, all| {
            b.set_length(all);
            b.set_position(done);
        }));
    }
    let mut rendered = session.render_state(&scene)?;
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    session.finish(&mut rendered, &output)?;
    let stopped = rendered.stats.stopped.then(|| {
        if stop.load(Ordering::SeqCst) {
            Stopped::Interrupted
        } else {
            Stopped::TimeLimit
        }
    });
    let report = Report {
        rendered: &rendered,
        opts: &session.opts,
        output: &output,
        resumed: args.resume.as_deref(),
        stopped,
    };
    for line in report.lines() {
        eprintln!("{line}");
    }
    if stopped == Some(Stopped::Interrupted) {
        std::process::exit(130);
    }
    let nonfinite = args.check_finite && rendered.stats.nonfinite > 0;
    if let Some(v) = viewer {
        v.replace(0, ViewImage::read_exr(&args.output)?);
        eprintln!(
            "heron render: the viewer shows {}; Ctrl-C to stop",
            display(&args.output)
        );
        while !stop.load(Ordering::SeqCst) {
            std::thread::sleep(Duration::from_millis(100));
        }
    }
    if nonfinite {
        std::process::exit(3);
    }
    Ok(())
}

/// `--preview-every`, checked against the output.
fn preview_every(args: &RenderArgs, output: &Output) -> Result<Option<Duration>> {
    let Some(v) = args.preview_every else {
        return Ok(None);
    };
    let every = match Duration::try_from_secs_f64(v) {
        Ok(d) if v.is_finite() && v > 0.0 => d,
        _ => bail!("--preview-every: expected a finite number of seconds > 0, got {v}"),
    };
    if output.film {
        bail!("--preview-every: a .heronfilm output has no PNG preview (render to an .exr)");
    }
    if args.no_png {
        bail!("--preview-every: rewrites the PNG preview, which --no-png turns off");
    }
    Ok(Some(every))
}

/// The flags that decide the pixels, for [`heron::settings::RenderSettings::apply`].
fn settings_args(args: &RenderArgs) -> SettingsArgs<'_> {
    SettingsArgs {
        spp: args.spp.map(i64::from),
        seed: args.seed,
        lanes: Some(args.lanes.count() as i64),
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
        hide_emitters: args.hide_emitters.then_some(true),
        filter: args.filter.as_deref(),
    }
}

/// How the render runs, not what it computes: checkpoints, the time limit, a resume
/// and the shard.
fn run_options(args: &RenderArgs, session: &mut Session) -> Result<()> {
    let seconds = |flag: &str, v: f64| -> Result<Duration> {
        match Duration::try_from_secs_f64(v) {
            Ok(d) if v.is_finite() => Ok(d),
            _ => bail!("{flag}: expected a finite number of seconds >= 0, got {v}"),
        }
    };
    let opts = &mut session.opts;
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
    Ok(())
}

/// Ctrl-C finishes the current pass and writes what it has (status 130); a second
/// Ctrl-C exits at once. Returns the flag the first sets.
fn ctrl_c(session: &mut Session) -> Result<Arc<AtomicBool>> {
    let stop = Arc::new(AtomicBool::new(false));
    let flag = stop.clone();
    ctrlc::set_handler(move || {
        if flag.swap(true, Ordering::SeqCst) {
            std::process::exit(130);
        }
    })
    .map_err(|e| anyhow::anyhow!("cannot install the Ctrl-C handler: {e}"))?;
    session.opts.stop = Some(stop.clone());
    Ok(stop)
}
