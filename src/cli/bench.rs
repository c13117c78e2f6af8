//! `heron bench`: Embree traversal throughput, ray logs and their replay, and the
//! render against raw Embree.
use super::{parse_size, parse_vec3};
use anyhow::{bail, Result};
use heron::render::RenderOptions;
use heron::scene::load_scene;
use heron::settings::SettingsArgs;
use std::path::{Path, PathBuf};

#[derive(clap::Subcommand)]
pub(crate) enum BenchCommand {
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
pub(crate) struct RecordedRender {
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
pub(crate) struct RecordArgs {
    #[command(flatten)]
    render: RecordedRender,
    /// Output ray log (.rays).
    #[arg(short, long)]
    output: PathBuf,
}

#[derive(clap::Args)]
pub(crate) struct LimitArgs {
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
pub(crate) struct TraversalArgs {
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

/// The scene and render options of a recorded render.
pub(crate) fn recorded_render(r: &RecordedRender) -> Result<(heron::scene::Scene, RenderOptions)> {
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

pub(crate) fn recorded_title(r: &RecordedRender, opts: &RenderOptions) -> String {
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

pub(crate) fn record(a: RecordArgs) -> Result<()> {
    heron::session::check_output(&a.output, &["rays"])?;
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

pub(crate) fn replay(log: &Path, rounds: u32) -> Result<()> {
    let r = heron::bench::limit::replay(log, rounds)?;
    println!(
        "# ray log {}, replayed on one thread, median of {rounds} rounds",
        log.display()
    );
    print!("{}", r.text());
    Ok(())
}

pub(crate) fn limit(a: LimitArgs) -> Result<()> {
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

pub(crate) fn traversal(a: TraversalArgs) -> Result<()> {
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
