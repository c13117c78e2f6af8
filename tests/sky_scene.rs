//! Skies in scenes: `[sky]` loads with the scene's sun and gives clear errors, and a
//! rendered Descartes sky puts the primary bow, Alexander's dark band and the secondary
//! bow at the angles geometric optics predicts.
use heron::camera::Camera;
use heron::render::{render, RenderOptions};
use heron::scene::load::load_scene_from_str;
use heron::scene::load_scene;
use std::path::Path;

fn scenes() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes")
}

const BASE: &str = r#"
[camera]
eye = [0.0, 1.5, 0.0]
look_at = [0.0, 1.75, -1.0]
resolution = [8, 8]
[[lights]]
type = "sun"
direction = [0.0, -0.258819, -0.965926]
irradiance = 3.0
"#;

fn load_err(extra: &str) -> String {
    let text = format!("{BASE}\n{extra}");
    match load_scene_from_str(&text, Path::new("sky.toml")) {
        Ok(_) => panic!("accepted: {extra}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn sky_section_errors_name_the_key() {
    for (extra, needle) in [
        ("[sky]\nmodel = \"rainbowz\"", "sky.model"),
        ("[sky]\nmodel = \"descartes\"\norders = [3]", "sky.orders"),
        ("[sky]\nmodel = \"airy\"", "sky.droplet_radius"),
        (
            "[sky]\nmodel = \"descartes\"\ndroplet_radius = 0.5",
            "sky.droplet_radius",
        ),
        (
            "[sky]\nmodel = \"aristotle\"\npolarisation = \"s\"",
            "sky.polarisation",
        ),
        (
            "[sky]\nmodel = \"mie\"\ndroplet_radius = 5.0",
            "sky.droplet_radius",
        ),
        ("[sky]\nmodel = \"descartes\"\ncolour = 1", "colour"),
        // Drop-size distributions and Debye terms (src/drops, src/optics/debye.rs).
        (
            "[sky]\nmodel = \"descartes\"\ndrops = { distribution = \"lognormal\", median_mm = 0.5, sigma = 0.1 }",
            "sky.drops",
        ),
        (
            "[sky]\nmodel = \"airy\"\ndroplet_radius = 0.5\ndrops = { distribution = \"lognormal\", median_mm = 0.5, sigma = 0.1 }",
            "sky.droplet_radius",
        ),
        (
            "[sky]\nmodel = \"airy\"\ndrops = { distribution = \"lognormal\", median_mm = 0.5, sigma = -0.1 }",
            "sky.drops.sigma",
        ),
        (
            "[sky]\nmodel = \"airy\"\ndrops = { distribution = \"lognormal\", median_mm = 0.5 }",
            "sky.drops.sigma",
        ),
        (
            "[sky]\nmodel = \"airy\"\ndrops = { distribution = \"lognormal\", median_mm = 0.5, sigmaa = 0.1 }",
            "sigmaa",
        ),
        (
            "[sky]\nmodel = \"mie\"\ndrops = { distribution = \"marshall-palmer\", rain_rate_mm_h = 5 }",
            "sky.drops",
        ),
        (
            "[sky]\nmodel = \"airy\"\ndroplet_radius = 0.5\ndebye = 2",
            "sky.debye",
        ),
        (
            "[sky]\nmodel = \"mie\"\ndroplet_radius = 0.5\ndebye = 99",
            "sky.debye",
        ),
    ] {
        let e = load_err(extra);
        assert!(
            e.contains(needle) && e.contains("sky.toml"),
            "{extra:?}: {e}"
        );
        assert_eq!(e.lines().count(), 1, "{e}");
    }
    // No sun, no sky.
    let e = match load_scene_from_str(
        "[camera]\neye = [0, 1, 0]\nlook_at = [0, 1, -1]\nresolution = [4, 4]\n[sky]\nmodel = \"descartes\"\n",
        Path::new("nosun.toml"),
    ) {
        Ok(_) => panic!("a sky without a sun was accepted"),
        Err(e) => e.to_string(),
    };
    assert!(e.contains("sun"), "{e}");
}

/// A scene's `[sky]` follows the limits of `heron sky profile` (one `SkySpec`): Airy
/// drops up to 10 mm, Mie drops up to 2 mm, a sun of at most 5°, descartes order 0.
#[test]
fn sky_limits_are_the_clis() {
    let e = load_err("[sky]\nmodel = \"airy\"\ndroplet_radius = 10.5");
    assert!(
        e.ends_with("sky.droplet_radius: expected at most 10 mm, got 10.5"),
        "{e}"
    );
    let e = load_err("[sky]\nmodel = \"mie\"\ndroplet_radius = 2.5");
    assert!(
        e.ends_with("sky.droplet_radius: expected at most 2 mm, got 2.5"),
        "{e}"
    );
    let e = load_err("angular_radius = 6\n[sky]\nmodel = \"descartes\"");
    assert!(
        e.ends_with("lights[0].angular_radius: expected an angle in (0°, 5°], got 6°"),
        "{e}"
    );
    let e = load_err("[sky]\nmodel = \"airy\"\ndroplet_radius = 0.5\norders = [0, 1]");
    assert!(
        e.ends_with("sky.orders: expected a non-empty subset of [1, 2], got [0, 1]"),
        "{e}"
    );
    // The fuzzing harness builds the sky's model without tabulating it.
    let text = format!("{BASE}\n[sky]\nmodel = \"descartes\"\norders = [0, 1]\n");
    let fixtures = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/fixtures");
    assert_eq!(
        heron::fuzzing::scene(text.as_bytes(), &fixtures),
        heron::fuzzing::Outcome::Accepted
    );
}

#[test]
fn rendered_descartes_sky_has_its_bows_and_dark_band_where_optics_puts_them() {
    let mut s = load_scene(&scenes().join("rainbow-descartes.toml")).unwrap();
    let sky = s.sky.clone().expect("the scene has a sky");
    // A tall, narrow view straight up through the top of the bows: one column, θ
    // from the antisolar point grows with the row.
    let c = &s.camera;
    let (w, h) = (1u32, 400u32);
    s.camera = Camera::new(c.eye, c.look_at, c.up, 0.6, w, h).unwrap();
    let mut o = RenderOptions::from_scene(&s);
    o.settings.spp = 64;
    let (film, _) = render(&s, &o).unwrap();
    let rows: Vec<(f64, f32)> = (0..h)
        .map(|y| {
            let d = s.camera.direction(0.5, y as f32 + 0.5);
            let theta = heron::sky::antisolar_angle(d, sky.sun_dir).to_degrees();
            (theta, film.xyz[y as usize][1])
        })
        .collect();
    let near = |lo: f64, hi: f64| -> Vec<(f64, f32)> {
        rows.iter()
            .copied()
            .filter(|(t, _)| *t >= lo && *t <= hi)
            .collect()
    };
    let brightest = |v: &[(f64, f32)]| {
        v.iter()
            .copied()
            .fold((0.0, f32::MIN), |a, b| if b.1 > a.1 { b } else { a })
    };
    let (t1, y1) = brightest(&near(38.0, 44.0));
    let (t2, y2) = brightest(&near(49.0, 55.0));
    // Luminance-weighted bows of water: primary near 42°, secondary near 51°.
    assert!((41.0..43.0).contains(&t1), "primary bow at {t1}°");
    assert!((50.0..52.5).contains(&t2), "secondary bow at {t2}°");
    let band: Vec<f32> = near(44.5, 48.5).iter().map(|r| r.1).collect();
    let band_max = band.iter().copied().fold(f32::MIN, f32::max);
    let inside: f32 =
        near(30.0, 35.0).iter().map(|r| r.1).sum::<f32>() / near(30.0, 35.0).len() as f32;
    // Alexander's dark band: darker than the sky inside the primary and than both bows.
    assert!(
        band_max < inside && band_max < y2 && y2 < y1,
        "band {band_max}, inside {inside}, bows {y1} {y2}"
    );
}

#[test]
fn sky_drops_reach_the_tabulated_model() {
    // A log-normal airy sky with 4 nodes (the table takes about a second): the scene's
    // (θ, λ) table at its grid nodes is the model's profile built from the same table,
    // and differs from the one-radius sky (so the distribution was not dropped).
    let text = format!(
        "{BASE}\n[sky]\nmodel = \"airy\"\ndrops = {{ distribution = \"lognormal\", median_mm = 0.2, sigma = 0.2, nodes = 4 }}\n"
    );
    let scene = load_scene_from_str(&text, Path::new("drops.toml")).unwrap();
    let heron::sky::table::SkyShape::Profile(table) = &scene.sky.as_ref().expect("a sky").shape
    else {
        panic!("an airy sky is a profile")
    };
    let alpha = 0.2666f64.to_radians();
    let want = heron::sky::AirySky::water(1.0, alpha).with_distribution(
        &heron::drops::DropSizeDistribution::LogNormal {
            median_mm: 0.2,
            sigma: 0.2,
        },
        4,
    );
    let mono = heron::sky::AirySky::water(0.2, alpha);
    let mut differs = false;
    for theta in [40.0, 40.5, 41.0, 41.5, 42.0] {
        let got = table.eval(theta, 550.0);
        let w = want.profile(f64::to_radians(theta), 550.0);
        assert!(
            (got - w).abs() <= 1e-5 * w.abs().max(1e-3),
            "θ {theta}: {got} vs {w}"
        );
        differs |= (got - mono.profile(f64::to_radians(theta), 550.0)).abs() > 0.01 * w;
    }
    assert!(differs, "the distribution's sky equals the one-radius sky");
}
