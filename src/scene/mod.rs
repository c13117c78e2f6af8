//! Scenes: the TOML file format, its validation, and the in-memory scene the renderer
//! uses.
pub mod features;
pub mod file;
pub mod load;

pub use features::Features;
pub use load::load_scene;

use crate::bsdf::Material;
use crate::camera::Camera;
use crate::geometry::Shape;
use crate::light::Light;
use crate::spectrum::DenseSpectrum;
use std::path::PathBuf;

/// Render settings a scene file may give; the CLI may override spp and seed.
#[derive(Clone, Debug)]
pub struct RenderSettings {
    pub spp: u32,
    /// Maximum path depth (the lecture's `depth` limit on continued rays).
    pub max_depth: u32,
    /// Ray offset ε for rays leaving surfaces (seed: 1e-4).
    pub epsilon: f32,
    pub seed: u64,
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            spp: 16,
            max_depth: 10,
            epsilon: 1e-4,
            seed: 0,
        }
    }
}

/// A validated scene. `shapes[i]` is Embree geometry i.
#[derive(Clone, Debug)]
pub struct Scene {
    pub source: PathBuf,
    pub camera: Camera,
    pub shapes: Vec<Shape>,
    pub materials: Vec<Material>,
    pub material_names: Vec<String>,
    pub lights: Vec<Light>,
    /// Radiance seen along rays that leave the scene.
    pub background: DenseSpectrum,
    /// A rainbow sky, when the scene has one.
    pub sky: Option<std::sync::Arc<SceneSky>>,
    pub settings: RenderSettings,
}

/// A sky model ready for rendering: tabulated over (θ, λ), tied to the scene's sun.
#[derive(Debug)]
pub struct SceneSky {
    /// The model's name, for messages.
    pub model: String,
    pub table: crate::sky::table::SkyTable,
    /// Unit direction toward the sun.
    pub sun_dir: glam::Vec3,
    /// Per-wavelength factor on the table: the sun's irradiance times `scale` for the
    /// physical models (their profile is radiance per unit solar irradiance), `scale`
    /// alone for the Aristotelian and constant skies.
    pub factor: DenseSpectrum,
    /// True when the model already contains the background (aristotle, constant), so it
    /// replaces it rather than adding to it.
    pub replaces_background: bool,
}
