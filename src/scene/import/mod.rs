//! Scenes written for other renderers, converted to the TOML heron renders: Mitsuba 3's
//! XML (`xml.rs` reads the document, `mitsuba.rs` converts its objects) and pbrt-v4's
//! scene files (`pbrt.rs`). `heron render
//! scene.xml` renders the conversion; `heron convert scene.xml -o scene.toml` writes it
//! for editing. What heron cannot carry over is a [`Diagnostic`]: a warning naming the
//! file, line and element, or an error with `strict`.
mod mitsuba;
mod pbrt;
mod props;
mod transform;
mod xml;

pub use mitsuba::{DISK_SEGMENTS, UNBOUNDED_DEPTH};
pub use xml::Diagnostic;

use crate::error::{HeronError, Result};
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

/// A converted scene: heron's scene table (mesh paths relative to the source file's
/// folder) and the warnings.
#[derive(Clone, Debug)]
pub struct Imported {
    pub source: PathBuf,
    pub table: toml::Table,
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
                table: c.table,
                warnings: c.warnings,
            })
        }
        Format::Pbrt => {
            let c = pbrt::convert(path, options.strict).map_err(error)?;
            Ok(Imported {
                source: path.to_path_buf(),
                table: c.table,
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
        table: c.table,
        warnings: c.warnings,
    })
}

/// [`import_scene`] for a pbrt-v4 file already in memory, read as if from `path` (its
/// `Include`s and meshes from `path`'s folder).
pub fn import_pbrt_str(text: &str, path: &Path, options: &ImportOptions) -> Result<Imported> {
    let c = pbrt::convert_str(text, path, options.strict).map_err(error)?;
    Ok(Imported {
        source: path.to_path_buf(),
        table: c.table,
        warnings: c.warnings,
    })
}

impl Imported {
    /// The scene as heron's TOML, for a file in folder `out_dir` (the paths of meshes,
    /// textures and the environment map rewritten relative to it), opened by a comment naming the source and listing the warnings.
    pub fn to_toml(&self, out_dir: &Path) -> String {
        let mut table = self.table.clone();
        let src_dir = self.source.parent().unwrap_or(Path::new(""));
        // Every file the table names (meshes, textures, the environment map) is relative
        // to the source file; rewritten relative to the output's folder.
        let rebase = |v: Option<&mut toml::Value>| {
            if let Some(toml::Value::String(f)) = v {
                let rel = mitsuba::relative_to(&src_dir.join(&*f), out_dir);
                *f = rel.to_string_lossy().replace('\\', "/");
            }
        };
        if let Some(toml::Value::Array(shapes)) = table.get_mut("shapes") {
            for s in shapes.iter_mut() {
                rebase(s.get_mut("file"));
            }
        }
        if let Some(toml::Value::Table(materials)) = table.get_mut("materials") {
            for (_, m) in materials.iter_mut() {
                rebase(m.as_table_mut().and_then(|t| t.get_mut("texture")));
            }
        }
        rebase(table.get_mut("environment").and_then(|e| e.get_mut("map")));
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
        out.push_str(&toml::to_string(&table).expect("a TOML table serialises"));
        out
    }
}
