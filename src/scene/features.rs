//! Which parts of the transport a scene needs, and the kernel that skips the rest.
//!
//! Only materials that some shape uses count: a material defined in the file but bound
//! to no shape never meets a ray.
//!
//! Each integrator that is specialised turns the features into the
//! [`KernelFlags`](crate::settings::KernelFlags) it needs (its declared
//! `Capabilities::kernel`; `integrator::capabilities::choose_kernel` applies it), which
//! the renderer uses, once per render, to pick an integrator monomorphised over them (a
//! `const K: u32` generic next to the lane count N): code behind a flag that is off is
//! not in that kernel at all. The flags:
//!
//! - `SHADOWS`: shadow rays (Whitted) or next-event estimation (path tracer);
//! - `SPECULAR`: specular continuation past the first hit (Whitted only);
//! - `EMITTERS`: emission of area lights found at hits;
//! - `ESCAPE`: radiance of the lights at infinity along escaping rays;
//! - `MEDIA`: participating media, free flights and transmittance (path tracer only).
//!
//! So a scene without shadow rays, specular paths, area lights, anything to see beyond
//! the scene or media pays for none of their tests. Light tracing and BDPT always run
//! their one general kernel. `--kernel general` runs the kernel with every flag on,
//! which must give the same image byte for byte.
//!
//! For measuring what a kernel costs against a build without a feature's code, the
//! build script turns `HERON_STRIP=shadows,specular,emitters,escape` (any subset; `MEDIA`
//! cannot be stripped) into cfgs that switch those flags off in every kernel; such a
//! build refuses scenes that need what it lacks (`scripts/bench_kernels.py`).
use super::{Scene, NO_LIGHT};
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
    /// Next-event estimation in the path tracer: some shape has a non-specular material
    /// and some light emits, the environment included (the path tracer samples it; the
    /// seed's tracer, whose shadow rays `shadows` is about, does not).
    pub nee: bool,
    /// Some shape emits (an area light): paths must look up and add emission at hits.
    pub emitters: bool,
    /// A ray that leaves the scene can find radiance: a background, sky or sun (the
    /// scene's lights at infinity). When false, an escaping path simply ends.
    pub escape: bool,
    /// Some shape encloses a participating medium: paths track the medium they are in,
    /// sample free flights and scatter in it, and shadow rays pass media boundaries with
    /// their transmittance. When false, none of that code is in the kernel.
    pub media: bool,
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
        let emits = |l: &Light| match l {
            Light::Point(p) => p.intensity.max_value() > 0.0,
            Light::Spot(p) => p.intensity.max_value() > 0.0,
            Light::Directional(d) => d.radiance.max_value() > 0.0,
            Light::Sun(s) => s.irradiance.max_value() > 0.0,
            Light::Area(a) => a.emission.max_value() > 0.0,
            // Exists only when the background or sky emits.
            Light::Environment(_) => true,
        };
        // The seed's tracer does not sample the environment.
        let lit = scene
            .lights
            .iter()
            .any(|l| !matches!(l, Light::Environment(_)) && emits(l));
        let non_specular = used().any(|m| m.flags().has_non_specular());
        Features {
            shadows: lit && non_specular,
            // Media scatter light from the lights too.
            nee: (non_specular || !scene.media.is_empty()) && scene.lights.iter().any(emits),
            specular: used().any(|m| m.flags().is_specular()),
            emitters: scene.shapes.iter().any(|s| s.light != NO_LIGHT),
            escape: !scene.infinite_lights.is_empty(),
            media: !scene.media.is_empty(),
        }
    }
}
