//! Where rays leaving a surface start.
//!
//! Two ways, chosen per render ([`RayOffset`]):
//!
//! * **Epsilon**, the seed's ("Shadow rays"): the new ray starts at the hit point with
//!   t_min = ε, and a shadow ray stops at dist − ε. ε is a length in scene units, so it
//!   fits a scene of about unit size; it stays the `whitted` integrator's default so the
//!   course scenes render as the lecture describes.
//! * **Robust**: the origin is moved off the surface along the geometric normal by the
//!   hit point's floating-point error bound and rounded away from the surface, and the
//!   ray starts at t_min = 0 (Pharr, Jakob & Humphreys, *Physically Based Rendering*,
//!   4th ed., §6.8.6 "Robust Spawned Ray Origins", `OffsetRayOrigin`; the error bounds
//!   of §6.8.5 for triangles and §6.8.4 for spheres are in [`triangle_point`] and
//!   [`sphere_point`]). A shadow ray is offset at both ends the same way and stops at
//!   1 − 10⁻⁴ of the way (pbrt-v4 `SpawnRayTo`, `ShadowEpsilon`). Nothing depends on the
//!   scene's size, so a scene scaled by 10⁻⁴ or 10⁴, or moved far from the origin,
//!   renders the same. The default of the physically based integrators.
use super::Ray;
use crate::accel::embree::RayQuery;
use glam::Vec3;

/// How rays leave surfaces in a render (see the module notes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RayOffset {
    /// The seed's fixed offset ε (scene units).
    Epsilon(f32),
    /// Offsets by the hit point's floating-point error bound.
    Robust,
}

/// pbrt-v4's `ShadowEpsilon`: a robust shadow ray stops this fraction short of its
/// (already offset) target, for the rounding of the ray's own arithmetic.
pub const SHADOW_EPSILON: f32 = 1e-4;

/// Higham's γ(n) = n u / (1 − n u) with u = 2⁻²⁴, the bound on the relative error of n
/// successive f32 roundings (pbrt-v4 §6.8.1).
#[inline]
pub const fn gamma(n: u32) -> f32 {
    let nu = n as f32 * (f32::EPSILON * 0.5);
    nu / (1.0 - nu)
}

/// A point rays may leave from: its position, a componentwise bound on the position's
/// floating-point error, and the surface's geometric normal (zero for a point in free
/// space: a pinhole, a point light).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpawnPoint {
    pub p: Vec3,
    pub err: Vec3,
    pub n: Vec3,
}

impl SpawnPoint {
    /// A point not on a surface: its rays need no offset.
    #[inline]
    pub fn free(p: Vec3) -> Self {
        SpawnPoint {
            p,
            err: Vec3::ZERO,
            n: Vec3::ZERO,
        }
    }

    /// The position moved off the surface, to the side that direction `w` leaves to
    /// (pbrt-v4 `OffsetRayOrigin`): by the error bound projected on the normal, d =
    /// Σ|nᵢ| errᵢ, times 9/8.
    ///
    /// Two departures from pbrt, both measured with `heron stress`:
    /// * pbrt rounds each component one float further from the surface, so that the sum
    ///   p + offset cannot round back toward it. Rounding the sum moves the point by at
    ///   most ½ ulp(pᵢ) per component, ½u Σ|nᵢ||pᵢ| across the plane, while every bound
    ///   here is at least 6u Σ|nᵢ||pᵢ| (u = 2⁻²⁴): the extra ⅛ of d covers it. The
    ///   per-component rounding was half the instruction cost of robust offsets in a
    ///   path-traced Cornell box (callgrind: +5.9% against ε, +3.1% without it).
    /// * d has a floor of ⅛ of the largest error component: on an axis-aligned plane
    ///   through 0 the error across the plane is exactly 0, and an origin a denormal off
    ///   it would be flushed back into the plane by Embree's flush-to-zero mode.
    #[inline]
    pub fn offset_toward(&self, w: Vec3) -> Vec3 {
        let n = self.n;
        let d = 1.125 * n.abs().dot(self.err).max(0.125 * self.err.max_element());
        let mut offset = d * n;
        if w.dot(n) < 0.0 {
            offset = -offset;
        }
        self.p + offset
    }
}

/// The point with barycentric coordinates (1 − u − v, u, v) of triangle (a, b, c) and its
/// error bound.
///
/// The bound has two terms. γ(7) Σ|bᵢ pᵢ| bounds the rounding of the interpolation
/// itself (pbrt-v4 §6.8.5, eq. 6.24, with the barycentrics' own rounding folded in as
/// pbrt does). pbrt's own intersector then rejects hits closer than its bound on t; Embree
/// does not, and its plane test dot(Ng, v₀ − o) rounds in proportion to the distance from
/// the origin to the triangle's vertices. So a second term, [`EMBREE_EXTENT_GAMMA`] times
/// the largest |pᵢ − p| component, keeps a ray from re-hitting a large triangle it left
/// (measured with `heron stress`: without it, walls of 2 m in scenes/newton-prism.toml
/// were re-hit at t ≈ 2e-8).
#[inline]
pub fn triangle_point(a: Vec3, b: Vec3, c: Vec3, u: f32, v: f32) -> (Vec3, Vec3) {
    let b0 = 1.0 - u - v;
    let (pa, pb, pc) = (b0 * a, u * b, v * c);
    let p = pa + pb + pc;
    let extent = (a - p)
        .abs()
        .max((b - p).abs())
        .max((c - p).abs())
        .max_element();
    let err = gamma(7) * (pa.abs() + pb.abs() + pc.abs())
        + Vec3::splat(gamma(EMBREE_EXTENT_GAMMA) * extent);
    (p, err)
}

/// The γ(n) of the triangle bound's extent term (see [`triangle_point`]).
pub const EMBREE_EXTENT_GAMMA: u32 = 8;

/// The point of the sphere (centre, radius) in unit direction `d` from its centre, and
/// its error bound: γ(5) of the radius vector for the re-projection (pbrt-v4 §6.8.4,
/// `Sphere::Intersect`'s pError) plus the translation by the centre, γ(6) overall to cover
/// both sums.
#[inline]
pub fn sphere_point(center: Vec3, radius: f32, d: Vec3) -> (Vec3, Vec3) {
    let rd = radius * d;
    let p = center + rd;
    let err = gamma(6) * (center.abs() + rd.abs());
    (p, err)
}

impl RayOffset {
    /// Whether hits need their error bounds ([`crate::geometry::Interaction::new`]).
    #[inline]
    pub fn is_robust(self) -> bool {
        self == RayOffset::Robust
    }

    /// A ray leaving `from` in unit direction `dir`.
    #[inline]
    pub fn spawn(self, from: &SpawnPoint, dir: Vec3) -> Ray {
        match self {
            RayOffset::Epsilon(eps) => Ray::new(from.p, dir, eps, f32::INFINITY),
            RayOffset::Robust => Ray::new(from.offset_toward(dir), dir, 0.0, f32::INFINITY),
        }
    }

    /// The shadow ray from `from` toward the point `to`, which lies along unit `wi` at
    /// distance `dist` (infinite for a light at infinity; `to` is then unused). `None`
    /// when the two points are too close to tell apart, which counts as blocked (the
    /// seed's rule: a light closer than 2ε is blocked).
    #[inline(always)]
    pub fn shadow(
        self,
        from: &SpawnPoint,
        wi: Vec3,
        dist: f32,
        to: &SpawnPoint,
    ) -> Option<RayQuery> {
        match self {
            RayOffset::Epsilon(eps) => {
                let t_max = if dist.is_finite() {
                    dist - eps
                } else {
                    f32::INFINITY
                };
                (t_max > eps).then_some(RayQuery {
                    origin: from.p,
                    dir: wi,
                    tnear: eps,
                    tfar: t_max,
                })
            }
            RayOffset::Robust => {
                let pf = from.offset_toward(wi);
                if !dist.is_finite() {
                    return Some(RayQuery {
                        origin: pf,
                        dir: wi,
                        tnear: 0.0,
                        tfar: f32::INFINITY,
                    });
                }
                // A target in free space (a point light, the pinhole) stays put.
                let pt = if to.n == Vec3::ZERO {
                    to.p
                } else {
                    to.offset_toward(-wi)
                };
                // Points within each other's error bounds cannot be told apart: the
                // offsets would meet or cross.
                let along = (pf - from.p).dot(wi) + (to.p - pt).dot(wi);
                let d = pt - pf;
                (along < dist && d.dot(wi) > 0.0).then_some(RayQuery {
                    origin: pf,
                    dir: d,
                    tnear: 0.0,
                    tfar: 1.0 - SHADOW_EPSILON,
                })
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gamma_matches_its_definition() {
        let u = f32::EPSILON * 0.5;
        assert_eq!(gamma(1), u / (1.0 - u));
        assert!(gamma(7) > 7.0 * u && gamma(7) < 7.01 * u);
    }

    #[test]
    fn offset_leaves_to_the_side_of_the_direction() {
        let sp = SpawnPoint {
            p: Vec3::new(3.0, 0.5, -2.0),
            err: Vec3::splat(1e-6),
            n: Vec3::Y,
        };
        let up = sp.offset_toward(Vec3::new(0.3, 0.1, 0.0));
        let down = sp.offset_toward(Vec3::new(0.3, -0.1, 0.0));
        assert!(up.y > 0.5 + 1e-6 && down.y < 0.5 - 1e-6);
        assert_eq!((up.x, up.z), (3.0, -2.0));
    }

    #[test]
    fn offset_from_a_plane_through_zero_is_a_normal_float() {
        // y = 0 exactly: no error across the plane, but the step must survive
        // flush-to-zero.
        let (p, err) = triangle_point(
            Vec3::new(-5.0, 0.0, -5.0),
            Vec3::new(5.0, 0.0, -5.0),
            Vec3::new(0.0, 0.0, 5.0),
            0.3,
            0.3,
        );
        assert_eq!(p.y, 0.0);
        let sp = SpawnPoint { p, err, n: Vec3::Y };
        let o = sp.offset_toward(Vec3::Y);
        assert!(o.y >= f32::MIN_POSITIVE, "{}", o.y);
    }

    #[test]
    fn epsilon_shadow_rays_keep_the_seeds_cutoffs() {
        let off = RayOffset::Epsilon(1e-3);
        let sp = SpawnPoint::free(Vec3::ZERO);
        let q = off.shadow(&sp, Vec3::X, 2.0, &sp).unwrap();
        assert_eq!((q.tnear, q.tfar), (1e-3, 2.0 - 1e-3));
        assert!(off.shadow(&sp, Vec3::X, 1.5e-3, &sp).is_none());
        let inf = off.shadow(&sp, Vec3::X, f32::INFINITY, &sp).unwrap();
        assert_eq!(inf.tfar, f32::INFINITY);
    }

    #[test]
    fn robust_shadow_rays_stop_short_of_an_offset_target() {
        let from = SpawnPoint {
            p: Vec3::new(1000.0, 0.0, 0.0),
            err: Vec3::splat(1e-4),
            n: Vec3::Y,
        };
        let to = SpawnPoint {
            p: Vec3::new(1000.0, 2.0, 0.0),
            err: Vec3::splat(1e-4),
            n: -Vec3::Y,
        };
        let q = RayOffset::Robust.shadow(&from, Vec3::Y, 2.0, &to).unwrap();
        assert!(q.origin.y > 1e-4 && q.tnear == 0.0);
        let end = q.origin + q.tfar * q.dir;
        assert!(end.y < 2.0 - 1e-4, "{end}");
        // Points within each other's error bound count as blocked.
        let near = SpawnPoint {
            p: Vec3::new(1000.0, 1e-5, 0.0),
            ..to
        };
        assert!(RayOffset::Robust
            .shadow(&from, Vec3::Y, 1e-5, &near)
            .is_none());
    }
}
