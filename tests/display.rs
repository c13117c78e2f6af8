//! Display transforms (src/spectrum/display.rs) and the progress image: Newton's spectrum
//! keeps a continuous hue under `--display hue` and breaks into plateaus under `clip`;
//! `heron display` re-encodes an EXR into the very PNG the render wrote and maps CSV rows
//! of XYZ; bad flags and files are one-line errors; `--preview-every` rewrites the PNG
//! during a render without changing the final outputs. Nothing here is timed.
mod common;

use common::cli::{heron, heron_ok};
use heron::render::{render, render_state, RenderOptions};
use heron::scene::load::load_scene_from_str;
use heron::scene::Scene;
use heron::spectrum::display::{DisplayMode, DisplayTransform};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::{Arc, Mutex};

fn scenes() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes")
}

/// A one-line error (status 1) containing `needle`.
fn fails(args: &[&str], needle: &str) {
    let o = heron(args);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "heron {}: {err}", args.join(" "));
    assert!(
        err.contains(needle) && err.trim().lines().count() == 1,
        "heron {}: expected one line naming {needle:?}, got {err}",
        args.join(" ")
    );
}

fn decode_png(path: &Path) -> (u32, u32, Vec<[u8; 3]>) {
    let img = image::open(path)
        .unwrap_or_else(|e| panic!("{}: not a PNG: {e}", path.display()))
        .to_rgb8();
    let (w, h) = img.dimensions();
    (w, h, img.pixels().map(|p| p.0).collect())
}

/// The sRGB decoding (IEC 61966-2-1) of an 8-bit code.
fn srgb_decode(v: u8) -> f64 {
    let c = v as f64 / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Newton's spectrum (scenes/newton-prism.toml at 256², 32 spp, the scene's D65 sun and
/// light tracing): the film, and its PNG under `hue` and under `clip`.
fn newton() -> (Scene, heron::film::Film) {
    let text = std::fs::read_to_string(scenes().join("newton-prism.toml"))
        .unwrap()
        .replace("resolution = [512, 512]", "resolution = [256, 256]");
    assert!(text.contains("[256, 256]"));
    let scene = load_scene_from_str(&text, &scenes().join("newton-prism.toml")).unwrap();
    let mut o = RenderOptions::from_scene(&scene);
    o.settings.spp = 32;
    o.settings.seed = 3;
    let (film, stats) = render(&scene, &o).unwrap();
    assert_eq!(stats.nonfinite, 0);
    (scene, film)
}

/// The hue of a linear sRGB colour as the CIE defines it, by its dominant wavelength:
/// the angle of its CIE 1931 chromaticity about D65's (0.3127, 0.3290), in degrees,
/// turned so that the spectrum runs without a wrap: 700 nm is about 51°, 600 nm 68°,
/// 500 nm 205°, 450 nm 303°, 400 nm 307°.
fn hue_xy(rgb: [f64; 3]) -> f64 {
    let m = heron::spectrum::color::SRGB_TO_XYZ;
    let xyz: [f64; 3] = std::array::from_fn(|i| (0..3).map(|j| m[i][j] as f64 * rgb[j]).sum());
    let s = xyz[0] + xyz[1] + xyz[2];
    let a = (xyz[1] / s - 0.3290)
        .atan2(xyz[0] / s - 0.3127)
        .to_degrees();
    (a - 300.0).rem_euclid(360.0)
}

/// Hue of the band, column by column from its red end: the hue ([`hue_xy`]) of the mean
/// linear colour over the band's rows (those whose brightest pixel has at least 30% of
/// the image's largest Y), for the film itself and for the PNG's decoded pixels; NaN
/// where the band is dark (its Y below 2% of the brightest column's).
fn band_hues(film: &heron::film::Film, png: &[[u8; 3]]) -> (Vec<f64>, Vec<f64>) {
    let (w, h) = (film.width as usize, film.height as usize);
    let y = |i: usize| film.xyz[i][1] as f64;
    let ymax = (0..w * h).map(y).fold(0.0, f64::max);
    let rows: Vec<usize> = (0..h)
        .filter(|&r| (0..w).map(|x| y(r * w + x)).fold(0.0, f64::max) >= 0.3 * ymax)
        .collect();
    assert!(rows.len() >= 8, "the band has {} rows", rows.len());
    let lin = film.linear_srgb();
    let col_y: Vec<f64> = (0..w)
        .map(|x| rows.iter().map(|&r| y(r * w + x)).sum::<f64>())
        .collect();
    let cmax = col_y.iter().cloned().fold(0.0, f64::max);
    let hue_of = |f: &dyn Fn(usize) -> [f64; 3]| -> Vec<f64> {
        (0..w)
            .map(|x| {
                if col_y[x] < 0.02 * cmax {
                    return f64::NAN;
                }
                let mut m = [0.0; 3];
                for &r in &rows {
                    let c = f(r * w + x);
                    for k in 0..3 {
                        m[k] += c[k] / rows.len() as f64;
                    }
                }
                hue_xy(m)
            })
            .collect()
    };
    let film_hue = hue_of(&|i| lin[i].map(f64::from));
    let png_hue = hue_of(&|i| png[i].map(srgb_decode));
    // Red (hue ≈ 51–68°) lies at the band's least deviated end: orient from it.
    let first_lit = film_hue.iter().position(|h| !h.is_nan()).unwrap();
    if film_hue[first_lit] > 180.0 {
        (
            film_hue.into_iter().rev().collect(),
            png_hue.into_iter().rev().collect(),
        )
    } else {
        (film_hue, png_hue)
    }
}

/// Columns over which the hue may stay within `PLATEAU_DEG` before it counts as a
/// plateau: at 256 px across, the film's own hue turns by about 1° per column or more
/// between 620 and 460 nm, so 3 columns are about 3° of real change.
const MAX_PLATEAU_COLUMNS: usize = 3;
const PLATEAU_DEG: f64 = 1.0;
/// Allowed backward step (noise of 32 spp, 8-bit rounding).
const MONOTONE_SLACK_DEG: f64 = 1.0;
/// The film's hues ([`hue_xy`]) of about 620 and 460 nm, between which the check runs.
const HUE_FROM: f64 = 57.0;
const HUE_TO: f64 = 300.0;

/// The columns from the first where the film's hue reaches [`HUE_FROM`] to the first
/// after it where it reaches [`HUE_TO`].
fn checked_columns(film_hue: &[f64]) -> Result<(usize, usize), String> {
    let start = film_hue
        .iter()
        .position(|&h| (HUE_FROM..180.0).contains(&h))
        .ok_or(format!("no column with a film hue of {HUE_FROM}°"))?;
    let end = start
        + film_hue[start..]
            .iter()
            .position(|&h| h >= HUE_TO)
            .ok_or(format!("no column with a film hue of {HUE_TO}°"))?;
    if end - start < 20 || film_hue[start..=end].iter().any(|h| h.is_nan()) {
        return Err(format!("the band spans only columns {start}..{end}"));
    }
    Ok((start, end))
}

/// The check: over the columns where the film's hue runs from about 620 to 460 nm, where
/// the spectral locus turns, the displayed hue rises monotonically (up to the slack) and
/// never stays within 1° for more than 3 columns. (Beyond that range the locus itself
/// hardly turns: above 650 nm and below 440 nm the chromaticity of a spectral colour is
/// nearly constant, which is physics, not a display artefact.)
fn check_continuous_hue(film_hue: &[f64], shown: &[f64]) -> Result<(), String> {
    let (start, end) = checked_columns(film_hue)?;
    let s = &shown[start..=end];
    for (i, pair) in s.windows(2).enumerate() {
        // NaN (a dark column inside the range) fails too.
        if pair[1].is_nan() || pair[1] < pair[0] - MONOTONE_SLACK_DEG {
            return Err(format!(
                "hue falls from {:.1}° to {:.1}° at column {} (band columns {start}..{end}: {s:.1?})",
                pair[0],
                pair[1],
                start + i + 1
            ));
        }
    }
    for (i, run) in s.windows(MAX_PLATEAU_COLUMNS + 1).enumerate() {
        let (lo, hi) = run
            .iter()
            .fold((f64::MAX, f64::MIN), |(a, b), &h| (a.min(h), b.max(h)));
        if hi - lo < PLATEAU_DEG {
            return Err(format!(
                "plateau: hue within {:.2}° over columns {}..={} ({run:.1?}), while the film's turns by {:.1}°",
                hi - lo,
                start + i,
                start + i + MAX_PLATEAU_COLUMNS,
                film_hue[start + i + MAX_PLATEAU_COLUMNS] - film_hue[start + i]
            ));
        }
    }
    Ok(())
}

#[test]
fn newtons_spectrum_has_a_continuous_hue_under_hue_and_plateaus_under_clip() {
    let (_, film) = newton();
    let d = tempfile::tempdir().unwrap();
    let mut results = Vec::new();
    for mode in [DisplayMode::Hue, DisplayMode::Clip] {
        let path = d.path().join(format!("{}.png", mode.name()));
        let t = DisplayTransform::new(mode, 0.0).unwrap();
        heron::film::png::stage_png(&film, &path, &t)
            .unwrap()
            .commit()
            .unwrap();
        let (w, h, px) = decode_png(&path);
        assert_eq!((w, h), (256, 256));
        let (film_hue, shown) = band_hues(&film, &px);
        results.push((
            mode,
            check_continuous_hue(&film_hue, &shown),
            film_hue,
            shown,
        ));
    }
    let (_, hue, film_hue, shown) = &results[0];
    assert!(hue.is_ok(), "--display hue: {}", hue.as_ref().unwrap_err());
    // Beyond the check: the PNG's hue follows the film's, column by column: to 6° where
    // the film is over range (the red end at this exposure, where step 2 keeps the Oklab
    // hue, which differs from the dominant wavelength's by up to 5° there), to under 1°
    // elsewhere.
    let (start, end) = checked_columns(film_hue).unwrap();
    for x in start..=end {
        assert!(
            (shown[x] - film_hue[x]).abs() < 6.0,
            "column {x}: the PNG's hue {:.1}° vs the film's {:.1}°",
            shown[x],
            film_hue[x]
        );
    }
    // Today's clipping fails the same check: flat blocks of red, yellow, green and blue.
    let (_, clip, ..) = &results[1];
    let e = clip
        .as_ref()
        .expect_err("--display clip passed the continuity check");
    assert!(e.contains("plateau"), "{e}");
}

/// A scene rendered small with out-of-gamut and over-range colours: the dispersion scene
/// at 1 spp (spectral fringes through an N-SF11 ball).
fn small_render(dir: &Path, name: &str, extra: &[&str]) -> PathBuf {
    let out = dir.join(format!("{name}.exr"));
    let sc = scenes().join("dispersion.toml");
    let mut args = vec![
        "render",
        sc.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--spp",
        "1",
        "--quiet",
    ];
    args.extend_from_slice(extra);
    heron_ok(&args);
    out
}

#[test]
fn heron_display_of_the_exr_is_the_png_the_render_wrote() {
    let d = tempfile::tempdir().unwrap();
    let p = |n: &str| d.path().join(n);
    let hue = small_render(d.path(), "hue", &[]);
    let clip = small_render(d.path(), "clip", &["--display", "clip"]);
    let dark = small_render(d.path(), "dark", &["--exposure", "-1.5"]);
    // The EXR does not depend on the display flags.
    let bytes = |q: &Path| std::fs::read(q).unwrap();
    assert_eq!(bytes(&hue), bytes(&clip));
    assert_eq!(bytes(&hue), bytes(&dark));
    let (_, _, ph) = decode_png(&p("hue.png"));
    let (_, _, pc) = decode_png(&p("clip.png"));
    let differ = ph.iter().zip(&pc).filter(|(a, b)| a != b).count();
    assert!(differ > 100, "hue and clip differ in only {differ} pixels");
    for (args, want) in [
        (vec![], "hue.png"),
        (vec!["--display", "clip"], "clip.png"),
        (vec!["--exposure", "-1.5"], "dark.png"),
    ] {
        let out = p("again.png");
        let mut a = vec![
            "display",
            hue.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ];
        a.extend_from_slice(&args);
        heron_ok(&a);
        assert!(
            bytes(&out) == bytes(&p(want)),
            "heron display {args:?} differs from the render's {want}"
        );
    }
    let mut left: Vec<String> = std::fs::read_dir(d.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    left.sort();
    assert_eq!(
        left,
        [
            "again.png",
            "clip.exr",
            "clip.png",
            "dark.exr",
            "dark.png",
            "hue.exr",
            "hue.png"
        ]
    );
}

#[test]
fn in_gamut_images_encode_to_the_same_bytes_under_hue_and_clip() {
    // A reddish Lambertian quad (ρd = RGB (0.7, 0.3, 0.2)) filling the view under a
    // directional light at 60°: linear sRGB about (0.35, 0.15, 0.1), every pixel inside
    // [0, 1]; hue changes nothing there.
    let d = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/python/scenes/quad_oblique.toml"),
    )
    .unwrap()
    .replace(
        "rho_d = { spectrum = \"E\", scale = 1.0 }",
        "rho_d = [0.7, 0.3, 0.2]",
    );
    assert!(text.contains("[0.7, 0.3, 0.2]"));
    let sc = d.path().join("red.toml");
    std::fs::write(&sc, text).unwrap();
    let exr = d.path().join("a.exr");
    heron_ok(&[
        "render",
        sc.to_str().unwrap(),
        "-o",
        exr.to_str().unwrap(),
        "--spp",
        "4",
        "--quiet",
    ]);
    let (_, _, rgb) = heron::film::exr::read_linear_srgb(&exr).unwrap();
    assert!(rgb.iter().flatten().all(|v| (0.0..=1.0).contains(v)));
    assert!(rgb.iter().all(|c| c[0] > 2.0 * c[1]), "not the red quad");
    let clip = d.path().join("clip.png");
    heron_ok(&[
        "display",
        exr.to_str().unwrap(),
        "-o",
        clip.to_str().unwrap(),
        "--display",
        "clip",
    ]);
    assert_eq!(
        std::fs::read(d.path().join("a.png")).unwrap(),
        std::fs::read(&clip).unwrap()
    );
}

#[test]
fn heron_display_maps_xyz_rows_of_a_csv() {
    let d = tempfile::tempdir().unwrap();
    let csv = d.path().join("c.csv");
    // D65 white (Y = 1); a mid grey; 520 nm at Y = 0.3 (CIE 1931: x̄ 0.06327, ȳ 0.71,
    // z̄ 0.07825), far outside sRGB; a value far over range.
    std::fs::write(
        &csv,
        "# comment\ntheta,X,Y,Z\n1,0.95047,1,1.08883\n2,0.2,0.21,0.23\n3,0.0267,0.3,0.0331\n4,9.5,10,10.9\n",
    )
    .unwrap();
    let out = heron_ok(&["display", csv.to_str().unwrap()]);
    let text = String::from_utf8(out.stdout).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("sR,sG,sB"));
    let rows: Vec<[f64; 3]> = lines
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect();
    assert_eq!(rows.len(), 4);
    for c in &rows {
        assert!(c.iter().all(|v| (0.0..=1.0).contains(v)), "{c:?}");
    }
    // White and over-range white are white; the grey is encoded as is.
    for r in [0, 3] {
        assert!(rows[r].iter().all(|&v| v > 0.999), "{:?}", rows[r]);
    }
    let grey = DisplayTransform::default().encode(heron::spectrum::color::xyz_to_linear_srgb([
        0.2, 0.21, 0.23,
    ]));
    for k in 0..3 {
        assert_eq!(rows[1][k] as f32, grey[k]);
    }
    // 520 nm keeps its dominant wavelength (white is added; it stays below 1), to the
    // precision of the printed digits; clipped, it would turn 10° toward sRGB's green.
    let want =
        hue_xy(heron::spectrum::color::xyz_to_linear_srgb([0.0267, 0.3, 0.0331]).map(f64::from));
    let got = hue_xy(rows[2].map(|v| {
        // The sRGB decoding of an encoded value in [0, 1].
        if v <= 0.04045 {
            v / 12.92
        } else {
            ((v + 0.055) / 1.055).powf(2.4)
        }
    }));
    assert!((got - want).abs() < 0.05, "520 nm: hue {got} vs {want}");
    let clipped = hue_xy(
        heron::spectrum::color::xyz_to_linear_srgb([0.0267, 0.3, 0.0331])
            .map(|v| v.clamp(0.0, 1.0) as f64),
    );
    assert!((clipped - want).abs() > 5.0, "{clipped} vs {want}");
    // To a file, atomically; the same text.
    let to = d.path().join("out.csv");
    heron_ok(&["display", csv.to_str().unwrap(), "-o", to.to_str().unwrap()]);
    assert_eq!(std::fs::read_to_string(&to).unwrap(), text);
}

#[test]
fn bad_display_flags_and_inputs_are_one_line_errors() {
    let d = tempfile::tempdir().unwrap();
    let p = |n: &str| d.path().join(n).to_string_lossy().into_owned();
    std::fs::write(p("noxyz.csv"), "a,b,c\n1,2,3\n").unwrap();
    std::fs::write(p("bad.csv"), "X,Y,Z\n1,2,3\n1,oops,3\n").unwrap();
    std::fs::write(p("nan.csv"), "X,Y,Z\n1,NaN,3\n").unwrap();
    std::fs::write(p("fake.exr"), "not an EXR").unwrap();
    std::fs::write(p("x.txt"), "X,Y,Z\n").unwrap();
    fails(
        &["display", &p("noxyz.csv")],
        "expected a header line with columns X, Y and Z",
    );
    fails(&["display", &p("bad.csv")], "bad.csv:3: column Y");
    fails(&["display", &p("nan.csv")], "nan.csv:2: column Y");
    fails(&["display", &p("missing.csv")], "missing.csv");
    fails(&["display", &p("fake.exr"), "-o", &p("o.png")], "fake.exr");
    fails(&["display", &p("fake.exr")], "--output");
    fails(&["display", &p("fake.exr"), "-o", &p("o.jpg")], "--output");
    fails(&["display", &p("x.txt")], "expected an .exr");
    fails(
        &["display", &p("bad.csv"), "--display", "gamut"],
        "--display",
    );
    for ev in ["nan", "inf", "100", "-65"] {
        fails(&["display", &p("bad.csv"), "--exposure", ev], "--exposure");
    }
    let sc = scenes().join("default.toml");
    let sc = sc.to_str().unwrap();
    let out = p("r.exr");
    for ev in ["NaN", "-1", "0", "inf", "1e300"] {
        fails(
            &["render", sc, "-o", &out, "--preview-every", ev],
            "--preview-every",
        );
    }
    fails(
        &["render", sc, "-o", &out, "--preview-every", "1", "--no-png"],
        "--preview-every",
    );
    fails(
        &[
            "render",
            sc,
            "-o",
            &p("r.heronfilm"),
            "--preview-every",
            "1",
        ],
        "--preview-every",
    );
    fails(
        &["render", sc, "-o", &out, "--exposure", "nan"],
        "--exposure",
    );
    fails(
        &["render", sc, "-o", &out, "--display", "none"],
        "--display",
    );
    fails(&["sky", "lee", "--display", "x"], "--display");
    let mut left: Vec<String> = std::fs::read_dir(d.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    left.sort();
    assert_eq!(
        left,
        ["bad.csv", "fake.exr", "nan.csv", "noxyz.csv", "x.txt"]
    );
}

#[test]
fn the_preview_hook_sees_every_pass_and_leaves_the_film_unchanged() {
    // default.toml at 64² and 2048 spp: passes of 2²² / 64² = 1024 spp, so two passes;
    // with an interval of zero the hook runs after every pass but the last.
    let text = std::fs::read_to_string(scenes().join("default.toml"))
        .unwrap()
        .replace("resolution = [512, 512]", "resolution = [64, 64]");
    assert!(text.contains("[64, 64]"));
    let scene = load_scene_from_str(&text, &scenes().join("default.toml")).unwrap();
    let mut o = RenderOptions::from_scene(&scene);
    o.settings.spp = 2048;
    o.settings.lanes = heron::settings::Lanes::One;
    let (plain, _) = render_state(&scene, &o).unwrap();
    let calls = Arc::new(AtomicU32::new(0));
    let seen = Arc::new(Mutex::new(Vec::new()));
    let d = tempfile::tempdir().unwrap();
    let png = d.path().join("preview.png");
    {
        let (calls, seen, png) = (calls.clone(), seen.clone(), png.clone());
        o.preview = Some((
            std::time::Duration::ZERO,
            Arc::new(move |state: &heron::checkpoint::Checkpoint| {
                calls.fetch_add(1, Ordering::SeqCst);
                seen.lock().unwrap().push(state.film.spp_done);
                // The writer --preview-every uses.
                heron::film::png::stage_png(
                    &state.film.image(),
                    &png,
                    &DisplayTransform::default(),
                )
                .unwrap()
                .commit()
                .unwrap();
            }),
        ));
    }
    let (with, stats) = render_state(&scene, &o).unwrap();
    assert_eq!(stats.spp, 2048);
    assert_eq!(calls.load(Ordering::SeqCst), 1);
    assert_eq!(*seen.lock().unwrap(), [1024]);
    let (w, h, _) = decode_png(&png);
    assert_eq!((w, h), (64, 64));
    assert!(
        plain.film.image() == with.film.image(),
        "the preview changed the image"
    );
}

fn default_scene_args<'a>(sc: &'a str, out: &'a str, spp: &'a str) -> Vec<&'a str> {
    vec![
        "render", sc, "-o", out, "--spp", spp, "--quiet", "--lanes", "1",
    ]
}

#[test]
fn preview_every_leaves_the_final_exr_and_png_unchanged() {
    // 512² at 32 spp is two passes of 16 spp; an interval of 1 ns is over at the end of
    // the first, so a preview is written there (the final write replaces it).
    let d = tempfile::tempdir().unwrap();
    let sc = scenes().join("default.toml");
    let sc = sc.to_str().unwrap();
    let (a, b) = (d.path().join("a.exr"), d.path().join("b.exr"));
    heron_ok(&default_scene_args(sc, a.to_str().unwrap(), "32"));
    let mut args = default_scene_args(sc, b.to_str().unwrap(), "32");
    args.extend_from_slice(&["--preview-every", "1e-9"]);
    heron_ok(&args);
    for ext in ["exr", "png"] {
        assert!(
            std::fs::read(a.with_extension(ext)).unwrap()
                == std::fs::read(b.with_extension(ext)).unwrap(),
            "the final .{ext} differs with --preview-every"
        );
    }
    let n = std::fs::read_dir(d.path()).unwrap().count();
    assert_eq!(n, 4, "temporary files left behind");
}

#[test]
fn a_preview_png_appears_while_the_render_runs() {
    // A render of 2000 passes (16 spp each at 512²), far longer than the wait: its PNG
    // must appear, complete and decodable, before the process ends; then it is killed.
    let d = tempfile::tempdir().unwrap();
    let sc = scenes().join("default.toml");
    let out = d.path().join("long.exr");
    let png = out.with_extension("png");
    let mut args = default_scene_args(sc.to_str().unwrap(), out.to_str().unwrap(), "32000");
    args.extend_from_slice(&["--preview-every", "0.001"]);
    let mut child = Command::new(env!("CARGO_BIN_EXE_heron"))
        .args(&args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn heron");
    // Polls until the file exists (bounded so a broken build fails instead of hanging).
    let mut seen = false;
    for _ in 0..30_000 {
        if png.exists() {
            seen = true;
            break;
        }
        if let Some(status) = child.try_wait().unwrap() {
            panic!("heron exited ({status}) before writing a preview");
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    let still_running = child.try_wait().unwrap().is_none();
    child.kill().ok();
    child.wait().ok();
    assert!(seen, "no preview appeared");
    assert!(
        still_running,
        "the render ended before its preview was seen"
    );
    let (w, h, px) = decode_png(&png);
    assert_eq!((w, h), (512, 512));
    assert!(
        px.iter().any(|p| p.iter().any(|&v| v > 0)),
        "the preview is black"
    );
    assert!(!out.exists(), "the EXR exists before the render ended");
}
