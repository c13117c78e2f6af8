//! `heron converge`: run time against error.
use super::parse_size;
use anyhow::{bail, Result};
use heron::render::RenderOptions;
use heron::scene::load_scene;
use heron::settings::SettingsArgs;
use std::path::PathBuf;

#[derive(clap::Args)]
pub(crate) struct ConvergeArgs {
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
    #[arg(long, default_value = "1,4,8", value_delimiter = ',', value_parser = heron::settings::Lanes::parse)]
    lanes: Vec<heron::settings::Lanes>,
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

pub(crate) fn run(a: ConvergeArgs) -> Result<()> {
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
