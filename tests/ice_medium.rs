//! The ice-crystal medium (issue 40, part 4): checks that fail when its physics is
//! wrong. Sampling (chi-square) and the white furnace are with the other media, in
//! tests/media.rs and tests/media_estimators.rs.
//!
//! - σ_t = 2 N ⟨A⟩ against the mean projected area of the prism over directions, found
//!   here by quadrature (Cauchy's S/4 is what the medium uses).
//! - The phase function integrates to 1 over the sphere, with and without the cutoff.
//! - The 22° and 46° halos' inner edges at the prisms' minimum deviation per wavelength,
//!   red inside.
//! - The forward cutoff keeps σ_s p outside its cone and removes what is inside.
//! - The table is deterministic in its seed.
//! - Bad keys are named.
mod common;

use glam::Vec3;
use heron::medium::ice::{self, IceMedium, IceSpec};
use heron::medium::{Medium, Optics};
use heron::optics::ice::{HexPrism, Orientation, Population};
use heron::scene::load::load_scene_from_str;
use heron::spectrum::SampledWavelengths;

fn plates(size_um: f64, aspect: f64) -> Population {
    Population {
        orientation: Orientation::Random,
        aspect,
        size_um,
        weight: 1.0,
    }
}

fn spec(rays: usize, cutoff: f64) -> IceSpec {
    IceSpec {
        populations: vec![plates(60.0, 0.5)],
        number_density: 1e6,
        rays,
        seed: 0,
        forward_cutoff_deg: cutoff,
    }
}

fn medium(s: IceSpec) -> Medium {
    Medium::homogeneous(Optics::Ice(IceMedium::new(s)))
}

/// p(θ) at one wavelength, θ in degrees.
fn p_at(m: &Medium, theta_deg: f64, lambda: f32) -> f64 {
    let wl = SampledWavelengths::<1>::new([lambda], [1.0]);
    let t = theta_deg.to_radians();
    let d_out = Vec3::new(t.sin() as f32, 0.0, t.cos() as f32);
    m.phase(Vec3::Z, d_out, &wl).0[0] as f64
}

/// σ_s at one wavelength.
fn sigma_s(m: &Medium, lambda: f32) -> f64 {
    m.sigma_s(&SampledWavelengths::<1>::new([lambda], [1.0])).0[0] as f64
}

/// Minimum deviation of a prism of apex `a_deg` at index n, degrees.
fn min_deviation(n: f64, a_deg: f64) -> f64 {
    let a = a_deg.to_radians();
    (2.0 * (n * (0.5 * a).sin()).asin() - a).to_degrees()
}

#[test]
fn extinction_is_twice_the_mean_projected_area() {
    // ⟨A⟩ over directions by a Fibonacci sphere of 200 000 points (the projected area
    // is continuous, so the mean converges fast), against Cauchy's S/4 in the medium.
    for (a, c_over_a) in [(60.0, 0.5), (20.0, 3.0), (100.0, 0.05)] {
        let prism = HexPrism::new(c_over_a);
        let n = 200_000;
        let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
        let mean: f64 = (0..n)
            .map(|i| {
                let z = 1.0 - (2.0 * i as f64 + 1.0) / n as f64;
                let r = (1.0 - z * z).sqrt();
                let phi = golden * i as f64;
                prism.projected_area(glam::DVec3::new(r * phi.cos(), r * phi.sin(), z))
            })
            .sum::<f64>()
            / n as f64;
        let want = 2.0 * 1e6 * mean * a * a * 1e-12;
        let m = IceMedium::new(IceSpec {
            populations: vec![plates(a, c_over_a)],
            rays: 4096,
            ..spec(4096, 0.0)
        });
        assert!(
            (m.sigma_t_full / want - 1.0).abs() < 1e-3,
            "a = {a}, c/a = {c_over_a}: σ_t {} against 2N⟨A⟩ = {want}",
            m.sigma_t_full
        );
        // No absorption: σ_s = σ_t at every wavelength.
        let mm = Medium::homogeneous(Optics::Ice(m));
        for l in [400.0, 550.0, 700.0] {
            let wl = SampledWavelengths::<1>::new([l], [1.0]);
            assert_eq!(mm.sigma_t(&wl).0[0], mm.sigma_s(&wl).0[0]);
            assert!((mm.sigma_t(&wl).0[0] as f64 / want - 1.0).abs() < 1e-3);
        }
    }
    // Two populations mix by number: σ_t of a 3:1 mixture is 3/4 of one's plus 1/4 of
    // the other's.
    let one = IceMedium::new(spec(4096, 0.0)).sigma_t_full;
    let other = IceMedium::new(IceSpec {
        populations: vec![plates(20.0, 3.0)],
        ..spec(4096, 0.0)
    })
    .sigma_t_full;
    let mix = IceMedium::new(IceSpec {
        populations: vec![
            Population {
                weight: 3.0,
                ..plates(60.0, 0.5)
            },
            plates(20.0, 3.0),
        ],
        ..spec(4096, 0.0)
    })
    .sigma_t_full;
    assert!((mix / (0.75 * one + 0.25 * other) - 1.0).abs() < 1e-9);
    // The number density scales σ and nothing else.
    let twice = IceMedium::new(IceSpec {
        number_density: 2e6,
        ..spec(4096, 0.0)
    });
    assert_eq!(twice.sigma_t_full, 2.0 * one);
}

#[test]
fn phase_function_integrates_to_one() {
    // ∫ p dΩ = 2π ∫ p(θ) sin θ dθ by the midpoint rule on 0.001° steps (the table's
    // bins are 0.02° and wider, so only the steps that straddle an edge err), at
    // wavelengths on and between nodes, with and without the cutoff.
    for cutoff in [0.0, 1.0] {
        let m = medium(spec(1 << 16, cutoff));
        for lambda in [440.0, 553.0, 700.0] {
            let steps = 180_000;
            let h = (180.0 / steps as f64).to_radians();
            let total: f64 = (0..steps)
                .map(|k| {
                    let t = (k as f64 + 0.5) * h;
                    p_at(&m, t.to_degrees(), lambda) * t.sin() * h
                })
                .sum::<f64>()
                * 2.0
                * std::f64::consts::PI;
            println!("cutoff {cutoff}°, {lambda} nm: ∫p dΩ = {total:.6}");
            assert!((total - 1.0).abs() < 2e-3, "{cutoff}, {lambda}: {total}");
        }
    }
}

#[test]
fn halos_begin_at_the_minimum_deviations() {
    // At two nodes (440 and 660 nm, so no mixture of nodes blurs the edge), the steepest
    // rise of p between neighbouring 0.1° bins is the halo's inner edge: within 0.1° of
    // D = 2 asin(n sin(A/2)) − A for A = 60° and 90°, red inside blue. The default rays.
    let m = medium(spec(ice::DEFAULT_RAYS, 0.0));
    let ior = heron::spectrum::ior::named("ice").unwrap();
    let mut edges = Vec::new();
    for lambda in [440.0f32, 660.0] {
        let n = ior.eval(lambda) as f64;
        for (apex, lo) in [(60.0, 20.0), (90.0, 44.0)] {
            let d = min_deviation(n, apex);
            // Bin centres over the 4° from lo; the rise between bins j and j + 1 is at the
            // edge between them.
            let centres: Vec<f64> = (0..40).map(|k| lo + 0.05 + 0.1 * k as f64).collect();
            let p: Vec<f64> = centres.iter().map(|&t| p_at(&m, t, lambda)).collect();
            let j = (0..p.len() - 1)
                .max_by(|&a, &b| (p[a + 1] - p[a]).total_cmp(&(p[b + 1] - p[b])))
                .unwrap();
            let edge = centres[j] + 0.05;
            println!("{lambda} nm, {apex}° prisms: edge at {edge:.2}°, D = {d:.3}°");
            assert!(
                (edge - d).abs() < 0.1,
                "{lambda} nm, A = {apex}°: {edge} vs {d}"
            );
            // A halo, not a wiggle: just outside the edge is brighter than just inside.
            let (inside, outside) = (p_at(&m, d - 1.0, lambda), p_at(&m, d + 0.3, lambda));
            let contrast = if apex == 60.0 { 3.0 } else { 1.3 };
            assert!(
                outside > contrast * inside,
                "{lambda} nm, A = {apex}°: {outside} vs {inside} inside"
            );
            edges.push(edge);
        }
    }
    // Red (660 nm) inside blue (440 nm), for both halos, as found in the table.
    assert!(edges[2] < edges[0] && edges[3] < edges[1], "{edges:?}");
}

#[test]
fn forward_cutoff_keeps_the_scattering_outside_its_cone() {
    let full = medium(spec(1 << 16, 0.0));
    let cut_m = IceMedium::new(spec(1 << 16, 1.0));
    let f = cut_m.forward_fraction.clone();
    let cut = Medium::homogeneous(Optics::Ice(cut_m));
    // Diffraction is half the scattering and lies within a few degrees; the rays through
    // parallel faces leave undeviated: together most of it is within 1°.
    println!("forward fractions within 1°: {f:?}");
    assert!(f.iter().all(|&f| (0.5..0.9).contains(&f)), "{f:?}");
    // At the nodes (440 and 620 nm) σ_s' p' = σ_s p exactly; between them σ_s' is
    // interpolated in λ apart from the nodes' mixture of p', a second-order difference
    // (f changes by 0.1% per node): 1.4e-4 at 450 nm.
    for lambda in [440.0f32, 620.0] {
        assert_eq!(p_at(&cut, 0.5, lambda), 0.0);
        assert!(p_at(&full, 0.5, lambda) > 0.0);
        for theta in [1.5, 10.0, 22.5, 46.5, 120.0, 179.0] {
            let (a, b) = (
                sigma_s(&cut, lambda) * p_at(&cut, theta, lambda),
                sigma_s(&full, lambda) * p_at(&full, theta, lambda),
            );
            assert!(
                (a / b - 1.0).abs() < 1e-5,
                "{lambda} nm, {theta}°: σ_s p {a} with the cutoff, {b} without"
            );
        }
    }
}

#[test]
fn tables_are_deterministic_in_their_seed() {
    let a = IceMedium::traced(spec(1 << 14, 0.0));
    let b = IceMedium::traced(spec(1 << 14, 0.0));
    let c = IceMedium::traced(IceSpec {
        seed: 7,
        ..spec(1 << 14, 0.0)
    });
    let (a, b, c) = (
        Medium::homogeneous(Optics::Ice(a)),
        Medium::homogeneous(Optics::Ice(b)),
        Medium::homogeneous(Optics::Ice(c)),
    );
    let values = |m: &Medium| -> Vec<u64> {
        (0..1800)
            .map(|k| p_at(m, 0.05 + 0.1 * k as f64, 553.0).to_bits())
            .collect()
    };
    assert_eq!(values(&a), values(&b));
    assert_ne!(values(&a), values(&c));
}

#[test]
fn bad_ice_keys_are_named() {
    let dir = std::env::temp_dir();
    let err = |medium: &str| {
        let toml = common::scenes::furnace_sphere(medium, "").replace(
            "max_depth = 1000",
            "max_depth = 1000\nintegrator = \"path\"",
        );
        match load_scene_from_str(&toml, &dir.join("ice-keys.toml")) {
            Ok(_) => panic!("{medium}: loaded"),
            Err(e) => e.to_string(),
        }
    };
    let cases = [
        (
            r#"{ type = "ice", crystals = [{ orientation = "plates" }], number_density = 1e5 }"#,
            "shapes[0].medium.crystals[0].orientation: an ice medium takes orientation = \"random\", got \"plates\"",
        ),
        (
            r#"{ type = "ice", number_density = 1e5 }"#,
            "shapes[0].medium.crystals: missing required key",
        ),
        (
            r#"{ type = "ice", crystals = [{ orientation = "random" }] }"#,
            "shapes[0].medium.number_density: missing required key (expected crystals per m³)",
        ),
        (
            r#"{ type = "ice", crystals = [{ orientation = "random", aspect = 100 }], number_density = 1e5 }"#,
            "shapes[0].medium.crystals[0].aspect: expected c/a in [0.02, 50]",
        ),
        (
            r#"{ type = "ice", crystals = [{ orientation = "random" }], number_density = 1e5, rays = 10 }"#,
            "shapes[0].medium.rays: expected 1000 to",
        ),
        (
            r#"{ type = "ice", crystals = [{ orientation = "random" }], number_density = 1e5, radius_mm = 0.01 }"#,
            "shapes[0].medium.radius_mm: applies to type = \"mie\", not to type = \"ice\"",
        ),
        (
            r#"{ type = "ice", crystals = [{ orientation = "random" }], number_density = 1e5, g = 0.5 }"#,
            "shapes[0].medium.g: applies to type = \"henyey-greenstein\", not to type = \"ice\"",
        ),
        (
            r#"{ type = "ice", crystals = [{ orientation = "random" }], number_density = 1e5, forward_cutoff = 20 }"#,
            "shapes[0].medium.forward_cutoff: expected degrees in [0, 10]",
        ),
        (
            r#"{ type = "mie", radius_mm = 0.01, number_density = 1e5, crystals = [{ orientation = "random" }] }"#,
            "shapes[0].medium.crystals: applies to type = \"ice\", not to type = \"mie\"",
        ),
        (
            r#"{ type = "henyey-greenstein", sigma_s = 1.0, forward_cutoff = 1 }"#,
            "shapes[0].medium.forward_cutoff: applies to type = \"mie\" or \"ice\", not to type = \"henyey-greenstein\"",
        ),
        (
            r#"{ type = "henyey-greenstein", sigma_s = 1.0, rays = 5000 }"#,
            "shapes[0].medium.rays: applies to type = \"ice\", not to type = \"henyey-greenstein\"",
        ),
    ];
    for (medium, want) in cases {
        let e = err(medium);
        assert!(e.contains(want), "{medium}:\n  got {e}\n  want {want}");
    }
}
