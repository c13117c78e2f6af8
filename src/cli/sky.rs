//! `heron sky`: radiance profiles and Lee diagrams of the rainbow sky models.
use super::DisplayFlags;
use anyhow::Result;
use std::path::PathBuf;

#[derive(clap::Subcommand)]
pub(crate) enum SkyCommand {
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
pub(crate) struct SkyLeeArgs {
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
pub(crate) struct SkyProfileArgs {
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
pub(crate) fn drops_from_flags(
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

pub(crate) fn run(c: SkyCommand) -> Result<()> {
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
