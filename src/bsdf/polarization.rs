//! What a material does to polarisation: the Mueller matrix of one scattering event,
//! for polarised transport (`[render] polarization`, `integrator::polarized`).
//!
//! A model's [`super::BsdfModel::mueller`] gives, for light arriving along ωi and
//! leaving along ωo (local frame, both pointing away from the surface), per lane, the
//! Mueller matrix M of the event **divided by its [0][0] element**, with the frames it is
//! written in: x̂_in ⊥ ωi for the arriving light and x̂_out ⊥ ωo for the leaving light
//! (each with ŷ = k̂ × x̂ for its direction of travel k̂, as `spectrum::stokes` says).
//! The event's full Mueller BSDF is f(ωo, ωi) · M, where f is what `eval` or `sample`
//! returns: the scalar transport, its sampling and its MIS stay the unpolarised ones,
//! and polarisation is the matrix's shape. A [`Polarizing::Depolarizing`] event (a
//! Lambertian or a Phong lobe: light scattered in every direction by many facets and
//! by the substrate, whose phases add incoherently) keeps only S0:
//! M = diag(1, 0, 0, 0), the depolariser (Collett 2005, "Depolarizers"; Mitsuba 3's
//! `diffuse` and `roughplastic` do the same).
//!
//! For Fresnel events the frames are the s direction of the plane of incidence, for
//! both beams: for a smooth interface x̂ = ẑ × ωi (normalised), for a microfacet one
//! x̂ = ωi × ωo, perpendicular to the plane that holds ωi, ωo and the microfacet normal
//! (Mitsuba 3's `roughconductor` rotates into the same frame); at normal incidence any
//! perpendicular will do, the matrices being symmetric about the normal there.
use crate::optics::mueller::Mueller;
use crate::spectrum::stokes::{any_perpendicular, mueller_from_rows};
use glam::{Mat4, Vec3};

/// The polarisation of one event (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Polarizing<const N: usize> {
    /// diag(1, 0, 0, 0): only the intensity survives.
    Depolarizing,
    /// Per lane M / M[0][0], from the frame `x_in` ⊥ ωi to `x_out` ⊥ ωo (local frame).
    Mueller {
        m: [Mat4; N],
        x_in: Vec3,
        x_out: Vec3,
    },
}

/// The f32 matrix of `m` divided by its [0][0] (the identity's shape when it is 0: the
/// lane carries nothing then, f being 0).
#[inline]
pub fn normalized(m: &Mueller) -> Mat4 {
    let a = m.0[0][0];
    if !(a > 0.0) {
        return Mat4::IDENTITY;
    }
    mueller_from_rows(m.0.map(|r| r.map(|v| (v / a) as f32)))
}

/// The s direction of a smooth interface for light arriving along `wi` (local frame,
/// normal ẑ): ẑ × ωi normalised, or any horizontal axis at normal incidence.
#[inline]
pub fn s_of_plane(wi: Vec3) -> Vec3 {
    let s = Vec3::new(-wi.y, wi.x, 0.0);
    let n = s.length_squared();
    if n > 1e-12 {
        s / n.sqrt()
    } else {
        Vec3::X
    }
}

/// The s direction of the plane that holds `wi` and `wo` (a microfacet's plane of
/// incidence): ωi × ωo normalised, or any perpendicular to ωi when they are parallel.
#[inline]
pub fn s_of_pair(wi: Vec3, wo: Vec3) -> Vec3 {
    let s = wi.cross(wo);
    let n = s.length_squared();
    if n > 1e-12 {
        s / n.sqrt()
    } else {
        any_perpendicular(wi)
    }
}

/// A retarder's fast axis for a ray along ±`k` (local frame): `axis` (local, any
/// length) projected onto the sheet's plane (the local x axis when that projection
/// vanishes), turned by `angle` radians about the normal ẑ (counter-clockwise seen from
/// the outward side), and then projected perpendicular to the ray (Yeh 1982, "Extended
/// Jones matrix method", to first order). At normal incidence it is the sheet axis.
/// Polarisers use [`polarizer_axis`].
#[inline]
pub fn retarder_axis(axis: Vec3, angle: f32, k: Vec3) -> Vec3 {
    let x = in_plane_axis(axis, angle);
    let p = x - k * x.dot(k);
    if p.length_squared() > 1e-12 {
        p.normalize()
    } else {
        any_perpendicular(k)
    }
}

/// A polariser sheet's transmission axis for a ray along ±`k` (local frame), from its
/// in-sheet transmission axis (`axis` projected onto the sheet and turned by `angle`,
/// as [`retarder_axis`]): the sheet absorbs along the in-sheet axis across it, ẑ × x̂ (the
/// aligned absorbers of a dichroic sheet, the wires of a wire grid), so an oblique ray
/// loses the field along that absorption axis projected perpendicular to the ray, and
/// transmits what is perpendicular to both: k̂ × (the projected absorption axis)
/// (Korger et al. 2013, "The polarization properties of a tilted polarizer", Opt.
/// Express 21, 27032; Mitsuba 3's `polarizer` does the same). At normal incidence it
/// is the in-sheet axis; off it, it differs from projecting the transmission axis itself
/// by up to a degree at 10° from the normal.
#[inline]
pub fn polarizer_axis(axis: Vec3, angle: f32, k: Vec3) -> Vec3 {
    let x = in_plane_axis(axis, angle);
    let absorb = Vec3::new(-x.y, x.x, 0.0);
    let p = absorb - k * absorb.dot(k);
    let t = k.cross(p);
    if t.length_squared() > 1e-12 {
        t.normalize()
    } else {
        any_perpendicular(k)
    }
}

/// `axis` projected onto the sheet's plane and turned by `angle` about ẑ.
#[inline]
fn in_plane_axis(axis: Vec3, angle: f32) -> Vec3 {
    let a = Vec3::new(axis.x, axis.y, 0.0);
    let a = if a.length_squared() > 1e-12 {
        a.normalize()
    } else {
        Vec3::X
    };
    let (s, c) = angle.sin_cos();
    Vec3::new(a.x * c - a.y * s, a.x * s + a.y * c, 0.0)
}
