//! Plots (`heron converge --plot`, `heron sky profile --plot`; src/plot): each is a PNG
//! of the stated size, the same bytes for the same data, written atomically, with bad
//! paths named; and its pixels show the data: every line passes through its points in
//! its own colour, where [`heron::plot::Frame`] (computed from the axes, not by
//! plotters) says they are. A chart with linear instead of log axes, a line in the
//! wrong colour, a missing series or a guide of the wrong slope fails these checks.
mod common;

use common::cli::{heron, repo};
use heron::converge::ConvergeRow;
use heron::plot::{self, converge, sky, Frame, Picture, GUIDE, PALETTE, SIZE};
use heron::sky::profile::{profile, ProfileRequest};

fn pixel(p: &Picture, x: i64, y: i64) -> Option<[u8; 3]> {
    if x < 0 || y < 0 || x >= p.width as i64 || y >= p.height as i64 {
        return None;
    }
    let i = ((y as usize) * p.width as usize + x as usize) * 3;
    Some([p.rgb[i], p.rgb[i + 1], p.rgb[i + 2]])
}

/// Whether a pixel of exactly `colour` lies within `r` pixels of data point (x, y).
fn colour_near(p: &Picture, f: &Frame, (x, y): (f64, f64), colour: [u8; 3], r: i64) -> bool {
    let Some((px, py)) = f.pixel(x, y) else {
        return false;
    };
    let (cx, cy) = (px.round() as i64, py.round() as i64);
    (-r..=r).any(|dy| (-r..=r).any(|dx| pixel(p, cx + dx, cy + dy) == Some(colour)))
}

fn count_colour(p: &Picture, colour: [u8; 3]) -> usize {
    p.rgb.chunks(3).filter(|c| *c == colour).count()
}

fn row(lanes: usize, spp: u32, wall_s: f64, rel_rmse: f64) -> ConvergeRow {
    ConvergeRow {
        lanes,
        spp,
        wall_s,
        ns_per_sample: 1.0,
        rel_rmse,
        rmse_sqrt_time: rel_rmse * wall_s.sqrt(),
        rel_mse: rel_rmse * rel_rmse,
        roi_rel_rmse: None,
        roi_rel_mse: None,
    }
}

/// 1 lane falling exactly as 1/√t (c = 0.5); 8 lanes as t^−0.3, whose best RMSE·√t is
/// at its first point (0.1 · 0.02^0.2 = 0.0457), so the guide runs below both.
fn synthetic_rows() -> Vec<ConvergeRow> {
    let mut rows = Vec::new();
    for (i, t) in [0.01, 0.04, 0.16, 0.64].into_iter().enumerate() {
        rows.push(row(1, 4 << (2 * i), t, 0.5 / f64::sqrt(t)));
    }
    for (i, t) in [0.02, 0.08, 0.32, 1.28].into_iter().enumerate() {
        rows.push(row(8, 4 << (2 * i), t, 0.1 * t.powf(-0.3)));
    }
    rows
}

#[test]
fn converge_chart_draws_each_setting_and_the_slope_on_log_axes() {
    let rows = synthetic_rows();
    let chart = converge::chart("synthetic", &rows);
    assert_eq!(chart.series.len(), 3);
    let p = plot::draw(&chart).unwrap();
    assert_eq!((p.width, p.height), SIZE);
    assert_eq!(p.rgb.len(), (SIZE.0 * SIZE.1 * 3) as usize);
    let f = p.frame;
    for (lanes, colour) in [(1, PALETTE[0]), (8, PALETTE[1])] {
        let pts: Vec<(f64, f64)> = rows
            .iter()
            .filter(|r| r.lanes == lanes)
            .map(|r| (r.wall_s, r.rel_rmse))
            .collect();
        // A marker at every point, and the line halfway (in log–log) between points.
        for &q in &pts {
            assert!(
                colour_near(&p, &f, q, colour, 1),
                "{lanes} lanes: point {q:?}"
            );
        }
        for w in pts.windows(2) {
            let mid = ((w[0].0 * w[1].0).sqrt(), (w[0].1 * w[1].1).sqrt());
            assert!(
                colour_near(&p, &f, mid, colour, 2),
                "{lanes} lanes: segment at {mid:?}"
            );
        }
    }
    // The guide: c/√t with c the best RMSE·√t, dashed (9 px on, 6 off), so most points
    // along it are drawn, across the whole time span.
    let c = 0.1 * 0.02f64.powf(0.2);
    let n = 40;
    let hits = (0..=n)
        .filter(|&i| {
            let t = 0.01 * 128f64.powf(i as f64 / n as f64);
            colour_near(&p, &f, (t, c / t.sqrt()), GUIDE, 2)
        })
        .count();
    assert!(
        hits >= n * 6 / 10,
        "guide found at {hits} of {} points",
        n + 1
    );
    // …and not where a 1/t line through the same first point would be.
    let t = 1.0;
    assert!(!colour_near(&p, &f, (t, c * 0.01f64.sqrt() / t), GUIDE, 2));
    // Log axes: the axis range covers the data with a factor of 1.25 on each side.
    assert!((f.x_range.0 - 0.01 / 1.25).abs() < 1e-12, "{:?}", f.x_range);
    assert!((f.x_range.1 - 1.28 * 1.25).abs() < 1e-12, "{:?}", f.x_range);
}

#[test]
fn the_same_chart_gives_the_same_bytes() {
    let chart = converge::chart("synthetic", &synthetic_rows());
    let a = plot::png_bytes(&plot::draw(&chart).unwrap()).unwrap();
    let b = plot::png_bytes(&plot::draw(&chart).unwrap()).unwrap();
    assert_eq!(a, b);
    let img = image::load_from_memory_with_format(&a, image::ImageFormat::Png).unwrap();
    assert_eq!((img.width(), img.height()), SIZE);
}

fn descartes(lambdas: &str) -> ProfileRequest {
    ProfileRequest {
        model: "descartes".into(),
        sun_radius_deg: 0.2666,
        droplet_radius_mm: None,
        lambdas: lambdas.into(),
        from_deg: 38.0,
        to_deg: 45.0,
        step_deg: 0.02,
        k: Some("1".into()),
        polarisation: None,
        background: None,
        drops: None,
        debye: None,
    }
}

#[test]
fn sky_chart_draws_each_wavelength_through_its_values_in_its_hue() {
    let prof = profile(&descartes("450,650")).unwrap();
    let chart = sky::chart("descartes", "descartes", &prof);
    let p = plot::draw(&chart).unwrap();
    let f = p.frame;
    // Hues: 450 nm blue-violet, 530 nm green, 650 nm red.
    let [r, g, b] = sky::wavelength_colour(450.0);
    assert!(b > r && b > g, "450 nm: {:?}", [r, g, b]);
    let [r, g, b] = sky::wavelength_colour(530.0);
    assert!(g > r && g > b, "530 nm: {:?}", [r, g, b]);
    let [r, g, b] = sky::wavelength_colour(650.0);
    assert!(r > g && r > b, "650 nm: {:?}", [r, g, b]);
    let mut peaks = Vec::new();
    for (j, &l) in prof.lambdas.iter().enumerate() {
        let colour = sky::wavelength_colour(l);
        let pts: Vec<(f64, f64)> = prof
            .thetas_deg
            .iter()
            .zip(prof.table.chunks(prof.lambdas.len()))
            .map(|(&t, row)| (t, row[j] as f64))
            .collect();
        // The bow's peak, and nearly every sample where no other curve is within 4 px
        // (the other draws over it there: both are 0 beyond their bows).
        let peak = pts
            .iter()
            .copied()
            .fold((0.0, 0.0), |a, q| if q.1 > a.1 { q } else { a });
        assert!(
            colour_near(&p, &f, peak, colour, 2),
            "{l} nm: peak {peak:?}"
        );
        peaks.push(peak.0);
        let clear: Vec<(f64, f64)> = pts
            .iter()
            .zip(prof.table.chunks(prof.lambdas.len()))
            .filter(|(q, row)| {
                let y = f.pixel(q.0, q.1).unwrap().1;
                (0..row.len())
                    .filter(|&k| k != j)
                    .all(|k| (f.pixel(q.0, row[k] as f64).unwrap().1 - y).abs() > 4.0)
            })
            .map(|(q, _)| *q)
            .collect();
        assert!(
            clear.len() > 100,
            "{l} nm: {} samples clear of the other",
            clear.len()
        );
        let drawn = clear
            .iter()
            .filter(|&&q| colour_near(&p, &f, q, colour, 2))
            .count();
        assert!(
            drawn * 100 >= clear.len() * 95,
            "{l} nm: {drawn} of {} samples",
            clear.len()
        );
    }
    // Red's bow is the larger (Descartes: 42.3° against 40.6° near these wavelengths).
    assert!(peaks[1] > peaks[0] + 1.0, "{peaks:?}");
    // The linear y axis starts at 0 (radiance).
    assert_eq!(f.y_range.0, 0.0);
}

#[test]
fn sky_profile_plot_from_the_cli() {
    let d = tempfile::tempdir().unwrap();
    let out = |name: &str| d.path().join(name).display().to_string();
    let args = |png: &str| {
        vec![
            "sky".to_string(),
            "profile".into(),
            "--model".into(),
            "descartes".into(),
            "--lambda".into(),
            "450,550,650".into(),
            "--from".into(),
            "38".into(),
            "--to".into(),
            "54".into(),
            "--step".into(),
            "0.1".into(),
            "--k".into(),
            "both".into(),
            "--plot".into(),
            png.to_string(),
        ]
    };
    let run = |png: &str| {
        let a = args(png);
        let a: Vec<&str> = a.iter().map(String::as_str).collect();
        heron(&a)
    };
    let first = run(&out("a.png"));
    assert!(
        first.status.success(),
        "{}",
        String::from_utf8_lossy(&first.stderr)
    );
    let second = run(&out("b.png"));
    assert!(second.status.success());
    // The CSV is still printed, the same as without --plot.
    let plain = args("");
    let plain: Vec<&str> = plain[..plain.len() - 2]
        .iter()
        .map(String::as_str)
        .collect();
    assert_eq!(first.stdout, heron(&plain).stdout);
    assert!(String::from_utf8_lossy(&first.stdout).starts_with("theta_deg,450nm,550nm,650nm\n"));
    let (a, b) = (
        std::fs::read(out("a.png")).unwrap(),
        std::fs::read(out("b.png")).unwrap(),
    );
    assert_eq!(a, b, "two runs gave different bytes");
    let img = image::load_from_memory_with_format(&a, image::ImageFormat::Png)
        .unwrap()
        .to_rgb8();
    assert_eq!(img.dimensions(), SIZE);
    let p = Picture {
        width: img.width(),
        height: img.height(),
        rgb: img.into_raw(),
        frame: plot::draw(&sky::chart(
            "",
            "descartes",
            &profile(&ProfileRequest {
                lambdas: "450,550,650".into(),
                to_deg: 54.0,
                step_deg: 0.1,
                k: Some("both".into()),
                ..descartes("")
            })
            .unwrap(),
        ))
        .unwrap()
        .frame,
    };
    for l in [450.0, 550.0, 650.0] {
        assert!(
            count_colour(&p, sky::wavelength_colour(l)) > 300,
            "{l} nm line missing"
        );
    }
    // No temporary file is left next to the plot.
    let names: Vec<String> = std::fs::read_dir(d.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names.len(), 2, "{names:?}");
}

#[test]
fn bad_plot_paths_are_named_and_leave_no_file() {
    let d = tempfile::tempdir().unwrap();
    let jpg = d.path().join("p.jpg").display().to_string();
    let nowhere = d.path().join("no/p.png").display().to_string();
    let scene = repo("scenes/cornell-box.toml");
    for (args, want) in [
        (
            vec![
                "sky",
                "profile",
                "--model",
                "descartes",
                "--lambda",
                "500",
                "--from",
                "40",
                "--to",
                "41",
                "--step",
                "1",
                "--plot",
                &jpg,
            ],
            format!("--plot {jpg}: expected a path ending in .png"),
        ),
        (
            vec![
                "sky",
                "profile",
                "--model",
                "descartes",
                "--lambda",
                "500",
                "--from",
                "40",
                "--to",
                "41",
                "--step",
                "1",
                "--plot",
                &nowhere,
            ],
            format!("--plot {nowhere}: folder"),
        ),
        // Checked before the renders start.
        (
            vec![
                "converge",
                &scene,
                "--reference-spp",
                "100000",
                "--plot",
                &jpg,
            ],
            format!("--plot {jpg}: expected a path ending in .png"),
        ),
    ] {
        let out = heron(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(out.stdout.is_empty(), "{args:?}");
        assert!(
            err.lines().next().unwrap().contains(&want),
            "{args:?}: {err}"
        );
        assert!(!err.contains("panicked"));
    }
    assert_eq!(std::fs::read_dir(d.path()).unwrap().count(), 0);
}

#[test]
fn converge_plot_from_the_cli() {
    let d = tempfile::tempdir().unwrap();
    let png = d.path().join("c.png").display().to_string();
    let scene = repo("scenes/cornell-box.toml");
    let out = heron(&[
        "converge",
        &scene,
        "--size",
        "8,8",
        "--reference-spp",
        "64",
        "--spp",
        "1,4,16",
        "--lanes",
        "1,4",
        "--threads",
        "1",
        "--plot",
        &png,
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let csv = String::from_utf8_lossy(&out.stdout);
    assert!(csv.contains("lanes,spp,wall_s"), "{csv}");
    let img = image::open(&png).unwrap().to_rgb8();
    assert_eq!(img.dimensions(), SIZE);
    let p = Picture {
        width: img.width(),
        height: img.height(),
        rgb: img.into_raw(),
        frame: Frame {
            area: [0, 0, 0, 0],
            x_range: (0.0, 1.0),
            y_range: (0.0, 1.0),
            x_scale: plot::Scale::Linear,
            y_scale: plot::Scale::Linear,
        },
    };
    // One line per lane count and the guide, each in its colour (markers alone are
    // 6 × 49 pixels; lines add more).
    for (what, colour) in [
        ("1 lane", PALETTE[0]),
        ("4 lanes", PALETTE[1]),
        ("guide", GUIDE),
    ] {
        assert!(count_colour(&p, colour) > 150, "{what} missing");
    }
    assert!(
        count_colour(&p, PALETTE[2]) == 0,
        "a third setting appeared"
    );
}
