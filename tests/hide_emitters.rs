//! `[render] hide_emitters` (issue 38, #11; Mitsuba 3's `hide_emitters`): emitters seen
//! directly by the camera contribute nothing, emitters seen through any scattering do.
//!
//! - A light seen directly and in a mirror: its own pixels are exactly 0 under every
//!   integrator, polarised or not, and every other pixel keeps its bytes (what the
//!   setting drops draws no random number).
//! - The background and the sun's disk behind escaping camera rays are 0; the surfaces
//!   they light keep their bytes.
//! - On the Cornell box (an area light in view), light tracing, BDPT and SPPM agree
//!   with the path tracer under the setting (`heron compare`'s region z-test).
//! - The scene key, the CLI flag, the provenance, the refusal of a resume or merge
//!   across the setting, a bad value's one-line error, and Mitsuba's integrator key.
mod common;

use common::cli::{heron, heron_ok, write_file};
use common::render::{compare_xyz, render_with};
use heron::compare::{compare, Correction, Image, Options};
use heron::film::Film;
use heron::render::Renderer;
use heron::scene::import::{import_scene, ImportOptions};
use heron::scene::load::load_scene_from_str;
use heron::scene::Scene;
use heron::settings::IntegratorKind;
use std::path::Path;

/// A sphere light (black, so that only its emission shows) above a grey sphere, before
/// a mirror that shows the light's reflection below its direct image, in empty space.
const MIRROR_SCENE: &str = r#"
[camera]
eye = [0.0, 0.0, 5.0]
look_at = [0.0, 0.0, 0.0]
d = 1.0
resolution = [40, 40]
[render]
max_depth = 6
[materials.black]
type = "lambertian"
rho_d = 0.0
[materials.grey]
type = "lambertian"
rho_d = 0.6
[materials.mirror]
type = "mirror"
[[shapes]]
type = "sphere"
center = [0.0, 1.5, 0.0]
radius = 0.3
material = "black"
emission = 20.0
[[shapes]]
type = "sphere"
center = [0.0, -0.8, 0.0]
radius = 0.5
material = "grey"
[[shapes]]
type = "quad"
origin = [-4.0, -4.0, -1.5]
edge1 = [8.0, 0.0, 0.0]
edge2 = [0.0, 8.0, 0.0]
material = "mirror"
"#;

fn load(text: &str) -> Scene {
    load_scene_from_str(text, Path::new("hide.toml")).unwrap()
}

fn render(scene: &Scene, kind: IntegratorKind, spp: u32, hide: bool) -> Film {
    render_polarized(scene, kind, spp, hide, false)
}

fn render_polarized(
    scene: &Scene,
    kind: IntegratorKind,
    spp: u32,
    hide: bool,
    polarized: bool,
) -> Film {
    render_with(scene, |o| {
        o.settings.integrator = kind;
        o.settings.spp = spp;
        o.settings.seed = 3;
        o.settings.hide_emitters = hide;
        o.settings.polarization = polarized;
    })
}

/// Pixels whose four corners' camera rays first meet the shape `geom`, or (None)
/// nothing at all.
fn first_hits(scene: &Scene, geom: Option<u32>) -> Vec<bool> {
    let r = Renderer::new(scene).unwrap();
    common::render::first_hit_mask_by(&r, scene, |g| g == geom)
}

/// A pixel some of whose camera rays may see the light (or the sky) directly: not
/// inside `hidden`'s mask nor wholly outside it. Pixels whose four corners meet other
/// shapes are taken as wholly outside (the shapes are convex or planar).
fn edge_of(hidden: &[bool], scene: &Scene, geom: Option<u32>) -> Vec<bool> {
    let (w, h) = (scene.camera.width as usize, scene.camera.height as usize);
    let touches = |x: usize, y: usize| {
        let r = Renderer::new(scene).unwrap();
        let cam = &scene.camera;
        // Any of a 4×4 grid of rays in the pixel meets `geom` first.
        (0..4).any(|i| {
            (0..4).any(|j| {
                let q = heron::accel::embree::RayQuery {
                    origin: cam.eye,
                    dir: cam.direction(
                        x as f32 + (i as f32 + 0.5) / 4.0,
                        y as f32 + (j as f32 + 0.5) / 4.0,
                    ),
                    tnear: 0.0,
                    tfar: f32::INFINITY,
                };
                r.accel().intersect1(&q).map(|h| h.geom_id) == geom
            })
        })
    };
    (0..w * h)
        .map(|k| !hidden[k] && touches(k % w, k / w))
        .collect()
}

/// (a) The light's own pixels are exactly 0 with the setting, under every integrator;
/// its reflection is still there; every pixel that does not see the light directly
/// keeps its bytes.
#[test]
fn a_light_seen_directly_is_hidden_and_its_reflection_is_not() {
    let scene = load(MIRROR_SCENE);
    let light = first_hits(&scene, Some(0));
    // The mirror image of the light, just below its direct image (rows 6–10).
    let reflection_rows = 11..15;
    let n_light = light.iter().filter(|&&b| b).count();
    assert!(n_light > 10, "the light covers {n_light} pixels");
    let edge = edge_of(&light, &scene, Some(0));
    let w = scene.camera.width as usize;
    for (kind, spp, polarized) in [
        (IntegratorKind::Path, 16, false),
        (IntegratorKind::Whitted, 4, false),
        (IntegratorKind::Sppm, 8, false),
        (IntegratorKind::Bdpt, 8, false),
        (IntegratorKind::LightTrace, 16, false),
        // Polarised transport runs each integrator's own polarised instance.
        (IntegratorKind::Path, 4, true),
        (IntegratorKind::Whitted, 2, true),
        (IntegratorKind::Bdpt, 4, true),
        (IntegratorKind::LightTrace, 4, true),
    ] {
        let shown = render_polarized(&scene, kind, spp, false, polarized);
        let hidden = render_polarized(&scene, kind, spp, true, polarized);
        for (k, &on) in light.iter().enumerate() {
            if on {
                assert_eq!(hidden.xyz[k], [0.0; 3], "{kind:?}: pixel {k}");
                if polarized {
                    let s = hidden.stokes.as_ref().unwrap();
                    assert_eq!(s[k], [[0.0; 3]; 3], "{kind:?}: pixel {k}");
                }
                if kind != IntegratorKind::LightTrace {
                    assert!(shown.xyz[k][1] > 1.0, "{kind:?}: pixel {k} shows the light");
                }
            }
        }
        // The reflection: the brightest pixel of the mirror image's rows.
        let brightest = |f: &Film| {
            (reflection_rows.start * w..reflection_rows.end * w)
                .map(|k| f.xyz[k][1])
                .fold(0.0f32, f32::max)
        };
        // (Light tracing cannot reach the camera through a mirror.)
        assert!(
            kind == IntegratorKind::LightTrace || brightest(&hidden) > 1.0,
            "{kind:?}: the light's reflection is gone ({})",
            brightest(&hidden)
        );
        // Nothing the setting drops draws a random number, so every other pixel keeps
        // its bytes, under the light-side integrators too (their dropped strategies only
        // reach the pixels that see the light).
        for k in 0..light.len() {
            if !light[k] && !edge[k] {
                assert_eq!(hidden.xyz[k], shown.xyz[k], "{kind:?}: pixel {k} changed");
                let stokes = |f: &Film| f.stokes.as_ref().map(|s| s[k]);
                assert_eq!(stokes(&hidden), stokes(&shown), "{kind:?}: pixel {k}");
            }
        }
    }
}

/// (b) The background and the sun's disk (in view) behind escaping camera rays are 0;
/// the sphere they light keeps its bytes.
#[test]
fn the_sky_and_the_sun_seen_directly_are_hidden() {
    let scene = load(
        r#"
background = [0.3, 0.4, 0.6]
[camera]
eye = [0.0, 0.0, 5.0]
look_at = [0.0, 0.0, 0.0]
d = 1.0
resolution = [32, 32]
[render]
max_depth = 4
[materials.grey]
type = "lambertian"
rho_d = 0.6
[[shapes]]
type = "sphere"
center = [0.0, 0.0, 0.0]
radius = 1.0
material = "grey"
[[lights]]
type = "sun"
direction = [-0.3, -0.3, 1.0]
irradiance = 3.0
angular_radius = 3.0
"#,
    );
    let sky = first_hits(&scene, None);
    let sphere = first_hits(&scene, Some(0));
    assert!(sky.iter().filter(|&&b| b).count() > 100);
    for (kind, spp) in [
        (IntegratorKind::Path, 8),
        (IntegratorKind::Whitted, 2),
        (IntegratorKind::Bdpt, 4),
        (IntegratorKind::Sppm, 4),
    ] {
        let shown = render(&scene, kind, spp, false);
        let hidden = render(&scene, kind, spp, true);
        // The sun's disk is in view (about (26, 6)), far brighter than the sky.
        let max_sky = (0..sky.len())
            .filter(|&k| sky[k])
            .map(|k| shown.xyz[k][1])
            .fold(0.0f32, f32::max);
        assert!(
            max_sky > 5.0,
            "{kind:?}: the sun's disk is not in view ({max_sky})"
        );
        for k in 0..sky.len() {
            if sky[k] {
                assert!(shown.xyz[k][1] > 0.1, "{kind:?}: pixel {k} shows the sky");
                assert_eq!(hidden.xyz[k], [0.0; 3], "{kind:?}: pixel {k}");
            }
            if sphere[k] {
                assert_eq!(hidden.xyz[k], shown.xyz[k], "{kind:?}: pixel {k} changed");
            }
        }
    }
}

/// (c) Under the setting, light tracing, BDPT and SPPM agree with the path tracer on the
/// Cornell box (its light in view), by `heron compare`'s region z-test (SPPM within its
/// radius bias, as in tests/agree.rs).
#[test]
fn every_integrator_agrees_with_path_when_emitters_are_hidden() {
    let scene = common::scenes::load_small("cornell-box.toml", 32, 32);
    let path = render(&scene, IntegratorKind::Path, 256, true);
    let light = first_hits(&scene, Some(0));
    // The light's own pixels: only the light reflected by its (white) quad is left,
    // which a path tracer finds as any other surface's.
    let before = render(&scene, IntegratorKind::Path, 16, false);
    let hidden = render(&scene, IntegratorKind::Path, 16, true);
    for k in (0..light.len()).filter(|&k| light[k]) {
        assert!(hidden.xyz[k][1] < 0.05 * before.xyz[k][1], "pixel {k}");
    }
    let alpha = 0.01 / 3.0;
    for (kind, spp) in [
        (IntegratorKind::LightTrace, 256),
        (IntegratorKind::Bdpt, 128),
    ] {
        let other = render(&scene, kind, spp, true);
        let c = compare_xyz(&path, &other, 8, alpha, None);
        assert!(
            c.same(),
            "{kind:?} against path:\n{}",
            c.report("path", "other", 10)
        );
    }
    let sppm = render(&scene, IntegratorKind::Sppm, 128, true);
    let c = compare(
        &Image::from_film_xyz(&path),
        &Image::from_film_xyz(&sppm),
        &Options {
            region: 8,
            alpha,
            correction: Correction::Sidak,
            mask: None,
            tolerance: 0.05,
        },
    )
    .unwrap();
    assert!(
        c.same(),
        "sppm against path:\n{}",
        c.report("path", "other", 10)
    );
}

/// A small scene file with an area light in view, `extra` added to its `[render]`.
fn tiny_scene(dir: &Path, name: &str, extra: &str) -> String {
    let text = format!(
        r#"
[camera]
eye = [0.0, 0.0, 5.0]
look_at = [0.0, 0.0, 0.0]
resolution = [8, 8]
[render]
integrator = "path"
spp = 2
{extra}
[materials.grey]
type = "lambertian"
rho_d = 0.5
[[shapes]]
type = "sphere"
center = [0.0, 0.0, 0.0]
radius = 1.0
material = "grey"
emission = 2.0
"#
    );
    write_file(dir, name, &text).to_str().unwrap().to_string()
}

/// (f) The scene key and the flag give the same bytes and record `hideEmitters`; the
/// default records nothing; a bad value is a one-line error naming the key.
#[test]
fn the_key_and_the_flag_agree_and_a_bad_value_names_the_key() {
    let d = tempfile::tempdir().unwrap();
    let keyed = tiny_scene(d.path(), "keyed.toml", "hide_emitters = true");
    let plain = tiny_scene(d.path(), "plain.toml", "");
    let out = |n: &str| d.path().join(n).to_str().unwrap().to_string();
    let (a, b, c) = (out("a.exr"), out("b.exr"), out("c.exr"));
    heron_ok(&["render", &keyed, "-o", &a, "--quiet", "--no-png"]);
    heron_ok(&[
        "render",
        &plain,
        "-o",
        &b,
        "--quiet",
        "--no-png",
        "--hide-emitters",
    ]);
    heron_ok(&["render", &plain, "-o", &c, "--quiet", "--no-png"]);
    let info = |p: &str| String::from_utf8_lossy(&heron_ok(&["info", p]).stdout).into_owned();
    assert!(info(&a).contains("hideEmitters"), "{}", info(&a));
    assert!(info(&b).contains("hideEmitters"), "{}", info(&b));
    assert!(!info(&c).contains("hideEmitters"), "{}", info(&c));
    // The images differ only in the scene's name and hash, which the provenance holds;
    // the pixels agree: the sphere is all light, hidden in both.
    let rgb = |p: &str| heron::film::exr::read_linear_srgb(Path::new(p)).unwrap();
    assert_eq!(rgb(&a), rgb(&b));
    assert_ne!(rgb(&a), rgb(&c));

    let bad = tiny_scene(d.path(), "bad.toml", "hide_emitters = 3");
    let o = heron(&["render", &bad, "-o", &out("x.exr"), "--quiet"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("render.hide_emitters"), "{err}");
}

/// (e) A shard rendered with the setting does not merge with one rendered without it,
/// and a checkpoint of one does not resume the other.
#[test]
fn a_merge_or_resume_across_the_setting_is_refused() {
    let d = tempfile::tempdir().unwrap();
    let sc = tiny_scene(d.path(), "s.toml", "");
    let out = |n: &str| d.path().join(n).to_str().unwrap().to_string();
    let (p0, p1) = (out("p0.heronfilm"), out("p1.heronfilm"));
    heron_ok(&["render", &sc, "-o", &p0, "--quiet", "--shard", "0/2"]);
    heron_ok(&[
        "render",
        &sc,
        "-o",
        &p1,
        "--quiet",
        "--shard",
        "1/2",
        "--hide-emitters",
    ]);
    let o = heron(&["merge", "-o", &out("m.exr"), &p0, &p1]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("hideEmitters"), "{err}");

    // A film file resumes as a checkpoint does (a stopped shard's part), checked alike.
    let o = heron(&[
        "render",
        &sc,
        "-o",
        &out("r.heronfilm"),
        "--quiet",
        "--shard",
        "0/2",
        "--resume",
        &p0,
        "--hide-emitters",
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("hideEmitters"), "{err}");
}

/// (d) Mitsuba's integrator key is read into `[render] hide_emitters`; when true, a
/// warning says heron keeps a hidden area light opaque where Mitsuba 3.7+'s path and
/// volpath see through it.
#[test]
fn mitsuba_hide_emitters_is_imported() {
    let d = tempfile::tempdir().unwrap();
    for (value, expect) in [("true", Some(true)), ("false", Some(false))] {
        let p = write_file(
            d.path(),
            "s.xml",
            &format!(
                r#"<scene version="3.0.0">
    <integrator type="path"><boolean name="hide_emitters" value="{value}"/></integrator>
    <sensor type="perspective"><float name="fov" value="45"/>
        <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film>
    </sensor>
    <shape type="sphere"/>
</scene>
"#
            ),
        );
        let imp = import_scene(&p, &ImportOptions::default()).unwrap();
        let render = imp.scene.render.as_ref().unwrap();
        assert_eq!(render.hide_emitters, expect);
        let warned = imp.warnings.iter().any(|w| {
            w.message
                .contains("hide_emitters: an area light the camera sees is black and opaque")
        });
        assert_eq!(warned, expect == Some(true), "{:?}", imp.warnings);
        let scene = heron::scene::load::load_imported(&imp).unwrap();
        assert_eq!(scene.settings.hide_emitters, expect == Some(true));
    }
}

/// The choice for media: a camera ray that crosses a medium (and its index-matched
/// boundary) without scattering still sees the background directly, and it is hidden
/// (the path tracer's depth counts scattering events, as Mitsuba 3's volpath's does).
/// In a purely absorbing sphere nothing scatters, so the whole image is 0.
#[test]
fn a_background_seen_through_a_medium_unscattered_is_hidden() {
    let scene = load(&common::scenes::furnace_sphere(
        r#"{ type = "henyey-greenstein", sigma_a = 1.0, sigma_s = 0.0, g = 0.0 }"#,
        "",
    ));
    for nee in [
        heron::settings::MediumNee::Forced,
        heron::settings::MediumNee::Collision,
    ] {
        let run = |hide: bool| {
            render_with(&scene, |o| {
                o.settings.integrator = IntegratorKind::Path;
                o.settings.spp = 4;
                o.settings.medium_nee = nee;
                o.settings.hide_emitters = hide;
            })
        };
        let (shown, hidden) = (run(false), run(true));
        // Through the sphere's middle (the camera sees the sphere whole): the background
        // dimmed by the free flights that got through unscattered.
        let through: f32 = (12..20)
            .flat_map(|y| (12..20).map(move |x| y * 32 + x))
            .map(|k| shown.xyz[k][1])
            .sum();
        assert!(through > 0.5, "{nee:?}: {through}");
        assert!(hidden.xyz.iter().all(|c| *c == [0.0; 3]), "{nee:?}");
    }
}
