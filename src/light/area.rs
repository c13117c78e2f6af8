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
//!
//! The emission is a spectrum L(λ), or a texture over the surface's uv times that
//! spectrum ([`EmissionTexture`]; pbrt-v4's `DiffuseAreaLight` with an `image`, Mitsuba
//! 3's `area` with a `radiance` texture). Points are sampled uniformly over the area
//! whatever the texture (Mitsuba 3 samples a spatially varying radiance by the texture,
//! pbrt-v4 by area as heron does), and a sampled point's uv is computed only for a
//! textured light: the constant arm reads none.
use super::{LightLeSample, LightLiSample};
use crate::geometry::{spawn, sphere_uv, triangle_uv};
use crate::math::warp::{cosine_hemisphere, uniform_sphere, uniform_triangle};
use crate::math::{Distribution1D, Frame};
use crate::spectrum::{DenseSpectrum, SampledSpectrum, SampledWavelengths, DENSE_LEN, LAMBDA_MIN};
use crate::texture::Texture;
use glam::{Vec2, Vec3};
use std::f32::consts::PI;
use std::sync::Arc;

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
        /// Texture coordinates of each triangle's corners (the mesh's; empty: a
        /// triangle's uv is its barycentrics, as [`crate::geometry::Mesh::uv`]). Kept only
        /// for a textured emission.
        uvs: Vec<[Vec2; 3]>,
    },
}

/// An emission that varies over the surface: the texture's value at the point's uv
/// times the light's `emission` spectrum (an RGB texture's reflectance-like spectrum
/// times D65 at Y = 1 and a scale: heron's illuminant uplift of a colour, and Mitsuba
/// 3's `d65` texture around a nested one).
#[derive(Clone, Debug)]
pub struct EmissionTexture {
    pub texture: Arc<Texture>,
    /// The mean of texture × emission over uv ∈ [0, 1]² and 360–830 nm, for the light's
    /// power (pbrt-v4's `DiffuseAreaLight::Phi` averages its image's texels so).
    pub mean: f32,
}

/// The side of the uv grid on which [`EmissionTexture::new`] averages the texture: its
/// cell midpoints split a checkerboard of up to 32 × 32 squares evenly.
const MEAN_GRID: usize = 64;

impl EmissionTexture {
    /// `texture` times `emission`, its mean taken at the midpoints of a 64 × 64 grid
    /// over uv and at every nanometre of heron's tables (exact for a checkerboard whose
    /// squares the grid's cells tile; an image's finer texels are averaged at 4096
    /// points, enough for choosing lights by power).
    pub fn new(texture: Arc<Texture>, emission: &DenseSpectrum) -> EmissionTexture {
        let mut sum = 0.0f64;
        let lambdas: Vec<f32> = (0..DENSE_LEN).map(|i| LAMBDA_MIN + i as f32).collect();
        for chunk in lambdas.chunks(8) {
            let mut lambda = [chunk[0]; 8];
            lambda[..chunk.len()].copy_from_slice(chunk);
            let wl = SampledWavelengths::<8>::new(lambda, [1.0; 8]);
            let e = wl.eval(emission);
            for j in 0..MEAN_GRID {
                for i in 0..MEAN_GRID {
                    let uv = Vec2::new(
                        (i as f32 + 0.5) / MEAN_GRID as f32,
                        (j as f32 + 0.5) / MEAN_GRID as f32,
                    );
                    let t = texture.eval(uv, &wl);
                    for k in 0..chunk.len() {
                        sum += (t.0[k] * e.0[k]) as f64;
                    }
                }
            }
        }
        let mean = (sum / (DENSE_LEN * MEAN_GRID * MEAN_GRID) as f64) as f32;
        EmissionTexture { texture, mean }
    }

    /// The texture's value at `uv`, per lane. Never inlined: the tree's lookup stays out
    /// of `AreaLight::l` and `sample_li`, which a constant emission runs as before
    /// (inlined, it made LLVM call `l` out of line: 1.2% more instructions per sample on
    /// the Cornell box by callgrind).
    #[inline(never)]
    pub fn eval<const N: usize>(&self, uv: Vec2, wl: &SampledWavelengths<N>) -> SampledSpectrum<N> {
        self.texture.eval(uv, wl)
    }
}

/// Where a sampled point lies on the light's parameterisation, for its uv.
#[derive(Clone, Copy, Debug)]
enum Param {
    /// A sphere's point in the direction of its outward normal.
    Sphere(Vec3),
    /// Triangle index and barycentrics (b1, b2).
    Triangle(u32, f32, f32),
}

#[derive(Clone, Debug)]
pub struct AreaLight {
    /// The scene shape (Embree geometry) that emits.
    pub shape: u32,
    /// Emitted radiance L(λ); with a texture, the texture's value at the point times it.
    pub emission: DenseSpectrum,
    /// None: `emission` everywhere (the constant arm, which reads no uv).
    pub texture: Option<Arc<EmissionTexture>>,
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
            texture: None,
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
            AreaShape::Triangles {
                triangles,
                by_area,
                uvs: Vec::new(),
            },
        )
    }

    /// The light with its emission textured: `texture` at the point's uv times
    /// `emission`; `uvs` the mesh's per-corner texture coordinates (ignored for a
    /// sphere; empty: barycentrics).
    pub fn with_texture(mut self, texture: Arc<Texture>, uvs: Vec<[Vec2; 3]>) -> Self {
        self.texture = Some(Arc::new(EmissionTexture::new(texture, &self.emission)));
        if let AreaShape::Triangles { uvs: u, .. } = &mut self.geometry {
            *u = uvs;
        }
        self
    }

    /// Whether the emission reads the point's uv.
    #[inline]
    pub fn is_textured(&self) -> bool {
        self.texture.is_some()
    }

    /// Emitted radiance leaving the point with outward normal `n` and texture
    /// coordinates `uv` (read only by a textured emission) along unit `w`.
    #[inline(always)]
    pub fn l<const N: usize>(
        &self,
        n: Vec3,
        w: Vec3,
        uv: Vec2,
        wl: &SampledWavelengths<N>,
    ) -> SampledSpectrum<N> {
        if !self.two_sided && n.dot(w) <= 0.0 {
            return SampledSpectrum::zero();
        }
        let l = wl.eval(&self.emission);
        match &self.texture {
            None => l,
            Some(t) => t.eval(uv, wl) * l,
        }
    }

    /// The texture coordinates of a sampled point (zero for a constant emission, which
    /// does not read them).
    #[inline(always)]
    fn uv(&self, at: Param) -> Vec2 {
        if self.texture.is_none() {
            return Vec2::ZERO;
        }
        self.textured_uv(at)
    }

    #[inline(never)]
    fn textured_uv(&self, at: Param) -> Vec2 {
        match (at, &self.geometry) {
            (Param::Triangle(i, b1, b2), AreaShape::Triangles { uvs, .. }) => {
                triangle_uv(uvs, i, b1, b2)
            }
            (Param::Sphere(n), _) => sphere_uv(n),
            _ => Vec2::ZERO,
        }
    }

    /// A point uniform over the surface, its outward normal, the point's
    /// floating-point error bound, and where it lies on the parameterisation.
    #[inline]
    fn sample_area(&self, u: Vec2) -> (Vec3, Vec3, Vec3, Param) {
        match &self.geometry {
            AreaShape::Sphere { center, radius } => {
                let n = uniform_sphere(u);
                let (p, err) = spawn::sphere_point(*center, *radius, n);
                (p, n, err, Param::Sphere(n))
            }
            AreaShape::Triangles {
                triangles, by_area, ..
            } => {
                let (i, _, t) = by_area.sample_discrete(u.x);
                let [a, b, c] = triangles[i];
                let bc = uniform_triangle(Vec2::new(t, u.y));
                let (p, err) = spawn::triangle_point(a, b, c, bc[1], bc[2]);
                let at = Param::Triangle(i as u32, bc[1], bc[2]);
                (p, (b - a).cross(c - a).normalize(), err, at)
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
        let (ps, n, pdf, p_err, at) = match &self.geometry {
            AreaShape::Sphere { center, radius }
                if (p - *center).length_squared() > radius * radius =>
            {
                let (_, n, pdf) = sample_sphere_cone(*center, *radius, p, u);
                let (ps, err) = spawn::sphere_point(*center, *radius, n);
                (ps, n, pdf, err, Param::Sphere(n))
            }
            _ => {
                let (ps, n, err, at) = self.sample_area(u);
                let to = ps - p;
                let d2 = to.length_squared();
                let cos_l = n.dot(-to).abs() / d2.sqrt();
                if !(d2 > 0.0) || cos_l == 0.0 {
                    return None;
                }
                (ps, n, d2 / (cos_l * self.area), err, at)
            }
        };
        let to = ps - p;
        let d = to.length();
        if !(d > 0.0) || !(pdf > 0.0) || !pdf.is_finite() {
            return None;
        }
        let wi = to / d;
        let l = self.l(n, -wi, self.uv(at), wl);
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
        let (p, n, origin_err, at) = self.sample_area(u1);
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
        let uv = self.uv(at);
        Some(LightLeSample {
            origin: p,
            origin_err,
            dir,
            l: self.l(n, dir, uv, wl),
            uv,
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

    /// Φ = π A L (twice that when two-sided), L the emission's mean over wavelength
    /// (and, when textured, over the texture's uv square: [`EmissionTexture::mean`]).
    pub fn phi(&self) -> f32 {
        let l = match &self.texture {
            None => self.emission.mean(),
            Some(t) => t.mean,
        };
        PI * self.area * l * if self.two_sided { 2.0 } else { 1.0 }
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
