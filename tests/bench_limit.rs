//! `heron bench record`, `replay` and `limit`: the ray log holds every ray a render
//! traced (as many as the render counted), in the same order on every run, recording
//! leaves the image as it was, replays through the raw-Embree C program and through
//! heron's wrapper find exactly what the render found (hits, primitive IDs, distances,
//! occlusions), and bad logs get one-line errors naming the file. Nothing here is timed;
//! the figures are in BENCHMARKS.md.
mod common;

use common::cli::heron;
use std::path::{Path, PathBuf};
use std::process::Output;

use heron::bench::limit::RayLogFile;
use heron::render::{RenderOptions, Renderer};

/// Spheres, a plane (two triangles), a triangle and a glass sphere under a point light:
/// camera packets, shadow rays, and (under `path`) single closest-hit rays.
const SCENE: &str = r#"
background = [0.1, 0.3, 0.6]
[camera]
eye = [2.0, 1.5, 2.0]
look_at = [0.0, 0.5, 0.0]
resolution = [27, 21]
[render]
spp = 2
max_depth = 4
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
type = "triangle"
vertices = [[-0.2, 0.1, 0.9], [0.2, 0.1, 0.9], [-0.2, 0.1, -0.1]]
material = "white"
[[shapes]]
type = "sphere"
center = [0.0, 0.5, 0.0]
radius = 0.3
material = "glass"
[[shapes]]
type = "sphere"
center = [0.6, 0.2, -0.3]
radius = 0.2
material = "white"
[[lights]]
type = "point"
position = [0.0, 1.0, 0.0]
intensity = 3.14159265
"#;

struct Dir(PathBuf);

impl Dir {
    fn new(name: &str) -> Dir {
        let d = std::env::temp_dir().join(format!("heron-limit-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        std::fs::write(d.join("scene.toml"), SCENE).unwrap();
        Dir(d)
    }
    fn path(&self, f: &str) -> String {
        self.0.join(f).display().to_string()
    }
}

impl Drop for Dir {
    fn drop(&mut self) {
        std::fs::remove_dir_all(&self.0).ok();
    }
}

fn ok(out: &Output) -> String {
    let stdout = String::from_utf8_lossy(&out.stdout).to_string();
    assert!(
        out.status.success(),
        "{}\n{stdout}",
        String::from_utf8_lossy(&out.stderr)
    );
    stdout
}

/// The number after `key ` in `text`.
fn number(text: &str, key: &str) -> u64 {
    let at = text
        .find(key)
        .unwrap_or_else(|| panic!("{key:?} in {text}"))
        + key.len();
    text[at..]
        .trim_start()
        .split(|c: char| !c.is_ascii_digit())
        .next()
        .unwrap()
        .parse()
        .unwrap_or_else(|_| panic!("a number after {key:?} in {text}"))
}

#[test]
fn the_log_holds_every_ray_the_render_counted_and_replays_find_the_same() {
    let d = Dir::new("record");
    for integrator in ["whitted", "path"] {
        let log = d.path(&format!("{integrator}.rays"));
        let args = [
            "bench",
            "record",
            &d.path("scene.toml"),
            "--integrator",
            integrator,
            "-o",
            &log,
        ];
        let out = ok(&heron(&args));
        let rays = number(&out, "\nrays");
        assert_eq!(rays, number(&out, "the render counted"), "{out}");
        // 27×21 pixels × 2 spp camera rays, plus shadow rays (and bounces).
        assert!(rays > 2 * 27 * 21, "{out}");
        assert!(
            number(&out, "hits") > 0 && number(&out, "occluded") > 0,
            "{out}"
        );
        // One thread: the same calls in the same order every time.
        let again = d.path("again.rays");
        let mut args2 = args;
        args2[6] = &again;
        ok(&heron(&args2));
        assert_eq!(std::fs::read(&log).unwrap(), std::fs::read(&again).unwrap());

        // The replay refuses to report unless the raw program's and heron's tallies equal
        // the recorded render's, so success is the check; the kinds of call are listed.
        let out = ok(&heron(&["bench", "replay", &log, "--rounds", "1"]));
        // `whitted` runs packets of paths (`--packets auto`): every ray in an 8-wide
        // call; `path` one path at a time: camera packets, single rays after them.
        let calls: &[&str] = if integrator == "path" {
            &["intersect8 ", "intersect1 ", "occluded1 "]
        } else {
            &["intersect8 ", "occluded8 "]
        };
        for call in calls {
            assert!(out.contains(call), "{call}: {out}");
        }
        assert_eq!(number(&out, "; rays"), rays, "{out}");
        for row in ["heron_replay,", "raw_replay,"] {
            assert!(out.lines().any(|l| l.starts_with(row)), "{out}");
        }
    }
}

#[test]
fn recording_leaves_the_image_as_it_was_and_tallies_what_embree_found() {
    let scene =
        heron::scene::load::load_scene_from_str(SCENE, Path::new("scene.toml")).expect("scene");
    let mut opts = RenderOptions::from_scene(&scene);
    opts.threads = 1;
    let plain = Renderer::new(&scene).unwrap();
    let (want, want_stats) = plain.render(&opts).unwrap();
    assert!(plain.accel().take_recording().is_none());

    let recorded = Renderer::new(&scene).unwrap();
    recorded.accel().record();
    let (got, stats) = recorded.render(&opts).unwrap();
    assert_eq!(got, want, "recording changed the image");
    let log = recorded.accel().take_recording().unwrap();
    assert_eq!(log.tally.rays, stats.total_rays());
    assert_eq!(stats.total_rays(), want_stats.total_rays());

    // The log's tally is what heron's own queries find when they make the calls again.
    let file = RayLogFile::new(&scene, log);
    let (back, calls, rays) = RayLogFile::parse(&file.to_bytes()).expect("own log");
    assert_eq!(back.geometry, file.geometry);
    assert_eq!(back.log.calls, file.log.calls);
    let device = heron::accel::embree::Device::new("").unwrap();
    let accel = heron::bench::limit::build_scene(&device, &back.geometry).unwrap();
    let mut scratch = heron::accel::embree::StreamScratch::default();
    let replayed = heron::bench::limit::replay_heron(&accel, &calls, &rays, &mut scratch).unwrap();
    assert!(
        heron::bench::limit::same_tally(&replayed, &file.log.tally),
        "{replayed:?} vs {:?}",
        file.log.tally
    );
    assert!(file.log.tally.hits > 0 && file.log.tally.occluded > 0);
    // A replay that finds something else is caught.
    let mut off = replayed;
    off.prim_sum += 1;
    assert!(!heron::bench::limit::same_tally(&off, &file.log.tally));

    // Recording goes on into an empty log after a take.
    assert_eq!(
        recorded.accel().take_recording().unwrap().tally,
        Default::default()
    );
}

#[test]
fn bad_logs_get_one_line_errors_naming_the_file() {
    let d = Dir::new("bad");
    let log = d.path("good.rays");
    ok(&heron(&[
        "bench",
        "record",
        &d.path("scene.toml"),
        "--spp",
        "1",
        "-o",
        &log,
    ]));
    let good = std::fs::read(&log).unwrap();
    let (file, _, _) = RayLogFile::parse(&good).expect("good log");
    // The calls start after the magic, the geometry count and each geometry.
    let calls_at = good.len() - 48 - file.log.calls.len();

    let mut cases: Vec<(&str, Vec<u8>, &str)> = Vec::new();
    cases.push((
        "magic",
        b"not a ray log at all".to_vec(),
        "not a heron ray log",
    ));
    cases.push((
        "truncated",
        good[..good.len() - 10].to_vec(),
        "48-byte tally",
    ));
    let mut b = good.clone();
    b[calls_at] = 3;
    cases.push(("op", b, "call 0: expected an op"));
    let mut b = good.clone();
    b[calls_at + 1] = 7;
    cases.push(("coherence", b, "call 0: expected a coherence flag"));
    let mut b = good.clone();
    // The first call is a camera packet: a NaN origin in its lane 0.
    b[calls_at + 8..calls_at + 12].copy_from_slice(&f32::NAN.to_le_bytes());
    cases.push(("nan", b, "call 0: ray 0 is not one Embree can trace"));
    let mut b = good.clone();
    let n = b.len();
    b[n - 48] ^= 1; // the tally's call count
    cases.push(("tally", b, "the tally counts"));
    let mut b = good.clone();
    b[16 + 4] = 9; // geometry 0's kind
    cases.push((
        "geometry",
        b,
        "geometry 0: expected kind 0 (mesh) or 1 (sphere)",
    ));

    for (name, bytes, needle) in &cases {
        let p = d.path(&format!("{name}.rays"));
        std::fs::write(&p, bytes).unwrap();
        let out = heron(&["bench", "replay", &p, "--rounds", "1"]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{name}: accepted");
        assert!(
            err.contains(&p) && err.contains(needle) && err.trim().lines().count() == 1,
            "{name}: {err}"
        );
    }
    let out = heron(&["bench", "replay", &d.path("missing.rays")]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("missing.rays") && err.contains("cannot read"));

    let out = heron(&[
        "bench",
        "record",
        &d.path("scene.toml"),
        "-o",
        &d.path("x.bin"),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("expected a path ending in .rays"),
        "{err}"
    );
    assert!(!Path::new(&d.path("x.bin")).exists());
}

#[test]
fn limit_times_the_render_against_the_replays() {
    let d = Dir::new("limit");
    let keep = d.path("kept.rays");
    let out = ok(&heron(&[
        "bench",
        "limit",
        &d.path("scene.toml"),
        "--rounds",
        "1",
        "--keep",
        &keep,
    ]));
    for row in ["heron_render,", "heron_replay,", "raw_replay,"] {
        let line = out
            .lines()
            .find(|l| l.starts_with(row))
            .unwrap_or_else(|| panic!("{row} in {out}"));
        let cells: Vec<f64> = line
            .split(',')
            .skip(1)
            .map(|c| c.parse().unwrap())
            .collect();
        assert_eq!(cells.len(), 4, "{line}");
        assert!(cells.iter().all(|&c| c > 0.0), "{line}");
    }
    assert_eq!(
        number(&out, "; rays"),
        number(&out, "the render counted"),
        "{out}"
    );
    // The kept log replays.
    ok(&heron(&["bench", "replay", &keep, "--rounds", "1"]));
    let out = heron(&[
        "bench",
        "limit",
        &d.path("scene.toml"),
        "--keep",
        &d.path("k.txt"),
    ]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--keep"));
}
