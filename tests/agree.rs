//! Every integrator agrees with every other on every bundled scene they both accept:
//! the integrator a user picks changes the noise, never the answer (issue 41).
//!
//! Each scene of `scenes/` is rendered, at a reduced size, by every integrator that
//! accepts it (`whitted`, `path`, `lighttrace`, `bdpt`, `sppm`), and each comparable
//! pair is held to `heron compare`'s region z-test (`heron::compare`, the code behind
//! the CLI): linear sRGB with standard errors from the variance channels (`--variance`;
//! from the spread within each region where an image has none: `sppm`, and the Stokes
//! components), and for polarised scenes S1, S2 and S3 too. The family of every pair's
//! tests is held at α = 0.01 (Šidák over the pairs, then over each pair's tests), so a
//! correct renderer fails this test with probability 0.01 at most, and, the renders
//! being deterministic, either always or never.
//!
//! What is compared, and why not everything with everything (the transport each
//! integrator cannot carry, which no sample count fixes):
//!
//! - **light tracing** reaches the camera only from a diffuse or glossy vertex: pixels
//!   that see a specular surface or the sky first are black in it. Its pairs compare
//!   the pixels whose camera ray meets a surface with no delta lobe at all four corners
//!   ([`seen_by_light_tracing`]);
//! - **caustics of a small light**: a point or directional light (a delta) seen through
//!   a mirror or glass has zero density for a camera path, and the sun's disk (0.53°)
//!   is found through glass by a BSDF sample so rarely that `path`'s estimate there is a
//!   heavy tail that no test budget resolves. In scenes with such a light and a
//!   delta-lobed material, `path` and `whitted` are compared with nothing that
//!   carries light from the light's side (their differences spread everywhere, through
//!   the caustic's interreflections), and `sppm`'s pairs keep to light tracing's
//!   pixels: a caustic seen through glass (specular–diffuse–specular: the pool, the
//!   magnifier) is photon mapping's alone;
//! - **whitted** omits light arriving at a diffuse surface other than straight from a
//!   light (interreflection, caustics, the sky): it is compared where every material
//!   is specular, where its paths are exactly the path tracer's;
//! - **sppm** is consistent but biased by its radius at any finite iteration count:
//!   its pairs allow a relative margin ([`SPPM_TOLERANCE`], `heron compare
//!   --tolerance`), and its standard errors come from the spread within a region (its
//!   pixels share photons, so that spread underestimates the noise a little: the
//!   margin covers it);
//! - scenes with participating media have one integrator (`path`); their estimators
//!   and engines are held to each other in [`media_estimators_and_packet_engines_agree`].
//!
//! Size: `HERON_AGREE=full` (`scripts/agree.sh`) renders at 96 pixels on the longer
//! side with the sample counts of [`Budget::full`], where most pairs' whole-image test
//! resolves a 1% difference; the default, run by the test command, at 64 pixels with a
//! quarter of those samples (about two minutes on two cores), where most resolve 4%.
//! Both print one line per pair: the regions tested, the largest |z|, and the
//! smallest whole-image difference the test would catch; and per render the time to a
//! relMSE of 10⁻³ estimated from its variance channels (the table of which integrator
//! converges fastest in docs/integrators.md). BENCHMARKS.md, "Integrators agree",
//! records both runs and the known error the test catches when put back.
mod common;

use heron::bsdf::LobeFlags;
use heron::compare::{compare, Comparison, Correction, Image, Options};
use heron::film::Film;
use heron::render::{RenderOptions, Renderer};
use heron::scene::{load_scene, Scene};
use heron::settings::{IntegratorKind, MediumNee, Packets};
use std::path::Path;

/// The relative margin of `sppm`'s pairs: its radius bias over a region, measured at
/// the budgets here (BENCHMARKS.md, "Integrators agree").
const SPPM_TOLERANCE: f64 = 0.05;

/// The family-wise significance level of the whole test.
const ALPHA: f64 = 0.01;

/// How large the renders are.
struct Budget {
    /// Pixels on the image's longer side.
    long_side: u32,
    /// Region edge of the z-test, in pixels.
    region: u32,
    /// Samples per pixel (iterations for sppm).
    spp: fn(IntegratorKind) -> u32,
    /// The largest whole-image difference a pair's test may miss (relative, Y-like G).
    resolves: f64,
}

impl Budget {
    fn full() -> Budget {
        Budget {
            long_side: 96,
            region: 12,
            spp: |k| match k {
                IntegratorKind::Whitted => 256,
                IntegratorKind::Path => 2048,
                IntegratorKind::LightTrace => 2048,
                IntegratorKind::Bdpt => 1024,
                IntegratorKind::Sppm => 512,
            },
            resolves: 0.01,
        }
    }

    fn ci() -> Budget {
        Budget {
            long_side: 64,
            region: 8,
            spp: |k| match k {
                IntegratorKind::Whitted => 64,
                IntegratorKind::Path => 512,
                IntegratorKind::LightTrace => 512,
                IntegratorKind::Bdpt => 256,
                IntegratorKind::Sppm => 128,
            },
            resolves: 0.04,
        }
    }

    fn from_env() -> Budget {
        match std::env::var("HERON_AGREE").as_deref() {
            Ok("full") => Budget::full(),
            _ => Budget::ci(),
        }
    }
}

const KINDS: [IntegratorKind; 5] = [
    IntegratorKind::Whitted,
    IntegratorKind::Path,
    IntegratorKind::LightTrace,
    IntegratorKind::Bdpt,
    IntegratorKind::Sppm,
];

fn name(k: IntegratorKind) -> &'static str {
    match k {
        IntegratorKind::Whitted => "whitted",
        IntegratorKind::Path => "path",
        IntegratorKind::LightTrace => "lighttrace",
        IntegratorKind::Bdpt => "bdpt",
        IntegratorKind::Sppm => "sppm",
    }
}

/// The scene `file` of `scenes/`, its image `long_side` pixels on the longer side.
fn load(file: &str, long_side: u32) -> Scene {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(file);
    let mut s = load_scene(&p).unwrap_or_else(|e| panic!("{file}: {e}"));
    let (w, h) = (s.camera.width as f64, s.camera.height as f64);
    let k = long_side as f64 / w.max(h);
    let (w, h) = (
        ((w * k).round() as u32).max(8),
        ((h * k).round() as u32).max(8),
    );
    s.camera = s.camera.resized(w, h).unwrap();
    s
}

/// One render's image and what it cost.
struct Rendered {
    film: Film,
    seconds: f64,
}

/// Renders `scene` with `kind` (and `set`'s changes to the options); Err with the
/// renderer's message when the integrator refuses the scene. Every sample must be
/// finite.
fn render(
    r: &Renderer,
    scene: &Scene,
    kind: IntegratorKind,
    spp: u32,
    set: impl FnOnce(&mut RenderOptions),
) -> Result<Rendered, String> {
    let mut o = RenderOptions::from_scene(scene);
    o.settings.integrator = kind;
    o.settings.spp = spp;
    // Seeds apart, so that no two integrators share random numbers.
    o.settings.seed = 1000 + KINDS.iter().position(|&k| k == kind).unwrap() as u64;
    o.variance = kind != IntegratorKind::Sppm;
    set(&mut o);
    let (film, stats) = r.render(&o).map_err(|e| e.to_string())?;
    assert_eq!(stats.nonfinite, 0, "{}: non-finite samples", name(kind));
    Ok(Rendered {
        film,
        seconds: stats.wall.as_secs_f64(),
    })
}

/// Whether a material has only delta lobes (mirror, smooth glass, polariser).
fn all_specular(flags: LobeFlags) -> bool {
    !flags.has_non_specular()
}

/// Pixels whose camera ray meets a surface without delta lobes at all four corners:
/// what light tracing, which reaches the camera only from a diffuse or glossy vertex,
/// renders (not glass, mirrors or the sky seen directly).
fn seen_by_light_tracing(r: &Renderer, scene: &Scene) -> Vec<bool> {
    common::render::first_hit_mask(r, scene, |m| !m.flags().intersects(LobeFlags::SPECULAR))
}

/// What a scene holds that decides which pairs are comparable.
struct Traits {
    /// Every material specular (no diffuse or glossy lobe).
    all_specular: bool,
    /// A delta light or the sun, and a material with a delta lobe: caustics that only
    /// the light's side carries.
    small_light_caustics: bool,
    /// A light at infinity (environment, sun, directional) over a scene whose bounding
    /// sphere is over 100 times the camera's distance to what it looks at (a `plane`
    /// shape is a square 2000 units across): such a light's paths start on a disk as
    /// wide as the scene, and almost none reach what the camera sees.
    far_lights_on_wide_ground: bool,
}

fn traits(scene: &Scene) -> Traits {
    use heron::light::Light;
    let used: Vec<LobeFlags> = scene
        .shapes
        .iter()
        .map(|s| scene.materials[s.material as usize].flags())
        .collect();
    let small_light = scene
        .lights
        .iter()
        .any(|l| l.is_delta() || matches!(l, Light::Sun(_)));
    let infinite = scene.environment.is_some()
        || scene
            .lights
            .iter()
            .any(|l| matches!(l, Light::Sun(_) | Light::Directional(_)));
    let view = (scene.camera.eye - scene.camera.look_at).length();
    Traits {
        far_lights_on_wide_ground: infinite && scene.bounds.radius > 100.0 * view,
        all_specular: used.iter().all(|&f| all_specular(f)),
        small_light_caustics: small_light && used.iter().any(|f| f.intersects(LobeFlags::SPECULAR)),
    }
}

/// How a pair is compared: over which pixels and with what margin.
struct Rule {
    light_tracing_pixels: bool,
    tolerance: f64,
}

/// The rule for the pair (a, b), or why it is not comparable.
fn rule(t: &Traits, a: IntegratorKind, b: IntegratorKind) -> Result<Rule, &'static str> {
    use IntegratorKind::*;
    let has = |k| a == k || b == k;
    if t.far_lights_on_wide_ground && (has(LightTrace) || has(Sppm)) {
        return Err(
            "a light at infinity over wide ground: its light paths almost never \
             reach what the camera sees (a heavy tail beyond any test budget)",
        );
    }
    if has(Whitted) && !t.all_specular {
        return Err("whitted omits indirect, caustic and sky light on diffuse surfaces");
    }
    let camera_side = |k| k == Path || k == Whitted;
    if t.small_light_caustics && (camera_side(a) != camera_side(b)) {
        return Err("caustics of a delta light or the sun: the camera side cannot carry them");
    }
    Ok(Rule {
        light_tracing_pixels: has(LightTrace) || (has(Sppm) && t.small_light_caustics),
        tolerance: if has(Sppm) { SPPM_TOLERANCE } else { 0.0 },
    })
}

/// A film's linear sRGB with its variance.
fn rgb(f: &Film) -> Image {
    Image::from_film(f)
}

/// A polarised film's S1, S2, S3 (their CIE Y), no variance.
fn stokes(f: &Film) -> Option<Image> {
    let s = f.stokes.as_ref()?;
    Some(
        Image::new(
            "stokes",
            f.width,
            f.height,
            ["S1", "S2", "S3"],
            s.iter().map(|p| [p[0][1], p[1][1], p[2][1]]).collect(),
            None,
        )
        .unwrap(),
    )
}

/// A comparison to run: what, and with which options.
struct Job {
    label: String,
    a: Image,
    b: Image,
    mask: Option<Vec<bool>>,
    tolerance: f64,
}

/// Runs every job with α split among them (Šidák); prints a line per job and returns
/// the reports of those that fail, and a failure when more than a quarter of the
/// (linear sRGB, no margin) pairs could not resolve a relative difference `resolves`
/// over the whole image.
fn run_jobs(jobs: Vec<Job>, region: u32, resolves: f64) -> Vec<String> {
    let per_job = 1.0 - (1.0 - ALPHA).powf(1.0 / jobs.len() as f64);
    eprintln!(
        "{} comparisons, each at family-wise level {per_job:.2e}",
        jobs.len()
    );
    let mut failures = Vec::new();
    let (mut checked, mut weak) = (0, Vec::new());
    for j in jobs {
        let c: Comparison = compare(
            &j.a,
            &j.b,
            &Options {
                region,
                alpha: per_job,
                correction: Correction::Sidak,
                mask: j.mask,
                tolerance: j.tolerance,
            },
        )
        .unwrap_or_else(|e| panic!("{}: {e}", j.label));
        // The whole image's second channel (G): the smallest relative difference its
        // test would call significant (the Stokes components' means are near zero, so
        // their relative figures mean nothing and are not printed).
        let stokes = j.a.channels[0] == "S1";
        let (whole, detects) = match c.whole.get(1) {
            Some(g) if !stokes => (
                format!("{:+.2}%", 100.0 * g.difference / g.mean_b.abs().max(1e-30)),
                c.critical_z * g.standard_error / g.mean_b.abs().max(1e-30),
            ),
            Some(_) => ("-".into(), 0.0),
            None => ("identical".into(), 0.0),
        };
        eprintln!(
            "{:<50} {:>4} regions  max|z| {:>5.2} (crit {:.2})  whole {whole:>8}  detects {:>5.2}%  {}",
            j.label,
            c.regions.len() / 3,
            c.max_abs_z(),
            c.critical_z,
            100.0 * detects,
            if c.same() { "same" } else { "DIFFERENT" }
        );
        if !c.same() {
            failures.push(c.report(&j.label, "", 12));
        } else if !stokes && j.tolerance == 0.0 {
            checked += 1;
            if detects > resolves {
                weak.push(format!("{} ({:.2}%)", j.label, 100.0 * detects));
            }
        }
    }
    // A pair whose whole-image test cannot see a difference of `resolves` is a weak
    // test, not a failure: a heavy tail (BDPT's fireflies on a wide ground, a prism's
    // sun seen by chance) keeps its standard error up. Most pairs must resolve it.
    eprintln!(
        "{} of {checked} pairs resolve {:.0}% over the whole image; not: {}",
        checked - weak.len(),
        100.0 * resolves,
        if weak.is_empty() {
            "none".to_string()
        } else {
            weak.join(", ")
        }
    );
    if 4 * weak.len() > checked {
        failures.push(format!(
            "{} of {checked} pairs do not resolve {:.0}%: {}",
            weak.len(),
            100.0 * resolves,
            weak.join(", ")
        ));
    }
    failures
}

/// Whether `mask` leaves any of the test's regions (edge `region`) at least half
/// covered.
fn any_region_half_covered(mask: &[bool], scene: &Scene, region: u32) -> bool {
    let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
    let e = region as usize;
    (0..h / e).any(|ry| {
        (0..w / e).any(|rx| {
            let n = (ry * e..(ry + 1) * e)
                .flat_map(|y| (rx * e..(rx + 1) * e).map(move |x| y * w + x))
                .filter(|&i| mask[i])
                .count();
            2 * n >= e * e
        })
    })
}

/// Which integrator converges fastest on a scene: each unbiased render's relMSE
/// estimated from its variance channels, times its time, scaled to relMSE 10⁻³, over
/// the pixels light tracing sees (all pixels where it sees none).
fn convergence_costs(
    stem: &str,
    renders: &[Option<Result<Rendered, String>>],
    lt_mask: &[bool],
) -> Vec<String> {
    let pixels: Vec<usize> = (0..lt_mask.len())
        .filter(|&i| lt_mask[i] || !lt_mask.contains(&true))
        .collect();
    let mut costs = Vec::new();
    for (k, x) in KINDS.iter().zip(renders) {
        let Some(Ok(x)) = x else { continue };
        let Some(var) = &x.film.variance else {
            continue;
        };
        let rgb = x.film.linear_srgb();
        let rel: f64 = pixels
            .iter()
            .flat_map(|&i| (0..3).map(move |c| (i, c)))
            .map(|(i, c)| {
                var[i][c] as f64 / ((rgb[i][c] as f64).powi(2) + heron::compare::REL_MSE_EPSILON)
            })
            .sum::<f64>()
            / (3 * pixels.len()) as f64;
        costs.push(format!(
            "{stem} {}: relMSE {rel:.3e} in {:.2} s: {:.3e} s to relMSE 1e-3 ({})",
            name(*k),
            x.seconds,
            x.seconds * rel / 1e-3,
            if pixels.len() < lt_mask.len() {
                "light tracing's pixels"
            } else {
                "all pixels"
            }
        ));
    }
    costs
}

#[test]
fn every_integrator_agrees_with_every_other_on_every_scene_they_accept() {
    let budget = Budget::from_env();
    let mut jobs = Vec::new();
    let mut skipped = Vec::new();
    let mut seconds = Vec::new();
    let mut costs = Vec::new();
    for file in common::scenes::names() {
        let scene = load(&file, budget.long_side);
        let stem = file.trim_end_matches(".toml");
        let r = Renderer::new(&scene).unwrap();
        let t = traits(&scene);
        let lt_mask = seen_by_light_tracing(&r, &scene);
        let lt_regions = any_region_half_covered(&lt_mask, &scene, budget.region);
        // Each integrator renders once, when a pair first needs it.
        let mut renders: Vec<Option<Result<Rendered, String>>> =
            KINDS.iter().map(|_| None).collect();
        let mut get = |i: usize, seconds: &mut Vec<(String, f64)>| -> Result<Film, String> {
            let kind = KINDS[i];
            let x = renders[i].get_or_insert_with(|| {
                let x = render(&r, &scene, kind, (budget.spp)(kind), |_| {});
                if let Ok(x) = &x {
                    seconds.push((format!("{stem} {}", name(kind)), x.seconds));
                }
                x
            });
            x.as_ref().map(|x| x.film.clone()).map_err(|e| e.clone())
        };
        for (i, &ka) in KINDS.iter().enumerate() {
            for (j, &kb) in KINDS.iter().enumerate().skip(i + 1) {
                let label = format!("{stem}: {} vs {}", name(ka), name(kb));
                let rule = match rule(&t, ka, kb) {
                    Ok(r) => r,
                    Err(why) => {
                        skipped.push(format!("{label}: {why}"));
                        continue;
                    }
                };
                let mask = rule.light_tracing_pixels.then(|| lt_mask.clone());
                if mask.is_some() && !lt_mask.contains(&true) {
                    skipped.push(format!("{label}: light tracing sees no pixel"));
                    continue;
                }
                if mask.is_some() && rule.tolerance > 0.0 && !lt_regions {
                    // Scattered pixels at the edges of what glass hides: each gathers
                    // photons from a disk reaching past the edge, the worst case of
                    // photon mapping's radius bias.
                    skipped.push(format!(
                        "{label}: no region is half seen by light tracing (sppm's radius bias at edges)"
                    ));
                    continue;
                }
                let (a, b) = match (get(i, &mut seconds), get(j, &mut seconds)) {
                    (Ok(a), Ok(b)) => (a, b),
                    (Err(e), _) | (_, Err(e)) => {
                        skipped.push(format!("{label}: refused: {e}"));
                        continue;
                    }
                };
                if let (Some(sa), Some(sb)) = (stokes(&a), stokes(&b)) {
                    jobs.push(Job {
                        label: format!("{label} (S1-S3)"),
                        a: sa,
                        b: sb,
                        mask: mask.clone(),
                        tolerance: rule.tolerance,
                    });
                }
                jobs.push(Job {
                    label,
                    a: rgb(&a),
                    b: rgb(&b),
                    mask,
                    tolerance: rule.tolerance,
                });
            }
        }
        costs.extend(convergence_costs(stem, &renders, &lt_mask));
    }
    for c in &costs {
        eprintln!("cost: {c}");
    }
    for s in &skipped {
        eprintln!("not compared: {s}");
    }
    for (what, s) in &seconds {
        eprintln!("time: {what} {s:.3} s");
    }
    assert!(jobs.len() >= 40, "only {} comparisons", jobs.len());
    let failures = run_jobs(jobs, budget.region, budget.resolves);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The media scenes (`path` only): the light-sampling estimators along media segments
/// (forced, the default, against collision-only), the sun guide against phase sampling
/// alone, and the packet engines (`--packets paths`, `off`) against the default
/// (camera rays in packets), each pair by the same z-test; polarised (S0–S3) too.
/// A media render's variant: its name and what it changes.
type Variant = (&'static str, fn(&mut RenderOptions));

#[test]
fn media_estimators_and_packet_engines_agree() {
    let budget = Budget::from_env();
    // A quarter of the path tracer's samples: the media scenes' pairs still resolve
    // about 1% over the whole image at the CI budget.
    let spp = (budget.spp)(IntegratorKind::Path) / 4;
    let mut jobs = Vec::new();
    let mut media_scenes = 0;
    for file in common::scenes::names() {
        let scene = load(&file, budget.long_side);
        if scene.media.is_empty() {
            continue;
        }
        media_scenes += 1;
        let stem = file.trim_end_matches(".toml");
        let r = Renderer::new(&scene).unwrap();
        for polarised in [false, true] {
            let base = render(&r, &scene, IntegratorKind::Path, spp, |o| {
                o.settings.polarization = polarised;
            })
            .unwrap();
            let variants: [Variant; 4] = [
                ("collision", |o| {
                    o.settings.medium_nee = MediumNee::Collision
                }),
                ("sun guide 0", |o| o.settings.sun_guide = 0.0),
                ("packets paths", |o| o.settings.packets = Packets::Paths),
                ("packets off", |o| o.settings.packets = Packets::Off),
            ];
            for (what, set) in variants {
                let v = render(&r, &scene, IntegratorKind::Path, spp, |o| {
                    o.settings.polarization = polarised;
                    o.settings.seed = 77;
                    set(o);
                })
                .unwrap_or_else(|e| panic!("{stem} {what}: {e}"));
                let label = format!(
                    "{stem}{}: {what} vs default",
                    if polarised { " polarised" } else { "" }
                );
                if let (Some(sa), Some(sb)) = (stokes(&v.film), stokes(&base.film)) {
                    jobs.push(Job {
                        label: format!("{label} (S1-S3)"),
                        a: sa,
                        b: sb,
                        mask: None,
                        tolerance: 0.0,
                    });
                }
                jobs.push(Job {
                    label,
                    a: rgb(&v.film),
                    b: rgb(&base.film),
                    mask: None,
                    tolerance: 0.0,
                });
            }
        }
    }
    assert!(media_scenes >= 2, "{media_scenes} media scenes");
    let failures = run_jobs(jobs, budget.region, budget.resolves);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
