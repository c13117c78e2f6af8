//! Kernels specialised to a scene's features (`scene/features.rs`): for every scene in
//! `scenes/`, under its own integrator and under `whitted` and `path`, the kernel the
//! renderer picks gives the same image, bit for bit, as the general kernel with every
//! feature compiled in; a kernel missing a feature the scene uses does not; and the
//! course's scenes get the kernels their contents imply.
mod common;

use heron::integrator::kernel_flags;
use heron::render::{render, RenderOptions};
use heron::scene::{Features, Scene};
use heron::settings::IntegratorKind;
use heron::settings::{
    flag_names, KernelChoice, KernelFlags, ALL, EMITTERS, ESCAPE, MEDIA, SHADOWS, SPECULAR,
};
use std::collections::BTreeSet;

fn scene(name: &str) -> Scene {
    // Small enough to render every scene twice per integrator in a second or two, large
    // enough that every feature is hit (each scene's camera sees its lights' effects).
    common::scenes::load_small(name, 40, 30)
}

fn image(s: &Scene, kind: IntegratorKind, kernel: KernelChoice) -> (Vec<u32>, KernelFlags) {
    let mut o = RenderOptions::from_scene(s);
    o.settings.integrator = kind;
    o.settings.kernel = kernel;
    o.settings.spp = 3;
    o.settings.lanes = heron::settings::Lanes::Four;
    o.threads = 2;
    // The specialised kernels are the unpolarised ones: a polarised scene (brewster,
    // polarized-*) is rendered unpolarised here; polarised renders have their own two
    // kernels (`integrator::stokes_flags`), whatever `kernel` says.
    o.settings.polarization = false;
    let (film, stats) = render(s, &o).unwrap();
    let bits = film.xyz.iter().flatten().map(|v| v.to_bits()).collect();
    (bits, stats.kernel)
}

#[test]
fn specialised_kernels_give_the_general_kernels_image() {
    let names = common::scenes::names();
    let mut kernels = BTreeSet::new();
    for name in &names {
        let s = scene(name);
        let own = s.settings.integrator;
        let mut kinds = vec![own, IntegratorKind::Whitted, IntegratorKind::Path];
        kinds.dedup();
        // Scenes with media render under the path tracer only (the others refuse them).
        if Features::of(&s).media {
            kinds = vec![IntegratorKind::Path];
        }
        for kind in kinds {
            let (auto, k) = image(&s, kind, KernelChoice::Auto);
            let (general, g) = image(&s, kind, KernelChoice::General);
            assert_eq!(g, ALL);
            assert_eq!(k, kernel_flags(kind, &Features::of(&s)), "{name}");
            assert!(
                auto == general,
                "{name}, {}: kernel {} differs from the general kernel",
                kind.name(),
                flag_names(k)
            );
            kernels.insert((kind.name(), k));
        }
    }
    // Not vacuous: the scenes exercise several specialised kernels of both integrators.
    let specialised = |n: &str| kernels.iter().filter(|(k, f)| *k == n && *f != ALL).count();
    assert!(specialised("whitted") >= 4, "{kernels:?}");
    assert!(specialised("path") >= 3, "{kernels:?}");
}

#[test]
fn a_kernel_without_a_feature_the_scene_uses_changes_the_image() {
    // Each flag matters somewhere: dropping it from the scene's own kernel changes the
    // image (so the flags switch real code, and the identity test above can fail).
    let cases: [(&str, IntegratorKind, KernelFlags); 6] = [
        ("default.toml", IntegratorKind::Whitted, SHADOWS),
        ("default.toml", IntegratorKind::Whitted, ESCAPE),
        ("default-mirror.toml", IntegratorKind::Whitted, SPECULAR),
        ("cornell-box.toml", IntegratorKind::Path, EMITTERS),
        ("cornell-box.toml", IntegratorKind::Path, SHADOWS),
        ("fogbow.toml", IntegratorKind::Path, MEDIA),
    ];
    for (name, kind, flag) in cases {
        let s = scene(name);
        let need = kernel_flags(kind, &Features::of(&s));
        assert!(need & flag != 0, "{name} should need {}", flag_names(flag));
        let (full, _) = image(&s, kind, KernelChoice::Auto);
        let (without, k) = image(&s, kind, KernelChoice::Forced(need & !flag));
        assert_eq!(k, need & !flag);
        assert!(
            full != without,
            "{name}: dropping {} changed nothing",
            flag_names(flag)
        );
    }
}

#[test]
fn course_scenes_get_the_kernels_their_contents_imply() {
    let w = |name: &str| kernel_flags(IntegratorKind::Whitted, &Features::of(&scene(name)));
    // A point light over Lambertian shapes under a blue background.
    assert_eq!(w("default.toml"), SHADOWS | ESCAPE);
    assert_eq!(w("default-mirror.toml"), SHADOWS | SPECULAR | ESCAPE);
    assert_eq!(w("default-glass.toml"), SHADOWS | SPECULAR | ESCAPE);
    // Mitsuba's Cornell box: an area light, diffuse walls, nothing outside the box.
    let c = scene("cornell-box.toml");
    assert_eq!(
        kernel_flags(IntegratorKind::Path, &Features::of(&c)),
        SHADOWS | EMITTERS
    );
    // Light tracing and BDPT have one kernel.
    assert_eq!(kernel_flags(IntegratorKind::Bdpt, &Features::of(&c)), ALL);
}
