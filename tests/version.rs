//! Versions that say what they are (issue 26, part 4): `heron --version` names the crate
//! version and the git commit the binary was built from, and whether its sources differed
//! from that commit; the EXR provenance carries the same commit. The expected values come
//! from `git` itself, run here, not from heron's build script.
use std::path::{Path, PathBuf};
use std::process::Command;

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

/// The files build.rs counts as the binary's sources (a change to one makes it dirty).
const SOURCES: [&str; 5] = ["src", "spectra", "build.rs", "Cargo.toml", "Cargo.lock"];

fn git(args: &[&str]) -> Option<String> {
    // --no-optional-locks: `git status` must not refresh the index, which build.rs
    // watches; a rewritten index would rebuild heron in every later cargo command.
    let out = Command::new("git")
        .arg("--no-optional-locks")
        .args(args)
        .current_dir(ROOT)
        .env_remove("GIT_DIR")
        .env_remove("GIT_WORK_TREE")
        .output()
        .ok()?;
    out.status.success().then(|| {
        String::from_utf8(out.stdout)
            .unwrap()
            .trim_end()
            .to_string()
    })
}

/// (commit, state) as git sees this checkout: `git rev-parse HEAD` and whether `git
/// status` lists a changed source; ("unknown", "unknown") outside a git checkout of this
/// crate (e.g. a source tarball).
fn expected() -> (String, &'static str) {
    let top = git(&["rev-parse", "--show-toplevel"]).map(PathBuf::from);
    let ours = top.is_some_and(|t| t.canonicalize().ok() == Path::new(ROOT).canonicalize().ok());
    if !ours {
        return ("unknown".into(), "unknown");
    }
    let head = git(&["rev-parse", "HEAD"]).expect("git rev-parse HEAD");
    let mut args = vec!["status", "--porcelain", "--untracked-files=no", "--"];
    args.extend(SOURCES);
    let changed = git(&args).expect("git status");
    (head, if changed.is_empty() { "clean" } else { "dirty" })
}

#[test]
fn version_names_the_crate_version_and_the_git_commit() {
    let out = Command::new(env!("CARGO_BIN_EXE_heron"))
        .arg("--version")
        .output()
        .expect("run heron --version");
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    let (commit, state) = expected();
    assert_eq!(
        text.trim_end(),
        format!(
            "heron {} (commit {commit}, {state})",
            env!("CARGO_PKG_VERSION")
        )
    );
    // The library's constants (the provenance's source) say the same.
    assert_eq!(heron::provenance::GIT_COMMIT, commit);
    assert_eq!(heron::provenance::GIT_STATE, state);
    let suffix = if state == "dirty" { "-dirty" } else { "" };
    assert_eq!(heron::provenance::COMMIT, format!("{commit}{suffix}"));
}

#[test]
fn the_exr_provenance_carries_the_commit() {
    let d = tempfile::tempdir().unwrap();
    let scene = d.path().join("s.toml");
    std::fs::write(
        &scene,
        "[camera]\neye = [0.0, 0.0, 1.0]\nlook_at = [0.0, 0.0, 0.0]\nresolution = [4, 4]\n",
    )
    .unwrap();
    let exr = d.path().join("s.exr");
    let heron = env!("CARGO_BIN_EXE_heron");
    let o = Command::new(heron)
        .args([
            "render",
            scene.to_str().unwrap(),
            "-o",
            exr.to_str().unwrap(),
        ])
        .args(["--spp", "1", "--no-png"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = Command::new(heron)
        .args(["info", exr.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8(o.stdout).unwrap();
    let (commit, state) = expected();
    let suffix = if state == "dirty" { "-dirty" } else { "" };
    assert!(
        text.lines()
            .any(|l| l == format!("commit: {commit}{suffix}")),
        "{text}"
    );
    assert!(
        text.lines()
            .any(|l| l == format!("version: {}", env!("CARGO_PKG_VERSION"))),
        "{text}"
    );
}
