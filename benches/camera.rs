//! Camera rays: the seed's pinhole against rays traced through a lens prescription
//! (`[camera] type = "lens"`, issue 22) on the lens scenes, with the exit pupil's
//! bounds and with the whole rear element. Each iteration makes the 4096 rays of a
//! 64×64 grid of film points at one wavelength (587.6 nm, low-discrepancy pupil points),
//! so time / 4096 is one camera sample (criterion reports elements/s); rays the lens
//! stops count too, as they cost a render its sample.
use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use glam::Vec2;
use heron::camera::Camera;
use heron::scene::load::load_scene_from_str;
use std::path::Path;

const N: u32 = 64;

fn camera(name: &str, pupil: Option<&str>) -> Camera {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("scenes/{name}.toml"));
    let mut text = std::fs::read_to_string(&path).expect("scene file");
    if let Some(p) = pupil {
        text = text.replacen("[camera]\n", &format!("[camera]\npupil = \"{p}\"\n"), 1);
    }
    load_scene_from_str(&text, &path)
        .expect("scene loads")
        .camera
}

fn rays(cam: &Camera) -> u32 {
    let (sx, sy) = (cam.width as f32 / N as f32, cam.height as f32 / N as f32);
    let mut through = 0;
    for j in 0..N {
        for i in 0..N {
            // An R2 sequence (Roberts 2018) for the pupil points: cheap and even.
            let k = (j * N + i) as f32;
            let u = Vec2::new(
                (0.5 + 0.754_877_7 * k).fract(),
                (0.5 + 0.569_840_3 * k).fract(),
            );
            let r = cam.ray((i as f32 + 0.5) * sx, (j as f32 + 0.5) * sy, || u, 587.6);
            through += black_box(r).is_some() as u32;
        }
    }
    through
}

fn camera_rays(c: &mut Criterion) {
    let mut g = c.benchmark_group("camera_ray");
    g.throughput(Throughput::Elements((N * N) as u64));
    g.sample_size(20);
    let mut pinhole = camera("cooke-triplet", None);
    pinhole.lens = None;
    g.bench_function("pinhole", |b| b.iter(|| rays(&pinhole)));
    for name in ["singlet-chromatic", "cooke-triplet", "double-gauss"] {
        for pupil in ["bounds", "rear-element"] {
            let cam = camera(name, Some(pupil));
            g.bench_function(format!("{name}/{pupil}"), |b| b.iter(|| rays(&cam)));
        }
    }
    g.finish();
}

criterion_group!(benches, camera_rays);
criterion_main!(benches);
