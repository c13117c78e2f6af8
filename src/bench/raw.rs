//! The raw-Embree side of `heron bench traversal --raw`: a small C program
//! (`embree_raw.c`, embedded in heron) that traces the same rays on the same mesh through
//! Embree's C API with nothing around it.
//!
//! heron writes the mesh and the two ray sets to a temporary folder, builds the program
//! with gcc against the Embree heron itself links (the arguments come from build.rs),
//! starts it once (it builds its BVH with heron's scene flags) and then asks it for one
//! pass at a time, so heron's and Embree's passes can be interleaved.
use super::Width;
use crate::accel::embree::RayQuery;
use crate::geometry::Mesh;
use crate::{HeronError, Result};
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, ChildStdout, Command, Stdio};

const SOURCE: &str = include_str!("embree_raw.c");

/// What a pass found: the number of hits, the sum of their primitive IDs and of their
/// distances (summed in ray order, so heron's and the C program's agree exactly).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Tally {
    pub hits: u64,
    pub prim_sum: u64,
    pub t_sum: f64,
}

/// One timed pass.
#[derive(Clone, Copy, Debug)]
pub struct Pass {
    pub ns: u64,
    pub tally: Tally,
}

pub struct RawEmbree {
    dir: PathBuf,
    child: Child,
    stdin: ChildStdin,
    stdout: BufReader<ChildStdout>,
}

fn invalid(m: String) -> HeronError {
    HeronError::Invalid(m)
}

fn write_file(path: &Path, bytes: &[u8]) -> Result<()> {
    std::fs::write(path, bytes).map_err(|e| HeronError::Io {
        path: path.to_path_buf(),
        message: e.to_string(),
    })
}

fn ray_bytes(rays: &[RayQuery]) -> Vec<u8> {
    let mut b = Vec::with_capacity(4 + 32 * rays.len());
    b.extend((rays.len() as u32).to_le_bytes());
    for r in rays {
        for v in [
            r.origin.x, r.origin.y, r.origin.z, r.tnear, r.dir.x, r.dir.y, r.dir.z, r.tfar,
        ] {
            b.extend(v.to_le_bytes());
        }
    }
    b
}

impl RawEmbree {
    /// Writes the inputs, compiles the program and waits until its BVH is built.
    pub fn start(mesh: &Mesh, coherent: &[RayQuery], incoherent: &[RayQuery]) -> Result<Self> {
        let stamp = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos());
        let dir = std::env::temp_dir().join(format!("heron-raw-{}-{stamp}", std::process::id()));
        std::fs::create_dir_all(&dir).map_err(|e| HeronError::Io {
            path: dir.clone(),
            message: e.to_string(),
        })?;
        // From here on the folder is removed on every exit path (Drop or the guard).
        let guard = DirGuard(Some(dir.clone()));
        let mut m = Vec::with_capacity(8 + 12 * (mesh.positions.len() + mesh.indices.len()));
        m.extend((mesh.positions.len() as u32).to_le_bytes());
        m.extend((mesh.indices.len() as u32).to_le_bytes());
        for p in &mesh.positions {
            for v in [p.x, p.y, p.z] {
                m.extend(v.to_le_bytes());
            }
        }
        for t in &mesh.indices {
            for v in t {
                m.extend(v.to_le_bytes());
            }
        }
        write_file(&dir.join("mesh.bin"), &m)?;
        write_file(&dir.join("coherent.bin"), &ray_bytes(coherent))?;
        write_file(&dir.join("incoherent.bin"), &ray_bytes(incoherent))?;
        write_file(&dir.join("embree_raw.c"), SOURCE.as_bytes())?;

        let exe = dir.join("embree_raw");
        let out = Command::new("gcc")
            .args(["-O2", "-std=c11", "-o"])
            .arg(&exe)
            .arg(dir.join("embree_raw.c"))
            .args(env!("HERON_EMBREE_GCC_ARGS").split('\t'))
            .output()
            .map_err(|e| {
                invalid(format!(
                    "--raw needs gcc to build the raw-Embree program (apt-get install gcc): {e}"
                ))
            })?;
        if !out.status.success() {
            return Err(invalid(format!(
                "--raw: gcc could not build the raw-Embree program: {}",
                String::from_utf8_lossy(&out.stderr).trim()
            )));
        }
        let mut child = Command::new(&exe)
            .args(["mesh.bin", "coherent.bin", "incoherent.bin"].map(|f| dir.join(f)))
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .spawn()
            .map_err(|e| invalid(format!("--raw: cannot start {}: {e}", exe.display())))?;
        let stdin = child.stdin.take().expect("piped stdin");
        let stdout = BufReader::new(child.stdout.take().expect("piped stdout"));
        let mut raw = RawEmbree {
            dir: guard.release(),
            child,
            stdin,
            stdout,
        };
        let line = raw.read_line()?;
        if line != "ready" {
            return Err(invalid(format!(
                "--raw: the raw-Embree program said {line:?}"
            )));
        }
        Ok(raw)
    }

    fn read_line(&mut self) -> Result<String> {
        let mut line = String::new();
        let n = self
            .stdout
            .read_line(&mut line)
            .map_err(|e| invalid(format!("--raw: reading the raw-Embree program: {e}")))?;
        if n == 0 {
            return Err(invalid(
                "--raw: the raw-Embree program stopped (its error is above)".into(),
            ));
        }
        Ok(line.trim().to_string())
    }

    /// One pass over set 0 (coherent) or 1 (incoherent); None where the library has no
    /// such query (the stream API on Embree 4).
    pub fn trace(&mut self, width: Width, set: usize) -> Result<Option<Pass>> {
        writeln!(self.stdin, "{} {set}", width.code())
            .and_then(|_| self.stdin.flush())
            .map_err(|e| invalid(format!("--raw: writing to the raw-Embree program: {e}")))?;
        let line = self.read_line()?;
        if line == "unavailable" {
            return Ok(None);
        }
        let f: Vec<&str> = line.split_whitespace().collect();
        let parsed = (|| -> Option<Pass> {
            Some(Pass {
                ns: f.first()?.parse().ok()?,
                tally: Tally {
                    hits: f.get(1)?.parse().ok()?,
                    prim_sum: f.get(2)?.parse().ok()?,
                    t_sum: f.get(3)?.parse().ok()?,
                },
            })
        })();
        parsed
            .map(Some)
            .ok_or_else(|| invalid(format!("--raw: unexpected answer {line:?}")))
    }
}

impl Drop for RawEmbree {
    fn drop(&mut self) {
        let _ = writeln!(self.stdin, "quit").and_then(|_| self.stdin.flush());
        let _ = self.child.wait();
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// Removes the temporary folder unless released.
struct DirGuard(Option<PathBuf>);

impl DirGuard {
    fn release(mut self) -> PathBuf {
        self.0.take().expect("released once")
    }
}

impl Drop for DirGuard {
    fn drop(&mut self) {
        if let Some(d) = &self.0 {
            let _ = std::fs::remove_dir_all(d);
        }
    }
}
