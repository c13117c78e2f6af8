//! Running the `heron` binary and writing the files it reads: the one copy of what every
//! CLI test needs.
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The `heron` binary Cargo built for these tests, ready for arguments (and, for the
/// tests that need them, environment variables or a child process to signal).
pub fn heron_command() -> Command {
    Command::new(env!("CARGO_BIN_EXE_heron"))
}

/// Runs `heron ARGS…` to its end.
pub fn heron(args: &[&str]) -> Output {
    heron_command().args(args).output().expect("run heron")
}

/// Runs `heron` with `line` split at whitespace (for arguments without spaces).
pub fn heron_words(line: &str) -> Output {
    heron_command()
        .args(line.split_whitespace())
        .output()
        .expect("run heron")
}

/// Runs `heron ARGS…` and asserts that it succeeded, showing its stderr if not.
pub fn heron_ok(args: &[&str]) -> Output {
    let out = heron(args);
    assert!(
        out.status.success(),
        "heron {}: {}",
        args.join(" "),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// A path in the repository, as text for an argument.
pub fn repo(p: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(p)
        .display()
        .to_string()
}

/// The bundled scene `scenes/NAME`, as text for an argument.
pub fn scene_path(name: &str) -> String {
    repo(&format!("scenes/{name}"))
}

/// Writes `text` (a scene, a mesh, a table) to `dir/name` and returns its path.
pub fn write_file(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    p
}

/// [`heron_words`] with rayon's pool of `threads` workers (`RAYON_NUM_THREADS`), for the
/// subcommands without a `--threads` flag.
pub fn heron_words_threads(line: &str, threads: usize) -> Output {
    heron_command()
        .args(line.split_whitespace())
        .env("RAYON_NUM_THREADS", threads.to_string())
        .output()
        .expect("run heron")
}
