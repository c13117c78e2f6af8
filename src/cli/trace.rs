//! `heron trace`: one ray at one wavelength through a scene, as JSON.
use super::parse_vec3;
use anyhow::Result;
use heron::scene::load_scene;
use std::path::PathBuf;

#[derive(clap::Args)]
pub(crate) struct TraceArgs {
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

pub(crate) fn parse_stokes(s: &str) -> std::result::Result<[f64; 4], String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|t| t.trim().parse::<f64>())
        .collect::<std::result::Result<_, _>>()
        .map_err(|_| format!("expected S0,S1,S2,S3 (four numbers), got {s:?}"))?;
    <[f64; 4]>::try_from(v).map_err(|_| format!("expected S0,S1,S2,S3 (four numbers), got {s:?}"))
}

pub(crate) fn run(a: TraceArgs) -> Result<()> {
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
