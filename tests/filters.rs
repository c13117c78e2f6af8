//! Pixel reconstruction filters by filter importance sampling (issue 38;
//! `camera::filter`): camera samples are drawn from the filter, weighted by f/(p ∫f).
//!
//! - Chi-square of every filter's sampler against its normalised |f| (the tabulated
//!   filters included: their 256-bin table is close enough to |f| that 10⁶ samples do
//!   not tell them apart, and the weights correct what remains).
//! - The weights: mean 1, and E[w g] = ∫ f g / ∫ f for a test function g (the
//!   estimator is unbiased for the filtered image); the box and tent weigh exactly 1,
//!   the Gaussian within 1%, Mitchell carries f's sign.
//! - The default box is heron's original jitter to the bit.
//! - Renders: a constant scene filtered by a Gaussian equals the box one; images are
//!   the same bytes for any thread count; the key and the flag agree and are recorded
//!   in the provenance; merges and resumes across filters, light tracing and BDPT with
//!   a filter, and bad keys are refused with one line.
mod common;

use common::chi2::{assert_all, Chi2, Outcome, Planar};
use common::cli::{heron, heron_ok, write_file};
use common::render::render_with;
use glam::Vec2;
use heron::camera::filter::Filter;
use heron::math::Rng;
use heron::scene::load::load_scene_from_str;
use heron::settings::{IntegratorKind, PixelFilter};
use std::path::Path;

/// The filters under test: every kind, at pbrt-v4's and Mitsuba 3's defaults.
fn filters() -> Vec<(&'static str, PixelFilter)> {
    vec![
        ("box 0.5", PixelFilter::BOX),
        ("box 1.5", PixelFilter::Box { radius: 1.5 }),
        ("tent 1", PixelFilter::Tent { radius: 1.0 }),
        ("tent 2", PixelFilter::Tent { radius: 2.0 }),
        (
            "gaussian pbrt",
            PixelFilter::Gaussian {
                radius: 1.5,
                stddev: 0.5,
            },
        ),
        (
            "gaussian mitsuba",
            PixelFilter::Gaussian {
                radius: 2.0,
                stddev: 0.5,
            },
        ),
        (
            "mitchell",
            PixelFilter::Mitchell {
                radius: 2.0,
                b: 1.0 / 3.0,
                c: 1.0 / 3.0,
            },
        ),
        (
            "catmull-rom",
            PixelFilter::Mitchell {
                radius: 2.0,
                b: 0.0,
                c: 0.5,
            },
        ),
    ]
}

const N: usize = 1_000_000;

/// ∫ g(x) h(x) dx over [−r, r] by Simpson's rule on 8192 intervals (h's kinks at 0,
/// ±r/2 fall on interval ends).
fn integrate(f: &Filter, r: f32, g: impl Fn(f64) -> f64) -> f64 {
    let n = 8192;
    let r = r as f64;
    let dx = 2.0 * r / n as f64;
    let v = |k: usize| {
        let x = -r + k as f64 * dx;
        g(x) * f.eval_1d(x as f32)
    };
    let mut s = v(0) + v(n);
    for k in 1..n {
        s += v(k) * if k % 2 == 1 { 4.0 } else { 2.0 };
    }
    s * dx / 3.0
}

/// ∫ |h| over [−r, r] (Simpson, as [`integrate`]).
fn integrate_abs(f: &Filter, r: f32) -> f64 {
    let n = 8192;
    let dx = 2.0 * r as f64 / n as f64;
    let v = |k: usize| f.eval_1d((-(r as f64) + k as f64 * dx) as f32).abs();
    let mut s = v(0) + v(n);
    for k in 1..n {
        s += v(k) * if k % 2 == 1 { 4.0 } else { 2.0 };
    }
    s * dx / 3.0
}

fn u2(r: &mut Rng) -> Vec2 {
    Vec2::new(r.uniform(), r.uniform())
}

/// The sampled offsets against |f(p)| / (∫|h|)², on 16 × 16 cells over [−r, r]².
/// The sampler's own density is the table's (`Filter::pdf`), not |f|'s: this asks
/// whether the table follows |f| closely enough not to be seen in 10⁶ samples.
fn chi2_test(name: &str, spec: &PixelFilter, tests: usize) -> Outcome {
    let f = Filter::new(spec);
    let r = spec.radius();
    let abs_1d = integrate_abs(&f, r);
    let density = |p: Vec2| (f.eval(p).abs() / (abs_1d * abs_1d)) as f32;
    let dom = Planar::new((-r as f64, r as f64), (-r as f64, r as f64), 16, 16);
    Chi2::new(format!("filter {name}"), N, tests).plane(
        &dom,
        |rng| {
            let s = f.sample(u2(rng));
            Some((s.offset, density(s.offset)))
        },
        density,
    )
}

#[test]
fn chi2_every_filter_against_its_normalised_abs_f() {
    let fs = filters();
    let outcomes: Vec<Outcome> = fs
        .iter()
        .map(|(name, spec)| chi2_test(name, spec, fs.len()))
        .collect();
    assert_all(&outcomes);
}

/// Mean weight 1 and E[w·g(offset)] = ∫ f g / ∫ f for g = x² + y (a second moment and
/// an odd part), each within 4 standard errors; per-sample weights as the kind allows:
/// exactly 1 for the box and tent, within 1% of 1 for 99% of a Gaussian's (in [0, 2]
/// in the table's last bins), f's sign for Mitchell.
#[test]
fn weights_have_mean_one_and_the_estimator_is_unbiased() {
    for (name, spec) in filters() {
        let f = Filter::new(&spec);
        let r = spec.radius();
        let i0 = integrate(&f, r, |_| 1.0);
        let i2 = integrate(&f, r, |x| x * x);
        let i1 = integrate(&f, r, |x| x);
        // E[x² + y] over f/∫f.
        let want = i2 / i0 + i1 / i0;
        let mut rng = Rng::new(0xf117e5, name.len() as u64);
        let (mut sw, mut sw2, mut sg, mut sg2) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        // Gaussian weights more than 1% from 1 (the table's last bins).
        let mut far = 0usize;
        for _ in 0..N {
            let s = f.sample(u2(&mut rng));
            let w = s.weight as f64;
            let fv = f.eval(s.offset);
            match spec {
                PixelFilter::Box { .. } | PixelFilter::Tent { .. } => {
                    assert_eq!(s.weight, 1.0, "{name}")
                }
                PixelFilter::Gaussian { .. } => {
                    assert!(
                        (0.0..=2.0).contains(&w),
                        "{name}: weight {w} at {}",
                        s.offset
                    );
                    far += ((w - 1.0).abs() > 0.01) as usize;
                }
                PixelFilter::Mitchell { .. } => assert!(
                    fv == 0.0 || (w > 0.0) == (fv > 0.0),
                    "{name}: weight {w} but f = {fv} at {}",
                    s.offset
                ),
            }
            // The weight is f/(p ∫f) with p the sampler's own density (an offset on a
            // bin's edge may be read back in the neighbouring bin: either will do).
            let nudge = [-1e-4f32, 0.0, 1e-4];
            let near = nudge
                .iter()
                .flat_map(|&dx| nudge.iter().map(move |&dy| Vec2::new(dx, dy)));
            let ok = near.clone().any(|d| {
                let expect = fv / (f.pdf(s.offset + d) as f64 * i0 * i0);
                (w - expect).abs() <= 1e-4 * expect.abs().max(1e-3)
            });
            assert!(
                ok,
                "{name}: weight {w}, f/(p∫f) = {} at {}",
                fv / (f.pdf(s.offset) as f64 * i0 * i0),
                s.offset
            );
            let g = w * ((s.offset.x as f64).powi(2) + s.offset.y as f64);
            (sw, sw2, sg, sg2) = (sw + w, sw2 + w * w, sg + g, sg2 + g * g);
        }
        println!("{name}: {far} of {N} weights more than 1% from 1");
        assert!(
            far < N / 100,
            "{name}: {far} of {N} weights are more than 1% from 1"
        );
        let n = N as f64;
        let se = |s: f64, s2: f64| ((s2 / n - (s / n).powi(2)) / n).sqrt();
        let (mw, mg) = (sw / n, sg / n);
        println!(
            "{name}: mean weight {mw:.5} ± {:.5}, E[w(x²+y)] {mg:.5} ± {:.5} (want {want:.5})",
            se(sw, sw2),
            se(sg, sg2)
        );
        assert!(
            (mw - 1.0).abs() <= 4.0 * se(sw, sw2) + 1e-6,
            "{name}: mean weight {mw}"
        );
        assert!(
            (mg - want).abs() <= 4.0 * se(sg, sg2) + 1e-6,
            "{name}: E[w g] = {mg}, want {want}"
        );
    }
}

/// The default box gives the film position px + u to the bit (every existing image
/// keeps its bytes), and weight 1.
#[test]
fn the_default_box_is_the_original_jitter() {
    let f = Filter::new(&PixelFilter::BOX);
    let mut rng = Rng::new(7, 7);
    for k in 0..100_000u32 {
        let u = u2(&mut rng);
        let (px, py) = (k % 1000, k / 100);
        let (x, y, w) = f.film_point(px, py, u);
        assert_eq!(
            (x.to_bits(), y.to_bits(), w),
            (
                (px as f32 + u.x).to_bits(),
                (py as f32 + u.y).to_bits(),
                1.0
            )
        );
    }
}

/// A scene whose every camera ray sees the same radiance: a grey background and
/// nothing else.
const CONSTANT: &str = "background = [0.5, 0.5, 0.5]\n[camera]\neye = [0.0, 0.0, 1.0]\n\
     look_at = [0.0, 0.0, 0.0]\nresolution = [24, 16]\n";

/// The Gaussian-filtered constant scene equals the box one: the two renders draw the
/// same wavelengths for each sample (the filter uses only the pixel's 2D dimensions),
/// so they differ only by the weights' departure from 1 (< 1% each, from the table),
/// averaged over 64 samples. Mitchell's weights are ±1.2 or so: its image mean agrees
/// within its standard error.
#[test]
fn a_filtered_constant_scene_equals_the_box_one() {
    let scene = load_scene_from_str(CONSTANT, Path::new("constant.toml")).unwrap();
    let render = |filter: PixelFilter| {
        render_with(&scene, |o| {
            o.settings.spp = 64;
            o.settings.integrator = IntegratorKind::Path;
            o.settings.filter = filter;
        })
    };
    let b = render(PixelFilter::BOX);
    let g = render(PixelFilter::Gaussian {
        radius: 1.5,
        stddev: 0.5,
    });
    let m = render(PixelFilter::Mitchell {
        radius: 2.0,
        b: 1.0 / 3.0,
        c: 1.0 / 3.0,
    });
    let mean =
        |f: &heron::film::Film| f.xyz.iter().map(|c| c[1] as f64).sum::<f64>() / f.xyz.len() as f64;
    assert!(mean(&b) > 0.1, "the background is not seen: {}", mean(&b));
    for (pb, pg) in b.xyz.iter().zip(&g.xyz) {
        for c in 0..3 {
            assert!(
                (pb[c] - pg[c]).abs() <= 2e-3 * pb[c].abs() + 1e-6,
                "box {pb:?} vs gaussian {pg:?}"
            );
        }
    }
    assert!(
        (mean(&b) - mean(&g)).abs() < 1e-3 * mean(&b),
        "{} {}",
        mean(&b),
        mean(&g)
    );
    // Mitchell: |w| ≈ ∫|f|/∫f ≈ 1.1, a sign per sample; the image mean of 24 576
    // samples has a relative standard error of about 0.5%.
    assert!(
        (mean(&m) / mean(&b) - 1.0).abs() < 0.03,
        "mitchell mean {} vs box {}",
        mean(&m),
        mean(&b)
    );
}

const SMALL: &str = r#"
[camera]
eye = [0.0, 0.0, 5.0]
look_at = [0.0, 0.0, 0.0]
d = 1.0
resolution = [40, 30]
[materials.grey]
type = "lambertian"
rho_d = 0.6
[[shapes]]
type = "sphere"
center = [0.0, 1.0, 0.0]
radius = 0.4
material = "grey"
emission = 5.0
[[shapes]]
type = "sphere"
center = [0.3, -0.6, 0.0]
radius = 0.7
material = "grey"
"#;

/// The same bytes for 1 and 3 threads, for every integrator that takes a filter.
#[test]
fn filtered_images_do_not_depend_on_the_thread_count() {
    let scene = load_scene_from_str(SMALL, Path::new("small.toml")).unwrap();
    for kind in [
        IntegratorKind::Whitted,
        IntegratorKind::Path,
        IntegratorKind::Sppm,
    ] {
        for filter in [
            PixelFilter::Gaussian {
                radius: 1.5,
                stddev: 0.5,
            },
            PixelFilter::Mitchell {
                radius: 2.0,
                b: 0.0,
                c: 0.5,
            },
        ] {
            let run = |threads: usize| {
                render_with(&scene, |o| {
                    o.settings.spp = 4;
                    o.settings.integrator = kind;
                    o.settings.filter = filter;
                    o.threads = threads;
                })
            };
            let a = run(1);
            assert!(
                a == run(3),
                "{kind:?} {filter:?}: thread count changes the image"
            );
            let box_ = render_with(&scene, |o| {
                o.settings.spp = 4;
                o.settings.integrator = kind;
                o.threads = 1;
            });
            assert!(a != box_, "{kind:?} {filter:?}: the filter changed nothing");
        }
    }
}

fn tiny_scene(dir: &Path, name: &str, render: &str) -> String {
    write_file(dir, name, &format!("{SMALL}\n[render]\n{render}\n"))
        .to_str()
        .unwrap()
        .to_string()
}

/// The scene keys and the flag give the same pixels and record `heron.filter`; the
/// default records nothing; merges and resumes across filters, light tracing and BDPT
/// with a filter, and bad keys are each one line naming what is wrong.
#[test]
fn keys_flag_provenance_and_refusals() {
    let d = tempfile::tempdir().unwrap();
    let keyed = tiny_scene(
        d.path(),
        "keyed.toml",
        "filter = \"gaussian\"\nfilter_stddev = 0.5\nfilter_radius = 1.5",
    );
    let plain = tiny_scene(d.path(), "plain.toml", "");
    let out = |n: &str| d.path().join(n).to_str().unwrap().to_string();
    let (a, b, c) = (out("a.exr"), out("b.exr"), out("c.exr"));
    let quick = ["--quiet", "--no-png", "--spp", "2"];
    heron_ok(&[&["render", &keyed, "-o", &a][..], &quick].concat());
    heron_ok(
        &[
            &["render", &plain, "-o", &b, "--filter", "gaussian"][..],
            &quick,
        ]
        .concat(),
    );
    heron_ok(&[&["render", &plain, "-o", &c][..], &quick].concat());
    let info = |p: &str| String::from_utf8_lossy(&heron_ok(&["info", p]).stdout).into_owned();
    assert!(
        info(&a).contains("gaussian radius=1.5 stddev=0.5"),
        "{}",
        info(&a)
    );
    assert!(
        info(&b).contains("gaussian radius=1.5 stddev=0.5"),
        "{}",
        info(&b)
    );
    assert!(!info(&c).contains("filter"), "{}", info(&c));
    let rgb = |p: &str| heron::film::exr::read_linear_srgb(Path::new(p)).unwrap();
    assert_eq!(rgb(&a), rgb(&b));
    assert_ne!(rgb(&a), rgb(&c));

    let one_line = |args: &[&str], says: &[&str]| {
        let o = heron(args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
        for s in says {
            assert!(err.contains(s), "{args:?}: {err}");
        }
    };
    // Shards of two filters do not merge; a film of one does not resume the other.
    let (p0, p1) = (out("p0.heronfilm"), out("p1.heronfilm"));
    heron_ok(&[
        "render", &plain, "-o", &p0, "--quiet", "--spp", "2", "--shard", "0/2",
    ]);
    heron_ok(&[
        "render", &plain, "-o", &p1, "--quiet", "--spp", "2", "--shard", "1/2", "--filter", "tent",
    ]);
    one_line(&["merge", "-o", &out("m.exr"), &p0, &p1], &["filter"]);
    one_line(
        &[
            "render",
            &plain,
            "-o",
            &out("r.heronfilm"),
            "--quiet",
            "--spp",
            "2",
            "--shard",
            "0/2",
            "--resume",
            &p0,
            "--filter",
            "mitchell",
        ],
        &["filter"],
    );
    for kind in ["lighttrace", "bdpt"] {
        one_line(
            &[
                "render",
                &plain,
                "-o",
                &out("x.exr"),
                "--quiet",
                "--integrator",
                kind,
                "--filter",
                "gaussian",
            ],
            &["filter \"gaussian\"", kind],
        );
    }
    for (bad, says) in [
        ("filter = \"lanczos\"", "render.filter: expected box"),
        (
            "filter = \"box\"\nfilter_stddev = 1.0",
            "render.filter_stddev",
        ),
        (
            "filter = \"gaussian\"\nfilter_radius = -1.0",
            "render.filter_radius",
        ),
        ("filter = 3", "render.filter"),
    ] {
        let s = tiny_scene(d.path(), "bad.toml", bad);
        one_line(&["render", &s, "-o", &out("x.exr"), "--quiet"], &[says]);
    }
    one_line(
        &[
            "render",
            &plain,
            "-o",
            &out("x.exr"),
            "--quiet",
            "--filter",
            "gaussian:sigma=1",
        ],
        &["--filter", "sigma"],
    );
}

/// Mitsuba 3's `<rfilter>` and pbrt-v4's `PixelFilter` become `[render] filter`: each
/// format's default (a Gaussian) when none is named, its kinds exactly, Lanczos as
/// Catmull–Rom with a warning, and the box with light tracing, with a warning.
#[test]
fn importers_read_the_formats_filters() {
    use heron::scene::import::{import_scene, ImportOptions};
    let d = tempfile::tempdir().unwrap();
    let gauss = |radius, stddev| PixelFilter::Gaussian { radius, stddev };
    let mitchell = |b, c| PixelFilter::Mitchell { radius: 2.0, b, c };
    let xml = |rfilter: &str, integrator: &str| {
        format!(
            r#"<scene version="3.0.0">
    <integrator type="{integrator}"/>
    <sensor type="perspective"><float name="fov" value="45"/>
        <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/>{rfilter}</film>
    </sensor>
    <shape type="sphere"/>
</scene>
"#
        )
    };
    let pbrt = |filter: &str, integrator: &str| {
        format!(
            "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\"\nFilm \"rgb\" \"integer xresolution\" 8 \"integer yresolution\" 8\n{filter}\nIntegrator \"{integrator}\"\nWorldBegin\nShape \"sphere\"\n"
        )
    };
    let cases: Vec<(String, &str, PixelFilter, Option<&str>)> = vec![
        (xml("", "path"), "xml", gauss(2.0, 0.5), None),
        (
            xml(r#"<rfilter type="gaussian"><float name="stddev" value="0.25"/></rfilter>"#, "path"),
            "xml",
            gauss(1.0, 0.25),
            None,
        ),
        (xml(r#"<rfilter type="tent"/>"#, "path"), "xml", PixelFilter::Tent { radius: 1.0 }, None),
        (xml(r#"<rfilter type="box"/>"#, "path"), "xml", PixelFilter::BOX, None),
        (
            xml(r#"<rfilter type="mitchell"><float name="B" value="0.5"/><float name="C" value="0.25"/></rfilter>"#, "path"),
            "xml",
            mitchell(0.5, 0.25),
            None,
        ),
        (xml(r#"<rfilter type="catmullrom"/>"#, "path"), "xml", mitchell(0.0, 0.5), None),
        (xml(r#"<rfilter type="lanczos"/>"#, "path"), "xml", mitchell(0.0, 0.5), Some("lanczos")),
        (xml("", "ptracer"), "xml", PixelFilter::BOX, Some("read as heron's box")),
        (pbrt("", "path"), "pbrt", gauss(1.5, 0.5), None),
        (pbrt("PixelFilter \"triangle\"", "path"), "pbrt", PixelFilter::Tent { radius: 2.0 }, None),
        (pbrt("PixelFilter \"box\"", "path"), "pbrt", PixelFilter::BOX, None),
        (
            pbrt("PixelFilter \"gaussian\" \"float sigma\" 0.3 \"float xradius\" 1 \"float yradius\" 1", "path"),
            "pbrt",
            gauss(1.0, 0.3),
            None,
        ),
        (pbrt("PixelFilter \"mitchell\"", "path"), "pbrt", mitchell(1.0 / 3.0, 1.0 / 3.0), None),
        (pbrt("PixelFilter \"lanczos\"", "path"), "pbrt", PixelFilter::Mitchell { radius: 4.0, b: 0.0, c: 0.5 }, Some("windowed sinc")),
        (pbrt("", "bdpt"), "pbrt", PixelFilter::BOX, Some("read as heron's box")),
    ];
    for (k, (text, ext, want, warn)) in cases.into_iter().enumerate() {
        let p = write_file(d.path(), &format!("s{k}.{ext}"), &text);
        let imp = import_scene(&p, &ImportOptions::default()).unwrap();
        let scene = heron::scene::load::load_imported(&imp).unwrap();
        assert_eq!(scene.settings.filter, want, "case {k}: {text}");
        let filter_warnings: Vec<_> = imp
            .warnings
            .iter()
            .filter(|w| {
                w.message.contains("filter")
                    || w.message.contains("lanczos")
                    || w.message.contains("sinc")
            })
            .collect();
        match warn {
            None => assert!(filter_warnings.is_empty(), "case {k}: {filter_warnings:?}"),
            Some(w) => assert!(
                filter_warnings.iter().any(|x| x.message.contains(w)),
                "case {k}: {:?}",
                imp.warnings
            ),
        }
        // The light-path warning points at the pbrt file's Integrator directive (line 5).
        if ext == "pbrt" && warn == Some("read as heron's box") {
            let at: Vec<u32> = filter_warnings.iter().map(|w| w.line).collect();
            assert_eq!(at, [5], "case {k}: {filter_warnings:?}");
        }
    }
}
