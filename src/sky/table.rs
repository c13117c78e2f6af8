//! A sky model tabulated over (θ, λ) for rendering. The physical models evaluate a
//! disk convolution on every call (tens of µs), far too slow per lane per escaping ray;
//! the table is built once per scene, in parallel, and read by bilinear interpolation.
//!
//! Grid: θ from 0 to 180° in steps of 0.01° over 35–56° (the primary bow, Alexander's
//! band and the secondary bow, where profiles change fastest) and 0.25° elsewhere; λ
//! every 5 nm over 360–830 nm. Interpolating between 5 nm rows moves a bow by at most
//! its own dispersion over 5 nm (≈ 0.03°), well inside the sun's 0.53° disk.
use super::{Polarisation, Sky, SkyModel, SkySpec};
use crate::spectrum::{DenseSpectrum, LAMBDA_MAX, LAMBDA_MIN};
use glam::Vec3;
use rayon::prelude::*;
use std::sync::OnceLock;

const FINE_FROM: f64 = 35.0;
const FINE_TO: f64 = 56.0;
const FINE_STEP: f64 = 0.01;
const COARSE_STEP: f64 = 0.25;
const LAMBDA_STEP: f32 = 5.0;

#[derive(Clone, Debug)]
pub struct SkyTable {
    /// θ of each column, degrees, increasing.
    theta_deg: Vec<f64>,
    n_lambda: usize,
    /// Row-major: values[l * n_theta + t].
    values: Vec<f32>,
}

fn theta_grid() -> Vec<f64> {
    let mut g = Vec::new();
    let push_range = |from: f64, to: f64, step: f64, g: &mut Vec<f64>| {
        let n = ((to - from) / step).round() as usize;
        for i in 0..n {
            g.push(from + i as f64 * step);
        }
    };
    push_range(0.0, FINE_FROM, COARSE_STEP, &mut g);
    push_range(FINE_FROM, FINE_TO, FINE_STEP, &mut g);
    push_range(FINE_TO, 180.0, COARSE_STEP, &mut g);
    g.push(180.0);
    g
}

impl SkyTable {
    /// Evaluates `sky.profile` on the grid, λ rows in parallel (deterministic: each
    /// value is computed independently).
    pub fn build(sky: &Sky) -> SkyTable {
        let theta_deg = theta_grid();
        let n_lambda = ((LAMBDA_MAX - LAMBDA_MIN) / LAMBDA_STEP).round() as usize + 1;
        let rows: Vec<Vec<f32>> = (0..n_lambda)
            .into_par_iter()
            .map(|l| {
                let lambda = LAMBDA_MIN + l as f32 * LAMBDA_STEP;
                theta_deg
                    .iter()
                    .map(|t| sky.profile(t.to_radians(), lambda).max(0.0))
                    .collect()
            })
            .collect();
        SkyTable {
            theta_deg,
            n_lambda,
            values: rows.concat(),
        }
    }

    /// The table whose every value is `f(a, b)` of `self`'s and `other`'s (same grid).
    fn combine(&self, other: &SkyTable, f: impl Fn(f32, f32) -> f32) -> SkyTable {
        SkyTable {
            theta_deg: self.theta_deg.clone(),
            n_lambda: self.n_lambda,
            values: self
                .values
                .iter()
                .zip(&other.values)
                .map(|(&a, &b)| f(a, b))
                .collect(),
        }
    }

    /// The θ nodes of the grid, degrees, increasing from 0 to 180.
    pub fn theta_grid(&self) -> &[f64] {
        &self.theta_deg
    }

    /// Column index and weight for θ in degrees.
    #[inline]
    fn column(&self, theta_deg: f64) -> (usize, f32) {
        let t = theta_deg.clamp(0.0, 180.0);
        let i = if t < FINE_FROM {
            (t / COARSE_STEP) as usize
        } else if t < FINE_TO {
            (FINE_FROM / COARSE_STEP) as usize + ((t - FINE_FROM) / FINE_STEP) as usize
        } else {
            (FINE_FROM / COARSE_STEP) as usize
                + ((FINE_TO - FINE_FROM) / FINE_STEP).round() as usize
                + ((t - FINE_TO) / COARSE_STEP) as usize
        };
        let i = i.min(self.theta_deg.len() - 2);
        let (a, b) = (self.theta_deg[i], self.theta_deg[i + 1]);
        (i, (((t - a) / (b - a)) as f32).clamp(0.0, 1.0))
    }

    /// The tabulated profile at θ (degrees) and λ (nm), bilinear.
    #[inline]
    pub fn eval(&self, theta_deg: f64, lambda_nm: f32) -> f32 {
        let (i, wt) = self.column(theta_deg);
        let x = ((lambda_nm - LAMBDA_MIN) / LAMBDA_STEP).clamp(0.0, (self.n_lambda - 1) as f32);
        let l = (x as usize).min(self.n_lambda - 2);
        let wl = x - l as f32;
        let n = self.theta_deg.len();
        let at = |l: usize, i: usize| self.values[l * n + i];
        let r0 = at(l, i) + wt * (at(l, i + 1) - at(l, i));
        let r1 = at(l + 1, i) + wt * (at(l + 1, i + 1) - at(l + 1, i));
        r0 + wl * (r1 - r0)
    }
}

/// What a scene's sky reads: a profile about the antisolar axis tabulated over (θ, λ),
/// or a halo table over the whole sky.
#[derive(Clone, Debug)]
pub enum SkyShape {
    Profile(SkyTable),
    Halo(super::halo::PlacedHalo),
}

/// A sky model ready for rendering: tabulated, tied to the scene's sun.
#[derive(Debug)]
pub struct SceneSky {
    /// The model's name, for messages.
    pub model: String,
    pub shape: SkyShape,
    /// Unit direction toward the sun.
    pub sun_dir: Vec3,
    /// Per-wavelength factor on the table: the sun's irradiance times `scale` for the
    /// physical models (their profile is radiance per unit solar irradiance), `scale`
    /// alone for the Aristotelian and constant skies.
    pub factor: DenseSpectrum,
    /// True when the model already contains the background (aristotle, constant), so it
    /// replaces it rather than adding to it.
    pub replaces_background: bool,
    /// The spec the model was built from, for the polarised table ([`Self::linear_table`]).
    spec: Option<SkySpec>,
    /// S1 of the scattered sunlight, built on first use (polarised renders only).
    linear: OnceLock<Option<SkyTable>>,
}

impl SceneSky {
    /// Tabulates `sky` for rendering (seconds for the physical models) and ties it to the
    /// scene's sun: `model` names it, `sun_dir` points toward the sun, `factor` and
    /// `replaces_background` as the fields say.
    pub fn new(
        model: String,
        mut sky: Sky,
        sun_dir: Vec3,
        factor: DenseSpectrum,
        replaces_background: bool,
    ) -> SceneSky {
        prepare(&mut sky);
        SceneSky {
            shape: SkyShape::Profile(SkyTable::build(&sky)),
            model,
            sun_dir,
            factor,
            replaces_background,
            spec: None,
            linear: OnceLock::new(),
        }
    }

    /// A halo sky ([`super::halo`]), traced for its sun, placed in the scene; it adds
    /// to the background and is unpolarised.
    pub fn halo(model: String, halo: super::halo::PlacedHalo, factor: DenseSpectrum) -> SceneSky {
        SceneSky {
            model,
            sun_dir: halo.placed.sun.as_vec3(),
            shape: SkyShape::Halo(halo),
            factor,
            replaces_background: false,
            spec: None,
            linear: OnceLock::new(),
        }
    }

    /// The same sky with the per-wavelength factor `factor` in place of its own (the
    /// tables are shared in value, the polarised one built anew when asked).
    pub fn with_factor(&self, factor: DenseSpectrum) -> SceneSky {
        SceneSky {
            model: self.model.clone(),
            shape: self.shape.clone(),
            sun_dir: self.sun_dir,
            factor,
            replaces_background: self.replaces_background,
            spec: self.spec.clone(),
            linear: OnceLock::new(),
        }
    }

    /// This sky with the spec its model was built from, so that a polarised render can
    /// tabulate its polarisation.
    pub fn with_spec(mut self, spec: SkySpec) -> SceneSky {
        self.spec = Some(spec);
        self
    }

    /// The linear polarisation of the sky light, S1 per unit solar irradiance over
    /// (θ, λ) (times `factor`, as the radiance table), in the frame x̂ perpendicular to
    /// the scattering plane (the plane of the sun, the drop and the observer): a
    /// sphere scatters the s and p components of unpolarised sunlight independently,
    /// with the intensities I_s and I_p of the model's `s` and `p` profiles, so the
    /// scattered light is S = ((I_s + I_p)/2, (I_s − I_p)/2, 0, 0) (Bohren & Huffman
    /// 1983, eq. 4.77 with an unpolarised incident beam: F11 and F12 only; Können 1985,
    /// "Polarized light in nature", ch. 10, for the bows' tangential polarisation). With
    /// the model's `polarisation = "s"` or `"p"` the sunlight is taken polarised that
    /// way, S1 = +S0 or −S0. None for the constant and Aristotelian skies, which are
    /// unpolarised. Tabulated on first call (twice the cost of the radiance table for an
    /// unpolarised sun); only polarised renders call it.
    pub fn linear_table(&self) -> Option<&SkyTable> {
        self.linear.get_or_init(|| self.build_linear()).as_ref()
    }

    fn build_linear(&self) -> Option<SkyTable> {
        let SkyShape::Profile(own) = &self.shape else {
            // The halo table is traced unpolarised (the crystals' Mueller matrices are
            // in `optics::ice`, not yet in the table).
            return None;
        };
        let spec = self.spec.as_ref()?;
        if !SkyModel::from_name(&spec.model).is_some_and(SkyModel::is_physical) {
            return None;
        }
        let pol = spec
            .polarisation
            .as_deref()
            .and_then(Polarisation::from_name)
            .unwrap_or_default();
        let table = |name: &str| {
            let mut s = spec.clone();
            s.polarisation = Some(name.into());
            // The spec was built once already: it builds again.
            let mut sky = s.build(&|k| format!("{k:?}")).ok()?;
            prepare(&mut sky);
            Some(SkyTable::build(&sky))
        };
        match pol {
            Polarisation::Unpolarised => {
                let (ts, tp) = (table("s")?, table("p")?);
                Some(ts.combine(&tp, |s, p| 0.5 * (s - p)))
            }
            Polarisation::S => Some(own.combine(own, |s, _| s)),
            Polarisation::P => Some(own.combine(own, |p, _| -p)),
        }
    }
}

/// Settings of a model that only its tabulation for rendering changes.
fn prepare(sky: &mut Sky) {
    if let Sky::Mie(m) = sky {
        if m.drops.len() > 1 {
            // One Mie series per node and wavelength: a table every 10 nm, interpolated
            // (the bows move by ≤ 0.06° over 10 nm, well inside the 0.53° disk), halves
            // the scene's 95 wavelengths of the sky table.
            m.lambda_step_nm = 10.0;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sky::DescartesSky;

    #[test]
    fn table_matches_the_model_between_its_nodes() {
        let sky = Sky::Descartes(DescartesSky::water(0.2666f64.to_radians()));
        let t = SkyTable::build(&sky);
        // Grid columns are where the table was evaluated.
        for &(theta, lambda) in &[
            (41.2, 450.0f32),
            (42.0, 650.0),
            (50.5, 500.0),
            (52.3, 600.0),
        ] {
            let exact = sky.profile(f64::to_radians(theta), lambda);
            let got = t.eval(theta, lambda);
            assert!(
                (got - exact).abs() <= 1e-6 + 1e-4 * exact.abs(),
                "θ {theta}: {got} vs {exact}"
            );
        }
        // Between nodes the error stays small against the bow's peak.
        let peak = sky.profile(41.9f64.to_radians(), 600.0);
        let mut worst = 0.0f32;
        for k in 0..2000 {
            let theta = 36.0 + 19.0 * k as f64 / 2000.0 + 0.0031;
            let lambda = 402.5 + (k % 80) as f32 * 4.1;
            let e = (t.eval(theta, lambda) - sky.profile(theta.to_radians(), lambda)).abs();
            worst = worst.max(e);
        }
        assert!(
            worst < 0.1 * peak,
            "worst interpolation error {worst} against peak {peak}"
        );
        // Column lookup is consistent at the grid's seams.
        for th in [0.0, 34.99, 35.0, 35.005, 55.999, 56.0, 56.1, 179.9, 180.0] {
            let (i, w) = t.column(th);
            assert!(
                t.theta_deg[i] <= th + 1e-9 && th <= t.theta_deg[i + 1] + 1e-9,
                "{th}"
            );
            assert!((0.0..=1.0).contains(&w));
        }
    }
}
