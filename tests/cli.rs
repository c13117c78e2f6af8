//! The `heron` binary: bad input gets a one-line error naming the file, key and
//! expectation, a non-zero exit and no output file; good input gives byte-identical
//! EXR files whatever the thread count.
mod common;

use common::cli::{heron, repo};
use std::path::{Path, PathBuf};
use std::process::Output;

const SMALL: &str = r#"
background = [0.1, 0.3, 0.6]
[camera]
eye = [2.0, 1.5, 2.0]
look_at = [0.0, 0.5, 0.0]
resolution = [48, 40]
[render]
spp = 2
[materials.white]
type = "lambertian"
rho_d = [0.8, 0.8, 0.8]
[materials.glass]
type = "dielectric"
ior = 1.5
[[shapes]]
type = "plane"
point = [0.0, 0.0, 0.0]
normal = [0.0, 1.0, 0.0]
material = "white"
[[shapes]]
type = "sphere"
center = [0.0, 0.5, 0.0]
radius = 0.3
material = "glass"
[[lights]]
type = "point"
position = [0.0, 1.0, 0.0]
intensity = 3.14159265
"#;

fn write_scene(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// Asserts failure with a single-line message containing every `needle`, and that the
/// folder holds no file but the scene.
fn assert_bad(dir: &Path, args: &[&str], needles: &[&str]) {
    let out = heron(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{args:?} succeeded");
    assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
    assert!(!err.contains("panicked"), "{args:?} panicked: {err}");
    let line = err.trim_end();
    assert_eq!(line.lines().count(), 1, "one line expected: {err}");
    for n in needles {
        assert!(line.contains(n), "{args:?}: {line:?} should mention {n:?}");
    }
    let outputs: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| !n.ends_with(".toml"))
        .collect();
    assert!(outputs.is_empty(), "{args:?} left files: {outputs:?}");
}

#[test]
fn bad_scenes_give_clear_errors_and_no_files() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("o.exr");
    let out = out.to_str().unwrap();
    let cases: &[(&str, &[&str])] = &[
        ("radius = 0.3", &["radius = -0.3"]),
        ("type = \"dielectric\"", &["type = \"glas\""]),
        ("spp = 2", &["colour = 2"]),
        ("ior = 1.5", &["ior = nan"]),
        ("resolution = [48, 40]", &["resolution = [24, 0]"]),
        ("material = \"glass\"", &["material = \"gold\""]),
    ];
    let expect: &[&[&str]] = &[
        &["shapes[1].radius", "-0.3"],
        &["materials.glass.type", "glas"],
        &["colour", "render"],
        &["materials.glass.ior"],
        &["camera.resolution"],
        &["shapes[1].material", "gold"],
    ];
    for ((from, to), needles) in cases.iter().zip(expect) {
        let text = SMALL.replacen(from, to[0], 1);
        assert_ne!(text, SMALL);
        let scene = write_scene(d.path(), "bad.toml", &text);
        let mut n: Vec<&str> = needles.to_vec();
        n.push("bad.toml");
        assert_bad(
            d.path(),
            &["render", scene.to_str().unwrap(), "-o", out],
            &n,
        );
    }
    let scene = write_scene(
        d.path(),
        "mesh.toml",
        &format!(
            "{SMALL}\n[[shapes]]\ntype = \"mesh\"\nfile = \"nowhere.obj\"\nmaterial = \"white\"\n"
        ),
    );
    assert_bad(
        d.path(),
        &["render", scene.to_str().unwrap(), "-o", out],
        &["nowhere.obj"],
    );
    // Beyond Embree's reach (a sphere big enough to be representable there).
    let far = SMALL
        .replacen("center = [0.0, 0.5, 0.0]", "center = [0.0, 3e18, 0.0]", 1)
        .replacen("radius = 0.3", "radius = 1e13", 1);
    let scene = write_scene(d.path(), "far.toml", &far);
    assert_bad(
        d.path(),
        &["render", scene.to_str().unwrap(), "-o", out],
        &["far.toml", "1e18"],
    );
    let scene = write_scene(d.path(), "syntax.toml", "[camera\neye = [1, 2, 3]\n");
    assert_bad(
        d.path(),
        &["render", scene.to_str().unwrap(), "-o", out],
        &["syntax.toml", "line"],
    );
    assert_bad(
        d.path(),
        &[
            "render",
            d.path().join("missing.toml").to_str().unwrap(),
            "-o",
            out,
        ],
        &["missing.toml"],
    );
}

#[test]
fn bad_flags_give_clear_errors_and_no_files() {
    let d = tempfile::tempdir().unwrap();
    let scene = write_scene(d.path(), "s.toml", SMALL);
    let s = scene.to_str().unwrap();
    let out = d.path().join("o.exr");
    let o = out.to_str().unwrap();
    let png = d.path().join("o.png");
    assert_bad(
        d.path(),
        &["render", s, "-o", png.to_str().unwrap()],
        &["--output", ".exr"],
    );
    assert_bad(d.path(), &["render", s, "-o", o, "--spp", "0"], &["--spp"]);
    assert_bad(
        d.path(),
        &["render", s, "-o", o, "--threads", "0"],
        &["--threads"],
    );
    assert_bad(
        d.path(),
        &["render", s, "-o", "/nonexistent/dir/x.exr"],
        &["does not exist"],
    );
}

#[test]
fn exr_bytes_do_not_depend_on_thread_count() {
    let d = tempfile::tempdir().unwrap();
    let scene = write_scene(d.path(), "s.toml", SMALL);
    let mut bytes = vec![];
    for t in ["1", "2", "5"] {
        let out = d.path().join(format!("t{t}.exr"));
        let r = heron(&[
            "render",
            scene.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--threads",
            t,
            "--quiet",
        ]);
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        let summary = String::from_utf8_lossy(&r.stderr);
        assert!(
            summary.contains("Mrays/s") && summary.contains("non-finite"),
            "{summary}"
        );
        assert!(d.path().join(format!("t{t}.png")).is_file());
        bytes.push(std::fs::read(&out).unwrap());
    }
    assert!(
        bytes[0] == bytes[1] && bytes[1] == bytes[2],
        "EXR bytes differ"
    );
}

#[test]
fn the_course_scenes_render() {
    let d = tempfile::tempdir().unwrap();
    for s in [
        "default",
        "default-mirror",
        "default-glass",
        "default-glossy",
        "cornell",
    ] {
        let out = d.path().join(format!("{s}.exr"));
        let r = heron(&[
            "render",
            &repo(&format!("scenes/{s}.toml")),
            "-o",
            out.to_str().unwrap(),
            "--spp",
            "1",
            "--quiet",
        ]);
        assert!(
            r.status.success(),
            "{s}: {}",
            String::from_utf8_lossy(&r.stderr)
        );
        assert!(out.is_file());
    }
}

#[test]
fn converge_reports_error_falling_with_samples() {
    let out = heron(&[
        "converge",
        &repo("scenes/default.toml"),
        "--size",
        "32,32",
        "--reference-spp",
        "256",
        "--spp",
        "1,64",
        "--lanes",
        "4",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    let rows: Vec<Vec<f64>> = text
        .lines()
        .filter(|l| l.starts_with(|c: char| c.is_ascii_digit()))
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 2, "{text}");
    let (e1, e64) = (rows[0][4], rows[1][4]);
    // Unbiased Monte Carlo: error ∝ 1/sqrt(spp), so 64× the samples should cut it by
    // about 8 (less, as the reference's own noise adds in); require at least 3.
    assert!(e1 > 3.0 * e64, "1 spp error {e1}, 64 spp error {e64}");
}

/// A point light of intensity 1e38 a millimetre above a sphere: the irradiance I/r²
/// overflows f32, so some samples are infinite. (Not 3e38, whose spectrum, D65 at Y = 1
/// times 3e38, is itself infinite and the scene loader rejects.)
const OVERFLOW: &str = r#"
[camera]
eye = [0.0, 0.0, 3.0]
look_at = [0.0, 0.0, 0.0]
resolution = [32, 24]
[materials.white]
type = "lambertian"
rho_d = 0.8
[[shapes]]
type = "sphere"
center = [0.0, 0.0, 0.0]
radius = 1.0
material = "white"
[[lights]]
type = "point"
position = [0.0, 0.0, 1.001]
intensity = 1.0e38
"#;

#[test]
fn check_finite_reports_the_count_and_first_location() {
    let d = tempfile::tempdir().unwrap();
    let scene = d.path().join("overflow.toml");
    std::fs::write(&scene, OVERFLOW).unwrap();
    let out = d.path().join("o.exr");
    let run = |extra: &[&str]| {
        let mut a = vec![
            "render",
            scene.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ];
        a.extend_from_slice(&["--spp", "2", "--quiet", "--no-png"]);
        a.extend_from_slice(extra);
        heron(&a)
    };
    let report = |o: &Output| {
        String::from_utf8_lossy(&o.stderr)
            .lines()
            .find(|l| l.starts_with("non-finite: "))
            .map(str::to_string)
    };
    // Without the flag: reported, status 0. With it: the image is still written and
    // the status is 3. The first location is the same whatever the thread count.
    let plain = run(&["--threads", "1"]);
    assert!(plain.status.success());
    let msg = report(&plain).expect("a non-finite report");
    assert!(
        msg.ends_with("left out of the image; the first at pixel (15, 11), sample 0"),
        "{msg}"
    );
    std::fs::remove_file(&out).unwrap();
    let checked = run(&["--threads", "2", "--check-finite"]);
    assert_eq!(checked.status.code(), Some(3));
    assert_eq!(report(&checked).as_deref(), Some(msg.as_str()));
    assert!(out.exists());
    // A scene without overflow passes the check silently.
    let fine = heron(&[
        "render",
        &repo("scenes/default.toml"),
        "-o",
        out.to_str().unwrap(),
        "--spp",
        "1",
        "--quiet",
        "--no-png",
        "--check-finite",
    ]);
    assert!(fine.status.success());
    assert_eq!(report(&fine), None);
}
