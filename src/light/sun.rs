//! The sun: a distant disk of angular radius α (default 0.2666°, the mean solar radius
//! seen from Earth; 0.262–0.271° over the year), given by its irradiance E at normal
//! incidence. Its disk has radiance L = E/Ω with Ω = 2π(1 − cos α), seen by rays that
//! leave the scene towards it. Light sampling draws directions uniformly in solid angle
//! over the disk (pdf 1/Ω), so shadows have the sun's penumbra, and a path that finds
//! the disk by BSDF sampling is weighted against it by MIS. The seed's Aristotelian
//! rainbow needs the disk's extent; so does a prism's spectrum, which is the disk's image
//! spread by dispersion.
use super::{LightLeSample, LightLiSample, SceneBounds};
use crate::math::warp::uniform_cone;
use crate::math::Frame;
use crate::spectrum::{DenseSpectrum, SampledSpectrum, SampledWavelengths};
use glam::{Vec2, Vec3};

/// The mean angular radius of the sun, degrees.
pub const SUN_ANGULAR_RADIUS_DEG: f32 = 0.2666;

#[derive(Clone, Debug)]
pub struct SunLight {
    /// Unit vector in the direction the light travels.
    pub direction: Vec3,
    /// Irradiance at normal incidence, E(λ).
    pub irradiance: DenseSpectrum,
    /// Angular radius α in radians.
    pub angular_radius: f32,
    /// 1 − cos α, computed as 2 sin²(α/2) to keep its digits for small α.
    one_minus_cos: f32,
    sin2: f32,
    /// Disk radiance L = E/Ω.
    pub radiance: DenseSpectrum,
    /// The frame whose z axis points at the sun.
    frame: Frame,
    /// Where sunlight enters the scene, if only through one opening (a window, a slit):
    /// light paths then start on it instead of on the scene's bounding disk.
    pub portal: Option<Portal>,
}

/// A parallelogram origin + s·edge1 + t·edge2 (s, t ∈ [0, 1]) through which all of a
/// light at infinity that reaches the scene passes. Light paths that start on it carry
/// the same flux as those started on the bounding disk, without the ones the scene's
/// geometry would block anyway; so a portal is exact only when everything else of the
/// scene is shadowed from the light (the wall around Newton's slit).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Portal {
    pub origin: Vec3,
    pub edge1: Vec3,
    pub edge2: Vec3,
    /// Unit normal, edge1 × edge2.
    pub normal: Vec3,
    pub area: f32,
}

impl Portal {
    pub fn new(origin: Vec3, edge1: Vec3, edge2: Vec3) -> Portal {
        let c = edge1.cross(edge2);
        Portal {
            origin,
            edge1,
            edge2,
            normal: c.normalize(),
            area: c.length(),
        }
    }

    /// A point uniform on the portal.
    #[inline]
    pub fn point(&self, u: Vec2) -> Vec3 {
        self.origin + u.x * self.edge1 + u.y * self.edge2
    }
}

impl SunLight {
    /// `angular_radius` in radians, in (0, π/2).
    pub fn new(direction: Vec3, irradiance: DenseSpectrum, angular_radius: f32) -> Self {
        let a = angular_radius as f64;
        let omc = 2.0 * (0.5 * a).sin().powi(2);
        let solid_angle = 2.0 * std::f64::consts::PI * omc;
        let direction = direction.normalize();
        SunLight {
            direction,
            radiance: irradiance.scaled((1.0 / solid_angle) as f32),
            irradiance,
            angular_radius,
            one_minus_cos: omc as f32,
            sin2: a.sin().powi(2) as f32,
            frame: Frame::from_z(-direction),
            portal: None,
        }
    }

    /// Solid angle of the disk, Ω = 2π(1 − cos α).
    pub fn solid_angle(&self) -> f32 {
        2.0 * std::f32::consts::PI * self.one_minus_cos
    }

    /// True when the unit direction `d` points into the disk. Uses |d × s|² ≤ sin²α,
    /// which keeps its precision for the sun's small radius, where 1 − d·s would not.
    #[inline]
    pub fn sees_disk(&self, d: Vec3) -> bool {
        let s = -self.direction;
        d.dot(s) > 0.0 && d.cross(s).length_squared() <= self.sin2
    }

    /// A direction towards the disk, uniform in solid angle (pdf 1/Ω).
    #[inline]
    pub fn sample_direction(&self, u: Vec2) -> Vec3 {
        self.frame.to_world(uniform_cone(u, self.one_minus_cos))
    }

    /// Radiance arriving along a ray that leaves the scene in direction `d`.
    #[inline]
    pub fn le<const N: usize>(&self, d: Vec3, wl: &SampledWavelengths<N>) -> SampledSpectrum<N> {
        if self.sees_disk(d) {
            wl.eval(&self.radiance)
        } else {
            SampledSpectrum::zero()
        }
    }

    #[inline]
    pub fn sample_li<const N: usize>(
        &self,
        u: Vec2,
        wl: &SampledWavelengths<N>,
    ) -> LightLiSample<N> {
        LightLiSample {
            l: wl.eval(&self.radiance),
            wi: self.sample_direction(u),
            pdf: 1.0 / self.solid_angle(),
            dist: f32::INFINITY,
            delta: false,
            n: Vec3::ZERO,
            p: Vec3::ZERO,
            p_err: Vec3::ZERO,
        }
    }

    #[inline]
    pub fn pdf_li(&self, wi: Vec3) -> f32 {
        if self.sees_disk(wi) {
            1.0 / self.solid_angle()
        } else {
            0.0
        }
    }

    /// A ray from the disk's direction through a point uniform on the disk covering the
    /// scene's bounding sphere, or on the portal when there is one (its normal then
    /// carries the cosine between the ray and the portal).
    #[inline]
    pub fn sample_le<const N: usize>(
        &self,
        u1: Vec2,
        u2: Vec2,
        wl: &SampledWavelengths<N>,
        bounds: &SceneBounds,
    ) -> LightLeSample<N> {
        let w = self.sample_direction(u1);
        let (origin, pdf_pos, normal) = match &self.portal {
            Some(p) => (p.point(u2), 1.0 / p.area, p.normal),
            None => {
                let (o, pdf) = bounds.disk_point(w, u2);
                (o, pdf, -w)
            }
        };
        LightLeSample {
            origin,
            origin_err: Vec3::ZERO,
            dir: -w,
            l: wl.eval(&self.radiance),
            pdf_pos,
            pdf_dir: 1.0 / self.solid_angle(),
            normal: Some(normal),
            uv: Vec2::ZERO,
        }
    }

    /// Density, per unit area perpendicular to a ray leaving in direction `dir`, of the
    /// ray's position as `sample_le` draws it: 1/(π R²) on the bounding disk, or
    /// 1/(A |cos|) on a portal (its area projected onto that plane).
    #[inline]
    pub fn pdf_le_position(&self, dir: Vec3, bounds: &SceneBounds) -> f32 {
        match &self.portal {
            Some(p) => {
                let c = p.normal.dot(dir).abs();
                if c > 0.0 {
                    1.0 / (p.area * c)
                } else {
                    0.0
                }
            }
            None => 1.0 / bounds.disk_area(),
        }
    }

    /// Φ = π R² E over the scene's bounding disk, or E A |cos| through a portal.
    pub fn phi(&self, bounds: &SceneBounds) -> f32 {
        let area = match &self.portal {
            Some(p) => p.area * p.normal.dot(self.direction).abs(),
            None => bounds.disk_area(),
        };
        area * self.irradiance.mean()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Rng;

    #[test]
    fn samples_cover_the_disk_uniformly_and_nothing_else() {
        let sun = SunLight::new(
            Vec3::new(0.3, -1.0, 0.2),
            DenseSpectrum::constant(1.0),
            SUN_ANGULAR_RADIUS_DEG.to_radians(),
        );
        let s = -sun.direction;
        let mut rng = Rng::new(2, 4);
        assert!((sun.pdf_li(-sun.direction) * sun.solid_angle() - 1.0).abs() < 1e-5);
        // Uniform in solid angle: the fraction inside half the angular radius is
        // (1 − cos(α/2)) / (1 − cos α) ≈ 1/4.
        let half = 0.5 * sun.angular_radius;
        let n = 100_000;
        let mut inner = 0;
        for _ in 0..n {
            let d = sun.sample_direction(Vec2::new(rng.uniform(), rng.uniform()));
            assert!((d.length() - 1.0).abs() < 1e-5);
            assert!(sun.sees_disk(d), "a sample outside the disk");
            if d.cross(s).length() < half.sin() {
                inner += 1;
            }
        }
        let expected = (1.0 - (half as f64).cos()) / (1.0 - (sun.angular_radius as f64).cos());
        let f = inner as f64 / n as f64;
        assert!((f - expected).abs() < 0.005, "{f} vs {expected}");
        // Just outside the rim is not the disk.
        let (t, _) = s.any_orthonormal_pair();
        let out = (s + 1.01 * sun.angular_radius.tan() * t).normalize();
        let inside = (s + 0.99 * sun.angular_radius.tan() * t).normalize();
        assert!(!sun.sees_disk(out) && sun.sees_disk(inside));
    }

    #[test]
    fn disk_radiance_times_solid_angle_is_the_irradiance() {
        let sun = SunLight::new(Vec3::NEG_Y, DenseSpectrum::constant(2.0), 0.01);
        let e = sun.radiance.eval(550.0) * sun.solid_angle();
        assert!((e - 2.0).abs() < 1e-5, "{e}");
    }
}
