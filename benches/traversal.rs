//! Embree traversal: closest hit and occlusion, single rays vs 8-wide packets, for
//! coherent camera rays and incoherent hemisphere rays, on a deterministic procedural
//! mesh of about one million triangles (heron::bench::procedural_mesh(708)). Runs on
//! criterion's own thread, so without the FTZ/DAZ bits heron's workers set.
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use glam::Vec3;
use heron::accel::embree::{self, RayQuery};
use heron::math::Rng;

const N: usize = 64 * 64;

fn camera_rays() -> Vec<RayQuery> {
    // 4×2 blocks of a 64×64 view of the mesh, so packets hold neighbouring pixels.
    let eye = Vec3::new(0.0, 0.3, 3.0);
    let mut rays = Vec::with_capacity(N);
    for by in 0..32 {
        for bx in 0..16 {
            for k in 0..8 {
                let (x, y) = (bx * 4 + k % 4, by * 2 + k / 4);
                let u = (x as f32 + 0.5) / 64.0 * 2.0 - 1.0;
                let v = 1.0 - (y as f32 + 0.5) / 64.0 * 2.0;
                rays.push(RayQuery {
                    origin: eye,
                    dir: Vec3::new(0.6 * u, 0.6 * v - 0.1, -1.0).normalize(),
                    tnear: 0.0,
                    tfar: f32::INFINITY,
                });
            }
        }
    }
    rays
}

fn incoherent_rays() -> Vec<RayQuery> {
    // Origins spread inside the mesh's bounds, directions uniform on the sphere.
    let mut rng = Rng::new(1, 2);
    (0..N)
        .map(|_| {
            let mut u = || 2.0 * rng.uniform() - 1.0;
            let o = 0.9 * Vec3::new(u(), u(), u());
            let d = loop {
                let d = Vec3::new(u(), u(), u());
                let l = d.length();
                if l > 1e-3 && l <= 1.0 {
                    break d / l;
                }
            };
            RayQuery {
                origin: o,
                dir: d,
                tnear: 0.0,
                tfar: f32::INFINITY,
            }
        })
        .collect()
}

fn traversal(c: &mut Criterion) {
    let mesh = heron::bench::procedural_mesh(708);
    let device = embree::Device::new("threads=1").unwrap();
    let mut b = device.scene_builder();
    b.add_triangle_mesh(&mesh.positions, &mesh.indices).unwrap();
    let scene = b.commit().unwrap();
    let mut g = c.benchmark_group(format!("traversal_{}k_tris", mesh.indices.len() / 1000));
    g.throughput(Throughput::Elements(N as u64));
    for (kind, rays) in [
        ("coherent", camera_rays()),
        ("incoherent", incoherent_rays()),
    ] {
        g.bench_function(format!("{kind}/intersect1"), |b| {
            b.iter(|| {
                rays.iter()
                    .filter(|r| scene.intersect1(r).is_some())
                    .count()
            })
        });
        g.bench_function(format!("{kind}/intersect8"), |b| {
            b.iter(|| {
                let mut n = 0;
                for p in rays.chunks_exact(8) {
                    let p: &[RayQuery; 8] = p.try_into().unwrap();
                    n += scene
                        .intersect8(p, 0xff)
                        .iter()
                        .filter(|h| h.is_some())
                        .count();
                }
                n
            })
        });
        g.bench_function(format!("{kind}/occluded1"), |b| {
            b.iter(|| rays.iter().filter(|r| scene.occluded1(r)).count())
        });
        g.bench_function(format!("{kind}/occluded8"), |b| {
            b.iter(|| {
                let mut n = 0;
                for p in rays.chunks_exact(8) {
                    let p: &[RayQuery; 8] = p.try_into().unwrap();
                    n += scene.occluded8(p, 0xff).count_ones();
                }
                n
            })
        });
    }
    g.finish();
}

criterion_group!(benches, traversal);
criterion_main!(benches);
