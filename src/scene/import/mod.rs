//! Scenes written for other renderers, converted to heron's scene: Mitsuba 3's XML
//! (`xml.rs` reads the document, `mitsuba/` converts its objects) and pbrt-v4's scene
//! files (`pbrt/`). The converters build the scene schema's own structs
//! ([`SceneFile`], `schema.rs` the values both share), so a schema key renamed or
//! retyped is a compile error here rather than a table the loader refuses. `heron render
//! scene.xml` renders the conversion; `heron convert scene.xml -o scene.toml` writes it
//! for editing. What heron cannot carry over is a [`Diagnostic`]: a warning naming the
//! file, line and element, or an error with `strict`.
mod mitsuba;
mod pbrt;
mod props;
mod schema;
mod transform;
mod xml;

pub use mitsuba::{DISK_SEGMENTS, UNBOUNDED_DEPTH};
pub use xml::Diagnostic;

use crate::error::{HeronError, Result};
use crate::scene::file::{LambertianFile, MaterialFile, SceneFile, ShapeFile, TextureFile};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// How a scene file is read, by its extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// heron's own TOML.
    Heron,
    /// Mitsuba 3's XML.
    Mitsuba,
    /// pbrt-v4's scene format (`.pbrt`).
    Pbrt,
}

impl Format {
    pub fn of(path: &Path) -> Format {
        match path.extension().and_then(|e| e.to_str()) {
            Some(e) if e.eq_ignore_ascii_case("xml") => Format::Mitsuba,
            Some(e) if e.eq_ignore_ascii_case("pbrt") => Format::Pbrt,
            _ => Format::Heron,
        }
    }
}

/// How to import: `strict` turns warnings into errors; `defines` set `$name`
/// parameters as Mitsuba's `-D name=value` does.
#[derive(Clone, Debug, Default)]
pub struct ImportOptions {
    pub strict: bool,
    pub defines: BTreeMap<String, String>,
}

/// A converted scene: heron's scene (the paths of meshes, textures and the environment
/// map relative to the source file's folder) and the warnings.
#[derive(Clone, Debug)]
pub struct Imported {
    pub source: PathBuf,
    pub scene: SceneFile,
    pub warnings: Vec<Diagnostic>,
}

fn error(d: Diagnostic) -> HeronError {
    HeronError::Scene {
        file: d.file,
        message: format!("line {}: {}", d.line, d.message),
    }
}

/// Converts the scene file `path` (by [`Format::of`]; heron's own TOML is an error
/// here, it needs no conversion).
pub fn import_scene(path: &Path, options: &ImportOptions) -> Result<Imported> {
    match Format::of(path) {
        Format::Mitsuba => {
            let root = xml::read_document(path, &options.defines).map_err(error)?;
            let c = mitsuba::convert(&root, path, options.strict).map_err(error)?;
            Ok(Imported {
                source: path.to_path_buf(),
                scene: c.scene,
                warnings: c.warnings,
            })
        }
        Format::Pbrt => {
            let c = pbrt::convert(path, options.strict).map_err(error)?;
            Ok(Imported {
                source: path.to_path_buf(),
                scene: c.scene,
                warnings: c.warnings,
            })
        }
        Format::Heron => Err(HeronError::Scene {
            file: path.to_path_buf(),
            message: "expected a Mitsuba 3 (.xml) or pbrt-v4 (.pbrt) scene to convert; this is heron's own format"
                .into(),
        }),
    }
}

/// [`import_scene`] for Mitsuba 3 XML already in memory, read as if from `path`.
pub fn import_mitsuba_str(text: &str, path: &Path, options: &ImportOptions) -> Result<Imported> {
    let root = xml::read_document_from_str(text, path, &options.defines).map_err(error)?;
    let c = mitsuba::convert(&root, path, options.strict).map_err(error)?;
    Ok(Imported {
        source: path.to_path_buf(),
        scene: c.scene,
        warnings: c.warnings,
    })
}

/// [`import_scene`] for a pbrt-v4 file already in memory, read as if from `path` (its
/// `Include`s and meshes from `path`'s folder).
pub fn import_pbrt_str(text: &str, path: &Path, options: &ImportOptions) -> Result<Imported> {
    let c = pbrt::convert_str(text, path, options.strict).map_err(error)?;
    Ok(Imported {
        source: path.to_path_buf(),
        scene: c.scene,
        warnings: c.warnings,
    })
}

impl Imported {
    /// The scene as a TOML table, its keys and values as `heron convert` writes them and
    /// its files relative to the source's folder (for looking at it by key path).
    pub fn table(&self) -> toml::Table {
        toml::Table::try_from(&self.scene).expect("a scene serialises to a TOML table")
    }

    /// The scene as heron's TOML, for a file in folder `out_dir` (the paths of meshes,
    /// textures and the environment map rewritten relative to it), opened by a comment
    /// naming the source and listing the warnings. The keys are sorted (the order of
    /// `toml::Table`), as the scene's tables were before they were typed.
    pub fn to_toml(&self, out_dir: &Path) -> String {
        let mut scene = self.scene.clone();
        let src_dir = self.source.parent().unwrap_or(Path::new(""));
        // Every file the scene names (meshes, textures, the environment map) is relative
        // to the source file; rewritten relative to the output's folder.
        let rebase = |f: &mut String| {
            let rel = mitsuba::relative_to(&src_dir.join(&*f), out_dir);
            *f = rel.to_string_lossy().replace('\\', "/");
        };
        for s in &mut scene.shapes {
            match s {
                ShapeFile::Mesh(m) if !m.file.is_empty() => rebase(&mut m.file),
                _ => {}
            }
        }
        for m in scene.materials.values_mut() {
            if let MaterialFile::Lambertian(LambertianFile {
                texture: Some(t), ..
            }) = m
            {
                rebase(t);
            }
        }
        for t in scene.textures.values_mut() {
            if let TextureFile::Image(i) = t {
                rebase(&mut i.file);
            }
        }
        if let Some(e) = &mut scene.environment {
            rebase(&mut e.map);
        }
        let mut out = format!(
            "# Converted by heron {} from {}.\n",
            env!("CARGO_PKG_VERSION"),
            self.source.display()
        );
        if self.warnings.is_empty() {
            out.push_str("# Everything in it was carried over.\n");
        } else {
            out.push_str("# What was not carried over as written:\n");
            for w in &self.warnings {
                out.push_str(&format!("#   {w}\n"));
            }
        }
        out.push('\n');
        let table = toml::Table::try_from(&scene).expect("a scene serialises to a TOML table");
        out.push_str(&toml::to_string(&table).expect("a TOML table serialises"));
        out
    }
}
