//! The `[camera]` table to the seed's pinhole [`Camera`].
use super::errors::fmt_points;
use crate::camera::{Camera, D_MAX, D_MIN};
use crate::scene::file::{fmt_f32, CameraFile};
use glam::Vec3;

/// The camera of the `[camera]` table `c`.
pub(super) fn build_camera(c: &CameraFile) -> Result<Camera, String> {
    if !(c.look_at.0 - c.eye.0).length().is_finite() {
        return Err(format!(
            "camera: expected eye and look_at at a distance finite in f32, got eye = {} and look_at = {}",
            fmt_points(&[c.eye.0]),
            fmt_points(&[c.look_at.0])
        ));
    }
    let d = c.d.map_or(1.0, |d| d.0);
    if !(D_MIN..=D_MAX).contains(&d) {
        return Err(format!(
            "camera.d: expected a camera constant in [{D_MIN:e}, {D_MAX:e}] (a vertical field of view from about 180° down to 1e-6 rad), got {}",
            fmt_f32(d)
        ));
    }
    Camera::new(
        c.eye.0,
        c.look_at.0,
        c.up.map_or(Vec3::Y, |u| u.unit()),
        d,
        c.resolution.width,
        c.resolution.height,
    )
    .map_err(|e| format!("camera: {e}"))
}
