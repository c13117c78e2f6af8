//! The lecture's pinhole camera: eye, look-at point, up vector and camera constant d
//! (the distance from the eye to an image plane of height 1).
use glam::Vec3;

#[derive(Clone, Debug)]
pub struct Camera {
    pub eye: Vec3,
    pub look_at: Vec3,
    pub up: Vec3,
    /// Camera constant d; the vertical field of view is 2 atan(1 / (2d)).
    pub d: f32,
    pub width: u32,
    pub height: u32,
    // Orthonormal basis: b1 (right), b2 (up), v (forward).
    b1: Vec3,
    b2: Vec3,
    v: Vec3,
}

impl Camera {
    /// Fails with a description when the view direction is zero or parallel to `up`, or
    /// when d or the resolution is not positive.
    pub fn new(
        eye: Vec3,
        look_at: Vec3,
        up: Vec3,
        d: f32,
        width: u32,
        height: u32,
    ) -> Result<Camera, String> {
        let fwd = look_at - eye;
        if fwd.length_squared() == 0.0 || !fwd.is_finite() {
            return Err("eye and look_at must be distinct finite points".into());
        }
        if !(d > 0.0 && d.is_finite()) {
            return Err(format!("camera constant d must be positive, got {d}"));
        }
        if width == 0 || height == 0 {
            return Err("resolution must be at least 1x1".into());
        }
        let v = fwd.normalize();
        let b1 = v.cross(up);
        if b1.length_squared() < 1e-12 {
            return Err("up must not be parallel to the view direction".into());
        }
        let b1 = b1.normalize();
        let b2 = b1.cross(v);
        Ok(Camera {
            eye,
            look_at,
            up,
            d,
            width,
            height,
            b1,
            b2,
            v,
        })
    }

    /// Unit direction of the ray through film position (x, y) in pixels, (0, 0) at the
    /// top-left corner. The image plane spans [-aspect/2, aspect/2] × [-1/2, 1/2] at
    /// distance d, as in the course framework.
    #[inline]
    pub fn direction(&self, x: f32, y: f32) -> Vec3 {
        let aspect = self.width as f32 / self.height as f32;
        let u = (x / self.width as f32 - 0.5) * aspect;
        let w = 0.5 - y / self.height as f32;
        (u * self.b1 + w * self.b2 + self.d * self.v).normalize()
    }
}
