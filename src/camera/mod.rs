//! The lecture's pinhole camera: eye, look-at point, up vector and camera constant d
//! (the distance from the eye to an image plane of height 1).
//!
//! As a sensor (for paths that start at the lights): the importance a pinhole camera
//! gives a direction ω at angle θ from its axis is We(ω) = 1/(A cos⁴θ), where A is the
//! area of the image plane moved to distance 1 (aspect/d²); it makes ∫ We cos θ dω over
//! the image equal 1 (pbrt-v4 `PerspectiveCamera::We`, Veach 1997 §8.2). Camera rays
//! through uniformly chosen film points have the direction density 1/(A cos³θ); the
//! eye is a point (position density 1, a delta). A light path connects to the camera
//! through [`Camera::sample_wi`], which also says which pixel it lands in.
//!
//! With a lens ([`lens::LensCamera`], `[camera] type = "lens"`) the film is behind a
//! real lens prescription and camera rays come from [`Camera::ray`]; the pinhole's
//! importance functions above are for the pinhole only (light tracing and BDPT refuse
//! a lens camera).
//!
//! An orthographic camera ([`Projection::Orthographic`], `[camera] type =
//! "orthographic"`) sends parallel rays along its axis from an image plane of a given
//! height in scene units centred at the eye (pbrt-v4 `OrthographicCamera`, Mitsuba 3
//! `orthographic.cpp`). Its importance is a delta in direction, so no light path can
//! reach it by a connection (pbrt-v4 leaves its `SampleWi` unimplemented): light tracing
//! and BDPT refuse it too, and the importance functions are the pinhole's only.
pub mod filter;
pub mod lens;

use crate::geometry::Ray;
use glam::{DVec3, Vec2, Vec3};
use std::sync::Arc;

/// A camera ray with its weight: 1 for the pinhole; the lens's cos⁴θ A/z²/E₀ (see
/// [`lens`]). `hero_only`: the lens dispersed the wavelengths, so only the hero's ray is
/// this one and the companions end here.
#[derive(Clone, Copy, Debug)]
pub struct CameraRay {
    pub ray: Ray,
    pub weight: f32,
    pub hero_only: bool,
}

/// A connection from a point in the scene to the camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraWiSample {
    /// Importance We of the direction from the eye to the point.
    pub we: f32,
    /// Unit direction from the point toward the eye.
    pub wi: Vec3,
    /// Distance to the eye.
    pub dist: f32,
    /// Density of this connection in solid angle at the point: dist²/cos θ.
    pub pdf: f32,
    /// Film position in pixels, (0, 0) at the top-left corner.
    pub raster: (f32, f32),
}

/// Smallest camera constant d (a vertical field of view just under 180°).
pub const D_MIN: f32 = 1e-6;
/// Largest camera constant d (a vertical field of view of 1e-6 rad). Far beyond it the ray
/// directions d·v + … overflow f32 when normalised (d ≳ 1.8e19), and the image area
/// aspect/d² that the light-tracing integrators divide by goes to zero.
pub const D_MAX: f32 = 1e6;

/// How camera rays leave the image plane: through the eye, or parallel to the axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// The seed's pinhole: rays from the eye through an image plane of height 1 at d
    /// (and a lens camera's film, which [`Camera::lens`] carries).
    Perspective,
    /// Rays parallel to the axis, from the point of an image plane of `height` scene
    /// units (its width height·aspect) centred at the eye, perpendicular to the axis.
    Orthographic { height: f32 },
}

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
    /// The lens in front of the film; None for the seed's pinhole.
    pub lens: Option<Arc<lens::LensCamera>>,
    /// Perspective (the pinhole and the lens) or orthographic.
    pub projection: Projection,
    /// An ideal linear analyser in front of the camera (`[camera] polarizer`), its
    /// transmission axis this many radians from the image's horizontal, counter-clockwise
    /// as the photographer sees it; read by polarised transport only.
    pub polarizer: Option<f32>,
}

impl Camera {
    /// Fails with a description when the view direction is zero or parallel to `up`,
    /// when d is outside [`D_MIN`, `D_MAX`] or when the resolution is not positive.
    pub fn new(
        eye: Vec3,
        look_at: Vec3,
        up: Vec3,
        d: f32,
        width: u32,
        height: u32,
    ) -> Result<Camera, String> {
        let fwd = look_at - eye;
        if fwd == Vec3::ZERO || !fwd.is_finite() {
            return Err("eye and look_at must be distinct finite points".into());
        }
        if !(D_MIN..=D_MAX).contains(&d) {
            return Err(format!(
                "expected a camera constant d in [{D_MIN:e}, {D_MAX:e}] (a vertical field of view from about 180° down to 1e-6 rad), got {d}"
            ));
        }
        if width == 0 || height == 0 {
            return Err("resolution must be at least 1x1".into());
        }
        // Scaled by its largest component first, so that eye and look_at 1e-23 apart
        // (whose squared distance underflows f32) still give a unit axis.
        let v = (fwd / fwd.abs().max_element()).normalize();
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
            lens: None,
            projection: Projection::Perspective,
            polarizer: None,
        })
    }

    /// This camera made orthographic, its image plane `height` scene units high
    /// (finite and positive, checked by the loader).
    pub fn orthographic(mut self, height: f32) -> Camera {
        self.projection = Projection::Orthographic { height };
        self
    }

    /// Whether light paths can reach the camera by a connection (its importance is not
    /// a delta in direction and [`Camera::sample_wi`] holds): the pinhole only.
    pub fn connectable(&self) -> bool {
        self.lens.is_none() && self.projection == Projection::Perspective
    }

    /// The Stokes frame of light arriving at the camera along −`dir` (`dir` the camera
    /// ray's unit direction): x̂ is the image's horizontal (rightward) made
    /// perpendicular to the ray, so ŷ = −dir × x̂ is the image's up and S1 > 0 is
    /// horizontally polarised light in the picture.
    #[inline]
    pub fn stokes_x(&self, dir: Vec3) -> Vec3 {
        let x = self.b1 - dir * self.b1.dot(dir);
        if x.length_squared() > 1e-12 {
            x.normalize()
        } else {
            crate::spectrum::stokes::any_perpendicular(dir)
        }
    }

    /// This camera with `lens` in front of its film (the film's centre at `eye`).
    pub fn with_lens(mut self, lens: lens::LensCamera) -> Camera {
        self.lens = Some(Arc::new(lens));
        self
    }

    /// The same camera with another resolution (a lens keeps its film diagonal).
    pub fn resized(&self, width: u32, height: u32) -> Result<Camera, String> {
        let mut c = Camera::new(self.eye, self.look_at, self.up, self.d, width, height)?;
        c.lens = self.lens.clone();
        c.projection = self.projection;
        c.polarizer = self.polarizer;
        Ok(c)
    }

    /// The camera ray through film position (x, y) in pixels ((0, 0) at the top-left
    /// corner) at the hero wavelength `lambda_nm`; None when the lens stops it (the
    /// sample then adds 0). The pinhole and the orthographic camera draw nothing from
    /// `u`; the lens draws its point on the rear element.
    #[inline]
    pub fn ray(
        &self,
        x: f32,
        y: f32,
        u: impl FnOnce() -> Vec2,
        lambda_nm: f32,
    ) -> Option<CameraRay> {
        let Some(lens) = &self.lens else {
            let (origin, dir) = match self.projection {
                Projection::Perspective => (self.eye, self.pinhole_direction(x, y)),
                Projection::Orthographic { height } => (self.plane_point(x, y, height), self.v),
            };
            return Some(CameraRay {
                ray: Ray::new(origin, dir, 0.0, f32::INFINITY),
                weight: 1.0,
                hero_only: false,
            });
        };
        let (fw, fh) = lens.film_size(self.width, self.height);
        // The lens turns the image upside down and left to right: the film point of
        // the image's top-left corner is the film's bottom-right. The film's centre is
        // at −film_offset for the same reason (the offset is in the image's
        // orientation); adding (−0, −0) changes no bit of the centred film's points.
        let (cx, cy) = lens.film_centre();
        let film = (
            -(x as f64 / self.width as f64 - 0.5) * fw + cx,
            -(0.5 - y as f64 / self.height as f64) * fh + cy,
        );
        let u = u();
        let s = lens.sample(film, (u.x as f64, u.y as f64), lambda_nm as f64)?;
        Some(CameraRay {
            ray: Ray::new(
                self.lens_point(lens, s.ray.o),
                self.lens_dir(s.ray.d),
                0.0,
                f32::INFINITY,
            ),
            weight: s.weight as f32,
            hero_only: lens.hero_only(),
        })
    }

    /// A point of the lens's frame (mm; the film at z = film_z, +z toward the film) in
    /// the scene.
    #[inline]
    fn lens_point(&self, lens: &lens::LensCamera, p: DVec3) -> Vec3 {
        let k = 1.0 / lens.settings.mm_per_unit;
        let back = ((lens.film_z() - p.z) * k) as f32;
        self.eye + back * self.v + (p.x * k) as f32 * self.b1 + (p.y * k) as f32 * self.b2
    }

    /// A direction of the lens's frame in the scene (unit).
    #[inline]
    fn lens_dir(&self, d: DVec3) -> Vec3 {
        (-(d.z as f32) * self.v + d.x as f32 * self.b1 + d.y as f32 * self.b2).normalize()
    }

    /// The orthographic camera's ray origin for film position (x, y) in pixels: the
    /// point of the image plane [-aspect/2, aspect/2] × [-1/2, 1/2] · `height` centred at
    /// the eye (the image's top-left corner at (0, 0), as for the pinhole).
    #[inline]
    fn plane_point(&self, x: f32, y: f32, height: f32) -> Vec3 {
        let aspect = self.width as f32 / self.height as f32;
        let u = (x / self.width as f32 - 0.5) * aspect * height;
        let w = (0.5 - y / self.height as f32) * height;
        self.eye + u * self.b1 + w * self.b2
    }

    /// Unit direction of the ray through film position (x, y) in pixels, (0, 0) at the
    /// top-left corner. The image plane spans [-aspect/2, aspect/2] × [-1/2, 1/2] at
    /// distance d, as in the course framework. The orthographic camera's rays all point
    /// along its axis.
    #[inline]
    pub fn direction(&self, x: f32, y: f32) -> Vec3 {
        match self.projection {
            Projection::Perspective => self.pinhole_direction(x, y),
            Projection::Orthographic { .. } => self.v,
        }
    }

    /// The pinhole's [`Camera::direction`].
    #[inline]
    fn pinhole_direction(&self, x: f32, y: f32) -> Vec3 {
        let aspect = self.width as f32 / self.height as f32;
        let u = (x / self.width as f32 - 0.5) * aspect;
        let w = 0.5 - y / self.height as f32;
        (u * self.b1 + w * self.b2 + self.d * self.v).normalize()
    }

    /// The side of one pixel on the orthographic camera's image plane (scene units), the
    /// same at every distance; None for the perspective cameras (see
    /// [`Camera::pixel_angle`]). Photon mapping sizes its first gather radii by it.
    pub fn pixel_size(&self) -> Option<f32> {
        match self.projection {
            Projection::Perspective => None,
            Projection::Orthographic { height } => Some(height / self.height as f32),
        }
    }

    /// The angle (radians) one pixel subtends at the centre of the image: 1/(d·height)
    /// for the pinhole; for a lens, the film's pixel pitch over the lens's effective
    /// focal length at its focus wavelength. Photon mapping sizes its first gather radii
    /// by it.
    pub fn pixel_angle(&self) -> f32 {
        match &self.lens {
            None => 1.0 / (self.d * self.height as f32),
            Some(lens) => {
                let (_, fh) = lens.film_size(self.width, self.height);
                let efl = lens::paraxial::paraxial(&lens.system, lens.settings.focus_wavelength)
                    .efl
                    .abs();
                (fh / self.height as f64 / efl.max(1e-9)) as f32
            }
        }
    }

    /// The unit viewing direction (the camera's axis).
    pub fn forward(&self) -> Vec3 {
        self.v
    }

    /// Area of the image plane at distance 1 from the eye.
    #[inline]
    fn film_area(&self) -> f32 {
        let aspect = self.width as f32 / self.height as f32;
        aspect / (self.d * self.d)
    }

    /// Film position (pixels) that the unit direction `w` from the eye passes through,
    /// or None when it is outside the image (or behind the camera). Inverse of
    /// [`Camera::direction`].
    #[inline]
    pub fn raster(&self, w: Vec3) -> Option<(f32, f32)> {
        let c = w.dot(self.v);
        if !(c > 0.0) {
            return None;
        }
        let aspect = self.width as f32 / self.height as f32;
        let u = self.d * w.dot(self.b1) / c;
        let v = self.d * w.dot(self.b2) / c;
        let x = (u / aspect + 0.5) * self.width as f32;
        let y = (0.5 - v) * self.height as f32;
        let inside =
            (0.0..self.width as f32).contains(&x) && (0.0..self.height as f32).contains(&y);
        inside.then_some((x, y))
    }

    /// Importance We(w) of the unit direction `w` leaving the eye (zero outside the
    /// image).
    #[inline]
    pub fn we(&self, w: Vec3) -> f32 {
        if self.raster(w).is_none() {
            return 0.0;
        }
        let c = w.dot(self.v);
        1.0 / (self.film_area() * c * c * c * c)
    }

    /// (position density, direction density) of the camera ray leaving in unit
    /// direction `w`, when film points are chosen uniformly: (1, 1/(A cos³θ)); the
    /// direction density is zero outside the image.
    #[inline]
    pub fn pdf_we(&self, w: Vec3) -> (f32, f32) {
        if self.raster(w).is_none() {
            return (1.0, 0.0);
        }
        let c = w.dot(self.v);
        (1.0, 1.0 / (self.film_area() * c * c * c))
    }

    /// The connection from point `p` to the eye: We, the direction, its solid-angle
    /// density dist²/cos θ (pbrt-v4 `PerspectiveCamera::SampleWi` with a pinhole) and
    /// the pixel; None when `p` is not in view.
    #[inline]
    pub fn sample_wi(&self, p: Vec3) -> Option<CameraWiSample> {
        let to_eye = self.eye - p;
        let d2 = to_eye.length_squared();
        let dist = d2.sqrt();
        if !(dist > 0.0) {
            return None;
        }
        let wi = to_eye / dist;
        let w = -wi;
        let raster = self.raster(w)?;
        let c = w.dot(self.v);
        Some(CameraWiSample {
            we: 1.0 / (self.film_area() * c * c * c * c),
            wi,
            dist,
            pdf: d2 / c,
            raster,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cam() -> Camera {
        Camera::new(
            Vec3::new(1.0, 2.0, 3.0),
            Vec3::new(0.0, 0.5, -1.0),
            Vec3::Y,
            1.3,
            64,
            40,
        )
        .unwrap()
    }

    #[test]
    fn axis_is_unit_for_close_points_and_d_is_bounded() {
        // eye and look_at 3e-23 apart: the squared distance underflows f32, and the axis
        // came out with length 0.8 before it was scaled first (found while writing the
        // scene_toml fuzz harness's camera check).
        let c = Camera::new(Vec3::new(3e-23, 0.0, 0.0), Vec3::ZERO, Vec3::Y, 1.0, 4, 3).unwrap();
        assert!(
            (c.forward() - Vec3::NEG_X).length() < 1e-6,
            "{}",
            c.forward()
        );
        for d in [D_MIN, 1.0, D_MAX] {
            let c = Camera::new(Vec3::Z, Vec3::ZERO, Vec3::Y, d, 4, 3).unwrap();
            let w = c.direction(0.0, 0.0);
            assert!((w.length() - 1.0).abs() < 1e-6, "d = {d}: {w}");
            let we = c.we(c.forward());
            assert!(we.is_finite() && we > 0.0, "d = {d}: We = {we}");
        }
        for d in [D_MIN * 0.5, D_MAX * 2.0, 1e20] {
            let e = Camera::new(Vec3::Z, Vec3::ZERO, Vec3::Y, d, 4, 3).unwrap_err();
            assert!(e.contains("camera constant d in [1e-6, 1e6]"), "{e}");
        }
    }

    #[test]
    fn raster_inverts_direction() {
        let c = cam();
        for &(x, y) in &[(0.5f32, 0.5f32), (10.25, 30.75), (63.5, 39.5), (32.0, 20.0)] {
            let (rx, ry) = c.raster(c.direction(x, y)).unwrap();
            assert!(
                (rx - x).abs() < 1e-3 && (ry - y).abs() < 1e-3,
                "({x}, {y}) -> ({rx}, {ry})"
            );
        }
        assert!(c.raster(-c.forward()).is_none());
    }

    /// ∫ We cos θ dω over the image is 1, and so is ∫ pdf_dir dω: integrated over the
    /// film in pixel space, where dω = cos³θ dA/d² (dA the film area element at
    /// distance d).
    #[test]
    fn importance_and_direction_density_integrate_to_one() {
        let c = cam();
        let aspect = c.width as f64 / c.height as f64;
        let pixel_area = aspect / c.width as f64 / c.height as f64; // at distance d
        let (mut a, mut b) = (0.0f64, 0.0f64);
        let k = 4;
        for y in 0..c.height * k {
            for x in 0..c.width * k {
                let w = c.direction((x as f32 + 0.5) / k as f32, (y as f32 + 0.5) / k as f32);
                let cos = w.dot(c.forward()) as f64;
                let domega = cos.powi(3) * pixel_area / (k * k) as f64 / (c.d as f64).powi(2);
                a += c.we(w) as f64 * cos * domega;
                b += c.pdf_we(w).1 as f64 * domega;
            }
        }
        assert!((a - 1.0).abs() < 1e-4 && (b - 1.0).abs() < 1e-4, "{a} {b}");
    }

    #[test]
    fn sample_wi_points_at_the_eye_with_dist_squared_over_cos() {
        let c = cam();
        let p = c.eye + 5.0 * c.direction(20.0, 10.0);
        let s = c.sample_wi(p).unwrap();
        assert!((s.dist - 5.0).abs() < 1e-4);
        assert!((s.wi + c.direction(20.0, 10.0)).length() < 1e-5);
        let cos = c.direction(20.0, 10.0).dot(c.forward());
        assert!((s.pdf - 25.0 / cos).abs() < 1e-2);
        assert!((s.raster.0 - 20.0).abs() < 1e-3 && (s.raster.1 - 10.0).abs() < 1e-3);
        assert!(c.sample_wi(c.eye - c.forward()).is_none());
    }
}
