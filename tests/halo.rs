//! Ice-crystal optics against the closed forms of halo theory (Tape 1994, "Atmospheric
//! Halos"; Greenler 1980, "Rainbows, Halos and Glories"; Können 1983, J. Opt. Soc. Am.
//! 73, 1629), per wavelength with ice's n(λ) from the catalogue (Warren & Brandt 2008).
//!
//! The closed forms hold for one ray path each (a 60° or 90° prism passed without
//! internal reflection), so the tests pick those rays by the faces they entered and left
//! by, and compare the smallest deviation found with the minimum deviation: no ray of the
//! path may deviate less (within float round-off), and with the rays drawn here some come
//! within the tolerance of it. Sample counts: with N rays of a path, the gap between
//! the smallest deviation and the minimum shrinks as 1/N² near a quadratic minimum; the
//! counts below leave it under a tenth of the tolerance (the tests print the gaps).
use glam::DVec3;
use heron::math::rng::Rng;
use heron::optics::ice::crystal::TOP;
use heron::optics::ice::{Crystals, Orientation, Population, Scattered};
use heron::spectrum::ior;

fn ice_n(lambda: f32) -> f64 {
    ior::named("ice")
        .expect("ice in the catalogue")
        .eval(lambda) as f64
}

fn uniform(rng: &mut Rng) -> impl FnMut() -> f64 + '_ {
    move || {
        let hi = (rng.next_u32() >> 5) as u64;
        let lo = (rng.next_u32() >> 6) as u64;
        ((hi << 26) | lo) as f64 / (1u64 << 53) as f64
    }
}

fn crystals(orientation: Orientation, aspect: f64) -> Crystals {
    Crystals::new(vec![Population {
        orientation,
        aspect,
        size_um: 50.0,
        weight: 1.0,
    }])
}

/// Light from a sun at elevation `h_deg` (azimuth 0; +z the zenith), travelling down.
fn sunlight(h_deg: f64) -> DVec3 {
    let h = h_deg.to_radians();
    -DVec3::new(h.cos(), 0.0, h.sin())
}

fn rays(c: &Crystals, incident: DVec3, n: f64, count: usize, seed: u64) -> Vec<Scattered> {
    let mut rng = Rng::new(seed, 0);
    let mut u = uniform(&mut rng);
    (0..count)
        .filter_map(|_| c.scatter(incident, n, false, &mut u))
        .collect()
}

fn deviation_deg(incident: DVec3, out: DVec3) -> f64 {
    incident
        .cross(out)
        .length()
        .atan2(incident.dot(out))
        .to_degrees()
}

fn min_deviation(n: f64, apex_deg: f64) -> f64 {
    let a = apex_deg.to_radians();
    (2.0 * (n * (0.5 * a).sin()).asin() - a).to_degrees()
}

/// Entered by one prism face and left by an alternate one (k → k ± 2), no reflection.
fn prism_60(s: &Scattered) -> bool {
    let (a, b) = (s.exit.entry, s.exit.exit);
    !s.exit.external
        && s.exit.reflections == 0
        && a < TOP
        && b < TOP
        && (a + 6 - b) % 6 % 3 != 0
        && (a + 6 - b) % 2 == 0
}

/// Between a basal face and a prism face, no reflection.
fn prism_90(s: &Scattered) -> bool {
    let (a, b) = (s.exit.entry, s.exit.exit);
    !s.exit.external && s.exit.reflections == 0 && ((a >= TOP) != (b >= TOP))
}

#[test]
fn halos_22_and_46_inner_edges_are_the_minimum_deviations() {
    let c = crystals(Orientation::Random, 1.0);
    let incident = sunlight(30.0);
    let mut edges = Vec::new();
    for lambda in [400.0f32, 550.0, 700.0] {
        let n = ice_n(lambda);
        let r = rays(&c, incident, n, 400_000, 1);
        for (apex, class) in [(60.0, prism_60 as fn(&Scattered) -> bool), (90.0, prism_90)] {
            let want = min_deviation(n, apex);
            let got = r
                .iter()
                .filter(|s| class(s))
                .map(|s| deviation_deg(incident, s.dir))
                .fold(f64::INFINITY, f64::min);
            println!("{lambda} nm, {apex}° prism: min deviation {got:.4}° vs {want:.4}°");
            assert!(
                got >= want - 1e-6,
                "{lambda} nm {apex}°: {got} below {want}"
            );
            assert!(got - want < 0.05, "{lambda} nm {apex}°: {got} vs {want}");
            edges.push((lambda, apex, got));
        }
    }
    // Red inside, blue outside: the inner edge moves out with falling wavelength.
    for apex in [60.0, 90.0] {
        let e: Vec<f64> = edges.iter().filter(|x| x.1 == apex).map(|x| x.2).collect();
        assert!(e[2] < e[1] && e[1] < e[0], "{apex}°: {e:?}");
    }
    // The closed forms themselves near the textbook values at 550 nm (n = 1.311).
    assert!((min_deviation(ice_n(550.0), 60.0) - 22.0).abs() < 0.2);
    assert!((min_deviation(ice_n(550.0), 90.0) - 46.0).abs() < 0.2);
}

#[test]
fn the_22_halo_is_a_bright_edge_in_the_phase_function() {
    // The whole phase function of random crystals (every path), histogrammed in 0.05°
    // bins: the 22° halo is the steepest rise between 15° and 30°, at the minimum
    // deviation (within the bin and the tolerance).
    let c = crystals(Orientation::Random, 1.0);
    let incident = sunlight(10.0);
    let n = ice_n(550.0);
    let r = rays(&c, incident, n, 1_000_000, 2);
    let bin = 0.05;
    let bins = (180.0 / bin) as usize;
    let mut h = vec![0u32; bins];
    for s in &r {
        let d = deviation_deg(incident, s.dir);
        h[((d / bin) as usize).min(bins - 1)] += 1;
    }
    // Per unit solid angle: counts over the bins' sin θ.
    let density = |i: usize| h[i] as f64 / ((i as f64 + 0.5) * bin).to_radians().sin();
    let (lo, hi) = ((15.0 / bin) as usize, (30.0 / bin) as usize);
    let steepest = (lo..hi)
        .max_by(|&a, &b| {
            (density(a + 1) - density(a))
                .partial_cmp(&(density(b + 1) - density(b)))
                .unwrap()
        })
        .unwrap();
    let edge = (steepest + 1) as f64 * bin;
    let want = min_deviation(n, 60.0);
    println!("steepest rise at {edge}° (minimum deviation {want:.3}°)");
    assert!((edge - want).abs() <= bin + 0.05, "{edge} vs {want}");
    // Brighter just outside the edge than just inside it, by far.
    let (inside, outside) = (density(steepest - 4), density(steepest + 4));
    assert!(outside > 3.0 * inside, "{inside} {outside}");
}

/// The plate's effective index for rays at elevation h through its vertical prism faces
/// (Bravais' law; Tape 1994 §3.2): n' = √(n² − sin² h) / cos h.
fn bravais(n: f64, h: f64) -> f64 {
    (n * n - h.sin().powi(2)).sqrt() / h.cos()
}

#[test]
fn sun_dogs_lie_at_the_effective_index_minimum_deviation() {
    // Thick plates (c/a = 1): in thin ones a ray from a high sun falls through the
    // height of the prism face before it reaches the alternate face and leaves by the
    // bottom, so they make no sun dogs above about 30° (the ray's slope inside is
    // tan asin(sin h / n)).
    let c = crystals(Orientation::Plates { tilt: 0.0 }, 1.0);
    let mut by_lambda = Vec::new();
    for lambda in [450.0f32, 650.0] {
        let n = ice_n(lambda);
        let mut last = 0.0;
        for h_deg in [0.0, 20.0, 40.0, 60.0] {
            let h = f64::to_radians(h_deg);
            let incident = sunlight(h_deg);
            let r = rays(&c, incident, n, 300_000, 3);
            let np = bravais(n, h);
            // Azimuth from the sun of the parhelion (the minimum deviation of the 60°
            // prism in the horizontal projection), and its distance on the sky.
            let daz = min_deviation(np, 60.0).to_radians();
            let want = (h.sin().powi(2) + h.cos().powi(2) * daz.cos())
                .acos()
                .to_degrees();
            let seen: Vec<DVec3> = r.iter().filter(|s| prism_60(s)).map(|s| -s.dir).collect();
            assert!(!seen.is_empty(), "{lambda} nm, sun at {h_deg}°: no sun dog");
            let sun = -incident;
            let got = seen
                .iter()
                .map(|v| deviation_deg(sun, *v))
                .fold(f64::INFINITY, f64::min);
            // Vertical faces keep the ray's elevation: the sun dog is level with the sun.
            for v in &seen {
                assert!((v.z.asin() - h).abs() < 1e-9);
            }
            println!("{lambda} nm, sun {h_deg}°: sun dog at {got:.4}° vs {want:.4}°");
            assert!(got >= want - 1e-6 && got - want < 0.1, "{got} vs {want}");
            // They move out as the sun climbs.
            assert!(got > last);
            last = got;
            by_lambda.push(got);
        }
        // Above the elevation where n'·sin 30° = 1 (60.75° at n = 1.31), none.
        let limit = ((n * n - 1.0) / 3.0).sqrt().acos().to_degrees();
        assert!((limit - 60.7).abs() < 0.3, "{limit}");
        let r = rays(&c, sunlight(limit + 0.5), n, 100_000, 4);
        assert_eq!(r.iter().filter(|s| prism_60(s)).count(), 0);
    }
    // Red inside (nearer the sun), blue outside, at every elevation.
    for k in 0..4 {
        assert!(by_lambda[k + 4] < by_lambda[k], "{by_lambda:?}");
    }
}

#[test]
fn circumzenithal_arc_radius_and_its_absence_above_32_degrees() {
    let c = crystals(Orientation::Plates { tilt: 0.0 }, 0.2);
    let mut elevations = Vec::new();
    for lambda in [420.0f32, 680.0] {
        let n = ice_n(lambda);
        // (30.9° is the limit at 420 nm, where n = 1.3177.)
        for h_deg in [5.0, 15.0, 25.0, 30.0] {
            let h = f64::to_radians(h_deg);
            let r = rays(&c, sunlight(h_deg), n, 200_000, 5);
            // In by the top face, out by a vertical one: the arc round the zenith at
            // elevation asin √(n² − cos² h) (Tape 1994 §3.4; Greenler 1980 ch. 2).
            let arc: Vec<f64> = r
                .iter()
                .filter(|s| s.exit.entry == TOP && s.exit.exit < TOP && s.exit.reflections == 0)
                .map(|s| (-s.dir).z.asin().to_degrees())
                .collect();
            assert!(!arc.is_empty(), "{lambda} nm, sun {h_deg}°: no arc");
            let want = (n * n - h.cos().powi(2)).sqrt().asin().to_degrees();
            for e in &arc {
                assert!(
                    (e - want).abs() < 0.1,
                    "{lambda} nm, sun {h_deg}°: {e} vs {want}"
                );
            }
            println!(
                "{lambda} nm, sun {h_deg}°: arc {:.3}° from the zenith ({} rays)",
                90.0 - want,
                arc.len()
            );
            elevations.push((lambda, h_deg, want));
        }
        // Gone above 32.2°: n² − cos² h > 1 is total internal reflection at the side face.
        // 32.2° for n = 1.31, the textbook figure; 30.9° at 420 nm, 32.5° at 680 nm.
        let limit = (n * n - 1.0).sqrt().acos().to_degrees();
        assert!((30.5..33.0).contains(&limit), "{limit}");
        assert!(((1.31f64 * 1.31 - 1.0).sqrt().acos().to_degrees() - 32.2).abs() < 0.05);
        let r = rays(&c, sunlight(limit + 0.3), n, 100_000, 6);
        let through = r
            .iter()
            .filter(|s| s.exit.entry == TOP && s.exit.exit < TOP && s.exit.reflections == 0)
            .count();
        assert_eq!(through, 0);
    }
    // Red nearer the sun (lower), blue nearer the zenith.
    for k in 0..4 {
        assert!(elevations[k].2 > elevations[k + 4].2);
    }
}

#[test]
fn external_reflection_is_fresnels_diffuse_albedo() {
    // Random crystals meet the light at cos θ distributed as 2 cos θ sin θ (the lit
    // faces weighted by projected area), so the externally reflected share is the
    // hemispherical-cosine average of the unpolarised Fresnel reflectance.
    let c = crystals(Orientation::Random, 1.0);
    let n = ice_n(550.0);
    let count = 400_000;
    let r = rays(&c, sunlight(0.0), n, count, 7);
    let share = r.iter().filter(|s| s.exit.external).count() as f64 / count as f64;
    let steps = 100_000;
    let mut want = 0.0;
    for i in 0..steps {
        let c = (i as f64 + 0.5) / steps as f64;
        let (rs, rp) = heron::optics::ice::trace::fresnel_rs_rp(c, n);
        want += 0.5 * (rs + rp) * 2.0 * c / steps as f64;
    }
    // Binomial standard error √(p(1−p)/N) ≈ 4e-4.
    println!("external reflection {share:.5} vs {want:.5}");
    assert!((share - want).abs() < 2e-3, "{share} vs {want}");
    // Rays trapped by total internal reflection (skew rays steeper than the critical
    // angle on every face they meet, which a perfect prism never releases) are rare.
    let lost = count - r.len();
    println!("{lost} of {count} rays trapped");
    assert!((lost as f64) < 1e-4 * count as f64, "{lost}");
}

#[test]
fn the_22_halo_is_weakly_radially_polarised() {
    // Fresnel transmission through the 60° prism favours p (the plane of scattering):
    // at minimum deviation S1/S0 = (T_s² − T_p²)/(T_s² + T_p²) ≈ −3.6% (radial), the
    // sign and size Können 1983 (J. Opt. Soc. Am. 73, 1629) computes for refraction
    // halos without birefringence.
    let c = crystals(Orientation::Random, 1.0);
    let n = ice_n(550.0);
    let incident = sunlight(20.0);
    let mut rng = Rng::new(8, 0);
    let mut u = uniform(&mut rng);
    let (mut s1_edge, mut n_edge, mut s1_halo, mut n_halo, mut s2) = (0.0, 0, 0.0, 0, 0.0);
    let dmin = min_deviation(n, 60.0);
    for _ in 0..400_000 {
        let Some(s) = c.scatter(incident, n, true, &mut u) else {
            continue;
        };
        let d = deviation_deg(incident, s.dir);
        if prism_60(&s) && d < dmin + 0.1 {
            s1_edge += s.s1;
            n_edge += 1;
        }
        if (dmin..dmin + 1.5).contains(&d) {
            s1_halo += s.s1;
            s2 += s.s2;
            n_halo += 1;
        }
    }
    let (edge, halo) = (s1_edge / n_edge as f64, s1_halo / n_halo as f64);
    // The closed form at minimum deviation: incidence (D + A)/2 on both faces.
    let i = ((dmin + 60.0) / 2.0).to_radians();
    let (rs, rp) = heron::optics::ice::trace::fresnel_rs_rp(i.cos(), n);
    let (ts, tp) = ((1.0 - rs).powi(2), (1.0 - rp).powi(2));
    let want = (ts - tp) / (ts + tp);
    println!(
        "S1/S0 at the edge {edge:.4} ({n_edge} rays) vs {want:.4}; over the halo's first 1.5°: {halo:.4}, S2/S0 {:.4}",
        s2 / n_halo as f64
    );
    assert!((edge - want).abs() < 0.005, "{edge} vs {want}");
    assert!(halo < -0.01 && halo > -0.08, "{halo}");
    // Mirror symmetry about the scattering plane: no S2 on average.
    assert!((s2 / n_halo as f64).abs() < 0.005);
}

// ----------------------------------------------------------------------------------
// The halo sky's table (src/sky/halo)
// ----------------------------------------------------------------------------------

use heron::sky::halo::table::{from_sun_coordinates, sun_coordinates, HaloTable, ROWS};
use heron::sky::halo::{ice_n as table_n, HaloSky};

fn plates_table(h_deg: f64, rays: usize, seed: u64) -> HaloTable {
    HaloTable::build(
        &crystals(
            Orientation::Plates {
                tilt: 0.2f64.to_radians(),
            },
            0.3,
        ),
        &table_n,
        h_deg.to_radians(),
        0.2666f64.to_radians(),
        rays,
        seed,
    )
}

#[test]
fn halo_table_integrates_to_geometric_optics_plus_diffraction() {
    // Geometric optics puts all the light somewhere (1, less the trapped rays) and
    // diffraction adds the crystals' projected area once more (Rayleigh's encircled
    // energy, 1 − 1/(πx) or so outside 90°: below 1e-3 for 50 µm crystals).
    let t = plates_table(20.0, 50_000, 1);
    for r in [0, ROWS / 2, ROWS - 1] {
        let i = t.integral(r);
        assert!((i - 2.0).abs() < 2e-3, "row {r}: ∫ = {i}");
    }
    assert!(t.lost < 1e-4, "{}", t.lost);
}

#[test]
fn halo_table_puts_the_sun_dogs_where_the_closed_form_does() {
    let h = 20f64.to_radians();
    let t = plates_table(20.0, 200_000, 2);
    let sun = DVec3::new(h.cos(), 0.0, h.sin());
    for lambda in [450.0f32, 650.0] {
        let n = ice_n(lambda);
        let daz = min_deviation(bravais(n, h), 60.0).to_radians();
        // Level with the sun, daz away in azimuth.
        let dog = DVec3::new(h.cos() * daz.cos(), h.cos() * daz.sin(), h.sin());
        let (theta, psi) = sun_coordinates(dog, sun, DVec3::Z);
        let at = |dt: f64| t.eval(theta + dt, psi, lambda);
        // Bright just outside the edge (the sun's disk spreads it by ±0.27°), dark 1°
        // inside it.
        let (outside, inside) = (at(0.3), at(-1.0));
        println!(
            "{lambda} nm: sun dog at θ {theta:.2}°, ψ {psi:.2}°: {outside:.3e} vs {inside:.3e}"
        );
        assert!(outside > 20.0 * inside, "{outside} vs {inside}");
    }
    // Coordinates round trip.
    let v = from_sun_coordinates(30.0, 80.0, sun, DVec3::Z);
    let (a, b) = sun_coordinates(v, sun, DVec3::Z);
    assert!((a - 30.0).abs() < 1e-9 && (b - 80.0).abs() < 1e-9);
}

#[test]
fn halo_tables_are_deterministic_and_follow_the_seed() {
    let (a, b, c) = (
        plates_table(35.0, 20_000, 5),
        plates_table(35.0, 20_000, 5),
        plates_table(35.0, 20_000, 6),
    );
    let mut differs = false;
    for k in 0..2000 {
        let (theta, psi, l) = (
            k as f64 * 0.09,
            (k * 37 % 180) as f64,
            360.0 + (k % 470) as f32,
        );
        assert_eq!(
            a.eval(theta, psi, l).to_bits(),
            b.eval(theta, psi, l).to_bits()
        );
        differs |= a.eval(theta, psi, l) != c.eval(theta, psi, l);
    }
    assert!(differs);
    // A sky caches its table by what it was traced from.
    let sky = || HaloSky::new(crystals(Orientation::Random, 1.0), 0.3, 0.0046, 5000, 9);
    assert!(std::sync::Arc::ptr_eq(sky().table(), sky().table()));
}

fn heron_cmd(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_heron"))
        .args(args)
        .output()
        .expect("heron runs")
}

#[test]
fn halo_profile_prints_csv_and_names_bad_flags() {
    let out = heron_cmd(&[
        "halo",
        "profile",
        "--sun-elevation",
        "10",
        "--crystals",
        "random",
        "--lambda",
        "450,650",
        "--psi",
        "0,90",
        "--from",
        "20",
        "--to",
        "24",
        "--step",
        "0.5",
        "--rays",
        "100000",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some("theta_deg,psi0_450nm,psi0_650nm,psi90_450nm,psi90_650nm")
    );
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 9);
    // The 22° halo's edge: red (650 nm) rises first, by 22.0° (its minimum deviation
    // is 21.7°), blue only past 22.3°.
    let at = |t: f64, col: usize| rows.iter().find(|r| r[0] == t).unwrap()[col];
    assert!(at(22.0, 2) > 3.0 * at(21.0, 2));
    assert!(at(22.0, 2) > at(22.0, 1));
    for (args, want) in [
        (
            vec!["--crystals", "needles"],
            "--crystals (population 1) orientation: expected one of random",
        ),
        (
            vec!["--crystals", "plates:aspect=100"],
            "--crystals (population 1) aspect: expected c/a in [0.02, 50], got 100",
        ),
        (vec!["--crystals", "plates:size=3"], "unknown key \"size\""),
        (
            vec!["--crystals", "random", "--psi", "200"],
            "--psi: expected position angles",
        ),
        (
            vec!["--crystals", "random", "--sun-radius", "9"],
            "--sun-radius: expected an angle in (0°, 5°]",
        ),
    ] {
        let mut all = vec![
            "halo",
            "profile",
            "--sun-elevation",
            "10",
            "--lambda",
            "550",
        ];
        all.extend(args);
        let out = heron_cmd(&all);
        assert_eq!(out.status.code(), Some(1));
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(want), "{err}");
        assert!(out.stdout.is_empty());
    }
}

#[test]
fn halo_scene_keys_are_checked_and_named() {
    let base = r#"
[camera]
eye = [0.0, 1.5, 0.0]
look_at = [0.0, 1.75, -1.0]
resolution = [8, 8]
[[lights]]
type = "sun"
direction = [0.0, -0.34, 0.94]
irradiance = 3.0
"#;
    let err = |sky: &str| {
        heron::scene::load::load_scene_from_str(
            &format!("{base}[sky]\n{sky}"),
            std::path::Path::new("h.toml"),
        )
        .err()
        .map(|e| e.to_string())
        .unwrap_or_default()
    };
    for (sky, want) in [
        ("model = \"halo\"\nrays = 5000\n", "sky.crystals: expected 1 to 8 populations"),
        (
            "model = \"halo\"\nrays = 5000\ncrystals = [{ orientation = \"plates\", tilt_deg = 95 }]\n",
            "sky.crystals[0].tilt_deg: expected an angle in [0°, 90°], got 95",
        ),
        (
            "model = \"halo\"\ncrystals = [{ orientation = \"random\" }]\nrays = 10\n",
            "sky.rays: expected 1000 to",
        ),
        (
            "model = \"halo\"\ncrystals = [{ orientation = \"random\" }]\ndroplet_radius = 1.0\n",
            "sky.droplet_radius: applies to the water-drop skies, not halo",
        ),
        (
            "model = \"halo\"\ncrystals = [{ orientation = \"random\" }]\nzenith = [0, 0, 0]\n",
            "sky.zenith: expected a non-zero direction",
        ),
        (
            "model = \"descartes\"\ncrystals = [{ orientation = \"random\" }]\n",
            "sky.crystals: applies to halo, not descartes",
        ),
        (
            "model = \"halo\"\ncrystals = [{ orientation = \"random\", colour = 1 }]\n",
            "unknown key \"colour\" at sky.crystals[0] (expected one of orientation, aspect, tilt_deg, size_um, weight)",
        ),
    ] {
        let e = err(sky);
        assert!(e.contains(want), "{sky}: {e}");
    }
    // A good one loads, and its sky is a halo placed for the sun 20° up.
    let s = heron::scene::load::load_scene_from_str(
        &format!("{base}[sky]\nmodel = \"halo\"\nrays = 5000\ncrystals = [{{ orientation = \"random\" }}]\n"),
        std::path::Path::new("h.toml"),
    )
    .expect("loads");
    let sky = s.sky.as_ref().expect("a sky");
    match &sky.shape {
        heron::sky::table::SkyShape::Halo(h) => {
            assert!((h.table.sun_elevation.to_degrees() - 19.88).abs() < 0.05)
        }
        _ => panic!("a halo sky"),
    }
}
