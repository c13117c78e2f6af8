//! `heron bench traversal`: every width traces the same rays as the raw-Embree C program
//! it builds (the benchmark itself refuses to report when any pass finds different hits:
//! count, primitive IDs and distances), the table has a row per ray set and width, and
//! bad flags get one-line errors. Nothing here is timed; the figures are in
//! BENCHMARKS.md.
mod common;

use common::cli::heron;
use std::path::PathBuf;

fn small_mesh(name: &str) -> PathBuf {
    let p = std::env::temp_dir().join(format!("heron-bench-{}-{name}.obj", std::process::id()));
    let out = heron(&["bench", "mesh", "-o", p.to_str().unwrap(), "--n", "40"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    p
}

#[test]
fn raw_embree_finds_the_same_hits_at_every_width() {
    let mesh = small_mesh("raw");
    let out = heron(&[
        "bench",
        "traversal",
        "--mesh",
        mesh.to_str().unwrap(),
        "--eye",
        "0,0.3,3",
        "--look-at",
        "0,0,0",
        "--fov",
        "45",
        "--size",
        "37,29",
        "--rounds",
        "1",
        "--raw",
    ]);
    std::fs::remove_file(&mesh).ok();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}\n{stdout}",
        String::from_utf8_lossy(&out.stderr)
    );
    let rows: Vec<Vec<&str>> = stdout
        .lines()
        .filter(|l| l.starts_with("coherent,") || l.starts_with("incoherent,"))
        .map(|l| l.split(',').collect())
        .collect();
    assert_eq!(rows.len(), 10, "{stdout}");
    let stream_exists = heron::accel::embree::BINDINGS_MAJOR == 3;
    for r in &rows {
        // 37×29 camera rays, in 4×4 tiles, some hitting the mesh.
        if r[0] == "coherent" {
            assert_eq!(r[2], "1073", "{r:?}");
        }
        if r[1] == "stream" && !stream_exists {
            assert_eq!(&r[3..], ["-", "-", "-", "-"], "{r:?}");
        } else {
            let hit: f64 = r[3].parse().unwrap();
            assert!(hit > 0.0 && hit <= 100.0, "{r:?}");
            for v in &r[4..] {
                assert!(v.parse::<f64>().unwrap() > 0.0, "{r:?}");
            }
        }
    }
}

#[test]
fn bad_flags_are_one_line_errors() {
    let mesh = small_mesh("bad");
    let m = mesh.to_str().unwrap();
    let base = ["bench", "traversal", "--mesh", m, "--look-at", "0,0,0"];
    let run = |extra: &[&str]| {
        let mut a = base.to_vec();
        a.extend_from_slice(extra);
        heron(&a)
    };
    let out = run(&["--eye", "0,0,3", "--widths", "1,32"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--widths") && err.contains("expected 1, 4, 8, 16 or stream"),
        "{err}"
    );
    let out = run(&["--eye", "0,0,3", "--rounds", "0"]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--rounds"));
    let out = run(&["--eye", "0,0,0"]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--eye, --look-at"));
    std::fs::remove_file(&mesh).ok();
    let out = heron(&[
        "bench",
        "traversal",
        "--mesh",
        "/nonexistent/x.obj",
        "--eye",
        "0,0,3",
        "--look-at",
        "0,0,0",
    ]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("/nonexistent/x.obj"), "{err}");
}
