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
use crate::settings::{IntegratorKind, RenderSettings};
use glam::Vec3;

/// How rays leave surfaces in a render (see the module notes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RayOffset {
    /// The seed's fixed offset ε (scene units).
    Epsilon(f32),
    /// Offsets by the hit point's floating-point error bound.
    Robust,
}

impl RenderSettings {
    /// The ray offsets of a render by `integrator`: `offset`, with `auto` resolved by
    /// the integrator.
    #[inline]
    pub fn ray_offset(&self, integrator: IntegratorKind) -> RayOffset {
        if self.offset.is_epsilon(integrator) {
            RayOffset::Epsilon(self.epsilon)
        } else {
            RayOffset::Robust
        }
    }
}

/// The smallest sphere radius a scene may have, relative to its centre's largest
/// coordinate: below it the sphere spans a handful of f32 steps at its centre, less than
/// the error bound of its hit points ([`sphere_point`]), and rays pass through it
/// (`heron stress` finds leaks from 2e-7 down).
pub const MIN_RELATIVE_RADIUS: f32 = 1e-6;

/// pbrt-v4's `ShadowEpsilon`: a robust shadow ray stops this fraction short of its
/// (already offset) target, for the rounding of the ray's own arithmetic.
///
/// Its limit, as in pbrt: an occluder within 10⁻⁴ of the distance from a light (or the
/// eye) is not seen, e.g. a cover glass 1 mm in front of a lamp seen from 10 m.
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
    /// Σ|nᵢ| errᵢ, times 5/4.
    ///
    /// Two departures from pbrt, both checked with `heron stress`:
    /// * pbrt rounds each component one float further from the surface, so that the sum
    ///   p + offset cannot round back toward it. Rounding the sum to nearest moves
    ///   component i by at most ½ ulp(yᵢ) ≤ u|yᵢ| (u = 2⁻²⁴), about u Σ|nᵢ||pᵢ| across
    ///   the plane, while every bound here is at least 6u Σ|nᵢ||pᵢ|: the extra ¼ of d
    ///   (≥ 1.5u Σ|nᵢ||pᵢ|) covers it. The per-component rounding was half of robust
    ///   offsets' extra instructions in a path-traced Cornell box when measured
    ///   (callgrind).
    /// * d has a floor of ⅛ of the largest error component: on an axis-aligned plane
    ///   through 0 the error across the plane is exactly 0, and an origin a denormal off
    ///   it would be flushed back into the plane by Embree's flush-to-zero mode.
    #[inline]
    pub fn offset_toward(&self, w: Vec3) -> Vec3 {
        let n = self.n;
        let d = 1.25 * n.abs().dot(self.err).max(0.125 * self.err.max_element());
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

/// As the provenance attribute `heron.offset` and `heron stress` name it: `epsilon 0.0001`
/// or `robust`.
impl std::fmt::Display for RayOffset {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RayOffset::Epsilon(eps) => write!(f, "epsilon {eps}"),
            RayOffset::Robust => f.write_str("robust"),
        }
    }
}

impl RayOffset {
    /// Whether hits need their error bounds ([`crate::geometry::Interaction::new`]).
    #[inline]
    pub fn is_robust(self) -> bool {
        self == RayOffset::Robust
    }

    /// A ray leaving `from` in unit direction `dir` (from t = 0 for a point in free
    /// space, whatever the offsets).
    #[inline]
    pub fn spawn(self, from: &SpawnPoint, dir: Vec3) -> Ray {
        match self {
            RayOffset::Epsilon(_) if from.n == Vec3::ZERO => {
                Ray::new(from.p, dir, 0.0, f32::INFINITY)
            }
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
        // y = 0 exactly with no error across the plane: only the floor moves the point,
        // and the step must survive flush-to-zero.
        let sp = SpawnPoint {
            p: Vec3::new(3.0, 0.0, -2.0),
            err: Vec3::new(2e-6, 0.0, 1e-6),
            n: Vec3::Y,
        };
        let o = sp.offset_toward(Vec3::Y);
        assert!(o.y >= 0.125 * 2e-6 && o.y.is_normal(), "{}", o.y);
        assert!(sp.offset_toward(-Vec3::Y).y <= -0.125 * 2e-6);
    }

    fn vec64(v: Vec3) -> [f64; 3] {
        [v.x as f64, v.y as f64, v.z as f64]
    }

    /// The bounds hold against f64 arithmetic on the same inputs, for triangles and
    /// spheres from 1e-4 to 1e4 in size and up to 1e4 from the origin, and the offset
    /// point lies strictly on the side it was sent to.
    #[test]
    fn error_bounds_cover_the_rounding_and_offsets_land_on_their_side() {
        let mut rng = crate::math::Rng::new(7, 3);
        let mut u = || rng.uniform();
        for _ in 0..200_000 {
            let scale = 10f32.powf(8.0 * u() - 4.0);
            let shift = Vec3::new(u() - 0.5, u() - 0.5, u() - 0.5) * 10f32.powf(4.0 * u());
            let mut vert = || Vec3::new(u() - 0.5, u() - 0.5, u() - 0.5) * scale + shift;
            let (a, b, c) = (vert(), vert(), vert());
            let n = (b - a).cross(c - a);
            if !(n.length() > 1e-3 * scale * scale) {
                continue;
            }
            let n = n.normalize();
            let (bu, bv) = (u(), u());
            let (bu, bv) = if bu + bv > 1.0 {
                (1.0 - bu, 1.0 - bv)
            } else {
                (bu, bv)
            };
            let (p, err) = triangle_point(a, b, c, bu, bv);
            let (a64, b64, c64) = (vec64(a), vec64(b), vec64(c));
            let w0 = 1.0 - bu as f64 - bv as f64;
            for k in 0..3 {
                let exact = w0 * a64[k] + bu as f64 * b64[k] + bv as f64 * c64[k];
                assert!(
                    (p[k] as f64 - exact).abs() <= err[k] as f64,
                    "triangle {a} {b} {c}: component {k} off by {:e}, bound {:e}",
                    (p[k] as f64 - exact).abs(),
                    err[k]
                );
            }
            // The plane through the exact vertices, in f64.
            let (n64, p0) = (vec64(n), a64);
            let side = |q: Vec3| -> f64 { (0..3).map(|k| n64[k] * (q[k] as f64 - p0[k])).sum() };
            let sp = SpawnPoint { p, err, n };
            assert!(side(sp.offset_toward(n)) > 0.0, "triangle {a} {b} {c}");
            assert!(side(sp.offset_toward(-n)) < 0.0, "triangle {a} {b} {c}");

            let center = shift;
            if scale < MIN_RELATIVE_RADIUS * center.abs().max_element() {
                // Below float precision where it is: the loader refuses such a sphere.
                continue;
            }
            let d = crate::math::warp::uniform_sphere(glam::Vec2::new(u(), u()));
            let (p, err) = sphere_point(center, scale, d);
            let c64 = vec64(center);
            let dist = |q: Vec3| -> f64 {
                (0..3)
                    .map(|k| (q[k] as f64 - c64[k]).powi(2))
                    .sum::<f64>()
                    .sqrt()
                    - scale as f64
            };
            assert!(
                dist(p).abs() <= d.abs().dot(err) as f64 + 1e-30,
                "sphere at {center}"
            );
            let sp = SpawnPoint { p, err, n: d };
            assert!(
                dist(sp.offset_toward(d)) > 0.0,
                "sphere at {center} r {scale}"
            );
            assert!(
                dist(sp.offset_toward(-d)) < 0.0,
                "sphere at {center} r {scale}"
            );
        }
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
