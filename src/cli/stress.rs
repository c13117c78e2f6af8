//! `heron stress`: random rays at the numerical edge cases of a scene.
use super::display;
use anyhow::Result;
use heron::scene::load_scene;
use heron::settings::SettingsArgs;
use std::path::PathBuf;

#[derive(clap::Args)]
pub(crate) struct StressArgs {
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

pub(crate) fn run(args: StressArgs) -> Result<()> {
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
