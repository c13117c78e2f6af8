//! The surface interaction: the seed's HitInfo, with the fields the lecture adds for
//! specular and glossy shading (shader index, ior1_over_ior2, specular, shininess) and
//! the path depth, plus the geometry the materials' local frame is built from.
use super::{Ray, Shape, ShapeKind};
use crate::accel::embree::Hit;
use crate::bsdf::Material;
use crate::math::Frame;
use glam::Vec3;

#[derive(Clone, Copy, Debug)]
pub struct Interaction {
    /// The lecture's has_hit: cleared by a shader that continues the path.
    pub has_hit: bool,
    /// Distance along the ray.
    pub dist: f32,
    pub position: Vec3,
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
    /// Relative index n_i/n_t for a ray crossing here (1 for non-refractive materials).
    pub ior1_over_ior2: f32,
    /// Specular reflectance ρs (glossy materials; 0 otherwise).
    pub specular: f32,
    /// Phong exponent s (glossy materials; 0 otherwise).
    pub shininess: f32,
    /// Number of times the path has been continued before reaching this hit.
    pub depth: u32,
}

impl Interaction {
    /// Fills the record for `hit` of `ray` on `shape`, whose material is `material`;
    /// `lambda` (nm) is the wavelength the path follows (the hero), at which the index
    /// ratio is evaluated.
    #[inline]
    pub fn new(
        ray: &Ray,
        hit: &Hit,
        shape: &Shape,
        material: &Material,
        depth: u32,
        lambda: f32,
    ) -> Self {
        let (position, outward) = match &shape.kind {
            ShapeKind::Sphere { center, radius } => {
                // Re-project onto the sphere: the float hit point drifts off the surface
                // by a few ulps of t, which the ε offset of the next ray must not see.
                let d = (ray.at(hit.t) - *center).normalize();
                (*center + *radius * d, d)
            }
            ShapeKind::Mesh(_) => (ray.at(hit.t), hit.ng.normalize()),
        };
        let front_face = outward.dot(ray.dir) < 0.0;
        let normal = if front_face { outward } else { -outward };
        let (ior1_over_ior2, specular, shininess) = material.hit_info(lambda, front_face);
        Interaction {
            has_hit: true,
            dist: hit.t,
            position,
            normal,
            n_outward: outward,
            front_face,
            material: shape.material,
            shape: hit.geom_id,
            ior1_over_ior2,
            specular,
            shininess,
            depth,
        }
    }

    /// The materials' local frame: z along the outward normal.
    #[inline]
    pub fn frame(&self) -> Frame {
        Frame::from_z(self.n_outward)
    }
}
