//! Provenance in every EXR (issue 10, part 5): `heron render` writes the version, the
//! scene's and its mesh's SHA-256 and the settings that made the pixels as `heron.*`
//! header attributes; `heron info` prints them; nothing in them differs between
//! identical runs, so the files stay byte-identical; bad input to `heron info` is a
//! one-line error. The hashes are checked against coreutils' `sha256sum`, an
//! implementation independent of heron's.
mod common;

use common::cli::heron;
use std::path::{Path, PathBuf};
use std::process::Command;

fn sha256sum(p: &Path) -> String {
    let out = Command::new("sha256sum")
        .arg(p)
        .output()
        .expect("sha256sum");
    assert!(out.status.success());
    String::from_utf8(out.stdout)
        .unwrap()
        .split_whitespace()
        .next()
        .unwrap()
        .to_string()
}

fn scenes() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes")
}

/// `heron render SCENE -o OUT --quiet --no-png EXTRA…`, which must succeed.
fn render(scene: &Path, out: &Path, extra: &[&str]) {
    let mut args = vec![
        "render",
        scene.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(&["--quiet", "--no-png"]);
    args.extend_from_slice(extra);
    let o = heron(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// Settings other than the defaults, so that each shows up in the provenance.
const SETTINGS: [&str; 14] = [
    "--spp",
    "3",
    "--seed",
    "7",
    "--lanes",
    "4",
    "--wavelengths",
    "uniform",
    "--sampler",
    "independent",
    "--integrator",
    "path",
    "--max-depth",
    "5",
];

#[test]
fn render_records_what_made_the_image_and_info_prints_it() {
    let d = tempfile::tempdir().unwrap();
    let (a, b) = (d.path().join("a.exr"), d.path().join("b.exr"));
    let cornell = scenes().join("cornell.toml");
    render(&cornell, &a, &[&SETTINGS[..], &["--threads", "1"]].concat());
    render(&cornell, &b, &[&SETTINGS[..], &["--threads", "2"]].concat());
    // No date, time, thread count or absolute path: identical renders, identical bytes.
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());

    let o = heron(&["info", a.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8(o.stdout).unwrap();
    let scene_hash = sha256sum(&scenes().join("cornell.toml"));
    let mesh_hash = sha256sum(&scenes().join("meshes/cornell.obj"));
    let expected = [
        format!("commit: {}", heron::provenance::COMMIT),
        "inputs: ".to_string() + &mesh_hash + "  meshes/cornell.obj",
        "integrator: path".into(),
        "lanes: 4".into(),
        "maxDepth: 5".into(),
        "offset: robust".into(),
        "packets: true".into(),
        "sampler: independent".into(),
        "scene: cornell.toml".into(),
        format!("sceneSha256: {scene_hash}"),
        "seed: 7".into(),
        "spectralBins: 0".into(),
        "spp: 3".into(),
        format!("version: {}", env!("CARGO_PKG_VERSION")),
        "wavelengths: uniform".into(),
    ];
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(
        lines,
        expected.iter().map(String::as_str).collect::<Vec<_>>(),
        "{text}"
    );
}

#[test]
fn a_changed_input_changes_its_hash() {
    // A copy of the Cornell scene whose mesh has one more comment line: same image,
    // different provenance.
    let d = tempfile::tempdir().unwrap();
    std::fs::create_dir(d.path().join("meshes")).unwrap();
    let obj = std::fs::read_to_string(scenes().join("meshes/cornell.obj")).unwrap();
    std::fs::write(
        d.path().join("meshes/cornell.obj"),
        format!("# edited\n{obj}"),
    )
    .unwrap();
    let scene = d.path().join("cornell.toml");
    std::fs::copy(scenes().join("cornell.toml"), &scene).unwrap();
    let out = d.path().join("c.exr");
    render(&scene, &out, &["--spp", "1"]);
    let info = String::from_utf8(heron(&["info", out.to_str().unwrap()]).stdout).unwrap();
    let edited = sha256sum(&d.path().join("meshes/cornell.obj"));
    assert!(
        info.contains(&format!("inputs: {edited}  meshes/cornell.obj")),
        "{info}"
    );
    assert!(
        !info.contains(&sha256sum(&scenes().join("meshes/cornell.obj"))),
        "{info}"
    );
}

#[test]
fn info_on_bad_input_is_a_one_line_error() {
    let d = tempfile::tempdir().unwrap();
    let not_exr = d.path().join("x.exr");
    std::fs::write(&not_exr, "not an image").unwrap();
    for (path, expect) in [
        (not_exr.clone(), "cannot read it as OpenEXR"),
        (d.path().join("missing.exr"), "cannot read it as OpenEXR"),
    ] {
        let o = heron(&["info", path.to_str().unwrap()]);
        assert_eq!(o.status.code(), Some(1));
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(
            err.contains(path.to_str().unwrap()) && err.contains(expect),
            "{err}"
        );
    }
}
