//! Participating media inside closed shapes: one file per medium, a closed [`Medium`]
//! enum dispatched by `match`.
//!
//! - `homogeneous`: water drops, σ_t(λ), σ_s(λ) and p(θ, λ) from heron's Lorenz–Mie code
//!   ([`crate::optics::mie`], BHMIE with water's complex index), tabulated once per scene
//!   (`phase_table`);
//! - `henyey_greenstein`: constant σ_a, σ_s and the Henyey–Greenstein phase function;
//! - `ice`: hexagonal ice crystals in random orientation (diamond dust), σ_t from their
//!   projected area and the phase function traced through them (`optics::ice`).
//!
//! Each is homogeneous, so that the transmittance over a distance d is exactly
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
pub mod ice;
pub mod phase_table;
pub mod tracking;

pub use density::Density;
pub use henyey_greenstein::HgMedium;
pub use homogeneous::{LorenzMieMedium, MieSpec, PopulationNode};
pub use ice::{IceMedium, IceSpec};

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
    Ice(IceMedium),
}

/// A participating medium: its optics, homogeneous, or scaled by a density field
/// (`density`: heterogeneous, tracked with null collisions, `tracking`), and optionally
/// a second population of drops that takes over with height (`aloft`).
#[derive(Debug)]
pub struct Medium {
    pub optics: Optics,
    pub density: Option<density::Density>,
    pub aloft: Option<Aloft>,
}

/// Drops that vary with height: the medium's own population below `from`, `optics`
/// above `to`, and between them the mixture (1 − s) · below + s · above of both
/// populations' coefficients, s the smoothstep of the height h = x·up from `from` to
/// `to` (large rain drops below, smaller ones aloft: the bow's colours and its
/// supernumeraries then change with height).
#[derive(Debug)]
pub struct Aloft {
    pub optics: Optics,
    pub up: Vec3,
    pub from: f32,
    pub to: f32,
}

impl Aloft {
    /// The part s ∈ [0, 1] of the population aloft at `p`.
    #[inline]
    pub fn share(&self, p: Vec3) -> f32 {
        let t = ((p.dot(self.up) - self.from) / (self.to - self.from)).clamp(0.0, 1.0);
        t * t * (3.0 - 2.0 * t)
    }
}

impl Optics {
    #[inline(always)]
    fn sigma_t<const N: usize>(&self, wl: &SampledWavelengths<N>) -> SampledSpectrum<N> {
        match self {
            Optics::LorenzMie(m) => wl.eval(&m.sigma_t),
            Optics::HenyeyGreenstein(m) => wl.eval(&m.sigma_t),
            Optics::Ice(m) => wl.eval(&m.sigma_t),
        }
    }

    #[inline(always)]
    fn sigma_s<const N: usize>(&self, wl: &SampledWavelengths<N>) -> SampledSpectrum<N> {
        match self {
            Optics::LorenzMie(m) => wl.eval(&m.sigma_s),
            Optics::HenyeyGreenstein(m) => wl.eval(&m.sigma_s),
            Optics::Ice(m) => wl.eval(&m.sigma_s),
        }
    }

    #[inline(always)]
    fn phase<const N: usize>(&self, v: f32, wl: &SampledWavelengths<N>) -> SampledSpectrum<N> {
        match self {
            Optics::LorenzMie(m) => m.phase.eval(v, &wl.lambda),
            Optics::HenyeyGreenstein(m) => SampledSpectrum::splat(henyey_greenstein::hg(m.g, v)),
            Optics::Ice(m) => m.phase.eval(v, &wl.lambda),
        }
    }

    /// (F12, F33, F34)/F11 per lane, None when the optics depolarise.
    #[inline(always)]
    fn matrix<const N: usize>(&self, v: f32, wl: &SampledWavelengths<N>) -> Option<[[f32; 3]; N]> {
        let Optics::LorenzMie(m) = self else {
            return None;
        };
        m.phase
            .has_matrix()
            .then(|| m.phase.eval_matrix(v, &wl.lambda))
    }

    /// v = 1 − cos θ drawn from the hero's phase function, and every lane's there.
    #[inline(always)]
    fn sample<const N: usize>(
        &self,
        u_node: f32,
        u: f32,
        wl: &SampledWavelengths<N>,
    ) -> (f32, SampledSpectrum<N>) {
        match self {
            Optics::LorenzMie(m) => m.phase.sample(u_node, u, &wl.lambda),
            Optics::HenyeyGreenstein(m) => {
                let (v, p) = henyey_greenstein::sample_hg(m.g, u);
                (v, SampledSpectrum::splat(p))
            }
            Optics::Ice(m) => m.phase.sample(u_node, u, &wl.lambda),
        }
    }
}

/// The Mueller matrix of rows (1, f12), (f12, 1), (f33, f34), (−f34, f33): a sphere's
/// normalised phase matrix (`homogeneous`'s module docs).
#[inline]
fn sphere_mueller([f12, f33, f34]: [f32; 3]) -> Mat4 {
    mueller_from_rows([
        [1.0, f12, 0.0, 0.0],
        [f12, 1.0, 0.0, 0.0],
        [0.0, 0.0, f33, f34],
        [0.0, 0.0, -f34, f33],
    ])
}

impl Medium {
    /// A homogeneous medium.
    pub fn homogeneous(optics: Optics) -> Medium {
        Medium {
            optics,
            density: None,
            aloft: None,
        }
    }

    /// Whether its coefficients vary in space (tracked with null collisions).
    #[inline]
    pub fn is_heterogeneous(&self) -> bool {
        self.density.is_some()
    }

    /// The Lorenz–Mie tables, if the medium is made of water drops.
    pub fn lorenz_mie(&self) -> Option<&LorenzMieMedium> {
        match &self.optics {
            Optics::LorenzMie(m) => Some(m),
            Optics::HenyeyGreenstein(_) | Optics::Ice(_) => None,
        }
    }

    /// Extinction coefficient at each lane (of the population below, at unit density).
    #[inline]
    pub fn sigma_t<const N: usize>(&self, wl: &SampledWavelengths<N>) -> SampledSpectrum<N> {
        self.optics.sigma_t(wl)
    }

    /// Scattering coefficient at each lane (of the population below, at unit density).
    #[inline]
    pub fn sigma_s<const N: usize>(&self, wl: &SampledWavelengths<N>) -> SampledSpectrum<N> {
        self.optics.sigma_s(wl)
    }

    /// Per lane, an extinction at unit density no population exceeds: the majorant's
    /// coefficient (the density's majorants times it bound σ_t everywhere).
    #[inline]
    pub fn majorant_sigma_t<const N: usize>(
        &self,
        wl: &SampledWavelengths<N>,
    ) -> SampledSpectrum<N> {
        let k = self.optics.sigma_t(wl);
        match &self.aloft {
            None => k,
            Some(a) => {
                let b = a.optics.sigma_t(wl);
                SampledSpectrum(std::array::from_fn(|i| k.0[i].max(b.0[i])))
            }
        }
    }

    /// σ_t and σ_s at each lane at point `p` of a heterogeneous medium, with the part of
    /// the population aloft there.
    #[inline]
    pub fn coefficients_at<const N: usize>(
        &self,
        p: Vec3,
        wl: &SampledWavelengths<N>,
    ) -> (SampledSpectrum<N>, SampledSpectrum<N>, f32) {
        let rho = self.density.as_ref().map_or(1.0, |d| d.eval(p));
        let (t, s) = (self.optics.sigma_t(wl), self.optics.sigma_s(wl));
        match &self.aloft {
            None => (t * rho, s * rho, 0.0),
            Some(a) => {
                let share = a.share(p);
                let (w0, w1) = (rho * (1.0 - share), rho * share);
                let (ta, sa) = (a.optics.sigma_t(wl), a.optics.sigma_s(wl));
                (t * w0 + ta * w1, s * w0 + sa * w1, share)
            }
        }
    }

    /// σ_t at each lane at point `p` of a heterogeneous medium.
    #[inline]
    pub fn extinction_at<const N: usize>(
        &self,
        p: Vec3,
        wl: &SampledWavelengths<N>,
    ) -> SampledSpectrum<N> {
        let rho = self.density.as_ref().map_or(1.0, |d| d.eval(p));
        let t = self.optics.sigma_t(wl);
        match &self.aloft {
            None => t * rho,
            Some(a) => {
                let share = a.share(p);
                t * (rho * (1.0 - share)) + a.optics.sigma_t(wl) * (rho * share)
            }
        }
    }

    /// Transmittance exp(−σ_t d) at each lane over distance `d` (homogeneous media).
    #[inline]
    pub fn transmittance<const N: usize>(
        &self,
        d: f32,
        wl: &SampledWavelengths<N>,
    ) -> SampledSpectrum<N> {
        let st = self.sigma_t(wl);
        SampledSpectrum(std::array::from_fn(|i| (-st.0[i] * d).exp()))
    }

    /// The medium at a point where a share `aloft` of its drops are the population aloft
    /// (0 without one): what its phase functions are there.
    #[inline]
    pub fn at(&self, aloft: f32) -> MediumPoint<'_> {
        MediumPoint {
            medium: self,
            aloft,
        }
    }

    /// The phase function at each lane for propagation `d_in` scattered into `d_out`
    /// (unit vectors), of the population below.
    #[inline]
    pub fn phase<const N: usize>(
        &self,
        d_in: Vec3,
        d_out: Vec3,
        wl: &SampledWavelengths<N>,
    ) -> SampledSpectrum<N> {
        self.at(0.0).phase(d_in, d_out, wl)
    }

    /// [`MediumPoint::phase_matrix`] of the population below.
    #[inline]
    pub fn phase_matrix<const N: usize>(
        &self,
        d_in: Vec3,
        d_out: Vec3,
        wl: &SampledWavelengths<N>,
    ) -> Option<([Mat4; N], Vec3)> {
        self.at(0.0).phase_matrix(d_in, d_out, wl)
    }

    /// [`MediumPoint::sample_phase`] of the population below.
    #[inline]
    pub fn sample_phase<const N: usize>(
        &self,
        d_in: Vec3,
        u_node: f32,
        u: Vec2,
        wl: &SampledWavelengths<N>,
    ) -> (Vec3, SampledSpectrum<N>) {
        self.at(0.0).sample_phase(d_in, u_node, u, wl)
    }
}

/// A medium where a share of its drops are the population aloft: its phase function
/// is the populations' mixture weighted by their scattering coefficients there.
#[derive(Clone, Copy, Debug)]
pub struct MediumPoint<'a> {
    pub medium: &'a Medium,
    pub aloft: f32,
}

impl<'a> MediumPoint<'a> {
    /// The population aloft and, per lane, the share of the scattering it does here
    /// (s σ_s,aloft / ((1 − s) σ_s,below + s σ_s,aloft)); None where only the population
    /// below scatters.
    #[inline]
    fn mixture<const N: usize>(
        &self,
        wl: &SampledWavelengths<N>,
    ) -> Option<(&'a Optics, SampledSpectrum<N>)> {
        let a = self.medium.aloft.as_ref()?;
        if self.aloft <= 0.0 {
            return None;
        }
        let (sb, sa) = (self.medium.optics.sigma_s(wl), a.optics.sigma_s(wl));
        let c = SampledSpectrum(std::array::from_fn(|i| {
            let (b, t) = ((1.0 - self.aloft) * sb.0[i], self.aloft * sa.0[i]);
            if b + t > 0.0 {
                t / (b + t)
            } else {
                self.aloft
            }
        }));
        Some((&a.optics, c))
    }

    /// The phase function at each lane for propagation `d_in` scattered into `d_out`
    /// (unit vectors).
    #[inline(always)]
    pub fn phase<const N: usize>(
        &self,
        d_in: Vec3,
        d_out: Vec3,
        wl: &SampledWavelengths<N>,
    ) -> SampledSpectrum<N> {
        let v = v_between(d_in, d_out);
        let below = self.medium.optics.phase(v, wl);
        if self.aloft <= 0.0 {
            return below;
        }
        match self.mixture(wl) {
            None => below,
            Some((aloft, c)) => mix(below, aloft.phase(v, wl), c),
        }
    }

    /// The phase matrix for propagation `d_in` scattered into `d_out`, per lane divided
    /// by the phase function, with the frame it is written in for both beams: x̂ =
    /// d_in × d_out normalised, perpendicular to the scattering plane
    /// (`homogeneous`'s module docs). None when the medium depolarises
    /// (Henyey–Greenstein and ice, which have no matrix, and a Lorenz–Mie table without one):
    /// then only the intensity survives, diag(1, 0, 0, 0). Two populations' matrices
    /// mix as their phase functions do, each weighted by its share of p.
    #[inline(always)]
    pub fn phase_matrix<const N: usize>(
        &self,
        d_in: Vec3,
        d_out: Vec3,
        wl: &SampledWavelengths<N>,
    ) -> Option<([Mat4; N], Vec3)> {
        let v = v_between(d_in, d_out);
        let r = self.medium.optics.matrix(v, wl)?;
        let n = d_in.cross(d_out);
        let x = if n.length_squared() > 1e-12 {
            n.normalize()
        } else {
            any_perpendicular(d_in)
        };
        let mixture = if self.aloft > 0.0 {
            self.mixture(wl)
        } else {
            None
        };
        let m = match mixture {
            None => std::array::from_fn(|i| sphere_mueller(r[i])),
            Some((aloft, c)) => {
                let ra = aloft.matrix(v, wl)?;
                let (pb, pa) = (self.medium.optics.phase(v, wl), aloft.phase(v, wl));
                std::array::from_fn(|i| {
                    let (wb, wa) = ((1.0 - c.0[i]) * pb.0[i], c.0[i] * pa.0[i]);
                    let w = if wb + wa > 0.0 { wa / (wb + wa) } else { 0.0 };
                    sphere_mueller(std::array::from_fn(|k| (1.0 - w) * r[i][k] + w * ra[i][k]))
                })
            }
        };
        Some((m, x))
    }

    /// A new direction about `d_in` drawn from the hero wavelength's phase function
    /// (`u_node` chooses the population, by the hero's share of the scattering, and then,
    /// rescaled, between the table's wavelength nodes; `u` the angles), and every lane's
    /// phase function there; lane 0's value is the sampling pdf (solid angle): the
    /// mixture's density is the mixture's phase function.
    #[inline(always)]
    pub fn sample_phase<const N: usize>(
        &self,
        d_in: Vec3,
        u_node: f32,
        u: Vec2,
        wl: &SampledWavelengths<N>,
    ) -> (Vec3, SampledSpectrum<N>) {
        let below = &self.medium.optics;
        let mixture = if self.aloft > 0.0 {
            self.mixture(wl)
        } else {
            None
        };
        let (v, p) = match mixture {
            None => below.sample(u_node, u.x, wl),
            Some((aloft, c)) => {
                let c0 = c.0[0];
                if u_node < c0 {
                    let (v, pa) = aloft.sample(u_node / c0, u.x, wl);
                    (v, mix(below.phase(v, wl), pa, c))
                } else {
                    let un = ((u_node - c0) / (1.0 - c0)).min(1.0 - f32::EPSILON / 2.0);
                    let (v, pb) = below.sample(un, u.x, wl);
                    (v, mix(pb, aloft.phase(v, wl), c))
                }
            }
        };
        (direction_at(d_in, v, u.y), p)
    }
}

/// (1 − c) below + c aloft, per lane.
#[inline]
fn mix<const N: usize>(
    below: SampledSpectrum<N>,
    aloft: SampledSpectrum<N>,
    c: SampledSpectrum<N>,
) -> SampledSpectrum<N> {
    SampledSpectrum(std::array::from_fn(|i| {
        (1.0 - c.0[i]) * below.0[i] + c.0[i] * aloft.0[i]
    }))
}
