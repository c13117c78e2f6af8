//! The surface interaction: the seed's HitInfo as far as anyone reads it (distance,
//! position, normal, shader index), plus the geometry the materials' local frame and the
//! robust ray offsets are built from.
//!
//! The seed's other HitInfo fields live where they are used: `has_hit` is the integrator
//! loop's `Option<Hit>`, `depth` its loop counter, `ior1_over_ior2` the dielectric's
//! (`Dielectric::ior1_over_ior2`, and `Material::ior1_over_ior2` for `heron trace` and
//! `heron stress`), `specular` and `shininess` the Phong material's `rho_s` and
//! `shininess`.
use super::spawn::{self, SpawnPoint};
use super::{Ray, Shape, ShapeKind};
use crate::accel::embree::Hit;
use crate::math::Frame;
use glam::Vec3;

#[derive(Clone, Copy, Debug)]
pub struct Interaction {
    /// Distance along the ray.
    pub dist: f32,
    pub position: Vec3,
    /// Componentwise bound on `position`'s floating-point error (robust ray offsets).
    pub p_err: Vec3,
    /// Unit normal turned to face the incoming ray (ωo·n ≥ 0).
    pub normal: Vec3,
    /// Unit geometric normal pointing out of the shape (a triangle's counter-clockwise
    /// side): the z axis of the materials' local frame.
    pub n_outward: Vec3,
    /// True when the ray arrived on the side the outward normal points to (for a closed
    /// shape: from outside).
    pub front_face: bool,
    /// The lecture's shader index: the material in `Scene::materials`.
    pub material: u32,
    /// The shape hit (its Embree geometry ID).
    pub shape: u32,
    /// Texture coordinates, computed only for a textured material or a textured
    /// emission (zero otherwise; [`Shape::uv`]).
    pub uv: glam::Vec2,
}

impl Interaction {
    /// Fills the record for `hit` of `ray` on `shape`. With `robust` (robust ray offsets) the position comes with its
    /// error bound; without, the bound is left zero and its cost (the triangle's
    /// vertices and the bound's arithmetic, 3% of a Whitted render's instructions by
    /// callgrind) is not paid.
    // Always inlined: left to itself LLVM outlines it since it grew the robust branch,
    // and the call with its copied-out record cost 3% of a Whitted render (callgrind).
    #[inline(always)]
    pub fn new(ray: &Ray, hit: &Hit, shape: &Shape, robust: bool) -> Self {
        let (position, p_err, outward) = match &shape.kind {
            ShapeKind::Sphere { center, radius } => {
                // Re-project onto the sphere: the float hit point drifts off the surface
                // by a few ulps of t, which the ε offset of the next ray must not see.
                let d = (ray.at(hit.t) - *center).normalize();
                let (p, err) = if robust {
                    spawn::sphere_point(*center, *radius, d)
                } else {
                    (*center + *radius * d, Vec3::ZERO)
                };
                (p, err, d)
            }
            ShapeKind::Mesh(m) => {
                // From the barycentrics rather than o + t d: the error then depends on
                // the triangle's coordinates, not on how far the ray came.
                let (p, err) = if robust {
                    let [a, b, c] = m.triangle(hit.prim_id);
                    spawn::triangle_point(a, b, c, hit.u, hit.v)
                } else {
                    (ray.at(hit.t), Vec3::ZERO)
                };
                (p, err, unit_normal(hit.ng, -ray.dir))
            }
        };
        let front_face = outward.dot(ray.dir) < 0.0;
        let normal = if front_face { outward } else { -outward };
        Interaction {
            dist: hit.t,
            position,
            p_err,
            normal,
            n_outward: outward,
            front_face,
            material: shape.material,
            shape: hit.geom_id,
            uv: glam::Vec2::ZERO,
        }
    }

    /// Where rays leaving this hit start from ([`spawn::SpawnPoint`]).
    #[inline]
    pub fn spawn_point(&self) -> SpawnPoint {
        SpawnPoint {
            p: self.position,
            err: self.p_err,
            n: self.n_outward,
        }
    }

    /// The materials' local frame: z along the outward normal.
    #[inline]
    pub fn frame(&self) -> Frame {
        Frame::from_z(self.n_outward)
    }
}

/// Embree's unnormalised triangle normal made unit length. Its length is twice the
/// triangle's area, so for a small sliver (scene at 1e-4 scale, edges of 1e-9) its
/// squared length underflows f32 and `normalize` would return NaN: such a normal is
/// rescaled by its largest component first. A normal that is exactly zero (Embree does
/// not report such triangles, but a bound must hold for any input) is `fallback`.
#[inline]
pub fn unit_normal(ng: Vec3, fallback: Vec3) -> Vec3 {
    let l2 = ng.length_squared();
    if l2 > 1e-30 && l2.is_finite() {
        return ng * l2.sqrt().recip();
    }
    let m = ng.abs().max_element();
    if m > 0.0 && m.is_finite() {
        (ng / m).normalize()
    } else {
        fallback
    }
}
