//! Scenes: the TOML file format, its validation, and the in-memory scene the renderer
//! uses.
pub mod export;
pub mod features;
pub mod file;
pub mod import;
pub mod load;

pub use features::Features;
pub use load::load_scene;

use crate::accel::embree::Hit;
use crate::bsdf::Material;
use crate::camera::Camera;
use crate::geometry::{Interaction, Ray, Shape};
use crate::light::{Light, LightSampler, SceneBounds};
use crate::settings::RenderSettings;
use crate::spectrum::{DenseSpectrum, SampledSpectrum, SampledWavelengths};
use glam::Vec3;
use std::path::PathBuf;

/// `Shape::light` of a shape that does not emit (defined with the shape).
pub use crate::geometry::NO_LIGHT;

/// A validated scene. `shapes[i]` is Embree geometry i.
#[derive(Clone, Debug)]
pub struct Scene {
    pub source: PathBuf,
    /// SHA-256 of the scene file's text (hex; empty for scenes built in code).
    pub source_sha256: String,
    /// The other files the scene read (meshes, index and n, k tables): the path as the
    /// scene names it and the SHA-256 of its bytes, sorted by path.
    pub inputs: Vec<(String, String)>,
    pub camera: Camera,
    /// Each with its material, area light and medium.
    pub shapes: Vec<Shape>,
    pub materials: Vec<Material>,
    pub material_names: Vec<String>,
    /// The file's lights in file order, then one area light per emitting shape, then
    /// the environment (background and sky), when it emits.
    pub lights: Vec<Light>,
    /// Per light (by index, possibly shorter than `lights`): its polarisation, for
    /// polarised transport; unpolarised where absent or None.
    pub light_polarization: Vec<Option<crate::light::LightPolarization>>,
    /// The index of the environment light, if the background or sky emits.
    pub environment: Option<u32>,
    /// Lights a ray that leaves the scene can see (the environment first, then suns).
    pub infinite_lights: Vec<u32>,
    /// Radiance seen along rays that leave the scene.
    pub background: DenseSpectrum,
    /// A rainbow sky, when the scene has one.
    pub sky: Option<std::sync::Arc<crate::sky::SceneSky>>,
    /// An environment map (`[environment]`), in place of the background.
    pub envmap: Option<std::sync::Arc<crate::light::EnvMap>>,
    pub settings: RenderSettings,
    /// The bounding sphere of the shapes.
    pub bounds: SceneBounds,
    /// Picks one light per shading point for the path integrator.
    pub light_sampler: LightSampler,
    /// Participating media (`Shape::medium` indexes them); empty for most scenes.
    pub media: std::sync::Arc<Vec<crate::medium::Medium>>,
    /// The direction toward the most powerful sun, if the scene has one (the guide of
    /// phase sampling in media, `RenderSettings::sun_guide`).
    pub sun_toward: Option<glam::Vec3>,
    /// What the loader changed and says (one line each, naming the file): zero-area
    /// triangles of a mesh dropped, a mesh left with none dropped. `load::load_scene`
    /// and `heron render` print them; an importer's own warnings come before them.
    pub warnings: Vec<String>,
}

/// What a scene is made of before its derived parts (the environment light, the list of
/// lights at infinity, the bounding sphere, the light sampler) are computed: everything
/// [`Scene::from_parts`] needs, so nothing is patched into the scene afterwards.
pub struct SceneParts {
    pub source: PathBuf,
    /// SHA-256 of the scene file's text (hex; empty for scenes built in code).
    pub source_sha256: String,
    /// The other files the scene read, with the SHA-256 of each (see [`Scene::inputs`]).
    pub inputs: Vec<(String, String)>,
    pub camera: Camera,
    /// Each with its material, its area light in `lights` and its medium in `media`.
    pub shapes: Vec<Shape>,
    pub materials: Vec<Material>,
    pub material_names: Vec<String>,
    /// Every light but the environment (area lights included).
    pub lights: Vec<Light>,
    pub background: DenseSpectrum,
    pub sky: Option<std::sync::Arc<crate::sky::SceneSky>>,
    /// An environment map, in place of the background (never with a sky).
    pub envmap: Option<std::sync::Arc<crate::light::EnvMap>>,
    pub settings: RenderSettings,
    /// The media the shapes enclose.
    pub media: Vec<crate::medium::Medium>,
}

impl Scene {
    /// The polarisation of light `light` (by index into `lights`), None when it is
    /// unpolarised (`light::polarization`).
    #[inline]
    pub fn light_polarization(&self, light: usize) -> Option<&crate::light::LightPolarization> {
        self.light_polarization.get(light)?.as_ref()
    }

    /// Completes `parts`: appends the environment light when the background or sky
    /// emits, lists the lights at infinity (environment first, then suns), bounds the
    /// shapes and builds the light sampler.
    pub fn from_parts(p: SceneParts) -> Scene {
        let mut lights = p.lights;
        let map_emits = p.envmap.as_ref().is_some_and(|m| m.power_per_area() > 0.0);
        let environment = if p.sky.is_some() || p.background.max_value() > 0.0 || map_emits {
            lights.push(Light::Environment(crate::light::EnvironmentLight::new(
                p.background.clone(),
                p.sky.clone(),
                p.envmap.clone(),
            )));
            Some(lights.len() as u32 - 1)
        } else {
            None
        };
        let mut infinite_lights: Vec<u32> = environment.into_iter().collect();
        infinite_lights.extend(
            lights
                .iter()
                .enumerate()
                .filter(|(_, l)| matches!(l, Light::Sun(_)))
                .map(|(i, _)| i as u32),
        );
        let bounds = load::scene_bounds(&p.shapes);
        let light_sampler = LightSampler::new(p.settings.light_sampler, &lights, &bounds);
        let sun_toward = lights
            .iter()
            .filter_map(|l| match l {
                Light::Sun(s) => Some((l.phi(&bounds), -s.direction)),
                _ => None,
            })
            .fold(None, |best: Option<(f32, glam::Vec3)>, c| match best {
                Some(b) if b.0 >= c.0 => Some(b),
                _ => Some(c),
            })
            .map(|(_, d)| d);
        Scene {
            source: p.source,
            source_sha256: p.source_sha256,
            inputs: p.inputs,
            camera: p.camera,
            shapes: p.shapes,
            materials: p.materials,
            material_names: p.material_names,
            lights,
            light_polarization: Vec::new(),
            warnings: Vec::new(),
            environment,
            infinite_lights,
            background: p.background,
            sky: p.sky,
            envmap: p.envmap,
            settings: p.settings,
            bounds,
            light_sampler,
            media: std::sync::Arc::new(p.media),
            sun_toward,
        }
    }

    /// The interaction record of `hit` (of `ray`) and the material there; `robust`
    /// whether the render's offsets need the hit point's error bound
    /// ([`Interaction::new`]).
    #[inline(always)]
    pub fn interaction(&self, ray: &Ray, hit: &Hit, robust: bool) -> (Interaction, &Material) {
        let shape = &self.shapes[hit.geom_id as usize];
        let material = &self.materials[shape.material as usize];
        let mut it = Interaction::new(ray, hit, shape, robust);
        // A textured material, or a textured emission (read by the integrators through
        // `Light::l` at `it.uv`).
        if material.is_textured() || shape.textured_emission {
            it.uv = shape.uv(it.position, hit.prim_id, hit.u, hit.v);
        }
        (it, material)
    }

    /// Radiance arriving along a ray that leaves the scene in direction `dir`: the
    /// environment (background or sky) plus every sun whose disk it points into.
    #[inline]
    pub fn escaped_radiance<const N: usize>(
        &self,
        dir: Vec3,
        wl: &SampledWavelengths<N>,
    ) -> SampledSpectrum<N> {
        let mut l = SampledSpectrum::<N>::zero();
        for &i in &self.infinite_lights {
            l += self.lights[i as usize].le(dir, wl);
        }
        l
    }
}
