//! Checkpoints and interruption (issue 10, part 4), with real processes: a render killed
//! with SIGKILL after a checkpoint resumes to the same bytes as a render never
//! interrupted (Whitted and a splatting integrator); SIGINT finishes the pass, writes a
//! valid image of the samples so far and exits with 130; `--time-limit` stops at a pass
//! boundary with status 0; a checkpoint of other settings, a corrupt one and bad numbers
//! are one-line errors. Nothing here is timed: the tests wait for files to appear.
mod common;

use common::cli::{heron, heron_command, scene_path};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

fn render_args<'a>(scene: &'a str, out: &'a str, spp: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut a = vec![
        "render", scene, "-o", out, "--spp", spp, "--quiet", "--no-png",
    ];
    a.extend_from_slice(extra);
    a
}

/// Starts a render and waits until its first checkpoint exists (the render is then
/// mid-way: the checkpoint is written only at pass boundaries before the last pass).
fn start_until_checkpoint(args: &[&str], checkpoint: &Path) -> Child {
    let mut child = heron_command()
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn heron");
    // Bounded so a broken build fails instead of hanging (about 2 minutes).
    for _ in 0..12_000 {
        if checkpoint.exists() {
            return child;
        }
        if let Some(status) = child.try_wait().unwrap() {
            panic!(
                "heron exited ({status}) before writing {}",
                checkpoint.display()
            );
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    child.kill().ok();
    panic!("no checkpoint appeared");
}

fn info_spp(exr: &Path) -> u32 {
    let o = heron(&["info", exr.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8(o.stdout).unwrap();
    text.lines()
        .find_map(|l| l.strip_prefix("spp: "))
        .unwrap_or_else(|| panic!("{text}"))
        .parse()
        .unwrap()
}

fn killed_and_resumed_equals_uninterrupted(scene_name: &str, spp: &str, extra: &[&str]) {
    let d = tempfile::tempdir().unwrap();
    let p = |n: &str| -> PathBuf { d.path().join(n) };
    let (full, resumed, ck) = (p("full.exr"), p("resumed.exr"), p("render.ckpt"));
    let sc = scene_path(scene_name);
    let o = heron(&render_args(&sc, full.to_str().unwrap(), spp, extra));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));

    let mut args = render_args(&sc, resumed.to_str().unwrap(), spp, extra);
    args.extend_from_slice(&[
        "--checkpoint",
        ck.to_str().unwrap(),
        "--checkpoint-every",
        "0",
    ]);
    let mut child = start_until_checkpoint(&args, &ck);
    child.kill().unwrap(); // SIGKILL: no chance to clean up
    child.wait().unwrap();
    assert!(!resumed.exists(), "a killed render left an image");

    let mut args = render_args(&sc, resumed.to_str().unwrap(), spp, extra);
    args.extend_from_slice(&["--resume", ck.to_str().unwrap()]);
    let o = heron(&args);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    let from: u32 = err
        .lines()
        .find_map(|l| l.strip_prefix("resumed from "))
        .and_then(|l| l.split(' ').next())
        .unwrap_or_else(|| panic!("{err}"))
        .parse()
        .unwrap();
    assert!(
        from > 0 && from < spp.parse().unwrap(),
        "resumed from {from}: {err}"
    );
    assert!(
        std::fs::read(&full).unwrap() == std::fs::read(&resumed).unwrap(),
        "{scene_name}: the resumed render differs from the uninterrupted one"
    );
}

#[test]
fn a_killed_whitted_render_resumes_to_the_same_bytes() {
    // 512² pixels: passes of 16 spp, so 64 spp is 4 passes.
    killed_and_resumed_equals_uninterrupted("default.toml", "64", &[]);
}

#[test]
fn a_killed_splatting_render_resumes_to_the_same_bytes() {
    // Light tracing splats into other pixels; 256² pixels: passes of 16 spp. With the
    // variance estimate, whose sums of squares the checkpoint keeps too.
    killed_and_resumed_equals_uninterrupted(
        "cornell-box.toml",
        "64",
        &["--integrator", "lighttrace", "--lanes", "4", "--variance"],
    );
}

#[test]
fn sigint_writes_what_it_has_and_exits_130() {
    let d = tempfile::tempdir().unwrap();
    let (out, ck, full) = (
        d.path().join("i.exr"),
        d.path().join("i.ckpt"),
        d.path().join("f.exr"),
    );
    let sc = scene_path("default.toml");
    // 64 spp at 512² is 4 passes; the signal arrives after the first.
    let mut args = render_args(&sc, out.to_str().unwrap(), "64", &[]);
    args.extend_from_slice(&[
        "--checkpoint",
        ck.to_str().unwrap(),
        "--checkpoint-every",
        "0",
    ]);
    let child = start_until_checkpoint(&args, &ck);
    let k = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(k.success());
    let o = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(130), "{err}");
    let spp = info_spp(&out);
    assert!(spp > 0 && spp < 64 && spp % 16 == 0, "{spp}");
    assert!(
        err.contains(&format!(
            "interrupted: the image holds {spp} of 64 spp per pixel"
        )),
        "{err}"
    );
    // The checkpoint written at the stop continues the same render.
    let o = heron(&render_args(&sc, full.to_str().unwrap(), "64", &[]));
    assert!(o.status.success());
    let resumed = d.path().join("r.exr");
    let mut args = render_args(&sc, resumed.to_str().unwrap(), "64", &[]);
    args.extend_from_slice(&["--resume", ck.to_str().unwrap()]);
    assert!(heron(&args).status.success());
    assert!(std::fs::read(&full).unwrap() == std::fs::read(&resumed).unwrap());
}

#[test]
fn a_time_limit_stops_at_a_pass_boundary() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("t.exr");
    let sc = scene_path("default.toml");
    let o = heron(&render_args(
        &sc,
        out.to_str().unwrap(),
        "64",
        &["--time-limit", "0"],
    ));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    // A limit of 0 s stops after the first pass: 16 spp at 512².
    assert_eq!(info_spp(&out), 16);
    assert!(
        err.contains("time limit reached: the image holds 16 of 64 spp per pixel"),
        "{err}"
    );
}

#[test]
fn bad_checkpoints_and_numbers_are_one_line_errors() {
    let d = tempfile::tempdir().unwrap();
    let (out, ck) = (d.path().join("o.exr"), d.path().join("c.ckpt"));
    let sc = scene_path("default.toml");
    // A checkpoint of a 32-spp render cannot continue a 48-spp one.
    let mut args = render_args(&sc, out.to_str().unwrap(), "32", &["--time-limit", "0"]);
    args.extend_from_slice(&["--checkpoint", ck.to_str().unwrap()]);
    assert!(heron(&args).status.success());
    assert!(ck.exists());
    let o = heron(&render_args(
        &sc,
        out.to_str().unwrap(),
        "48",
        &["--resume", ck.to_str().unwrap()],
    ));
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        err.contains("spp: \"32\" in the checkpoint, \"48\" in this render"),
        "{err}"
    );
    // Nor can a checkpoint without the variance's squares continue a render with it.
    let o = heron(&render_args(
        &sc,
        out.to_str().unwrap(),
        "32",
        &["--resume", ck.to_str().unwrap(), "--variance"],
    ));
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("the checkpoint was made without --variance, this render is with it"),
        "{err}"
    );
    // Truncated and foreign files name the file.
    let bytes = std::fs::read(&ck).unwrap();
    let bad = d.path().join("bad.ckpt");
    for content in [&bytes[..bytes.len() / 2], b"hello".as_slice()] {
        std::fs::write(&bad, content).unwrap();
        let o = heron(&render_args(
            &sc,
            out.to_str().unwrap(),
            "16",
            &["--resume", bad.to_str().unwrap()],
        ));
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(
            err.contains("bad.ckpt") && err.contains("not a heron checkpoint"),
            "{err}"
        );
    }
    for arg in [
        "--time-limit=-1",
        "--time-limit=nan",
        "--checkpoint-every=-2",
    ] {
        let mut extra = vec![arg];
        if arg.starts_with("--checkpoint-every") {
            extra.extend_from_slice(&["--checkpoint", ck.to_str().unwrap()]);
        }
        let o = heron(&render_args(&sc, out.to_str().unwrap(), "4", &extra));
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{err}");
        let flag = arg.split('=').next().unwrap();
        assert!(
            err.contains(flag) && err.contains("expected a finite number"),
            "{err}"
        );
    }
}
