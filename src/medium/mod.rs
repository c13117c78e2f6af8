//! Participating media inside closed shapes: one file per medium, a closed [`Medium`]
//! enum dispatched by `match`.
//!
//! - `homogeneous`: water drops, σ_t(λ), σ_s(λ) and p(θ, λ) from heron's Lorenz–Mie code
//!   ([`crate::optics::mie`], BHMIE with water's complex index), tabulated once per scene
//!   (`phase_table`);
//! - `henyey_greenstein`: constant σ_a, σ_s and the Henyey–Greenstein phase function.
//!
//! Either is homogeneous, so that the transmittance over a distance d is exactly
//! T(λ) = exp(−σ_t(λ) d) and free-flight sampling with the hero's σ_t has no majorant
//! to bound (the majorant is σ_t itself; `integrator::path`), or heterogeneous: a
//! `density` field (`density`: height fog, a rain shaft, noise, a grid) scales its
//! coefficients, and the path tracer tracks null collisions against the field's
//! majorant grid (`tracking`: delta tracking for free flights, ratio tracking for
//! shadow rays, with the lanes' spectral MIS).
//!
//! In a scene (`medium = { ... }` on a shape, `scene/file.rs`): the shape must be closed
//! (a sphere, or a mesh whose every edge is shared by two triangles) and is either
//! - a medium's **index-matched boundary** (no material): rays cross it without
//!   refraction or reflection, and shadow rays continue through it; or
//! - a **dielectric** (smooth or rough) with the medium inside (a glass of milk): the
//!   surface refracts and reflects as any dielectric, the medium fills the inside.
//!   Opaque materials around a medium are refused (light could never enter it).
//!
//! Limits, stated: the camera is outside every medium; media do not nest or overlap (a
//! path leaving a shape's medium is in no medium, so a glass inside fog is surrounded by
//! vacuum once the path has entered it); only the path integrator renders media (the
//! others refuse such a scene with a one-line error).
//!
//! Directions: the phase functions take the angle θ between the path's propagation
//! direction `d_in` (the ray that reached the scattering point) and the new direction;
//! θ = 0 is forward. Being reciprocal, p is the same for light and importance.
pub mod density;
pub mod henyey_greenstein;
pub mod homogeneous;
pub mod phase_table;
pub mod tracking;

pub use density::Density;
pub use henyey_greenstein::HgMedium;
pub use homogeneous::{LorenzMieMedium, MieSpec, PopulationNode};

use crate::spectrum::stokes::{any_perpendicular, mueller_from_rows};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use glam::{Mat4, Vec2, Vec3};
use phase_table::{direction_at, v_between};

/// `Shape::medium` of a shape without a medium (defined with the shape).
pub use crate::geometry::NO_MEDIUM;

/// What a medium is made of: its coefficients at unit density and its phase function.
// A scene holds a handful of media, so the variants' sizes cost nothing; boxing the
// tabulated one would put an indirection in every phase lookup.
#[allow(clippy::large_enum_variant)]
#[derive(Debug)]
pub enum Optics {
    LorenzMie(LorenzMieMedium),
    HenyeyGreenstein(HgMedium),
}

/// A participating medium: its optics, homogeneous, or scaled by a density field
/// (`density`: heterogeneous, tracked with null collisions, `tracking`).
#[derive(Debug)]
pub struct Medium {
    pub optics: Optics,
    pub density: Option<density::Density>,
}

impl Medium {
    /// A homogeneous medium.
    pub fn homogeneous(optics: Optics) -> Medium {
        Medium {
            optics,
            density: None,
        }
    }

    /// The Lorenz–Mie tables, if the medium is made of water drops.
    pub fn lorenz_mie(&self) -> Option<&LorenzMieMedium> {
        match &self.optics {
            Optics::LorenzMie(m) => Some(m),
            Optics::HenyeyGreenstein(_) => None,
        }
    }

    /// Extinction coefficient at each lane.
    #[inline]
    pub fn sigma_t<const N: usize>(&self, wl: &SampledWavelengths<N>) -> SampledSpectrum<N> {
        match &self.optics {
            Optics::LorenzMie(m) => wl.eval(&m.sigma_t),
            Optics::HenyeyGreenstein(m) => wl.eval(&m.sigma_t),
        }
    }

    /// Scattering coefficient at each lane.
    #[inline]
    pub fn sigma_s<const N: usize>(&self, wl: &SampledWavelengths<N>) -> SampledSpectrum<N> {
        match &self.optics {
            Optics::LorenzMie(m) => wl.eval(&m.sigma_s),
            Optics::HenyeyGreenstein(m) => wl.eval(&m.sigma_s),
        }
    }

    /// Transmittance exp(−σ_t d) at each lane over distance `d`.
    #[inline]
    pub fn transmittance<const N: usize>(
        &self,
        d: f32,
        wl: &SampledWavelengths<N>,
    ) -> SampledSpectrum<N> {
        let st = self.sigma_t(wl);
        SampledSpectrum(std::array::from_fn(|i| (-st.0[i] * d).exp()))
    }

    /// The phase function at each lane for propagation `d_in` scattered into `d_out`
    /// (unit vectors).
    #[inline]
    pub fn phase<const N: usize>(
        &self,
        d_in: Vec3,
        d_out: Vec3,
        wl: &SampledWavelengths<N>,
    ) -> SampledSpectrum<N> {
        let v = v_between(d_in, d_out);
        match &self.optics {
            Optics::LorenzMie(m) => m.phase.eval(v, &wl.lambda),
            Optics::HenyeyGreenstein(m) => SampledSpectrum::splat(henyey_greenstein::hg(m.g, v)),
        }
    }

    /// The phase matrix for propagation `d_in` scattered into `d_out`, per lane divided
    /// by the phase function, with the frame it is written in for both beams: x̂ =
    /// d_in × d_out normalised, perpendicular to the scattering plane
    /// (`homogeneous`'s module docs). None when the medium depolarises
    /// (Henyey–Greenstein, which has no matrix, and a Lorenz–Mie table without one):
    /// then only the intensity survives, diag(1, 0, 0, 0).
    #[inline]
    pub fn phase_matrix<const N: usize>(
        &self,
        d_in: Vec3,
        d_out: Vec3,
        wl: &SampledWavelengths<N>,
    ) -> Option<([Mat4; N], Vec3)> {
        let Optics::LorenzMie(m) = &self.optics else {
            return None;
        };
        if !m.phase.has_matrix() {
            return None;
        }
        let r = m.phase.eval_matrix(v_between(d_in, d_out), &wl.lambda);
        let n = d_in.cross(d_out);
        let x = if n.length_squared() > 1e-12 {
            n.normalize()
        } else {
            any_perpendicular(d_in)
        };
        let m = std::array::from_fn(|i| {
            let [f12, f33, f34] = r[i];
            mueller_from_rows([
                [1.0, f12, 0.0, 0.0],
                [f12, 1.0, 0.0, 0.0],
                [0.0, 0.0, f33, f34],
                [0.0, 0.0, -f34, f33],
            ])
        });
        Some((m, x))
    }

    /// A new direction about `d_in` drawn from the hero wavelength's phase function
    /// (`u_node` chooses between the table's wavelength nodes, `u` the angles), and every
    /// lane's phase function there; lane 0's value is the sampling pdf (solid angle).
    #[inline]
    pub fn sample_phase<const N: usize>(
        &self,
        d_in: Vec3,
        u_node: f32,
        u: Vec2,
        wl: &SampledWavelengths<N>,
    ) -> (Vec3, SampledSpectrum<N>) {
        let (v, p) = match &self.optics {
            Optics::LorenzMie(m) => m.phase.sample(u_node, u.x, &wl.lambda),
            Optics::HenyeyGreenstein(m) => {
                let (v, p) = henyey_greenstein::sample_hg(m.g, u.x);
                (v, SampledSpectrum::splat(p))
            }
        };
        (direction_at(d_in, v, u.y), p)
    }
}
