//! Loading and validating a scene file into a [`Scene`](super::Scene).
//!
//! Three stages, each failing with `HeronError::Scene { file, message }` and a one-line
//! message that starts with the key path (or the line and column for TOML syntax):
//!
//! 1. TOML syntax: the text is parsed into a table (`line 3, column 9: …`).
//! 2. Shape of the data: the table is deserialized into [`SceneFile`] through
//!    `serde_path_to_error`, whose leaf types check ranges (`shapes[2].radius: expected a
//!    positive finite number, got -0.3`). serde's internally tagged enums buffer the
//!    item they read, which loses the key path inside `materials.X`, `shapes[i]` and
//!    `lights[i]`; when an error lands on such an item, the item alone is deserialized
//!    again into the struct of its `type` to recover the full path.
//! 3. Cross-key checks while building the [`Scene`]: material names, ρd + ρs ≤ 1,
//!    zero-area triangles and quads, the camera, and the meshes (whose errors name the
//!    mesh file and carry the scene's key path in the message).
//!
//! Orders: `Scene::materials` is sorted by material name (a TOML table keeps no order);
//! `Scene::shapes` follows the file, and a mesh entry becomes one shape per material it
//! uses, in the order in which the materials' OBJ groups first appear in the OBJ file.
//!
//! Rooms, one per concern, each building its models from their tables: `errors.rs`
//! (stages 1 and 2's messages, key paths, `scene_error`), `materials.rs`, `shapes.rs`
//! (spheres, triangles, planes, quads, meshes; `obj.rs` reads OBJ text, `ply.rs` PLY,
//! `serialized.rs` Mitsuba's serialized meshes), `media.rs`,
//! `lights.rs` (the file's lights and the area lights of emitting shapes), `sky.rs`
//! (`[sky]` to a [`crate::sky::SkySpec`]), `environment.rs` (`[environment]`, its image
//! read by `image.rs`), `settings.rs` (`[render]`), `camera.rs`.
//! [`build`] runs them in the order of the errors they report.
pub(crate) mod obj;
pub(crate) mod ply;
pub(crate) mod serialized;

mod camera;
mod environment;
mod errors;
pub(crate) mod image;
pub mod lens;
mod lights;
mod materials;
mod media;
mod settings;
mod shapes;
mod sky;
mod textures;

pub use materials::ior_from_value;
pub use media::MEDIUM_DEFAULT_NODES;
pub use shapes::scene_bounds;
pub(crate) use shapes::{is_degenerate, mesh_shapes, shapes_of_groups};

use super::file::SceneFile;
use super::{Scene, SceneParts};
use crate::error::Result;
use crate::spectrum::DenseSpectrum;
use errors::scene_error;
use std::path::Path;

/// Reads, parses and validates the scene file at `path` (meshes are resolved relative to
/// it). Every error names the file, the key path and what was expected.
pub fn load_scene(path: &Path) -> Result<Scene> {
    if super::import::Format::of(path) != super::import::Format::Heron {
        let imported = super::import::import_scene(path, &Default::default())?;
        for w in &imported.warnings {
            eprintln!("heron: warning: {w}");
        }
        let scene = load_imported(&imported)?;
        for w in &scene.warnings {
            eprintln!("heron: warning: {w}");
        }
        return Ok(scene);
    }
    let text = std::fs::read_to_string(path)
        .map_err(|e| scene_error(path, format!("cannot read the scene file: {e}")))?;
    let scene = load_scene_from_str(&text, path)?;
    for w in &scene.warnings {
        eprintln!("heron: warning: {w}");
    }
    Ok(scene)
}

/// The scene of a converted file ([`super::import`]); its errors name the source
/// file and the key of the converted scene, which `heron convert` writes out.
pub fn load_imported(imported: &super::import::Imported) -> Result<Scene> {
    let dir = imported.source.parent().unwrap_or(Path::new(""));
    let text = imported.to_toml(dir);
    load_scene_from_str(&text, &imported.source).map_err(|e| match e {
        crate::error::HeronError::Scene { file, message } if file == imported.source => {
            crate::error::HeronError::Scene {
                file,
                message: format!("in the converted scene (heron convert writes it): {message}"),
            }
        }
        e => e,
    })
}

/// Like [`load_scene`] for scene text already in memory; `path` names the file in error
/// messages and its folder is where relative mesh paths start.
pub fn load_scene_from_str(text: &str, path: &Path) -> Result<Scene> {
    let file = parse_scene_file(text).map_err(|m| scene_error(path, m))?;
    build(
        path,
        file,
        SkyTables::Build,
        crate::files::sha256_hex(text.as_bytes()),
    )
}

/// Whether [`build`] tabulates a `[sky]` model and Lorenz–Mie media. Tabulating a
/// physical sky or a medium of rain drops takes seconds (it is the model's evaluation,
/// not the file's reading), so the fuzzing harness ([`crate::fuzzing`]) checks the
/// `[sky]` table and constructs its model but leaves `Scene::sky` empty, and checks a
/// `type = "mie"` medium's keys and shape but builds no medium for it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum SkyTables {
    Build,
    Skip,
}

/// Stages 1 and 2: TOML text to [`SceneFile`]. The error is the one-line message.
pub fn parse_scene_file(text: &str) -> std::result::Result<SceneFile, String> {
    let table: toml::Table = text
        .parse()
        .map_err(|e: toml::de::Error| errors::toml_syntax(text, &e))?;
    errors::require_tables(&table)?;
    serde_path_to_error::deserialize::<_, SceneFile>(toml::Value::Table(table.clone()))
        .map_err(|e| errors::data_error(&table, &e))
}

/// Stage 3: the scene of `file` (read from `path`, whose text has the SHA-256
/// `source_sha256`), room by room in the order of the errors they report.
pub(crate) fn build(
    path: &Path,
    file: SceneFile,
    sky_tables: SkyTables,
    source_sha256: String,
) -> Result<Scene> {
    let err = |m: String| scene_error(path, m);
    let base_dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    // Every file the scene reads besides itself (meshes, tables), for provenance.
    let mut inputs: Vec<String> = Vec::new();
    let materials = materials::Materials::build(&file, &base_dir, &mut inputs).map_err(err)?;
    let plans = media::plan_media(&file.shapes, &base_dir, &mut inputs).map_err(err)?;
    let mut warnings: Vec<String> = Vec::new();
    let (mut shapes, entry) = shapes::build_shapes(
        path,
        &base_dir,
        &file.shapes,
        &materials,
        &mut inputs,
        &mut warnings,
    )?;
    let media = media::assign_media(
        &file.shapes,
        &entry,
        &plans,
        &mut shapes,
        &materials,
        sky_tables,
    )
    .map_err(err)?;
    shapes::check_bounds(&shapes, &entry).map_err(err)?;
    let mut lights = lights::build_lights(&file.lights).map_err(err)?;
    let light_polarization = lights::build_light_polarization(&file.lights).map_err(err)?;
    lights::add_area_lights(
        &file.shapes,
        &entry,
        &mut shapes,
        &mut lights,
        &mut textures::Textures::new(&file.textures, &base_dir),
        &mut inputs,
    )
    .map_err(err)?;
    let background = file
        .background
        .as_ref()
        .map_or_else(|| DenseSpectrum::constant(0.0), |b| b.spectrum());
    let settings = settings::render_settings(file.render.as_ref()).map_err(err)?;
    let sky = match &file.sky {
        Some(sf) => {
            let plan = sky::plan_sky(sf, &file.lights, &lights, &background).map_err(err)?;
            match sky_tables {
                SkyTables::Build => Some(std::sync::Arc::new(plan.tabulate())),
                SkyTables::Skip => None,
            }
        }
        None => None,
    };
    let envmap = match &file.environment {
        Some(env) => {
            if file.background.is_some() {
                return Err(err(
                    "environment: a scene has a background or an [environment] map, not both (the map is the background)".into(),
                ));
            }
            if file.sky.is_some() {
                return Err(err(
                    "environment: a scene has a [sky] or an [environment] map, not both".into(),
                ));
            }
            Some(environment::build_envmap(env, &base_dir, &mut inputs).map_err(err)?)
        }
        None => None,
    };
    let camera = camera::build_camera(&file.camera, &base_dir, &mut inputs).map_err(err)?;
    let inputs = crate::files::hash_inputs(&base_dir, inputs).map_err(err)?;
    let mut scene = Scene::from_parts(SceneParts {
        source: path.to_path_buf(),
        source_sha256,
        inputs,
        camera,
        shapes,
        materials: materials.list,
        material_names: materials.names,
        lights,
        background,
        sky,
        envmap,
        settings,
        media,
    });
    scene.light_polarization = light_polarization;
    scene.warnings = warnings;
    Ok(scene)
}
