//! Replays the fuzzing corpus on the stable toolchain: every file of `fuzz/corpus/<target>/`
//! and `fuzz/regressions/<target>/` goes through the harness the fuzz target of that name
//! runs ([`heron::fuzzing::TARGETS`]), which panics on a finding. The corpus holds the
//! inputs the fuzzers found interesting (minimised with `cargo fuzz cmin`) and every
//! input that once crashed heron.
use heron::fuzzing::{Harness, Outcome, TARGETS};
use std::path::{Path, PathBuf};

const FUZZ: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/fuzz");

fn files(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = match std::fs::read_dir(dir) {
        Ok(rd) => rd
            .map(|e| e.unwrap().path())
            .filter(|p| p.is_file())
            .collect(),
        Err(_) => Vec::new(),
    };
    v.sort();
    v
}

/// The sub-folders of `dir`, which must all be target names.
fn target_dirs(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_dir())
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    names.sort();
    for n in &names {
        assert!(
            TARGETS.iter().any(|(t, _)| t == n),
            "{}/{n}: no fuzz target of that name in heron::fuzzing::TARGETS",
            dir.display()
        );
    }
    names
}

/// Runs `harness` on every file of `dir`, naming the file if it panics; returns the
/// number of files the reader accepted, rejected and skipped.
fn replay(harness: Harness, dir: &Path, fixtures: &Path) -> [usize; 3] {
    let mut counts = [0; 3];
    for f in files(dir) {
        let data = std::fs::read(&f).unwrap();
        let run = std::panic::catch_unwind(|| harness(&data, fixtures));
        match run {
            Ok(Outcome::Accepted) => counts[0] += 1,
            Ok(Outcome::Rejected) => counts[1] += 1,
            Ok(Outcome::Skipped) => counts[2] += 1,
            Err(_) => panic!("{}: the harness panicked (a fuzzing finding)", f.display()),
        }
    }
    counts
}

#[test]
fn corpus_and_regressions_replay_without_a_finding() {
    let fuzz = Path::new(FUZZ);
    let fixtures = fuzz.join("fixtures");
    assert!(fixtures.join("meshes/cornell.obj").is_file());
    // No folder is left unreplayed: each is named after a target.
    target_dirs(&fuzz.join("corpus"));
    target_dirs(&fuzz.join("regressions"));
    for (name, harness) in TARGETS {
        let [acc, rej, skip] = replay(*harness, &fuzz.join("corpus").join(name), &fixtures);
        eprintln!("fuzz/corpus/{name}: {acc} accepted, {rej} rejected, {skip} skipped");
        // A corpus that is empty, or whose inputs never get past the first check (or are
        // never refused), would test nothing.
        assert!(acc > 0, "fuzz/corpus/{name}: no input is accepted");
        assert!(rej > 0, "fuzz/corpus/{name}: no input is rejected");
        let [acc, rej, skip] = replay(*harness, &fuzz.join("regressions").join(name), &fixtures);
        eprintln!("fuzz/regressions/{name}: {acc} accepted, {rej} rejected, {skip} skipped");
    }
}

/// The harnesses tell acceptance from rejection (so the counts above mean something).
#[test]
fn harnesses_accept_and_reject() {
    use heron::fuzzing::{obj, scene, spectral_csv};
    let fixtures = Path::new(FUZZ).join("fixtures");
    let prism = std::fs::read(fixtures.join("meshes/prism60.obj")).unwrap();
    assert_eq!(obj(&prism), Outcome::Accepted);
    assert_eq!(obj(b"v 0 0 0\nf 1 1 1\n"), Outcome::Rejected);
    assert_eq!(obj(b"v 0 0 0\xff\n"), Outcome::Skipped);
    let toml = std::fs::read(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/prism.toml")).unwrap();
    assert_eq!(scene(&toml, &fixtures), Outcome::Accepted);
    let outside = String::from_utf8(toml.clone())
        .unwrap()
        .replace("meshes/prism60.obj", "../../scenes/meshes/prism60.obj");
    assert_eq!(scene(outside.as_bytes(), &fixtures), Outcome::Skipped);
    assert_eq!(scene(&toml[..toml.len() / 2], &fixtures), Outcome::Rejected);
    assert_eq!(
        spectral_csv(b"400,0.1\n500,0.2\n600,0.3\n700,0.4\n"),
        Outcome::Accepted
    );
    assert_eq!(spectral_csv(b"400,0.1\n"), Outcome::Rejected);
}
