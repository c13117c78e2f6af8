//! `heron halo`: profiles of the halo sky (heron::sky::halo).
use anyhow::Result;
use std::path::PathBuf;

#[derive(clap::Subcommand)]
pub(crate) enum HaloCommand {
    /// CSV of the halo sky's radiance per unit solar irradiance (sr⁻¹) against the angle
    /// from the sun along great circles through it, one column per position angle ψ and
    /// wavelength: theta_deg,psi<ψ>_<λ>nm,… The table is traced first (seconds).
    Profile(Box<HaloProfileArgs>),
}

#[derive(clap::Args)]
pub(crate) struct HaloProfileArgs {
    /// The sun's elevation above the horizon, degrees.
    #[arg(long, allow_hyphen_values = true)]
    sun_elevation: f64,
    /// A population of crystals, ORIENTATION[:key=value,…]: random, plates, columns,
    /// parry or lowitz, with aspect (c/a), tilt_deg, size_um and weight, e.g.
    /// plates:aspect=0.2,tilt_deg=0.5. Repeat for a mixture.
    #[arg(long, required = true)]
    crystals: Vec<String>,
    /// Wavelengths in nm, comma-separated.
    #[arg(long)]
    lambda: String,
    /// Position angles of the great circles about the sun, degrees, comma-separated: 0
    /// up toward the zenith, 90 sideways, 180 down.
    #[arg(long, default_value = "0,90,180")]
    psi: String,
    /// First angle from the sun, degrees.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    from: f64,
    /// Last angle, degrees.
    #[arg(long, default_value_t = 60.0, allow_hyphen_values = true)]
    to: f64,
    /// Angle step, degrees.
    #[arg(long, default_value_t = 0.25, allow_hyphen_values = true)]
    step: f64,
    /// Sun angular radius in degrees.
    #[arg(long, default_value_t = 0.2666, allow_hyphen_values = true)]
    sun_radius: f64,
    /// Rays per wavelength row of the table (default 2^20).
    #[arg(long)]
    rays: Option<u64>,
    /// Seed of the table's random numbers (default 0).
    #[arg(long)]
    seed: Option<u64>,
    /// Also draw the profile as a PNG chart, written atomically; the CSV still goes to
    /// standard output.
    #[arg(long)]
    plot: Option<PathBuf>,
}

pub(crate) fn run(c: HaloCommand) -> Result<()> {
    match c {
        HaloCommand::Profile(a) => {
            let a = *a;
            if let Some(p) = &a.plot {
                heron::plot::check_path(p, "--plot")?;
            }
            let req = heron::sky::halo::profile::HaloProfileRequest {
                sun_elevation_deg: a.sun_elevation,
                sun_radius_deg: a.sun_radius,
                crystals: a.crystals.clone(),
                lambdas: a.lambda,
                psi: a.psi,
                from_deg: a.from,
                to_deg: a.to,
                step_deg: a.step,
                rays: a.rays,
                seed: a.seed,
            };
            let profile = heron::sky::halo::profile::profile(&req)?;
            if let Some(p) = &a.plot {
                let title = format!(
                    "heron halo profile: sun at {}°, {}",
                    a.sun_elevation,
                    a.crystals.join(" + ")
                );
                let chart = heron::plot::sky::halo_chart(&title, &profile);
                heron::plot::write_png(p, &chart, "--plot")?;
            }
            print!("{}", profile.csv());
            Ok(())
        }
    }
}
