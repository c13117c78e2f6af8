//! Packets of paths (`--packets paths`: the tile engine's `Steps` program under `whitted`
//! and `path`; camera packets under `bdpt`, none under `lighttrace`) against one path at
//! a time (`--packets camera`), on every scene in `scenes/` under every integrator.
//!
//! Both engines run the same integrator code (`whitted::step`, `path::step`) with the
//! same random numbers per (pixel, sample, dimension), so they would give the same bytes
//! but for Embree: its 8-wide packet kernels return the same hits as `rtcIntersect1`
//! and `rtcOccluded1` only up to the last bits of t, u and v (tests/embree.rs checks
//! 1e-5), and a ray that grazes an edge, or meets two coincident surfaces (the fog
//! bank's floor on the ground), can find a different surface. Such a path goes its own
//! way from there. Measured at 4 spp over the scenes at their own size under `whitted`
//! and `path` (BENCHMARKS.md, "Packets of paths"): 16 of 36 pairs give the same pixels,
//! the other non-media pairs agree to relative RMSE 1e-6, and the two media scenes, whose
//! scattered rays leave from points inside the fog and rain, to 5e-3, in about 0.1% of
//! their pixels. The bound below allows that and no more: a lost shadow ray, a sample added twice or a random
//! number read out of turn changes most pixels.
mod common;

use common::scenes::{load_small as scene, names as scene_names};
use heron::checkpoint::Shard;
use heron::render::{render, render_state, RenderOptions};
use heron::scene::{Features, Scene};
use heron::settings::{IntegratorKind, Packets};

struct Image {
    xyz: Vec<[f32; 3]>,
    rays: u64,
    shadow_rays: u64,
}

fn image(s: &Scene, kind: IntegratorKind, packets: Packets, threads: usize) -> Image {
    let mut o = RenderOptions::from_scene(s);
    o.settings.integrator = kind;
    o.settings.packets = packets;
    o.settings.spp = 4;
    o.settings.lanes = heron::settings::Lanes::Eight;
    o.threads = threads;
    // Packets of paths carry scalar throughputs: polarised scenes are compared
    // unpolarised (a polarised render runs camera packets only, `render.rs`).
    o.settings.polarization = false;
    let (film, stats) = render(s, &o).unwrap();
    Image {
        xyz: film.xyz,
        rays: stats.counters.rays,
        shadow_rays: stats.counters.shadow_rays,
    }
}

/// The pixels whose XYZ differ by more than 1e-4 of their own value (with a floor of
/// 1e-6 of the image's brightest, so that black pixels compare absolutely).
fn differing(a: &[[f32; 3]], b: &[[f32; 3]]) -> usize {
    let peak = b.iter().flatten().fold(0f32, |m, v| m.max(v.abs()));
    a.iter()
        .zip(b)
        .filter(|(p, q)| {
            p.iter()
                .zip(q.iter())
                .any(|(x, y)| (x - y).abs() > 1e-4 * y.abs().max(1e-6 * peak))
        })
        .count()
}

#[test]
fn packets_of_paths_give_the_one_path_at_a_time_image() {
    let names = scene_names();
    let (mut pairs, mut exact) = (0, 0);
    for name in &names {
        // 37x29: tiles narrower than a packet at the right and bottom edges.
        let s = scene(name, 37, 29);
        let kinds = if Features::of(&s).media {
            vec![IntegratorKind::Path]
        } else {
            vec![
                IntegratorKind::Whitted,
                IntegratorKind::Path,
                IntegratorKind::LightTrace,
                IntegratorKind::Bdpt,
            ]
        };
        for kind in kinds {
            let a = image(&s, kind, Packets::Paths, 2);
            let b = image(&s, kind, Packets::Camera, 2);
            let n = differing(&a.xyz, &b.xyz);
            // 1% of 1073 pixels: about ten paths that found another surface.
            assert!(
                n * 100 <= a.xyz.len(),
                "{name}, {}: {n} of {} pixels differ",
                kind.name(),
                a.xyz.len()
            );
            let close = |x: u64, y: u64| x.abs_diff(y) * 200 <= y.max(1);
            assert!(
                close(a.rays, b.rays) && close(a.shadow_rays, b.shadow_rays),
                "{name}, {}: rays {} and {} (shadow {} and {})",
                kind.name(),
                a.rays,
                b.rays,
                a.shadow_rays,
                b.shadow_rays
            );
            pairs += 1;
            exact += (a.xyz == b.xyz) as u32;
        }
    }
    // Not vacuous: most scenes give the same bytes.
    assert!(
        pairs >= 40 && exact * 2 >= pairs,
        "{exact} of {pairs} exact"
    );
}

/// The packet engine's image does not depend on the thread count (the passes' sample
/// ranges, which decide the packets' partners, are the next test's).
#[test]
fn packets_of_paths_are_deterministic() {
    let s = scene("default-glass.toml", 45, 35);
    for kind in [
        IntegratorKind::Whitted,
        IntegratorKind::Path,
        IntegratorKind::LightTrace,
        IntegratorKind::Bdpt,
    ] {
        let one = image(&s, kind, Packets::Paths, 1);
        let two = image(&s, kind, Packets::Paths, 2);
        assert!(one.xyz == two.xyz, "{}", kind.name());
        assert_eq!((one.rays, one.shadow_rays), (two.rays, two.shadow_rays));
    }
}

/// The shards of a render with packets of paths add up to the one render exactly, in a
/// scene where a ray's hit is most sensitive to how Embree traverses it (the fog bank's
/// floor on the ground): each shard's passes start at other samples, so its packets hold
/// other partners, and a hint chosen by what a packet holds made the two differ.
#[test]
fn shards_of_packets_of_paths_add_up_to_the_one_render() {
    let s = scene("fogbow.toml", 96, 54);
    let mut o = RenderOptions::from_scene(&s);
    o.settings.integrator = IntegratorKind::Path;
    o.settings.packets = Packets::Paths;
    o.settings.spp = 7;
    o.threads = 2;
    let (one, _) = render_state(&s, &o).unwrap();
    let mut sum = vec![0i128; one.film.planes.xyz.len()];
    for k in 0..3 {
        o.shard = Some(Shard::parse(&format!("{k}/3")).unwrap());
        let (part, _) = render_state(&s, &o).unwrap();
        for (a, b) in sum.iter_mut().zip(&part.film.planes.xyz) {
            *a = a.wrapping_add(*b);
        }
    }
    let differ = sum
        .iter()
        .zip(&one.film.planes.xyz)
        .filter(|(a, b)| a != b)
        .count();
    assert_eq!(differ, 0, "{differ} of {} sums differ", sum.len());
}

/// `auto` runs packets of paths under `whitted` and one path at a time otherwise, and
/// the film's settings key (the EXR's provenance) names what ran.
#[test]
fn auto_resolves_and_the_provenance_says_what_ran() {
    let s = scene("default.toml", 16, 16);
    for (kind, ran) in [
        (IntegratorKind::Whitted, "paths"),
        (IntegratorKind::Path, "true"),
        (IntegratorKind::Bdpt, "true"),
        (IntegratorKind::LightTrace, "false"),
    ] {
        let mut o = RenderOptions::from_scene(&s);
        o.settings.integrator = kind;
        o.settings.spp = 1;
        assert_eq!(o.settings.packets, Packets::Auto);
        let (state, _) = render_state(&s, &o).unwrap();
        assert_eq!(state.key.provenance["packets"], ran, "{}", kind.name());
    }
    // Asked for, packets of paths run under the path tracer too; light tracing and BDPT
    // have no steps (their connections' shadow rays in packets gained nothing:
    // BENCHMARKS.md, "Packets of paths"), so they run what `camera` runs.
    for (kind, ran) in [
        (IntegratorKind::Path, "paths"),
        (IntegratorKind::LightTrace, "false"),
        (IntegratorKind::Bdpt, "true"),
    ] {
        let mut o = RenderOptions::from_scene(&s);
        o.settings.integrator = kind;
        o.settings.spp = 1;
        o.settings.packets = Packets::Paths;
        let (state, _) = render_state(&s, &o).unwrap();
        assert_eq!(state.key.provenance["packets"], ran, "{}", kind.name());
    }
}
