//! Rainbow skies: the radiance seen in a direction, as a function of the angle θ from
//! the antisolar point, the wavelength and the sun's angular radius.
//!
//! Conventions shared by every model:
//!
//! - `sun_dir` is the unit direction **toward** the sun; the antisolar point is
//!   −`sun_dir`; θ is the angle between the view direction and −`sun_dir`
//!   ([`antisolar_angle`]). The primary bow is near θ = 42°, the secondary near 51°.
//! - Wavelengths in nm, angles in radians (degrees only in the CLI and in files).
//! - Every model has `profile(theta_rad, lambda_nm)` (radiance against θ) and
//!   `radiance(view_dir, lambda_nm, sun_dir)`, which evaluates the profile at the
//!   view's θ (the Aristotelian model evaluates the seed's vector formula instead; both
//!   agree).
//! - The sun is a uniform disk of angular radius α (default
//!   [`SUN_ANGULAR_RADIUS_DEG`](crate::light::sun::SUN_ANGULAR_RADIUS_DEG)). The physical
//!   models convolve their point-sun profile with the disk: near a bow of radius ≈ 42° a
//!   disk of radius α ≪ θ contributes along θ with the chord-length kernel
//!   K(u) = 2 √(α² − u²) / (π α²), |u| < α ([`disk_kernel`]), which integrates to 1.
//!
//! Normalisation of the physical models (`descartes`, `airy`, `mie`): the profile is the
//! differential scattering cross-section of one drop per unit solid angle divided by its
//! geometric cross-section, p(θ) = (dσ/dΩ) / (π a²) in sr⁻¹, averaged over the sun's
//! disk. It is the sky radiance per unit solar irradiance for an optically thin sheet of
//! drops with total geometric cross-section per unit area 1 (L = E_sun · p), so it is a
//! *relative radiance* whose scale is the same at every wavelength: multiplying by the
//! solar spectrum gives the colour. In this unit the geometric-optics contributions of all
//! orders k integrate to 1 over the sphere when Fresnel factors are 1; Mie adds diffraction
//! (another 1, almost all within a few degrees of the sun).
//!
//! Drop-size distributions (`airy`, `mie`; [`crate::drops`]): the profile is
//! ⟨dσ/dΩ⟩ / ⟨π a²⟩ over the distribution, i.e. the per-radius profiles averaged with
//! weights ∝ number × a², so one radius gives that radius's profile unchanged. `mie` can
//! keep one term of the Debye series ([`crate::optics::debye`]); `lee` computes Lee
//! diagrams.
//!
//! The single-particle physics (Lorenz–Mie, Debye) is [`crate::optics`]; this module holds
//! what makes it a sky (profiles, disk averages, tables). [`SkySpec`] (`spec.rs`) is the
//! one description of a sky that scene files, `heron sky profile` and the Python module
//! fill, with its rules and limits.
//!
//! Halos (`halo`): sunlight scattered by ice crystals, which depends on the direction
//! about the sun as well as the angle from it when the crystals are oriented, so it is a
//! table over the sphere ([`halo`]) rather than a profile in θ; it shares the unit of
//! the physical models (radiance per unit solar irradiance per unit geometric
//! cross-section).
//!
//! Polarisation: `S` means incident light polarised perpendicular to the scattering plane
//! (Fresnel's s, Mie's S₁), `P` parallel to it (Fresnel's p, Mie's S₂); unpolarised light is
//! their mean.
pub mod airy;
pub mod aristotle;
pub mod constant;
pub mod descartes;
pub mod halo;
pub mod lee;
pub mod mie;
pub mod profile;
pub mod spec;
pub mod table;

pub use airy::AirySky;
pub use aristotle::AristotleSky;
pub use constant::ConstantSky;
pub use descartes::DescartesSky;
pub use mie::MieSky;
pub use spec::{SkyKey, SkyModel, SkySpec};
pub use table::SceneSky;

use glam::Vec3;

/// Polarisation of the incident sunlight relative to the scattering plane.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Polarisation {
    #[default]
    Unpolarised,
    /// Perpendicular to the scattering plane (Fresnel s, Mie S₁).
    S,
    /// Parallel to the scattering plane (Fresnel p, Mie S₂).
    P,
}

impl Polarisation {
    /// The names scene files, the CLI and Python give, in the order of the variants
    /// ("unpolarized" is read as "unpolarised" too).
    pub const NAMES: [&'static str; 3] = ["unpolarised", "s", "p"];

    /// The polarisation named `name`, if any.
    pub fn from_name(name: &str) -> Option<Polarisation> {
        match name {
            "unpolarized" => Some(Polarisation::Unpolarised),
            _ => [Polarisation::Unpolarised, Polarisation::S, Polarisation::P]
                .into_iter()
                .zip(Self::NAMES)
                .find_map(|(p, n)| (n == name).then_some(p)),
        }
    }

    /// Combines a quantity computed for s and for p light.
    #[inline]
    pub fn mix(self, s: f64, p: f64) -> f64 {
        match self {
            Polarisation::Unpolarised => 0.5 * (s + p),
            Polarisation::S => s,
            Polarisation::P => p,
        }
    }
}

/// A sky model; closed enum dispatched with `match`.
pub enum Sky {
    Constant(ConstantSky),
    Aristotle(AristotleSky),
    Descartes(DescartesSky),
    Airy(AirySky),
    Mie(MieSky),
}

impl Sky {
    /// Radiance seen along the unit `view_dir` at `lambda_nm` with the sun toward the unit
    /// `sun_dir`.
    pub fn radiance(&self, view_dir: Vec3, lambda_nm: f32, sun_dir: Vec3) -> f32 {
        match self {
            Sky::Constant(s) => s.radiance(view_dir, lambda_nm, sun_dir),
            Sky::Aristotle(s) => s.radiance(view_dir, lambda_nm, sun_dir),
            Sky::Descartes(s) => s.radiance(view_dir, lambda_nm, sun_dir),
            Sky::Airy(s) => s.radiance(view_dir, lambda_nm, sun_dir),
            Sky::Mie(s) => s.radiance(view_dir, lambda_nm, sun_dir),
        }
    }

    /// Radiance at angle `theta_rad` from the antisolar point.
    pub fn profile(&self, theta_rad: f64, lambda_nm: f32) -> f32 {
        match self {
            Sky::Constant(s) => s.profile(theta_rad, lambda_nm),
            Sky::Aristotle(s) => s.profile(theta_rad, lambda_nm),
            Sky::Descartes(s) => s.profile(theta_rad, lambda_nm),
            Sky::Airy(s) => s.profile(theta_rad, lambda_nm),
            Sky::Mie(s) => s.profile(theta_rad, lambda_nm),
        }
    }
}

/// Angle θ (radians, in [0, π]) between `view_dir` and the antisolar direction
/// −`sun_dir`; atan2 of |cross| and dot in f64, accurate at every angle. Neither vector
/// needs to be unit length.
#[inline]
pub fn antisolar_angle(view_dir: Vec3, sun_dir: Vec3) -> f64 {
    let v = view_dir.as_dvec3();
    let a = -sun_dir.as_dvec3();
    v.cross(a).length().atan2(v.dot(a))
}

/// The solar disk's chord-length kernel K(u) = 2 √(α² − u²) / (π α²) for |u| < α, else 0
/// (radians; ∫K du = 1): the fraction of a uniform disk of angular radius α per unit
/// angle along one axis.
#[inline]
pub fn disk_kernel(u: f64, alpha: f64) -> f64 {
    let s = alpha * alpha - u * u;
    if s <= 0.0 {
        0.0
    } else {
        2.0 * s.sqrt() / (std::f64::consts::PI * alpha * alpha)
    }
}

/// Nodes t_j and weights w_j (Σ w_j = 1) for averaging f over the solar disk along θ:
/// ∫ K(u) f(θ − u) du = Σ w_j f(θ − α t_j). Gauss–Chebyshev quadrature of the second kind
/// (Abramowitz & Stegun 25.4.40): t_j = cos(jπ/(N+1)), w_j = 2 sin²(jπ/(N+1)) / (N+1),
/// exact for polynomials of degree 2N − 1 times the kernel.
pub fn disk_quadrature(n: usize) -> Vec<(f64, f64)> {
    (1..=n)
        .map(|j| {
            let a = j as f64 * std::f64::consts::PI / (n as f64 + 1.0);
            (a.cos(), 2.0 * a.sin().powi(2) / (n as f64 + 1.0))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn disk_quadrature_integrates_the_kernel() {
        let q = disk_quadrature(40);
        let sum: f64 = q.iter().map(|&(_, w)| w).sum();
        assert!((sum - 1.0).abs() < 1e-12);
        // Second moment of the chord kernel: α²/4.
        let m2: f64 = q.iter().map(|&(t, w)| w * t * t).sum();
        assert!((m2 - 0.25).abs() < 1e-12);
        // The kernel itself integrates to 1.
        let a = 0.01;
        let n = 200_000;
        let h = 2.0 * a / n as f64;
        let s: f64 = (0..n)
            .map(|i| disk_kernel(-a + (i as f64 + 0.5) * h, a) * h)
            .sum();
        assert!((s - 1.0).abs() < 1e-6, "{s}");
    }

    #[test]
    fn antisolar_angle_is_measured_from_minus_sun() {
        let sun = Vec3::new(0.0, 0.0, 1.0);
        assert!(antisolar_angle(-sun, sun).abs() < 1e-12);
        let v = Vec3::new(42f32.to_radians().sin(), 0.0, -42f32.to_radians().cos());
        assert!((antisolar_angle(v, sun).to_degrees() - 42.0).abs() < 1e-5);
    }
}
