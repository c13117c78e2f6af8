//! Stochastic progressive photon mapping (`integrator = "sppm"`) through the whole
//! renderer, against closed forms and against the other integrators:
//!
//! - energy: inside a closed diffuse sphere around a point light, the photons carry the
//!   interreflection series (Σ ρᵏ, k ≥ 1, times the direct light) and the camera pass
//!   the direct light, each to its closed form;
//! - consistency: on the Cornell box and `caustic-glass`, the error of SPPM's image
//!   against a converged BDPT reference falls as the iterations grow and the radii
//!   shrink, to within a stated tolerance;
//! - dispersion: 4 lanes (companions ending at every refraction, on the camera side and
//!   the photons') and 1 lane estimate the same image;
//! - determinism for any thread count, checkpoints that resume to the same bytes, shards
//!   that merge, and clear errors for what it refuses.
//!
//! SPPM's pixels are not independent (neighbours gather the same photons) and its
//! estimate is biased by the radius at any finite iteration count, so the statistical
//! checks here take their standard errors from independent seeds, never from the
//! spread of pixels.
mod common;

use common::render::mean_se;
use heron::checkpoint::{merge, Checkpoint, Shard};
use heron::film::fixed::to_f64;
use heron::film::Film;
use heron::render::{render, render_state, RenderOptions};
use heron::scene::load::load_scene_from_str;
use heron::scene::Scene;
use heron::settings::IntegratorKind;
use std::path::Path;

fn load(toml: &str) -> Scene {
    load_scene_from_str(toml, Path::new("sppm-test.toml")).unwrap_or_else(|e| panic!("{e}"))
}

fn scene_file(name: &str, w: u32, h: u32) -> Scene {
    let mut s = heron::scene::load_scene(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scenes")
            .join(name),
    )
    .unwrap();
    s.camera = s.camera.resized(w, h).unwrap();
    s
}

fn sppm(
    scene: &Scene,
    iterations: u32,
    seed: u64,
    set: impl FnOnce(&mut RenderOptions),
) -> Checkpoint {
    let mut o = RenderOptions::from_scene(scene);
    o.settings.integrator = IntegratorKind::Sppm;
    o.settings.spp = iterations;
    o.settings.seed = seed;
    set(&mut o);
    let (state, stats) = render_state(scene, &o).unwrap();
    assert_eq!(stats.nonfinite, 0, "non-finite samples or deposits");
    state
}

/// The mean over the pixels of Y of the camera pass's light (the direct light) and of
/// the photons' estimate.
fn parts_y(c: &Checkpoint) -> (f64, f64) {
    let p = &c.film.planes;
    let n = p.good.len() as f64;
    let direct = p
        .xyz
        .chunks_exact(3)
        .zip(&p.good)
        .map(|(s, &g)| to_f64(s[1]) / g.max(1) as f64)
        .sum::<f64>()
        / n;
    let photons =
        p.splat.chunks_exact(3).map(|s| to_f64(s[1])).sum::<f64>() / n / c.film.spp_done as f64;
    (direct, photons)
}

#[test]
fn photons_in_a_closed_diffuse_sphere_carry_the_interreflection_series() {
    // A point light of intensity I at the centre of a closed diffuse sphere of radius R
    // and albedo ρ: the direct light is L₀ = ρI/(πR²) everywhere, and every reflection
    // stays in the sphere, so the irradiance series gives L = L₀/(1 − ρ). The camera
    // pass estimates L₀ and the photons (one bounce or more) L₀ ρ/(1 − ρ). Radiance is
    // uniform, and the sphere's area within distance r of a point on it is exactly πr²
    // (a cap of height r²/2R), so the density estimate has no bias here at any radius.
    // ρ = 0.6, I = π, R = 1: L₀ = 0.6, photons 0.9.
    let scene = load(
        r#"
[camera]
eye = [0.3, 0.1, 0.0]
look_at = [1.0, 0.2, 0.3]
resolution = [32, 32]
[render]
max_depth = 100000
[materials.wall]
type = "lambertian"
rho_d = { spectrum = "E", scale = 0.6 }
[[shapes]]
type = "sphere"
center = [0.0, 0.0, 0.0]
radius = 1.0
material = "wall"
[[lights]]
type = "point"
position = [0.0, 0.0, 0.0]
intensity = { spectrum = "E", scale = 3.14159265 }
"#,
    );
    // Seeds are independent renders; 6 of 16 iterations resolve each part to about
    // 0.3% (the photons' seed-to-seed spread), far below a missing bounce (ρ = 0.6 of
    // the series) or a lost 1/π (a factor of 3).
    let (mut d, mut p) = (Vec::new(), Vec::new());
    for seed in 0..6 {
        let (a, b) = parts_y(&sppm(&scene, 16, seed, |_| {}));
        d.push(a);
        p.push(b);
    }
    let ((md, sd), (mp, sp)) = (mean_se(&d), mean_se(&p));
    assert!(
        (md - 0.6).abs() < 4.0 * sd + 1e-3,
        "direct {md} ± {sd}, expected 0.6"
    );
    assert!(
        (mp - 0.9).abs() < 4.0 * sp + 2e-3,
        "photons {mp} ± {sp}, expected 0.9"
    );
}

/// The relative RMS difference of Y between two films over regions of `r` × `r` pixels
/// (region means, so that the per-pixel noise of the reference matters less).
fn region_error(a: &Film, b: &Film, r: u32) -> f64 {
    let (w, h) = (a.width, a.height);
    let (mut num, mut den) = (0.0, 0.0);
    for ry in 0..h / r {
        for rx in 0..w / r {
            let (mut sa, mut sb) = (0.0, 0.0);
            for y in ry * r..(ry + 1) * r {
                for x in rx * r..(rx + 1) * r {
                    let i = (y * w + x) as usize;
                    sa += a.xyz[i][1] as f64;
                    sb += b.xyz[i][1] as f64;
                }
            }
            num += (sa - sb).powi(2);
            den += sb * sb;
        }
    }
    (num / den).sqrt()
}

fn bdpt_reference(scene: &Scene, spp: u32) -> Film {
    let mut o = RenderOptions::from_scene(scene);
    o.settings.integrator = IntegratorKind::Bdpt;
    o.settings.spp = spp;
    o.settings.seed = 1234;
    render(scene, &o).unwrap().0
}

/// The error of SPPM's image against the reference at each iteration count.
fn errors(scene: &Scene, reference: &Film, iterations: &[u32]) -> Vec<f64> {
    iterations
        .iter()
        .map(|&i| region_error(&sppm(scene, i, 7, |_| {}).film.image(), reference, 4))
        .collect()
}

// Measured (2026-12-03, initial radius 4 pixel footprints): Cornell box 0.120, 0.0054,
// 0.0016 at 2, 16 and 256 iterations; caustic-glass 0.128, 0.056, 0.018, where two BDPT
// references of 1024 spp with other seeds differ by 0.0115 (each about 0.008 from the
// truth), so the last figure is mostly SPPM's remaining noise and bias. The tolerance,
// 0.03, fails an estimator that stalls at the 16-iteration error on the caustic (0.056)
// and any missing factor of the photons' part (0.1 and more on both scenes).
#[test]
fn sppm_converges_to_bdpt_on_the_cornell_box() {
    let scene = scene_file("cornell-box.toml", 48, 48);
    let reference = bdpt_reference(&scene, 1024);
    let e = errors(&scene, &reference, &[2, 16, 256]);
    eprintln!("cornell-box: region errors {e:?}");
    assert!(e[0] > e[1] && e[1] > e[2], "errors do not fall: {e:?}");
    assert!(e[2] < 0.03, "after 256 iterations the error is {}", e[2]);
}

#[test]
fn sppm_converges_to_bdpt_on_the_glass_caustic() {
    let scene = scene_file("caustic-glass.toml", 64, 48);
    let reference = bdpt_reference(&scene, 1024);
    let e = errors(&scene, &reference, &[2, 16, 256]);
    eprintln!("caustic-glass: region errors {e:?}");
    assert!(e[0] > e[1] && e[1] > e[2], "errors do not fall: {e:?}");
    assert!(e[2] < 0.03, "after 256 iterations the error is {}", e[2]);
}

/// The dense-flint caustic (`common::scenes::flint_caustic`) at 32 × 24: refraction
/// paths only, which end the companions on both sides.
fn flint() -> String {
    common::scenes::flint_caustic(32, 24)
}

#[test]
fn four_lanes_and_one_estimate_the_same_dispersive_image() {
    // With the same radii (the same seed's camera paths set them), the lane counts
    // differ only in how the spectrum is sampled; each region's mean X, Y, Z over 8
    // seeds per lane count is compared by a two-sample z-test at 4 standard errors.
    let scene = load(&flint());
    let regions = |film: &Film| -> Vec<f64> {
        let r = 8;
        let mut out = Vec::new();
        for ry in 0..film.height / r {
            for rx in 0..film.width / r {
                for c in 0..3 {
                    let mut s = 0.0;
                    for y in ry * r..(ry + 1) * r {
                        for x in rx * r..(rx + 1) * r {
                            s += film.xyz[(y * film.width + x) as usize][c] as f64;
                        }
                    }
                    out.push(s / (r * r) as f64);
                }
            }
        }
        out
    };
    let stats = |lanes: usize, seeds: std::ops::Range<u64>| {
        let films: Vec<Vec<f64>> = seeds
            .map(|s| {
                regions(
                    &sppm(&scene, 32, s, |o| {
                        o.settings.lanes = heron::settings::Lanes::from_count(lanes as i64).unwrap()
                    })
                    .film
                    .image(),
                )
            })
            .collect();
        (0..films[0].len())
            .map(|k| mean_se(&films.iter().map(|f| f[k]).collect::<Vec<_>>()))
            .collect::<Vec<_>>()
    };
    let (four, one) = (stats(4, 0..8), stats(1, 100..108));
    let mut worst = 0.0f64;
    for (k, ((a, sa), (b, sb))) in four.iter().zip(&one).enumerate() {
        let z = (a - b) / (sa * sa + sb * sb).sqrt().max(1e-12);
        worst = worst.max(z.abs());
        assert!(
            z.abs() < 4.0,
            "region value {k}: 4 lanes {a} ± {sa}, 1 lane {b} ± {sb}"
        );
    }
    eprintln!("lanes: worst |z| {worst:.2} over {} values", four.len());
}

#[test]
fn the_image_does_not_depend_on_the_thread_count_and_resumes_to_the_same_bytes() {
    let scene = load(&flint());
    let by_threads: Vec<Vec<u8>> = [1usize, 2, 3]
        .iter()
        .map(|&t| sppm(&scene, 6, 3, |o| o.threads = t).to_bytes())
        .collect();
    assert!(by_threads[0] == by_threads[1] && by_threads[1] == by_threads[2]);

    // Stopped after 2 of 6 iterations (SIGINT's flag, set by the progress callback),
    // checkpointed, then resumed: the bytes of the render never stopped.
    let dir = tempfile_dir();
    let path = dir.join("sppm.heronfilm");
    let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let flag = stop.clone();
    let part = sppm(&scene, 6, 3, |o| {
        o.stop = Some(stop.clone());
        o.checkpoint = Some((path.clone(), std::time::Duration::ZERO));
        o.progress = Some(std::sync::Arc::new(move |done, _| {
            if done == 2 {
                flag.store(true, std::sync::atomic::Ordering::Relaxed);
            }
        }));
    });
    assert_eq!(part.film.spp_done, 2);
    let saved = Checkpoint::read(&path).unwrap();
    assert!(
        saved.film.integrator.is_some(),
        "the checkpoint keeps the radii"
    );
    let resumed = sppm(&scene, 6, 3, |o| {
        o.resume = Some(std::sync::Arc::new(saved))
    });
    assert_eq!(resumed.to_bytes(), by_threads[0]);
}

#[test]
fn shards_are_independent_chains_that_merge_into_their_weighted_mean() {
    let scene = load(&flint());
    let parts: Vec<(std::path::PathBuf, Checkpoint)> = (0..2)
        .map(|k| {
            let c = sppm(&scene, 6, 5, |o| {
                o.shard = Some(Shard { index: k, count: 2 })
            });
            (format!("part-{k}").into(), c)
        })
        .collect();
    let merged = merge(&parts).unwrap();
    assert_eq!(merged.film.spp_done, 6);
    assert!(
        merged.film.integrator.is_none(),
        "a merged film is not resumable"
    );
    // Each shard is an SPPM render of 3 iterations from the initial radii: the merged
    // image is the mean of the two parts' images, pixel by pixel.
    let (a, b, m) = (
        parts[0].1.film.image(),
        parts[1].1.film.image(),
        merged.film.image(),
    );
    for i in 0..m.xyz.len() {
        for c in 0..3 {
            let want = 0.5 * (a.xyz[i][c] as f64 + b.xyz[i][c] as f64);
            let got = m.xyz[i][c] as f64;
            assert!(
                (got - want).abs() <= 1e-5 * want.abs().max(1e-3),
                "pixel {i}: {got} vs {want}"
            );
        }
    }
    // The shards are different chains (other iterations' numbers), not copies.
    assert_ne!(a.xyz, b.xyz);
}

#[test]
fn what_photon_mapping_refuses_is_named() {
    let scene = load(&flint());
    let mut o = RenderOptions::from_scene(&scene);
    o.settings.integrator = IntegratorKind::Sppm;
    o.variance = true;
    let e = render(&scene, &o).unwrap_err().to_string();
    assert!(
        e.contains("--variance") && e.contains("photon mapping"),
        "{e}"
    );

    let bad = flint().replace("max_depth = 8", "max_depth = 8\nsppm_alpha = 1.5");
    let e = load_scene_from_str(&bad, Path::new("a.toml"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("render.sppm_alpha") && e.contains("(0, 1)"),
        "{e}"
    );
    let bad = flint().replace("max_depth = 8", "max_depth = 8\nsppm_radius = -1.0");
    let e = load_scene_from_str(&bad, Path::new("a.toml"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("render.sppm_radius"), "{e}");
    let bad = flint().replace("max_depth = 8", "max_depth = 8\nsppm_photons = -3");
    let e = load_scene_from_str(&bad, Path::new("a.toml"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("render.sppm_photons"), "{e}");
}

fn tempfile_dir() -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("heron-sppm-test-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Where the central ray of the beam at `lambda` (from the middle of the slit, along the
/// sun) meets the screen, by `heron trace`.
fn screen_point(scene: &Scene, accel: &heron::accel::embree::Scene, lambda: f32) -> glam::Vec3 {
    let slit = match &scene.lights[0] {
        heron::light::Light::Sun(s) => s.portal.unwrap(),
        _ => panic!("the sun is light 0"),
    };
    let centre = slit.origin + 0.5 * slit.edge1 + 0.5 * slit.edge2;
    let dir = glam::Vec3::new(0.8370, 0.5473, 0.0);
    let rep =
        heron::trace::trace(scene, accel, centre - 0.01 * dir, dir, lambda, &[], None).unwrap();
    let last = rep.events.last().unwrap();
    assert_eq!(
        last.material.as_deref(),
        Some("screen"),
        "{lambda} nm: {rep:?}"
    );
    glam::Vec3::from(last.position)
}

/// The film position whose camera ray at `lambda` (through the lens, when it passes it)
/// lands on the screen at `target`: Newton's method on the film position, from `guess`,
/// with the Jacobian by central differences of `heron trace`'s rays.
fn film_position_of(
    scene: &Scene,
    accel: &heron::accel::embree::Scene,
    lambda: f32,
    target: glam::Vec3,
    guess: (f64, f64),
) -> (f64, f64) {
    let land = |x: f64, y: f64| -> glam::DVec3 {
        let cam = &scene.camera;
        let d = cam.direction(x as f32, y as f32);
        let rep = heron::trace::trace(scene, accel, cam.eye, d, lambda, &[], None).unwrap();
        let last = rep.events.last().unwrap();
        assert_eq!(
            last.material.as_deref(),
            Some("screen"),
            "({x}, {y}) {lambda} nm: {rep:?}"
        );
        glam::Vec3::from(last.position).as_dvec3()
    };
    // Screen coordinates: along its edge in the xy plane and along z.
    let t = target.as_dvec3();
    let along = glam::DVec3::new(0.492570, 0.753300, 0.0).normalize();
    let coords = |p: glam::DVec3| glam::DVec2::new((p - t).dot(along), p.z - t.z);
    let (mut x, mut y) = guess;
    for _ in 0..8 {
        let f = coords(land(x, y));
        if f.length() < 1e-7 {
            break;
        }
        let h = 0.25;
        let fx = (coords(land(x + h, y)) - coords(land(x - h, y))) / (2.0 * h);
        let fy = (coords(land(x, y + h)) - coords(land(x, y - h))) / (2.0 * h);
        let det = fx.x * fy.y - fy.x * fx.y;
        x -= (f.x * fy.y - fy.x * f.y) / det;
        y -= (fx.x * f.y - f.x * fx.y) / det;
    }
    (x, y)
}

#[test]
fn the_spectrum_seen_through_the_magnifier_lies_where_heron_trace_sends_each_band() {
    // scenes/lens-over-spectrum.toml at 192×144 with 47 bins of 10 nm and uniform
    // wavelengths: the iterations' heroes are stratified, so 188 iterations give each
    // bin 4 wavelengths spread over it, whose rays the prediction traces. The prism ends the companions, so one lane is
    // enough (and 188 iterations of it cost what 47 would with 4 lanes).
    // The sun's disk shrunk to 0.02° (from 0.2666°): each band's image is then a few
    // pixels wide, over which the magnifier's distortion is well below a pixel; with the
    // real sun the bands near the lens's rim are 20 pixels wide and stretched more on
    // their outer side, which moves their centroids outward by up to 3 pixels.
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/lens-over-spectrum.toml");
    let text = std::fs::read_to_string(&path).unwrap().replace(
        "type = \"sun\"\n",
        "type = \"sun\"\nangular_radius = 0.02\n",
    );
    assert!(text.contains("angular_radius = 0.02"));
    let mut scene = load_scene_from_str(&text, &path).unwrap();
    scene.camera = scene.camera.resized(192, 144).unwrap();
    let state = sppm(&scene, 188, 2, |o| {
        o.settings.lanes = heron::settings::Lanes::One;
        o.settings.spectral_bins = 47;
        o.settings.wavelengths = heron::settings::WavelengthSampler::Uniform;
    });
    let film = state.film.image();
    let renderer = heron::render::Renderer::new(&scene).unwrap();
    let accel = renderer.accel();
    let (bins, data) = film.spectral.as_ref().unwrap();
    let (w, h, nb) = (film.width as usize, film.height as usize, bins.count);
    for lambda in [455.0f32, 555.0, 655.0] {
        let k = bins.index(lambda);
        let centre = bins.centre(k);
        // The band's image: its centroid first over the whole image, then, along the
        // dispersion (x), within 6 rows of the traced point: the band is taller than the
        // lens, whose rim cuts it, so its centroid across the dispersion tells where the
        // rim is rather than where the ray goes.
        let value = |x: usize, y: usize| (data[(y * w + x) * nb + k] as f64).max(0.0);
        let (mut sx, mut sy, mut s) = (0.0, 0.0, 0.0);
        for y in 0..h {
            for x in 0..w {
                sx += value(x, y) * (x as f64 + 0.5);
                sy += value(x, y) * (y as f64 + 0.5);
                s += value(x, y);
            }
        }
        assert!(s > 0.0, "{centre} nm: the band is not in the image");
        // The traced position: the mean over the heroes the iterations put in this bin
        // (each iteration's one wavelength, as the render drew them), each ray traced to
        // the screen and from the camera back to that point.
        let heroes: Vec<f32> = (0..188)
            .map(|i| {
                heron::integrator::sppm::iteration_wavelengths::<1>(
                    heron::settings::WavelengthSampler::Uniform,
                    2,
                    i,
                )
                .lambda[0]
            })
            .filter(|&l| bins.index(l) == k)
            .collect();
        assert!(heroes.len() >= 3, "{centre} nm: {heroes:?}");
        let (mut tx, mut ty) = (0.0, 0.0);
        for &l in &heroes {
            let target = screen_point(&scene, accel, l);
            let (x, y) = film_position_of(&scene, accel, l, target, (sx / s, sy / s));
            tx += x / heroes.len() as f64;
            ty += y / heroes.len() as f64;
        }
        let (mut sx, mut s) = (0.0, 0.0);
        let row = ty.floor() as i64;
        for y in (row - 6).max(0)..(row + 7).min(h as i64) {
            for x in 0..w {
                sx += value(x, y as usize) * (x as f64 + 0.5);
                s += value(x, y as usize);
            }
        }
        let cx = sx / s;
        eprintln!("{centre} nm: centroid x {cx:.2}, traced ({tx:.2}, {ty:.2})");
        assert!(
            (cx - tx).abs() < 1.0,
            "{centre} nm: centroid x {cx:.2}, traced x {tx:.2}"
        );
    }
}
