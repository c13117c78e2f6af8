//! The ray of the lecture: origin, direction and the interval [t_min, t_max].
use crate::accel::embree::RayQuery;
use glam::Vec3;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub origin: Vec3,
    /// Unit direction.
    pub dir: Vec3,
    /// Offset distance ε for rays leaving a surface (seed, "Shadow rays").
    pub t_min: f32,
    pub t_max: f32,
}

impl Ray {
    pub fn new(origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> Self {
        Ray {
            origin,
            dir,
            t_min,
            t_max,
        }
    }

    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + t * self.dir
    }

    /// The Embree query of this ray.
    #[inline]
    pub fn query(&self) -> RayQuery {
        RayQuery {
            origin: self.origin,
            dir: self.dir,
            tnear: self.t_min,
            tfar: self.t_max,
        }
    }
}
