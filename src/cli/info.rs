//! `heron info`: the provenance heron wrote into an EXR.
use anyhow::Result;
use std::path::Path;

pub(crate) fn run(path: &Path) -> Result<()> {
    let attrs = heron::film::exr::read_provenance(path)?;
    if attrs.is_empty() {
        anyhow::bail!(
            "{}: no heron provenance in this EXR (expected heron.* header attributes)",
            path.display()
        );
    }
    for (k, v) in attrs {
        // Multi-line values (the input files) are indented under their key.
        println!("{k}: {}", v.replace('\n', "\n  "));
    }
    Ok(())
}
