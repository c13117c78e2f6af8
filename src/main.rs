//! The heron command line.
use anyhow::{bail, Result};
use clap::{Parser, Subcommand};
use heron::film::{exr::write_exr, png::write_png};
use heron::render::{render, RenderOptions};
use heron::scene::load_scene;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::path::{Path, PathBuf};
use std::sync::Arc;

#[derive(Parser)]
#[command(
    name = "heron",
    version,
    about = "A physically faithful spectral ray tracer for optics research"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene file to OpenEXR (linear sRGB) and an sRGB PNG preview.
    Render(RenderArgs),
}

#[derive(clap::Args)]
struct RenderArgs {
    /// Scene file (TOML).
    scene: PathBuf,
    /// Output EXR path; the PNG preview goes next to it with the extension .png.
    #[arg(short, long)]
    output: PathBuf,
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
    #[arg(long, default_value_t = 4, value_parser = parse_lanes)]
    lanes: usize,
    /// Trace camera rays one by one instead of in 8-wide Embree packets.
    #[arg(long)]
    no_packets: bool,
    /// Do not write the PNG preview.
    #[arg(long)]
    no_png: bool,
    /// Do not draw the progress bar.
    #[arg(long)]
    quiet: bool,
}

fn parse_lanes(s: &str) -> std::result::Result<usize, String> {
    match s {
        "1" => Ok(1),
        "4" => Ok(4),
        "8" => Ok(8),
        _ => Err(format!("expected 1, 4 or 8, got {s}")),
    }
}

fn main() {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render(args) => cmd_render(args),
    };
    if let Err(e) = result {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}

fn cmd_render(args: RenderArgs) -> Result<()> {
    let exr_path = args.output;
    if exr_path.extension().and_then(|e| e.to_str()) != Some("exr") {
        bail!(
            "--output {}: expected a path ending in .exr",
            exr_path.display()
        );
    }
    let dir = exr_path.parent().filter(|p| !p.as_os_str().is_empty());
    if let Some(d) = dir {
        if !d.is_dir() {
            bail!(
                "--output {}: folder {} does not exist",
                exr_path.display(),
                d.display()
            );
        }
    }
    if args.threads == Some(0) {
        bail!("--threads: expected at least 1");
    }
    if args.spp == Some(0) {
        bail!("--spp: expected at least 1");
    }
    let scene = load_scene(&args.scene)?;
    let mut opts = RenderOptions::from_scene(&scene);
    if let Some(s) = args.spp {
        opts.spp = s;
    }
    if let Some(s) = args.seed {
        opts.seed = s;
    }
    opts.threads = args.threads.unwrap_or(0);
    opts.lanes = args.lanes;
    opts.packets = !args.no_packets;
    let bar = progress_bar(args.quiet);
    if let Some(bar) = &bar {
        let b = bar.clone();
        opts.progress = Some(Arc::new(move |done, all| {
            b.set_length(all);
            b.set_position(done);
        }));
    }
    let (film, stats) = render(&scene, &opts)?;
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    write_exr(&film, &exr_path)?;
    let png_path = exr_path.with_extension("png");
    if !args.no_png {
        write_png(&film, &png_path)?;
    }
    eprintln!(
        "{}: {}x{} at {} spp, {} lanes in {:.3} s: {} rays ({} camera/continued, {} shadow), {:.2} Mrays/s, {} non-finite samples",
        display(&exr_path),
        film.width,
        film.height,
        opts.spp,
        opts.lanes,
        stats.wall.as_secs_f64(),
        stats.total_rays(),
        stats.counters.rays,
        stats.counters.shadow_rays,
        stats.mrays_per_s(),
        stats.nonfinite
    );
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
