//! `heron compare` (issue 24, part 3), through the CLI and the library: two renders of
//! the Cornell box with different seeds agree (status 0), with the variance channels of
//! `heron render --variance` and with the spread within regions; a 3% change of the
//! white walls' reflectance is found (status 1); images that cannot be compared (sizes,
//! channels, unreadable files, bad options) give status 2 and a one-line message naming
//! the file; the heat map is written atomically. And the statistics: over many pure
//! noise comparisons the family-wise false-positive rate is α, as the correction
//! promises.
mod common;

use common::cli::heron;
use heron::compare::{compare, Correction, Image, Options};
use heron::math::rng::Rng;
use std::path::{Path, PathBuf};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The Cornell box at 64×64, with `replace` applied to its text, written into `dir`.
fn cornell(dir: &Path, name: &str, replace: Option<(&str, &str)>) -> PathBuf {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell-box.toml"),
    )
    .unwrap()
    .replace("resolution = [256, 256]", "resolution = [64, 64]");
    let text = match replace {
        Some((from, to)) => {
            assert!(text.contains(from), "{from}");
            text.replace(from, to)
        }
        None => text,
    };
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn render(scene: &Path, out: &Path, seed: &str, extra: &[&str]) {
    let mut a = vec![
        "render",
        s(scene),
        "-o",
        s(out),
        "--spp",
        "64",
        "--seed",
        seed,
        "--quiet",
        "--no-png",
    ];
    a.extend_from_slice(extra);
    let o = heron(&a);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// (status, stdout, stderr) of `heron compare`.
fn cmp(args: &[&str]) -> (i32, String, String) {
    let mut a = vec!["compare"];
    a.extend_from_slice(args);
    let o = heron(&a);
    (
        o.status.code().unwrap(),
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

#[test]
fn renders_agree_and_a_three_percent_change_is_found() {
    let d = tempfile::tempdir().unwrap();
    let p = |n: &str| d.path().join(n);
    let box_ = cornell(d.path(), "box.toml", None);
    // The white walls (floor, ceiling, back) 3% darker in every channel. (The red
    // wall alone is a column 8 pixels wide at 64×64, whose 3% change 64 spp do not
    // resolve with the Sobol' sampler's conservative variance: |z| 4.0 against 4.05;
    // at 256 spp it fails at z 5.4.)
    let darker = cornell(
        d.path(),
        "darker.toml",
        Some((
            "rho_d = [0.885809, 0.698859, 0.666422]",
            "rho_d = [0.859235, 0.677893, 0.646429]",
        )),
    );
    render(&box_, &p("a.exr"), "1", &["--variance"]);
    render(&box_, &p("b.exr"), "2", &["--variance"]);
    render(&darker, &p("c.exr"), "3", &["--variance"]);
    render(&box_, &p("plain.exr"), "4", &[]);
    // Same scene, other seeds: the same image, by the variance channels and by the
    // spread within regions (plain.exr has no variance channels).
    for (x, y, from) in [
        ("a.exr", "b.exr", "the variance channels of both images"),
        ("a.exr", "plain.exr", "the spread of the differences"),
    ] {
        let (code, out, err) = cmp(&[s(&p(x)), s(&p(y)), "--region", "8"]);
        assert_eq!(code, 0, "{x} vs {y}:\n{out}{err}");
        assert!(
            out.contains(from) && out.contains("verdict: same up to noise"),
            "{out}"
        );
        assert!(out.contains("failing regions: none"), "{out}");
    }
    // The darker walls: different, every failing region brighter in A (z > 0), on
    // the white walls (not the red and green walls' columns at the sides).
    let heat = p("heat.png");
    let (code, out, err) = cmp(&[
        s(&p("a.exr")),
        s(&p("c.exr")),
        "--region",
        "8",
        "--heatmap",
        s(&heat),
    ]);
    assert_eq!(code, 1, "{out}{err}");
    assert!(out.contains("verdict: different"), "{out}");
    let lines: Vec<&str> = out.lines().filter(|l| l.starts_with("  x ")).collect();
    assert!(!lines.is_empty(), "{out}");
    for l in &lines {
        // "  x 32-39, y 32-39 G: …, z +6.7, …".
        let x0: u32 = l[4..].split('-').next().unwrap().parse().unwrap();
        assert!((8..56).contains(&x0) && l.contains("z +"), "{l}\n{out}");
    }
    let png = image::open(&heat).unwrap().to_rgb8();
    assert_eq!(png.dimensions(), (64, 64));
    // Failing regions are outlined in black and filled red beyond the critical z (half
    // the colour scale, which saturates at twice it); no region is as blue (B brighter).
    assert!(png.pixels().any(|p| p.0 == [0, 0, 0]));
    assert!(png.pixels().any(|p| p.0[0] == 255 && p.0[2] < 128));
    assert!(!png.pixels().any(|p| p.0[2] == 255 && p.0[0] < 128));
    let leftover: Vec<_> = std::fs::read_dir(d.path())
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().ends_with(".tmp"))
        .collect();
    assert!(leftover.is_empty(), "temporary files left: {leftover:?}");
    // The library gives the same verdict and statistics as the CLI prints.
    let (a, c) = (
        Image::read_exr(&p("a.exr")).unwrap(),
        Image::read_exr(&p("c.exr")).unwrap(),
    );
    let r = compare(
        &a,
        &c,
        &Options {
            region: 8,
            ..Options::default()
        },
    )
    .unwrap();
    assert!(!r.same());
    assert_eq!(
        r.report(s(&p("a.exr")), s(&p("c.exr")), 20),
        out,
        "the CLI prints the library's report"
    );
    // An equivalence margin: a 5% tolerance allows the 3% darker walls, a 1% one
    // leaves 2% for the noise to explain, which it cannot.
    for (tolerance, status) in [("0.05", 0), ("0.01", 1)] {
        let (code, out, err) = cmp(&[
            s(&p("a.exr")),
            s(&p("c.exr")),
            "--region",
            "8",
            "--tolerance",
            tolerance,
        ]);
        assert_eq!(code, status, "--tolerance {tolerance}: {out}{err}");
        assert!(
            out.contains(&format!("tolerance {tolerance}: differences within")),
            "{out}"
        );
    }
    let (code, _, err) = cmp(&[s(&p("a.exr")), s(&p("c.exr")), "--tolerance", "1.5"]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("--tolerance: expected a relative margin in [0, 1)"),
        "{err}"
    );
}

#[test]
fn images_that_cannot_be_compared_exit_2_naming_the_file() {
    let d = tempfile::tempdir().unwrap();
    let p = |n: &str| d.path().join(n);
    let box_ = cornell(d.path(), "box.toml", None);
    let small = cornell(
        d.path(),
        "small.toml",
        Some(("resolution = [64, 64]", "resolution = [32, 32]")),
    );
    render(&box_, &p("a.exr"), "1", &[]);
    render(&small, &p("small.exr"), "1", &[]);
    let one_line = |args: &[&str], want: &[&str]| {
        let (code, out, err) = cmp(args);
        assert_eq!(code, 2, "{args:?}: {out}{err}");
        assert_eq!(err.lines().count(), 1, "{err}");
        for w in want {
            assert!(err.contains(w), "{args:?}: expected {w:?} in: {err}");
        }
        assert!(out.is_empty(), "{out}");
    };
    one_line(
        &[s(&p("a.exr")), s(&p("small.exr"))],
        &[
            "a.exr",
            "small.exr",
            "64x64",
            "32x32",
            "expected the same size",
        ],
    );
    one_line(
        &[s(&p("a.exr")), s(&p("missing.exr"))],
        &["missing.exr", "cannot read it as OpenEXR"],
    );
    std::fs::write(p("junk.exr"), b"not an image").unwrap();
    one_line(&[s(&p("junk.exr")), s(&p("a.exr"))], &["junk.exr"]);
    // An EXR without R, G, B: its X, Y, Z only.
    let xyz = p("xyz.exr");
    {
        use exr::prelude::*;
        let ch = |n: &str| AnyChannel::new(n, FlatSamples::F32(vec![0.5f32; 64 * 64]));
        let list: SmallVec<[AnyChannel<FlatSamples>; 4]> =
            [ch("X"), ch("Y"), ch("Z")].into_iter().collect();
        let layer = Layer::new(
            (64, 64),
            LayerAttributes::default(),
            Encoding::FAST_LOSSLESS,
            AnyChannels::sort(list),
        );
        exr::prelude::Image::from_layer(layer)
            .write()
            .to_file(&xyz)
            .unwrap();
    }
    one_line(
        &[s(&p("a.exr")), s(&xyz)],
        &["xyz.exr", "no R, G and B channels", "X, Y, Z"],
    );
    // Bad options: status 2 too (1 means "different").
    one_line(
        &[s(&p("a.exr")), s(&p("a.exr")), "--alpha", "1.5"],
        &["--alpha", "between 0 and 1"],
    );
    one_line(
        &[s(&p("a.exr")), s(&p("a.exr")), "--region", "0"],
        &["--region"],
    );
    one_line(
        &[s(&p("a.exr")), s(&p("a.exr")), "--correction", "holm"],
        &["--correction"],
    );
    one_line(
        &[s(&p("a.exr")), s(&p("a.exr")), "--heatmap", s(&p("h.jpg"))],
        &["--heatmap", ".png"],
    );
    // An image against itself: nothing to test, the same.
    let (code, out, _) = cmp(&[s(&p("a.exr")), s(&p("a.exr"))]);
    assert_eq!(code, 0, "{out}");
    // A render with --variance needs 2 samples per pixel.
    let o = heron(&[
        "render",
        s(&box_),
        "-o",
        s(&p("one.exr")),
        "--spp",
        "1",
        "--variance",
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--variance: needs at least 2"));
}

/// Pure noise against pure noise: the family of region tests must call two images of the
/// same mean different with probability α, no more (else the tool cries wolf) and, for
/// Šidák's correction over independent tests, not much less (else it wastes power).
///
/// 2 000 comparisons of 64×48 images in regions of 8 (48 regions × 3 channels + 3
/// whole-image tests = 147 tests each) at α = 0.05, for each estimator: 100 false
/// positives are expected, with a binomial standard deviation of √(2000 · 0.05 · 0.95)
/// ≈ 9.7, so 70–130 holds with probability 0.998 for a correct test, while an error of
/// the critical value by 10% (|z| 3.6 instead of 4.0) would roughly double the rate and
/// fail it. The whole-image tests are not independent of the regions', which can only
/// lower the rate a little. The images are seeded, so the count is the same every run.
/// Bonferroni's correction is at most α by construction, and near it here.
#[test]
fn pure_noise_is_called_different_at_the_rate_alpha() {
    let (w, h) = (64u32, 48u32);
    let n = (w * h) as usize;
    let gauss = |r: &mut Rng| {
        // Box–Muller, in f64 for the tails.
        let (u1, u2) = (r.uniform() as f64, r.uniform() as f64);
        ((-2.0 * (1.0 - u1).ln()).sqrt() * (std::f64::consts::TAU * u2).cos()) as f32
    };
    let image = |r: &mut Rng, variance: bool| {
        // An image with detail (a ramp and a bright square) and per-pixel noise whose
        // σ varies over the image, as a render's does.
        let mut values = Vec::with_capacity(n);
        let mut var = Vec::with_capacity(n);
        for i in 0..n {
            let (x, y) = (i as u32 % w, i as u32 / w);
            let base = 0.2 + x as f32 / w as f32 + if (20..30).contains(&y) { 2.0 } else { 0.0 };
            let sigma = 0.05 + 0.1 * base;
            values.push(std::array::from_fn(|_| base + sigma * gauss(r)));
            var.push([sigma * sigma; 3]);
        }
        Image::new(
            "noise",
            w,
            h,
            ["R", "G", "B"],
            values,
            variance.then_some(var),
        )
        .unwrap()
    };
    let runs = 2000;
    for (variance, correction) in [
        (true, Correction::Sidak),
        (false, Correction::Sidak),
        (true, Correction::Bonferroni),
    ] {
        let mut r = Rng::new(17, variance as u64);
        let o = Options {
            region: 8,
            alpha: 0.05,
            correction,
            mask: None,
            tolerance: 0.0,
        };
        let mut false_positives = 0;
        for _ in 0..runs {
            let (a, b) = (image(&mut r, variance), image(&mut r, variance));
            let c = compare(&a, &b, &o).unwrap();
            assert_eq!(c.tests(), 147);
            false_positives += (!c.same()) as u32;
        }
        eprintln!(
            "variance channels {variance}, {correction:?}: {false_positives} of {runs} called different"
        );
        assert!(
            (70..=130).contains(&false_positives),
            "variance channels {variance}, {correction:?}: {false_positives} of {runs} noise pairs called different at α = 0.05"
        );
    }
}
