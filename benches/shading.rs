//! The per-sample loop: camera ray, Embree hit, material, shadow rays, continuation, film
//! weights, on the course's scenes (Whitted, their default), single-threaded, for 1, 4
//! and 8 wavelength lanes; and the path integrator on the Cornell box of
//! `scenes/cornell-box.toml`; both with packets of paths and one path at a time
//! (`--packets paths|camera`). Each iteration renders a 64×64 image at 1 spp on an
//! already built Embree scene, so time / 4096 is the cost of one sample (criterion
//! reports it as elements/s).
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use heron::render::{RenderOptions, Renderer};
use heron::scene::load_scene;
use heron::settings::Packets;
use std::path::Path;

fn shading(c: &mut Criterion) {
    let mut g = c.benchmark_group("sample");
    g.throughput(Throughput::Elements(64 * 64));
    g.sample_size(20);
    for name in [
        "default",
        "default-glass",
        "default-glossy",
        "cornell",
        "cornell-box",
    ] {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("scenes/{name}.toml"));
        let mut scene = load_scene(&path).expect("scene loads");
        scene.camera = heron::camera::Camera::new(
            scene.camera.eye,
            scene.camera.look_at,
            scene.camera.up,
            scene.camera.d,
            64,
            64,
        )
        .unwrap();
        let renderer = Renderer::new(&scene).expect("embree scene");
        for lanes in [1usize, 4, 8] {
            if lanes != 4 && name != "default" && name != "cornell-box" {
                continue;
            }
            let mut o = RenderOptions::from_scene(&scene);
            o.settings.spp = 1;
            o.threads = 1;
            o.settings.lanes = heron::settings::Lanes::from_count(lanes as i64).unwrap();
            let id = match o.settings.integrator {
                heron::settings::IntegratorKind::Whitted => format!("{name}/lanes{lanes}"),
                k => format!("{name}/{}/lanes{lanes}", k.name()),
            };
            g.bench_function(&id, |b| b.iter(|| renderer.render(&o).unwrap()));
            if name == "default" && lanes == 4 {
                // Every ray alone, camera rays too.
                let mut o = o.clone();
                o.settings.packets = Packets::Off;
                g.bench_function(format!("{name}/lanes{lanes}/no-packets"), |b| {
                    b.iter(|| renderer.render(&o).unwrap())
                });
            }
            if lanes == 8 && (name == "default" || name == "cornell-box") {
                // The two engines, whichever `auto` picks: packets of paths, and one
                // path at a time with camera packets.
                for (p, tag) in [(Packets::Paths, "paths"), (Packets::Camera, "camera")] {
                    let mut o = o.clone();
                    o.settings.packets = p;
                    g.bench_function(format!("{id}/packets-{tag}"), |b| {
                        b.iter(|| renderer.render(&o).unwrap())
                    });
                }
            }
        }
    }
    g.finish();
}

criterion_group!(benches, shading);
criterion_main!(benches);
