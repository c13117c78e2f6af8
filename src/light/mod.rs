//! Light sources, one file per kind, behind a closed enum dispatched by `match`.
//!
//! Every light samples itself (pbrt-v4 `base/light.h`; Mitsuba 3 `Emitter`):
//! - [`Light::sample_li`]: from a receiving point, a direction toward the light with the
//!   incident radiance, its density in solid angle and the distance for the shadow ray;
//! - [`Light::pdf_li`]: that density for a direction found otherwise (a BSDF sample
//!   that hit the light), for multiple importance sampling;
//! - [`Light::le`] / [`AreaLight::l`]: the radiance a ray sees when it reaches the light;
//! - [`Light::sample_le`]: an emitted ray with its position and direction densities, for
//!   paths that start at the lights.
//!
//! Delta lights (point, spot, directional) are reached only by sampling them. Lights at
//! infinity (directional, sun, environment) use the scene's bounding sphere for
//! `sample_le` and for their power.
pub mod area;
pub mod directional;
pub mod environment;
pub mod envmap;
pub mod point;
pub mod polarization;
pub mod sampler;
pub mod spot;
pub mod sun;

pub use area::{AreaLight, AreaShape, EmissionTexture, SurfacePoint};
pub use directional::DirectionalLight;
pub use environment::EnvironmentLight;
pub use envmap::{EnvMap, EnvMapping};
pub use point::PointLight;
pub use polarization::LightPolarization;
pub use sampler::LightSampler;
pub use spot::SpotLight;
pub use sun::{Portal, SunLight};

use crate::geometry::SpawnPoint;
use crate::math::warp::concentric_disk;
use crate::math::Frame;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use glam::{Vec2, Vec3};

/// A direction toward a light from a receiving point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightLiSample<const N: usize> {
    /// Incident radiance per lane (for a delta light: the radiance times its delta's
    /// solid angle, i.e. irradiance at normal incidence).
    pub l: SampledSpectrum<N>,
    /// Unit direction from the receiver toward the light.
    pub wi: Vec3,
    /// Density in solid angle (1 for a delta light).
    pub pdf: f32,
    /// Distance to the sampled point (infinite for lights at infinity).
    pub dist: f32,
    pub delta: bool,
    /// The light's outward normal at the sampled point (area lights; zero otherwise).
    pub n: Vec3,
    /// The sampled point (lights at infinity: unused) and its floating-point error
    /// bound (zero but for area lights), for robust shadow rays.
    pub p: Vec3,
    pub p_err: Vec3,
}

impl<const N: usize> LightLeSample<N> {
    /// Where the emitted ray starts: on an area light's surface (with its error bound),
    /// else a point in free space (point and spot lights, the disk of a light at
    /// infinity, which is no surface of the scene).
    #[inline]
    pub fn spawn_point(&self) -> SpawnPoint {
        match self.normal {
            Some(n) if self.origin_err != Vec3::ZERO => SpawnPoint {
                p: self.origin,
                err: self.origin_err,
                n,
            },
            _ => SpawnPoint::free(self.origin),
        }
    }
}

impl<const N: usize> LightLiSample<N> {
    /// The sampled point as the far end of a shadow ray.
    #[inline]
    pub fn target(&self) -> SpawnPoint {
        SpawnPoint {
            p: self.p,
            err: self.p_err,
            n: self.n,
        }
    }
}

/// A ray leaving a light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightLeSample<const N: usize> {
    pub origin: Vec3,
    /// Floating-point error bound of `origin` (area lights; zero otherwise).
    pub origin_err: Vec3,
    /// Unit direction of travel.
    pub dir: Vec3,
    /// Emitted radiance (point and spot lights: intensity) per lane.
    pub l: SampledSpectrum<N>,
    /// Density of the origin (per area; 1 for a point).
    pub pdf_pos: f32,
    /// Density of the direction (per solid angle; 1 for a delta direction).
    pub pdf_dir: f32,
    /// The normal of the surface the origin was drawn on (an area light, a portal, the
    /// disk of a light at infinity), so that the flux of the ray is
    /// L |cos| / (pdf_pos pdf_dir); None for point and spot lights.
    pub normal: Option<Vec3>,
    /// Texture coordinates of the origin on a textured area light (zero otherwise), for
    /// the emission toward another direction ([`Light::l`]).
    pub uv: Vec2,
}

/// The scene's bounding sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneBounds {
    pub center: Vec3,
    pub radius: f32,
}

impl SceneBounds {
    /// The area of a disk of the sphere's radius, π R².
    pub fn disk_area(&self) -> f32 {
        std::f32::consts::PI * self.radius * self.radius
    }

    /// A point uniform on the disk of radius R that faces unit `w`, placed at distance R
    /// from the centre toward `w` (so rays from it along −w cover the sphere), and its
    /// area density 1/(π R²).
    pub fn disk_point(&self, w: Vec3, u: Vec2) -> (Vec3, f32) {
        let f = Frame::from_z(w);
        let d = concentric_disk(u) * self.radius;
        (
            self.center + self.radius * w + d.x * f.s + d.y * f.t,
            1.0 / self.disk_area(),
        )
    }
}

#[derive(Clone, Debug)]
pub enum Light {
    Point(PointLight),
    Spot(SpotLight),
    Directional(DirectionalLight),
    Sun(SunLight),
    Area(AreaLight),
    Environment(EnvironmentLight),
}

impl Light {
    /// True for lights that only sampling can reach (point, spot, directional).
    #[inline]
    pub fn is_delta(&self) -> bool {
        matches!(
            self,
            Light::Point(_) | Light::Spot(_) | Light::Directional(_)
        )
    }

    /// True for lights at infinity (directional, sun, environment).
    #[inline]
    pub fn is_infinite(&self) -> bool {
        matches!(
            self,
            Light::Directional(_) | Light::Sun(_) | Light::Environment(_)
        )
    }

    /// A direction toward the light from `p`; `u` is used by lights with extent.
    #[inline]
    pub fn sample_li<const N: usize>(
        &self,
        p: Vec3,
        u: Vec2,
        wl: &SampledWavelengths<N>,
    ) -> Option<LightLiSample<N>> {
        match self {
            Light::Point(l) => l.sample_li(p, wl),
            Light::Spot(l) => l.sample_li(p, wl),
            Light::Directional(l) => Some(l.sample_li(wl)),
            Light::Sun(l) => Some(l.sample_li(u, wl)),
            Light::Area(l) => l.sample_li(p, u, wl),
            Light::Environment(l) => l.sample_li(u, wl),
        }
    }

    /// Solid-angle density of `sample_li` from `p` for direction `wi`; for an area light,
    /// `hit` is the point of the light that `wi` reaches. Zero for delta lights.
    #[inline]
    pub fn pdf_li(&self, p: Vec3, wi: Vec3, hit: Option<&SurfacePoint>) -> f32 {
        match self {
            Light::Point(_) | Light::Spot(_) | Light::Directional(_) => 0.0,
            Light::Sun(l) => l.pdf_li(wi),
            Light::Area(l) => hit.map_or(0.0, |h| l.pdf_li(p, h)),
            Light::Environment(l) => l.pdf_li(wi),
        }
    }

    /// Radiance an emitting surface of this light sends from a point with outward
    /// normal `n` and texture coordinates `uv` (read by a textured emission only: the
    /// interaction's uv, which `Scene::interaction` computes for such a shape) into
    /// direction `w` (pbrt-v4 `Light::L`); zero for lights without a surface.
    /// Integrators read emission here, whatever the light.
    #[inline]
    pub fn l<const N: usize>(
        &self,
        n: Vec3,
        w: Vec3,
        uv: Vec2,
        wl: &SampledWavelengths<N>,
    ) -> SampledSpectrum<N> {
        match self {
            Light::Area(a) => a.l(n, w, uv, wl),
            _ => SampledSpectrum::zero(),
        }
    }

    /// Radiance a ray leaving the scene in direction `dir` receives from this light
    /// (zero for lights that are not at infinity or not seen).
    #[inline]
    pub fn le<const N: usize>(&self, dir: Vec3, wl: &SampledWavelengths<N>) -> SampledSpectrum<N> {
        match self {
            Light::Sun(l) => l.le(dir, wl),
            Light::Environment(l) => l.le(dir, wl),
            _ => SampledSpectrum::zero(),
        }
    }

    /// The linear polarisation of the light a ray leaving the scene along `dir`
    /// receives, for polarised transport: S1 per lane in the frame x̂ returned (⊥ `dir`;
    /// S2 = S3 = 0), or None when this light is unpolarised there (every light but a
    /// physical rainbow sky: `SceneSky::linear_table`).
    #[inline]
    pub fn le_linear<const N: usize>(
        &self,
        dir: Vec3,
        wl: &SampledWavelengths<N>,
    ) -> Option<(SampledSpectrum<N>, Vec3)> {
        match self {
            Light::Environment(l) => l.le_linear(dir, wl),
            _ => None,
        }
    }

    /// An emitted ray; `u1` picks the position (or, at infinity, the direction) and `u2`
    /// the other.
    #[inline]
    pub fn sample_le<const N: usize>(
        &self,
        u1: Vec2,
        u2: Vec2,
        wl: &SampledWavelengths<N>,
        bounds: &SceneBounds,
    ) -> Option<LightLeSample<N>> {
        match self {
            Light::Point(l) => Some(l.sample_le(u2, wl)),
            Light::Spot(l) => l.sample_le(u2, wl),
            Light::Directional(l) => Some(l.sample_le(u1, wl, bounds)),
            Light::Sun(l) => Some(l.sample_le(u1, u2, wl, bounds)),
            Light::Area(l) => l.sample_le(u1, u2, wl),
            Light::Environment(l) => l.sample_le(u1, u2, wl, bounds),
        }
    }

    /// (position density, direction density) with which `sample_le` emits a ray in unit
    /// direction `dir` from a point on a surface of outward normal `n` (area lights; the
    /// densities do not depend on where on the light the ray starts). Positions of lights at infinity are densities per unit area across
    /// the rays ([`Light::pdf_le_position`]); delta positions have density 1, delta
    /// directions density 0 (pbrt-v4 `Light::PDF_Le`).
    pub fn pdf_le(&self, dir: Vec3, n: Vec3, bounds: &SceneBounds) -> (f32, f32) {
        match self {
            Light::Point(_) => (1.0, crate::math::warp::UNIFORM_SPHERE_PDF),
            Light::Spot(s) => (1.0, s.pdf_dir(dir)),
            Light::Directional(_) => (1.0 / bounds.disk_area(), 0.0),
            Light::Sun(s) => (s.pdf_le_position(dir, bounds), s.pdf_li(-dir)),
            Light::Area(a) => (1.0 / a.area, a.pdf_dir(n, dir)),
            Light::Environment(e) => (1.0 / bounds.disk_area(), e.pdf_li(-dir)),
        }
    }

    /// For lights at infinity: the density of where `sample_le` starts a ray that leaves
    /// in direction `dir`, per unit area perpendicular to it (the bounding disk, or the
    /// sun's portal). 0 for other lights.
    pub fn pdf_le_position(&self, dir: Vec3, bounds: &SceneBounds) -> f32 {
        match self {
            Light::Sun(s) => s.pdf_le_position(dir, bounds),
            Light::Directional(_) | Light::Environment(_) => 1.0 / bounds.disk_area(),
            _ => 0.0,
        }
    }

    /// Emitted power averaged over 360–830 nm (per nm), for choosing lights by power.
    pub fn phi(&self, bounds: &SceneBounds) -> f32 {
        match self {
            Light::Point(l) => l.phi(),
            Light::Spot(l) => l.phi(),
            Light::Directional(l) => l.phi(bounds),
            Light::Sun(l) => l.phi(bounds),
            Light::Area(l) => l.phi(),
            Light::Environment(l) => l.phi(bounds),
        }
    }
}
