//! `heron convert`: a Mitsuba 3 or pbrt-v4 scene to heron's TOML.
use super::ImportArgs;
use std::path::PathBuf;

#[derive(clap::Args)]
pub(crate) struct ConvertArgs {
    /// The scene: Mitsuba 3 XML (.xml) or pbrt-v4 (.pbrt).
    scene: PathBuf,
    /// The TOML file to write (mesh paths are written relative to its folder).
    #[arg(short, long)]
    output: PathBuf,
    #[command(flatten)]
    import: ImportArgs,
}

pub(crate) fn run(a: ConvertArgs) -> anyhow::Result<()> {
    use heron::scene::import::{import_scene, Format};
    if Format::of(&a.scene) == Format::Heron {
        anyhow::bail!(
            "{}: expected a Mitsuba 3 (.xml) or pbrt-v4 (.pbrt) scene; heron's TOML needs no conversion",
            a.scene.display()
        );
    }
    let imported = import_scene(&a.scene, &a.import.options())?;
    for w in &imported.warnings {
        eprintln!("warning: {w}");
    }
    // The conversion must be a scene heron renders; its errors are found before writing.
    heron::scene::load::load_imported(&imported)?;
    let dir = match a.output.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let text = imported.to_toml(&dir);
    heron::files::write_atomically(&a.output, |tmp| {
        std::fs::write(tmp, &text).map_err(|e| e.to_string())
    })?;
    eprintln!(
        "{}: written, {} warning{}",
        a.output.display(),
        imported.warnings.len(),
        if imported.warnings.len() == 1 {
            ""
        } else {
            "s"
        }
    );
    Ok(())
}
