//! Sharded rendering (issue 11, part 2), through the CLI: `heron render --shard K/N -o
//! part.heronfilm` for every K and `heron merge` give the EXR and PNG of one `heron
//! render` with all the samples, byte for byte, for any N, any order of the parts, any
//! thread count per part, and every integrator (the splatting ones too); with the XYZ
//! and spectral channels, and the variance channels (`--variance`: sums of squares, as
//! exact as the sums). Merging refuses a missing, repeated, foreign, incomplete or
//! differently split part, or parts with and without `--variance`, with a one-line
//! message naming it.
mod common;

use common::cli::{heron, heron_ok, scene_path};
use std::path::{Path, PathBuf};

/// The one-line error of a failing command.
fn fails(args: &[&str]) -> String {
    let o = heron(args);
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(o.status.code(), Some(1), "heron {}: {err}", args.join(" "));
    assert_eq!(err.lines().count(), 1, "{err}");
    err
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Renders `scene` once whole and as `n` shards (shard k on k % 2 + 1 threads), merges
/// the parts in the order `order`, and asserts the merged EXR and PNG equal the whole
/// render's bytes.
fn merged_equals_whole(dir: &Path, scene: &str, settings: &[&str], n: u32, order: &[u32]) {
    let whole = dir.join(format!("whole-{n}.exr"));
    let mut a = vec!["render", scene, "-o", s(&whole), "--quiet"];
    a.extend_from_slice(settings);
    heron_ok(&a);
    let parts: Vec<PathBuf> = (0..n)
        .map(|k| dir.join(format!("part-{k}-of-{n}.heronfilm")))
        .collect();
    for k in 0..n {
        let (shard, threads) = (format!("{k}/{n}"), format!("{}", k % 2 + 1));
        let mut a = vec!["render", scene, "-o", s(&parts[k as usize]), "--quiet"];
        a.extend_from_slice(&["--shard", &shard, "--threads", &threads]);
        a.extend_from_slice(settings);
        heron_ok(&a);
    }
    let merged = dir.join(format!("merged-{n}.exr"));
    let mut a = vec!["merge", "-o", s(&merged)];
    a.extend(order.iter().map(|&k| s(&parts[k as usize])));
    heron_ok(&a);
    for ext in ["exr", "png"] {
        let (x, y) = (whole.with_extension(ext), merged.with_extension(ext));
        assert!(
            std::fs::read(&x).unwrap() == std::fs::read(&y).unwrap(),
            "{scene} {settings:?}, {n} shards in order {order:?}: the merged {ext} differs from one render's"
        );
    }
}

#[test]
fn whitted_shards_merge_to_the_bytes_of_one_render() {
    let d = tempfile::tempdir().unwrap();
    let sc = scene_path("default.toml");
    let set = ["--spp", "6", "--xyz", "--spectral-bins", "7"];
    merged_equals_whole(d.path(), &sc, &set, 1, &[0]);
    merged_equals_whole(d.path(), &sc, &set, 2, &[1, 0]);
    merged_equals_whole(d.path(), &sc, &set, 4, &[2, 0, 3, 1]);
    // More shards than samples: two of the eight hold none.
    merged_equals_whole(d.path(), &sc, &set, 8, &[7, 6, 5, 4, 3, 2, 1, 0]);
    let var = ["--spp", "6", "--xyz", "--variance"];
    merged_equals_whole(d.path(), &sc, &var, 3, &[1, 2, 0]);
}

/// Path tracing, light tracing and BDPT on the Cornell box (light tracing and BDPT
/// splat into other pixels, which the shards sum separately), without and with the
/// variance estimate (whose splats' squares the shards also sum separately).
#[test]
fn physically_based_shards_merge_to_the_bytes_of_one_render() {
    let d = tempfile::tempdir().unwrap();
    let sc = scene_path("cornell-box.toml");
    for (integrator, variance) in [
        ("path", false),
        ("lighttrace", false),
        ("bdpt", false),
        ("path", true),
        ("bdpt", true),
    ] {
        let mut set = vec![
            "--spp",
            "5",
            "--integrator",
            integrator,
            "--spectral-bins",
            "4",
            "--lanes",
            "4",
        ];
        if variance {
            set.push("--variance");
        }
        merged_equals_whole(d.path(), &sc, &set, 3, &[2, 0, 1]);
    }
}

/// Polarised renders (their Stokes sums and, with spectral bins, Stokes bins) merge to
/// the bytes of one render too, under the path tracer and the Whitted tracer (with the
/// camera's analyser). The EXR holds S0–S3 per bin; the DoLP and AoLP previews are written
/// beside the PNG of both.
#[test]
fn polarised_shards_merge_to_the_bytes_of_one_render() {
    let d = tempfile::tempdir().unwrap();
    let set = [
        "--spp",
        "3",
        "--spectral-bins",
        "5",
        "--lanes",
        "4",
        "--xyz",
    ];
    merged_equals_whole(d.path(), &scene_path("brewster.toml"), &set, 3, &[1, 2, 0]);
    let mut w = set.to_vec();
    w.extend_from_slice(&["--integrator", "whitted", "--polarizer", "30"]);
    merged_equals_whole(d.path(), &scene_path("brewster.toml"), &w, 2, &[1, 0]);
    for which in ["dolp", "aolp"] {
        let (x, y) = (
            d.path().join(format!("whole-2.{which}.png")),
            d.path().join(format!("merged-2.{which}.png")),
        );
        assert!(
            std::fs::read(&x).unwrap() == std::fs::read(&y).unwrap(),
            "the merged {which} preview differs"
        );
    }
    // Polarised light tracing and BDPT splat Stokes radiance (their films keep the
    // splats' S1–S3 and bins): a rough gold floor under a linearly polarised spot,
    // whose light it reflects to the camera still polarised.
    let sc = d.path().join("rough-gold.toml");
    std::fs::write(
        &sc,
        "[camera]\neye = [0.0, 2.0, 3.0]\nlook_at = [0.0, 0.0, 0.0]\nd = 1.5\nresolution = [24, 16]\n\
[render]\npolarization = true\nmax_depth = 3\n\
[materials.gold]\ntype = \"conductor\"\nmetal = \"Au\"\nroughness = 0.3\n\
[[shapes]]\ntype = \"quad\"\norigin = [-2.0, 0.0, 2.0]\nedge1 = [4.0, 0.0, 0.0]\nedge2 = [0.0, 0.0, -4.0]\nmaterial = \"gold\"\n\
[[lights]]\ntype = \"spot\"\nposition = [-1.0, 2.0, -1.0]\ndirection = [0.4, -1.0, 0.4]\nintensity = 6.0\ncone_angle = 60.0\n\
polarization = { axis = [1.0, 0.0, 0.0], linear = 0.8, circular = 0.3 }\n",
    )
    .unwrap();
    for integrator in ["lighttrace", "bdpt"] {
        let dir = d.path().join(integrator);
        std::fs::create_dir(&dir).unwrap();
        let mut w = set.to_vec();
        w.extend_from_slice(&["--integrator", integrator, "--variance"]);
        merged_equals_whole(&dir, s(&sc), &w, 3, &[2, 0, 1]);
    }
}

/// A shard stopped early (here by a time limit of zero: one pass) writes a film that
/// --resume finishes; the merge refuses it before that and equals one render after.
#[test]
fn a_stopped_shard_resumes_and_then_merges() {
    let d = tempfile::tempdir().unwrap();
    let p = |n: &str| d.path().join(n);
    let sc = scene_path("cornell-box.toml");
    // Splatting passes of 2²⁰ pixel samples: 16 spp per pass at 256², so 64 spp
    // split in two gives shards of 32 spp, two passes each.
    let set = ["--spp", "64", "--integrator", "lighttrace", "--quiet"];
    let whole = p("whole.exr");
    let mut a = vec!["render", &sc, "-o", s(&whole), "--no-png"];
    a.extend_from_slice(&set);
    heron_ok(&a);
    let (p0, p1) = (p("p0.heronfilm"), p("p1.heronfilm"));
    for (k, part) in [("0/2", &p0), ("1/2", &p1)] {
        let mut a = vec!["render", &sc, "-o", s(part), "--shard", k];
        a.extend_from_slice(&set);
        if k == "1/2" {
            a.extend_from_slice(&["--time-limit", "0"]);
        }
        heron_ok(&a);
    }
    let merged = p("merged.exr");
    let err = fails(&["merge", s(&p0), s(&p1), "-o", s(&merged), "--no-png"]);
    assert!(
        err.contains("p1.heronfilm")
            && err.contains("shard 1/2 is incomplete: it holds 16 of its 32 samples per pixel"),
        "{err}"
    );
    assert!(!merged.exists(), "a failed merge left an image");
    let mut a = vec!["render", &sc, "-o", s(&p1), "--shard", "1/2"];
    a.extend_from_slice(&["--resume", s(&p1)]);
    a.extend_from_slice(&set);
    heron_ok(&a);
    heron_ok(&["merge", s(&p1), s(&p0), "-o", s(&merged), "--no-png"]);
    assert!(std::fs::read(&whole).unwrap() == std::fs::read(&merged).unwrap());
    // Resuming a film as another shard is refused.
    let mut a = vec!["render", &sc, "-o", s(&p1), "--shard", "0/2"];
    a.extend_from_slice(&["--resume", s(&p1)]);
    a.extend_from_slice(&set);
    let err = fails(&a);
    assert!(
        err.contains("the checkpoint holds shard 1/2, this render shard 0/2"),
        "{err}"
    );
}

#[test]
fn merge_names_the_missing_repeated_or_foreign_part() {
    let d = tempfile::tempdir().unwrap();
    let p = |n: &str| d.path().join(n);
    let sc = scene_path("default.toml");
    let render = |out: &Path, shard: &str, extra: &[&str]| {
        let mut a = vec!["render", &sc, "-o", s(out), "--quiet", "--spp", "3"];
        a.extend_from_slice(&["--shard", shard]);
        a.extend_from_slice(extra);
        heron_ok(&a);
    };
    let parts: Vec<PathBuf> = (0..3).map(|k| p(&format!("p{k}.heronfilm"))).collect();
    for (k, part) in parts.iter().enumerate() {
        render(part, &format!("{k}/3"), &[]);
    }
    let out = p("out.exr");
    let merge = |files: &[&Path]| {
        let mut a = vec!["merge", "-o", s(&out)];
        a.extend(files.iter().map(|f| s(f)));
        fails(&a)
    };
    let err = merge(&[&parts[2], &parts[0]]);
    assert!(err.contains("missing shard 1/3"), "{err}");
    let err = merge(&[&parts[0], &parts[1], &parts[1], &parts[2]]);
    assert!(
        err.contains("p1.heronfilm: is shard 1/3, and so is"),
        "{err}"
    );
    // Another seed: a foreign part, named with the setting that differs.
    let foreign = p("foreign.heronfilm");
    render(&foreign, "1/3", &["--seed", "99"]);
    let err = merge(&[&parts[0], &foreign, &parts[2]]);
    assert!(
        err.contains("foreign.heronfilm: is from another render (seed: \"99\" here, \"1\" in")
            || err.contains("foreign.heronfilm: is from another render (seed: \"99\" here"),
        "{err}"
    );
    // The same shard with --variance: its film keeps squares the others lack.
    let var = p("var.heronfilm");
    render(&var, "1/3", &["--variance"]);
    let err = merge(&[&parts[0], &var, &parts[2]]);
    assert!(
        err.contains("var.heronfilm: was rendered with --variance")
            && err.contains("p0.heronfilm without it"),
        "{err}"
    );
    // Another split of the same render.
    let half = p("half.heronfilm");
    render(&half, "1/2", &[]);
    let err = merge(&[&parts[0], &half]);
    assert!(
        err.contains("half.heronfilm: is shard 1/2, but") && err.contains("a shard of 3"),
        "{err}"
    );
    // Not a film file; a wrong extension; an image output for a shard.
    let junk = p("junk.heronfilm");
    std::fs::write(&junk, b"hello").unwrap();
    let err = merge(&[&junk]);
    assert!(
        err.contains("junk.heronfilm") && err.contains("not a heron film file"),
        "{err}"
    );
    let err = fails(&["merge", s(&parts[0]), "-o", s(&p("out.png"))]);
    assert!(err.contains("expected a path ending in .exr"), "{err}");
    let err = fails(&["render", &sc, "-o", s(&out), "--shard", "0/3"]);
    assert!(
        err.contains("--shard 0/3: expected --output to end in .heronfilm"),
        "{err}"
    );
    let err = fails(&["render", &sc, "-o", s(&parts[0]), "--shard", "3/3"]);
    assert!(err.contains("expected K/N with 0 <= K < N"), "{err}");
    assert!(!out.exists(), "a failed merge left an image");
}
