//! Area lights: a shape of the scene that emits radiance L(λ) from its surface
//! (pbrt-v4 `DiffuseAreaLight`; Mitsuba 3 `area`). One-sided lights emit from the side
//! their outward normal points to (a triangle's counter-clockwise side, a sphere's
//! outside); two-sided lights from both.
//!
//! Sampling a point toward a receiver p:
//! - a sphere seen from outside is sampled uniformly over the cone of directions it
//!   subtends (pbrt-v4 `Sphere::Sample`, after Shirley et al. 1996), pdf 1/(2π(1 − cos θmax));
//!   from inside, uniformly over its area;
//! - a triangle mesh picks a triangle in proportion to its area and a point uniform on it
//!   (Heitz 2019's low-distortion map); the area density 1/A becomes a solid-angle
//!   density by d²/|cos θ_light|.
use super::{LightLeSample, LightLiSample};
use crate::geometry::spawn;
use crate::math::warp::{cosine_hemisphere, uniform_sphere, uniform_triangle};
use crate::math::{Distribution1D, Frame};
use crate::spectrum::{DenseSpectrum, SampledSpectrum, SampledWavelengths};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// The emitting surface, copied from the scene's shape so that a light can sample itself.
#[derive(Clone, Debug)]
pub enum AreaShape {
    Sphere {
        center: Vec3,
        radius: f32,
    },
    Triangles {
        /// Vertices of each triangle, counter-clockwise seen from the front.
        triangles: Vec<[Vec3; 3]>,
        /// Triangle choice in proportion to area.
        by_area: Distribution1D,
    },
}

#[derive(Clone, Debug)]
pub struct AreaLight {
    /// The scene shape (Embree geometry) that emits.
    pub shape: u32,
    pub emission: DenseSpectrum,
    pub two_sided: bool,
    pub geometry: AreaShape,
    /// Total surface area.
    pub area: f32,
}

/// A point on an emitter that a ray hit, for [`AreaLight::pdf_li`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfacePoint {
    pub p: Vec3,
    /// Unit outward normal.
    pub n: Vec3,
}

/// Below sin²θmax = sin²(1.5°) the cone's 1 − cos θmax loses its digits in f32; pbrt-v4
/// switches to the first-order expansion there.
const SMALL_CONE_SIN2: f32 = 0.000_685_23;

impl AreaLight {
    pub fn new(shape: u32, emission: DenseSpectrum, two_sided: bool, geometry: AreaShape) -> Self {
        let area = match &geometry {
            AreaShape::Sphere { radius, .. } => 4.0 * PI * radius * radius,
            AreaShape::Triangles { triangles, .. } => triangles.iter().map(triangle_area).sum(),
        };
        AreaLight {
            shape,
            emission,
            two_sided,
            geometry,
            area,
        }
    }

    /// A mesh emitter: triangles chosen by area.
    pub fn triangles(
        shape: u32,
        emission: DenseSpectrum,
        two_sided: bool,
        triangles: Vec<[Vec3; 3]>,
    ) -> Self {
        let areas: Vec<f32> = triangles.iter().map(triangle_area).collect();
        let by_area = Distribution1D::new(&areas);
        Self::new(
            shape,
            emission,
            two_sided,
            AreaShape::Triangles { triangles, by_area },
        )
    }

    /// Emitted radiance leaving the point with outward normal `n` along unit `w`.
    #[inline]
    pub fn l<const N: usize>(
        &self,
        n: Vec3,
        w: Vec3,
        wl: &SampledWavelengths<N>,
    ) -> SampledSpectrum<N> {
        if !self.two_sided && n.dot(w) <= 0.0 {
            return SampledSpectrum::zero();
        }
        wl.eval(&self.emission)
    }

    /// A point uniform over the surface, its outward normal, and the point's
    /// floating-point error bound.
    #[inline]
    fn sample_area(&self, u: Vec2) -> (Vec3, Vec3, Vec3) {
        match &self.geometry {
            AreaShape::Sphere { center, radius } => {
                let n = uniform_sphere(u);
                let (p, err) = spawn::sphere_point(*center, *radius, n);
                (p, n, err)
            }
            AreaShape::Triangles { triangles, by_area } => {
                let (i, _, t) = by_area.sample_discrete(u.x);
                let [a, b, c] = triangles[i];
                let bc = uniform_triangle(Vec2::new(t, u.y));
                let (p, err) = spawn::triangle_point(a, b, c, bc[1], bc[2]);
                (p, (b - a).cross(c - a).normalize(), err)
            }
        }
    }

    #[inline]
    pub fn sample_li<const N: usize>(
        &self,
        p: Vec3,
        u: Vec2,
        wl: &SampledWavelengths<N>,
    ) -> Option<LightLiSample<N>> {
        let (ps, n, pdf, p_err) = match &self.geometry {
            AreaShape::Sphere { center, radius }
                if (p - *center).length_squared() > radius * radius =>
            {
                let (_, n, pdf) = sample_sphere_cone(*center, *radius, p, u);
                let (ps, err) = spawn::sphere_point(*center, *radius, n);
                (ps, n, pdf, err)
            }
            _ => {
                let (ps, n, err) = self.sample_area(u);
                let to = ps - p;
                let d2 = to.length_squared();
                let cos_l = n.dot(-to).abs() / d2.sqrt();
                if !(d2 > 0.0) || cos_l == 0.0 {
                    return None;
                }
                (ps, n, d2 / (cos_l * self.area), err)
            }
        };
        let to = ps - p;
        let d = to.length();
        if !(d > 0.0) || !(pdf > 0.0) || !pdf.is_finite() {
            return None;
        }
        let wi = to / d;
        let l = self.l(n, -wi, wl);
        if l.is_zero() {
            return None;
        }
        Some(LightLiSample {
            l,
            wi,
            pdf,
            dist: d,
            delta: false,
            n,
            p: ps,
            p_err,
        })
    }

    /// Solid-angle density with which `sample_li` from `p` returns the direction toward
    /// `hit`, a point of this light.
    #[inline]
    pub fn pdf_li(&self, p: Vec3, hit: &SurfacePoint) -> f32 {
        if let AreaShape::Sphere { center, radius } = &self.geometry {
            let dc2 = (p - *center).length_squared();
            if dc2 > radius * radius {
                let sin2 = radius * radius / dc2;
                let omc = if sin2 < SMALL_CONE_SIN2 {
                    0.5 * sin2
                } else {
                    1.0 - (1.0 - sin2).max(0.0).sqrt()
                };
                return 1.0 / (2.0 * PI * omc);
            }
        }
        let to = hit.p - p;
        let d2 = to.length_squared();
        let cos_l = hit.n.dot(to).abs() / d2.sqrt();
        if cos_l == 0.0 || d2 == 0.0 {
            return 0.0;
        }
        d2 / (cos_l * self.area)
    }

    /// An emitted ray: a point uniform over the area, a cosine-weighted direction about
    /// its normal (either side for a two-sided light).
    #[inline]
    pub fn sample_le<const N: usize>(
        &self,
        u1: Vec2,
        u2: Vec2,
        wl: &SampledWavelengths<N>,
    ) -> Option<LightLeSample<N>> {
        let (p, n, origin_err) = self.sample_area(u1);
        let (mut u2, mut side) = (u2, 1.0);
        if self.two_sided {
            // The first half of u2.x emits from the front, the second from the back.
            if u2.x < 0.5 {
                u2.x *= 2.0;
            } else {
                u2.x = (2.0 * u2.x - 1.0).min(1.0 - f32::EPSILON / 2.0);
                side = -1.0;
            }
        }
        let local = cosine_hemisphere(u2);
        let dir = Frame::from_z(side * n).to_world(local);
        let pdf_dir = local.z / PI * if self.two_sided { 0.5 } else { 1.0 };
        if pdf_dir <= 0.0 {
            return None;
        }
        Some(LightLeSample {
            origin: p,
            origin_err,
            dir,
            l: self.l(n, dir, wl),
            pdf_pos: 1.0 / self.area,
            pdf_dir,
            normal: Some(n),
        })
    }

    /// Direction density of `sample_le` for a ray leaving the point with outward normal
    /// `n` in direction `dir`: cos θ/π on the emitting side (half each side when
    /// two-sided).
    #[inline]
    pub fn pdf_dir(&self, n: Vec3, dir: Vec3) -> f32 {
        let c = n.dot(dir);
        if self.two_sided {
            0.5 * c.abs() / PI
        } else if c > 0.0 {
            c / PI
        } else {
            0.0
        }
    }

    /// Φ = π A L (twice that when two-sided).
    pub fn phi(&self) -> f32 {
        PI * self.area * self.emission.mean() * if self.two_sided { 2.0 } else { 1.0 }
    }
}

fn triangle_area(t: &[Vec3; 3]) -> f32 {
    0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length()
}

/// A point of the sphere (center `c`, radius `r`) seen from `p` outside it, uniform in
/// the solid angle of the cone it subtends (pbrt-v4 `Sphere::Sample`): the direction at
/// angle θ from the axis meets the sphere where its normal makes angle α with the axis,
/// cos α = sin²θ/sin θmax + cos θ √(1 − sin²θ/sin²θmax). Returns the point, its normal
/// and the solid-angle pdf.
fn sample_sphere_cone(c: Vec3, r: f32, p: Vec3, u: Vec2) -> (Vec3, Vec3, f32) {
    let dc2 = (p - c).length_squared();
    let sin2_max = r * r / dc2;
    let sin_max = sin2_max.sqrt();
    let cos_max = (1.0 - sin2_max).max(0.0).sqrt();
    let mut omc_max = 1.0 - cos_max;
    let mut cos_t = (cos_max - 1.0) * u.x + 1.0;
    let mut sin2_t = 1.0 - cos_t * cos_t;
    if sin2_max < SMALL_CONE_SIN2 {
        sin2_t = sin2_max * u.x;
        cos_t = (1.0 - sin2_t).sqrt();
        omc_max = 0.5 * sin2_max;
    }
    let cos_a = sin2_t / sin_max + cos_t * (1.0 - sin2_t / sin2_max).max(0.0).sqrt();
    let sin_a = (1.0 - cos_a * cos_a).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    let frame = Frame::from_z((c - p).normalize());
    let n = frame.to_world(-Vec3::new(sin_a * phi.cos(), sin_a * phi.sin(), cos_a));
    (c + r * n, n, 1.0 / (2.0 * PI * omc_max))
}
