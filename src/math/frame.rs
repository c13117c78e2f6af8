//! Orthonormal shading frames: the local coordinate system in which materials are
//! written (z = the surface normal; directions point away from the surface, as in the
//! seed and pbrt-v4 §9.1).
use glam::Vec3;

/// An orthonormal basis (s, t, n).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    pub s: Vec3,
    pub t: Vec3,
    pub n: Vec3,
}

impl Frame {
    /// A frame whose z axis is the unit vector `n`; the tangents come from Duff et al.
    /// 2017 ("Building an Orthonormal Basis, Revisited", JCGT 6(1)), which glam's
    /// `any_orthonormal_pair` implements and which has no singularity at n = −z.
    #[inline]
    pub fn from_z(n: Vec3) -> Frame {
        let (s, t) = n.any_orthonormal_pair();
        Frame { s, t, n }
    }

    #[inline]
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }

    #[inline]
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        v.x * self.s + v.y * self.t + v.z * self.n
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Rng;

    #[test]
    fn frames_are_orthonormal_and_round_trip() {
        let mut rng = Rng::new(1, 2);
        for k in 0..10_000 {
            let n = if k < 4 {
                [Vec3::Z, -Vec3::Z, Vec3::X, -Vec3::Y][k]
            } else {
                crate::math::warp::uniform_sphere(glam::Vec2::new(rng.uniform(), rng.uniform()))
            };
            let f = Frame::from_z(n);
            for (a, b) in [(f.s, f.t), (f.t, f.n), (f.s, f.n)] {
                assert!(a.dot(b).abs() < 1e-6);
            }
            for v in [f.s, f.t, f.n] {
                assert!((v.length() - 1.0).abs() < 1e-6);
            }
            assert!((f.s.cross(f.t) - f.n).length() < 1e-5, "right-handed");
            let v = Vec3::new(0.3, -0.4, 0.5);
            assert!((f.to_world(f.to_local(v)) - v).length() < 1e-6);
        }
    }
}
