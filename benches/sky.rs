//! Cost of one sky evaluation per model: `Sky::radiance` for a view direction and a
//! wavelength (the physical models convolve with the sun's disk on every call), and the
//! tabulated lookup the renderer uses instead (`SkyTable::eval`). Each iteration
//! evaluates 64 directions spread over 35–56° from the antisolar point at one
//! wavelength (so the Mie table for that wavelength is built once, in warm-up).
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use glam::Vec3;
use heron::sky::table::SkyTable;
use heron::sky::{AirySky, AristotleSky, DescartesSky, MieSky, Sky};
use heron::spectrum::DenseSpectrum;

fn dirs(sun: Vec3) -> Vec<Vec3> {
    let anti = -sun;
    let (t, _) = anti.any_orthonormal_pair();
    (0..64)
        .map(|k| {
            let th = (35.0 + 21.0 * k as f32 / 64.0).to_radians();
            (th.cos() * anti + th.sin() * t).normalize()
        })
        .collect()
}

fn sky(c: &mut Criterion) {
    let alpha = 0.2666f64.to_radians();
    let sun = Vec3::new(0.0, 0.26, 0.97).normalize();
    let d = dirs(sun);
    let models: Vec<(&str, Sky)> = vec![
        (
            "aristotle",
            Sky::Aristotle(AristotleSky::new(alpha, DenseSpectrum::constant(0.3))),
        ),
        ("descartes", Sky::Descartes(DescartesSky::water(alpha))),
        ("airy_0.5mm", Sky::Airy(AirySky::water(0.5, alpha))),
        ("mie_0.1mm", Sky::Mie(MieSky::water(0.1, alpha))),
    ];
    let mut g = c.benchmark_group("sky_eval");
    g.throughput(Throughput::Elements(d.len() as u64));
    g.sample_size(20);
    for (name, m) in &models {
        g.bench_function(format!("{name}/direct"), |b| {
            b.iter(|| d.iter().map(|v| m.radiance(*v, 550.0, sun)).sum::<f32>())
        });
    }
    let table = SkyTable::build(&models[1].1);
    g.bench_function("descartes/table", |b| {
        b.iter(|| {
            d.iter()
                .map(|v| table.eval(heron::sky::antisolar_angle(*v, sun).to_degrees(), 550.0))
                .sum::<f32>()
        })
    });
    g.finish();
}

criterion_group!(benches, sky);
criterion_main!(benches);
