//! The raw-Embree side of `heron bench traversal --raw`: a small C program
//! (`embree_raw.c`, embedded in heron) that traces the same rays on the same mesh through
//! Embree's C API with nothing around it.
//!
//! heron writes the mesh and the two ray sets to a temporary folder, builds the program
//! with gcc against the Embree heron itself links (the arguments come from build.rs),
//! starts it once (it builds its BVH with heron's scene flags) and then asks it for one
//! pass at a time, so heron's and Embree's passes can be interleaved.
use super::Width;
use crate::accel::embree::{QueryTally, RayQuery};
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
    /// Who started it, for messages: `--raw` or `the replay`.
    who: &'static str,
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
        let dir = TempDir::new()?;
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
        write_file(&dir.0.join("mesh.bin"), &m)?;
        write_file(&dir.0.join("coherent.bin"), &ray_bytes(coherent))?;
        write_file(&dir.0.join("incoherent.bin"), &ray_bytes(incoherent))?;
        let args = ["mesh.bin", "coherent.bin", "incoherent.bin"].map(|f| dir.0.join(f));
        Self::spawn("--raw", dir, &args.map(|a| a.into_os_string()))
    }

    /// Compiles the program and starts it on a ray log (`heron bench record`), which
    /// the caller has checked; waits until its BVH is built.
    pub fn start_replay(log: &Path) -> Result<Self> {
        let dir = TempDir::new()?;
        let log = std::path::absolute(log).map_err(|e| HeronError::Io {
            path: log.to_path_buf(),
            message: e.to_string(),
        })?;
        Self::spawn(
            "the replay",
            dir,
            &["--replay".into(), log.into_os_string()],
        )
    }

    /// Builds `embree_raw.c` in `dir` with gcc at Embree's tutorials' optimisation
    /// (CMake's Release flags, `-O3 -DNDEBUG`) and starts it with `args`.
    fn spawn(who: &'static str, dir: TempDir, args: &[std::ffi::OsString]) -> Result<Self> {
        write_file(&dir.0.join("embree_raw.c"), SOURCE.as_bytes())?;
        let exe = dir.0.join("embree_raw");
        let out = Command::new("gcc")
            .args(["-O3", "-DNDEBUG", "-std=c11", "-o"])
            .arg(&exe)
            .arg(dir.0.join("embree_raw.c"))
            .args(env!("HERON_EMBREE_GCC_ARGS").split('\t'))
            .output()
            .map_err(|e| {
                invalid(format!(
                    "{who} needs gcc to build the raw-Embree program (apt-get install gcc): {e}"
                ))
            })?;
        if !out.status.success() {
            return Err(invalid(format!(
                "{who}: gcc could not build the raw-Embree program: {}",
                String::from_utf8_lossy(&out.stderr).trim()
            )));
        }
        let mut child = Command::new(&exe)
            .args(args)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .spawn()
            .map_err(|e| invalid(format!("{who}: cannot start {}: {e}", exe.display())))?;
        let stdin = child.stdin.take().expect("piped stdin");
        let stdout = BufReader::new(child.stdout.take().expect("piped stdout"));
        let mut raw = RawEmbree {
            who,
            dir: dir.release(),
            child,
            stdin,
            stdout,
        };
        let line = raw.read_line()?;
        if line != "ready" {
            return Err(invalid(format!(
                "{who}: the raw-Embree program said {line:?}"
            )));
        }
        Ok(raw)
    }

    fn read_line(&mut self) -> Result<String> {
        let mut line = String::new();
        let n = self
            .stdout
            .read_line(&mut line)
            .map_err(|e| invalid(format!("{}: reading the raw-Embree program: {e}", self.who)))?;
        if n == 0 {
            return Err(invalid(format!(
                "{}: the raw-Embree program stopped (its error is above)",
                self.who
            )));
        }
        Ok(line.trim().to_string())
    }

    fn command(&mut self, line: &str) -> Result<Option<Vec<String>>> {
        writeln!(self.stdin, "{line}")
            .and_then(|_| self.stdin.flush())
            .map_err(|e| {
                invalid(format!(
                    "{}: writing to the raw-Embree program: {e}",
                    self.who
                ))
            })?;
        let answer = self.read_line()?;
        if answer == "unavailable" {
            return Ok(None);
        }
        Ok(Some(answer.split_whitespace().map(String::from).collect()))
    }

    /// One pass over set 0 (coherent) or 1 (incoherent); None where the library has no
    /// such query (the stream API on Embree 4).
    pub fn trace(&mut self, width: Width, set: usize) -> Result<Option<Pass>> {
        let Some(f) = self.command(&format!("{} {set}", width.code()))? else {
            return Ok(None);
        };
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
            .ok_or_else(|| invalid(format!("{}: unexpected answer {f:?}", self.who)))
    }

    /// One replay of every call of the ray log ([`RawEmbree::start_replay`]): its time in
    /// ns and what the calls found; None where the log has a stream call and the library
    /// no stream API (Embree 4).
    pub fn replay(&mut self) -> Result<Option<(u64, QueryTally)>> {
        let Some(f) = self.command("replay")? else {
            return Ok(None);
        };
        let parsed = (|| -> Option<(u64, QueryTally)> {
            Some((
                f.first()?.parse().ok()?,
                QueryTally {
                    calls: f.get(1)?.parse().ok()?,
                    rays: f.get(2)?.parse().ok()?,
                    hits: f.get(3)?.parse().ok()?,
                    prim_sum: f.get(4)?.parse().ok()?,
                    t_sum: f.get(5)?.parse().ok()?,
                    occluded: f.get(6)?.parse().ok()?,
                },
            ))
        })();
        parsed
            .map(Some)
            .ok_or_else(|| invalid(format!("{}: unexpected answer {f:?}", self.who)))
    }
}

impl Drop for RawEmbree {
    fn drop(&mut self) {
        let _ = writeln!(self.stdin, "quit").and_then(|_| self.stdin.flush());
        let _ = self.child.wait();
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// A fresh temporary folder, removed on drop unless released.
struct TempDir(PathBuf);

impl TempDir {
    fn new() -> Result<Self> {
        let stamp = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos());
        let dir = std::env::temp_dir().join(format!("heron-raw-{}-{stamp}", std::process::id()));
        std::fs::create_dir_all(&dir).map_err(|e| HeronError::Io {
            path: dir.clone(),
            message: e.to_string(),
        })?;
        Ok(TempDir(dir))
    }

    fn release(self) -> PathBuf {
        let d = self.0.clone();
        std::mem::forget(self);
        d
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}
