//! Files: outputs written atomically (to a temporary file in the target's folder,
//! renamed into place, so a failed run never leaves a partial or stray file), and the
//! SHA-256 of inputs (the provenance of a render names every file it read by its hash).
use crate::error::{HeronError, Result};
use sha2::{Digest, Sha256};
use std::io;
use std::path::{Path, PathBuf};

/// An output written to a temporary file in its target's folder, waiting to be renamed
/// into place by [`Staged::commit`]. Dropped without commit, the temporary file is
/// removed, so a failed run never leaves a partial or stray file.
pub struct Staged {
    tmp: PathBuf,
    path: PathBuf,
    committed: bool,
}

impl Staged {
    /// Runs `write` on a temporary path next to `path`.
    pub fn write(
        path: &Path,
        write: impl FnOnce(&Path) -> std::result::Result<(), String>,
    ) -> Result<Staged> {
        let err = |message: String| HeronError::Io {
            path: path.to_path_buf(),
            message,
        };
        let name = path
            .file_name()
            .ok_or_else(|| err("not a file path".into()))?;
        let dir = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        if !dir.is_dir() {
            return Err(err(format!(
                "output folder {} does not exist",
                dir.display()
            )));
        }
        let staged = Staged {
            tmp: dir.join(format!(
                ".{}.{}.tmp",
                name.to_string_lossy(),
                std::process::id()
            )),
            path: path.to_path_buf(),
            committed: false,
        };
        write(&staged.tmp).map_err(err)?;
        Ok(staged)
    }

    /// Renames the temporary file into place.
    pub fn commit(mut self) -> Result<()> {
        std::fs::rename(&self.tmp, &self.path).map_err(|e: io::Error| HeronError::Io {
            path: self.path.clone(),
            message: format!("cannot rename into place: {e}"),
        })?;
        self.committed = true;
        Ok(())
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        if !self.committed {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

/// Writes one file through a temporary file and a rename.
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&Path) -> std::result::Result<(), String>,
) -> Result<()> {
    Staged::write(path, write)?.commit()
}

/// SHA-256 of `bytes`, as 64 lowercase hex digits.
pub fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// (path as the scene names it, SHA-256 of the file's bytes) for each distinct file,
/// sorted by path. The files were just read by the loader; an error names the file.
pub fn hash_inputs(
    base_dir: &Path,
    mut files: Vec<String>,
) -> std::result::Result<Vec<(String, String)>, String> {
    files.sort();
    files.dedup();
    files
        .into_iter()
        .map(|f| {
            let bytes = std::fs::read(base_dir.join(&f))
                .map_err(|e| format!("{f}: cannot read it again to hash it: {e}"))?;
            Ok((f, sha256_hex(&bytes)))
        })
        .collect()
}
