//! Which parts of the transport a scene needs, so the renderer can pick a kernel that
//! skips the rest.
//!
//! Only materials that some shape uses count: a material defined in the file but bound
//! to no shape never meets a ray.
use super::Scene;
use crate::bsdf::Material;
use crate::light::Light;

/// The parts of the transport a scene uses. Each field is conservative: when it is true
/// the part may be needed; when it is false the renderer can skip it without changing
/// the image.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Features {
    /// Direct lighting by shadow rays (seed, "Shadow rays"): some light has non-zero
    /// emission and some shape has a non-specular material (Lambertian, or glossy, whose
    /// Phong lobe is evaluated towards the lights). When false, the renderer can skip
    /// light sampling and shadow rays altogether: no surface it sees reacts to a light
    /// (point and directional lights are not seen in mirrors or through glass, seed
    /// "Glossy materials").
    pub shadows: bool,
    /// Paths continue past the first hit (the seed's "overwrite the ray and increment
    /// depth"): some shape is a mirror, a dielectric, or glossy over a refractive base.
    /// When false, every path ends at its first hit (depth 1), so the renderer can skip
    /// the continuation loop, reflection/refraction and Fresnel code.
    pub specular: bool,
    /// Some shape uses the seed's modified Phong model. When false, the renderer can
    /// skip the glossy lobe ((s + 2)/(2π) (ωo·ωr)^s) in its shading.
    pub glossy: bool,
}

impl Features {
    /// The features `scene` uses.
    pub fn of(scene: &Scene) -> Features {
        let used = || {
            scene
                .shapes
                .iter()
                .filter_map(|s| scene.materials.get(s.material as usize))
        };
        let lit = scene.lights.iter().any(|l| match l {
            Light::Point(p) => p.intensity.max_value() > 0.0,
            Light::Spot(p) => p.intensity.max_value() > 0.0,
            Light::Directional(d) => d.radiance.max_value() > 0.0,
            Light::Sun(s) => s.irradiance.max_value() > 0.0,
            Light::Area(a) => a.emission.max_value() > 0.0,
            // The seed's tracer does not sample the environment.
            Light::Environment(_) => false,
        });
        let non_specular = used().any(|m| m.flags().has_non_specular());
        Features {
            shadows: lit && non_specular,
            specular: used().any(|m| m.flags().is_specular()),
            glossy: used().any(|m| matches!(m, Material::Glossy(_))),
        }
    }
}
