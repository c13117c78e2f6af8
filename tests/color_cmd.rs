//! `heron color FILE.csv [--illuminant D65|D50|A|E|none] [--observer 1931|1964]
//! [--interpolation cie167|linear]`: bad input
//! gets a one-line error naming the file (and line) and what was expected, exit status 1
//! (2 for a bad command-line value, clap's usage error) and no panic; good input prints
//! the JSON whose numbers follow from heron's tables (spectra/README.md).
mod common;

use common::cli::heron;
use std::path::{Path, PathBuf};

fn write(dir: &Path, name: &str, text: &str) -> String {
    let p: PathBuf = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.display().to_string()
}

/// Fails with status `code`, nothing on stdout, no panic, and a first stderr line
/// containing every needle.
fn assert_fails(args: &[&str], code: i32, needles: &[&str]) {
    let out = heron(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(code), "{args:?}: {err}");
    assert!(out.stdout.is_empty(), "{args:?} printed to stdout");
    assert!(!err.contains("panicked"), "{args:?} panicked: {err}");
    let first = err.lines().next().unwrap_or("");
    for n in needles {
        assert!(
            first.contains(n),
            "{args:?}: {first:?} should mention {n:?}"
        );
    }
}

fn assert_input_error(args: &[&str], needles: &[&str]) {
    let out = heron(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(
        err.trim_end().lines().count(),
        1,
        "one line expected: {err}"
    );
    assert_fails(args, 1, needles);
}

/// Runs `heron color` and returns the parsed JSON.
fn color(args: &[&str]) -> serde_json::Value {
    let mut a = vec!["color"];
    a.extend_from_slice(args);
    let out = heron(&a);
    assert!(
        out.status.success(),
        "{a:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("stdout is JSON")
}

fn vec3(v: &serde_json::Value, key: &str) -> [f64; 3] {
    let a = v[key].as_array().unwrap_or_else(|| panic!("{key} in {v}"));
    assert_eq!(a.len(), 3, "{key}");
    [0, 1, 2].map(|i| a[i].as_f64().unwrap())
}

fn assert_close(got: [f64; 3], want: [f64; 3], tol: f64, what: &str) {
    for k in 0..3 {
        assert!(
            (got[k] - want[k]).abs() <= tol,
            "{what}: {got:?} vs {want:?} (tolerance {tol})"
        );
    }
}

#[test]
fn bad_input_names_file_line_and_expectation() {
    let d = tempfile::tempdir().unwrap();
    let bad_line = write(
        d.path(),
        "bad_line.csv",
        "wavelength_nm,value\n400,0.1\n# comment\n450,zero\n500,0.3\n",
    );
    assert_input_error(
        &["color", &bad_line],
        &[
            &bad_line,
            "line 4",
            "value",
            "expected a number",
            "\"zero\"",
        ],
    );

    let three = write(d.path(), "three.csv", "400,0.1\n500,0.2,9\n");
    assert_input_error(
        &["color", &three],
        &[&three, "line 2", "expected two comma-separated numbers"],
    );

    let order = write(d.path(), "order.csv", "400,0.1\n500,0.2\n500,0.3\n");
    assert_input_error(
        &["color", &order],
        &[&order, "line 3", "strictly increasing", "(line 2)"],
    );
    let backwards = write(d.path(), "backwards.csv", "600,0.1\n# x\n\n500,0.2\n");
    assert_input_error(
        &["color", &backwards],
        &[&backwards, "line 4", "strictly increasing"],
    );

    let inf = write(d.path(), "inf.csv", "400,0.1\n500,inf\n");
    assert_input_error(
        &["color", &inf],
        &[&inf, "line 2", "expected a finite number"],
    );
    let nan_wl = write(d.path(), "nan.csv", "400,0.1\nNaN,0.2\n");
    assert_input_error(
        &["color", &nan_wl],
        &[&nan_wl, "line 2", "wavelength", "finite"],
    );

    let one_row = write(d.path(), "one.csv", "wavelength_nm,value\n555,1\n");
    assert_input_error(
        &["color", &one_row],
        &[&one_row, "expected at least 2 rows", "found 1"],
    );

    let missing = d.path().join("missing.csv").display().to_string();
    assert_input_error(
        &["color", &missing],
        &[&missing, "cannot read", "No such file"],
    );
}

#[test]
fn bad_command_line_values_are_usage_errors() {
    let d = tempfile::tempdir().unwrap();
    let ok = write(d.path(), "ok.csv", "360,1\n830,1\n");
    assert_fails(
        &["color", &ok, "--illuminant", "F2"],
        1,
        &["--illuminant", "expected D65, D50, A, E or none", "F2"],
    );
    assert_fails(
        &["color", &ok, "--interpolation", "sprague"],
        1,
        &["--interpolation", "expected cie167", "linear", "sprague"],
    );
    assert_fails(
        &["color", &ok, "--observer", "2015"],
        1,
        &["--observer", "expected 1931", "1964", "2015"],
    );
}

#[test]
fn equal_energy_emitter_has_the_film_white() {
    // The constant 1 as an emitter: XYZ = (Σx̄, Σȳ, Σz̄)/Σȳ over heron's 1 nm tables
    // (spectra/README.md): (1.00008004, 1, 1.00033067) for 2°, (0.9998855, 1, 1.00010375)
    // for 10°. Two rows are enough: the ends are held constant.
    let d = tempfile::tempdir().unwrap();
    let e = write(
        d.path(),
        "e.csv",
        "# E\nwavelength_nm,value\n500,1\n600,1\n",
    );
    let v = color(&[&e, "--illuminant", "none"]);
    assert_eq!(v["file"], e.as_str());
    assert_eq!(v["observer"], "1931");
    assert_eq!(v["illuminant"], "none");
    let xyz = vec3(&v, "XYZ");
    assert_close(xyz, [1.00008004, 1.0, 1.00033067], 2e-7, "E, 1931");
    let xy = v["xy"].as_array().unwrap();
    let s = xyz[0] + xyz[1] + xyz[2];
    assert!((xy[0].as_f64().unwrap() - xyz[0] / s).abs() < 1e-7);
    assert!((xy[1].as_f64().unwrap() - xyz[1] / s).abs() < 1e-7);
    // IEC 61966-2-1 matrix applied as is (tests/python/README.md: background_e).
    assert_close(
        vec3(&v, "linear_srgb"),
        [1.2048945, 0.9483362, 0.9090540],
        3e-7,
        "E sRGB",
    );

    let v = color(&[&e, "--illuminant", "none", "--observer", "1964"]);
    assert_eq!(v["observer"], "1964");
    assert_close(
        vec3(&v, "XYZ"),
        [0.9998855, 1.0, 1.00010375],
        2e-7,
        "E, 1964",
    );
    // A reflectance of 1 under E is the same sum.
    let under_e = color(&[&e, "--illuminant", "E", "--observer", "1964"]);
    assert_eq!(under_e["XYZ"], v["XYZ"]);
}

#[test]
fn perfect_reflector_gives_the_illuminant_white() {
    let d = tempfile::tempdir().unwrap();
    let white = write(d.path(), "white.csv", "360,1\n830,1\n");
    // D65 is the default; its white under the film convention is the one
    // spectra/README.md quotes: XYZ (0.95047076, 1, 1.08882842), linear sRGB
    // (1.0000057, 1.0000753, 0.9998329).
    let v = color(&[&white]);
    assert_eq!(v["illuminant"], "D65");
    assert_close(
        vec3(&v, "XYZ"),
        [0.95047076, 1.0, 1.08882842],
        3e-7,
        "D65 white",
    );
    assert_close(
        vec3(&v, "linear_srgb"),
        [1.0000057, 1.0000753, 0.9998329],
        5e-7,
        "D65 white sRGB",
    );
    // Half the reflectance, half the XYZ.
    let grey = write(d.path(), "grey.csv", "360,0.5\n830,0.5\n");
    assert_close(
        vec3(&color(&[&grey]), "XYZ"),
        [0.47523538, 0.5, 0.54441421],
        2e-7,
        "grey",
    );
    // Illuminant A (case-insensitive name): Y = 1 and the chromaticity of the tabulated
    // A at 1 nm, x = 0.447561, y = 0.407431 (CIE 15 quotes 0.44757, 0.40745).
    let v = color(&[&white, "--illuminant", "a"]);
    assert_eq!(v["illuminant"], "A");
    let xyz = vec3(&v, "XYZ");
    assert!((xyz[1] - 1.0).abs() < 1e-6, "{xyz:?}");
    let xy = v["xy"].as_array().unwrap();
    assert!((xy[0].as_f64().unwrap() - 0.447561).abs() < 2e-6, "{v}");
    assert!((xy[1].as_f64().unwrap() - 0.407431).abs() < 2e-6, "{v}");
    // D50: x = 0.345684, y = 0.358504 (the 5 nm table linearly interpolated; CIE 15
    // quotes 0.34567, 0.35850).
    let v = color(&[&white, "--illuminant", "D50"]);
    assert_eq!(v["illuminant"], "D50");
    assert!((vec3(&v, "XYZ")[1] - 1.0).abs() < 1e-6, "{v}");
    let xy = v["xy"].as_array().unwrap();
    assert!((xy[0].as_f64().unwrap() - 0.345684).abs() < 2e-6, "{v}");
    assert!((xy[1].as_f64().unwrap() - 0.358504).abs() < 2e-6, "{v}");
}

#[test]
fn linear_interpolation_joins_the_rows_with_straight_lines() {
    // A triangle on 5 nm rows (uniform, so Sprague by default): linear interpolation
    // gives the triangle, whose emitted Y is Σ ȳ(λ)·tri(λ) / Σ ȳ; Sprague rings beside
    // the peak and gives another Y. The JSON names the interpolation.
    let d = tempfile::tempdir().unwrap();
    let mut text = String::from("wavelength_nm,value\n");
    for i in 0..=20 {
        let l = 500 + 5 * i;
        text += &format!("{l},{}\n", if l == 550 { 1.0 } else { 0.0 });
    }
    let tri = write(d.path(), "tri.csv", &text);
    let lin = color(&[&tri, "--illuminant", "none", "--interpolation", "linear"]);
    let cie = color(&[&tri, "--illuminant", "none"]);
    assert_eq!(lin["interpolation"], "linear");
    assert_eq!(cie["interpolation"], "cie167");
    let rows: Vec<(f64, f64)> = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("spectra/cie1931_2deg.csv"),
    )
    .unwrap()
    .lines()
    .skip(1)
    .map(|l| {
        let f: Vec<f64> = l.split(',').map(|v| v.parse().unwrap()).collect();
        (f[0], f[2])
    })
    .collect();
    let sum_y: f64 = rows.iter().map(|r| r.1).sum();
    let want: f64 = rows
        .iter()
        .map(|&(l, y)| y * (1.0 - (l - 550.0).abs() / 5.0).max(0.0))
        .sum::<f64>()
        / sum_y;
    let got = vec3(&lin, "XYZ")[1];
    assert!((got - want).abs() < 1e-6 * want, "{got} vs {want}");
    let sprague = vec3(&cie, "XYZ")[1];
    // (7.8e-4 relative here.)
    assert!((sprague - want).abs() > 3e-4 * want, "{sprague} vs {want}");
}

#[test]
fn a_box_spectrum_on_the_grid_is_taken_as_it_is() {
    // Rows every 1 nm over 480–620 nm, 1 on 500–600 and 0 elsewhere: uniform data, so
    // Sprague interpolation, which passes through every row, gives the 1 nm table back
    // unchanged. As an emitter its Y is Σ_{500..600} ȳ / Σ ȳ. (Four rows 499/500/600/601
    // would be irregular and, as in colour-science, a cubic through them, not a box.)
    let d = tempfile::tempdir().unwrap();
    let rows: String = (480..=620)
        .map(|l| format!("{l},{}\n", u8::from((500..=600).contains(&l))))
        .collect();
    let boxed = write(d.path(), "box.csv", &rows);
    let y = vec3(&color(&[&boxed, "--illuminant", "none"]), "XYZ")[1];
    let table = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/spectra/cie1931_2deg.csv"
    ))
    .unwrap();
    let (mut inside, mut all) = (0.0f64, 0.0f64);
    for row in table.lines().skip(1) {
        let f: Vec<f64> = row.split(',').map(|v| v.parse().unwrap()).collect();
        all += f[2];
        if (500.0..=600.0).contains(&f[0]) {
            inside += f[2];
        }
    }
    assert!((y - inside / all).abs() < 1e-6, "{y} vs {}", inside / all);
}

#[test]
fn all_zero_spectrum_has_no_chromaticity() {
    let d = tempfile::tempdir().unwrap();
    let black = write(d.path(), "black.csv", "400,0\n700,0\n");
    let v = color(&[&black, "--illuminant", "none"]);
    assert_eq!(vec3(&v, "XYZ"), [0.0; 3]);
    assert!(v["xy"].is_null(), "{v}");
}
