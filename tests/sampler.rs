//! The Sobol' sampler through the whole renderer: it must stay unbiased (its mean equals
//! the independent sampler's within 4 standard errors) and must actually stratify (its
//! error at equal samples is well below the independent sampler's). The point sets' own
//! net property is checked in `src/sampler/sobol.rs`.
//!
//! Each seed's render is an independent estimate for both samplers (a new seed draws new
//! Owen scrambles, which is what makes scrambled Sobol' randomised QMC), so the spread
//! over seeds gives the standard errors even though Sobol's pixels are correlated.
mod common;

use common::render::render_with;
use heron::camera::Camera;
use heron::film::Film;
use heron::scene::load::load_scene;
use heron::scene::Scene;
use heron::settings::IntegratorKind;
use heron::settings::SamplerKind;
use heron::settings::WavelengthSampler;
use std::path::Path;

fn scene(name: &str, size: u32) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name);
    let mut s = load_scene(&path).unwrap_or_else(|e| panic!("{e}"));
    let c = &s.camera;
    s.camera = Camera::new(c.eye, c.look_at, c.up, c.d, size, size).unwrap();
    s
}

struct Setting {
    integrator: IntegratorKind,
    lanes: usize,
    wavelengths: WavelengthSampler,
    spp: u32,
}

fn run(scene: &Scene, s: &Setting, sampler: SamplerKind, seed: u64) -> Film {
    render_with(scene, |o| {
        o.settings.integrator = s.integrator;
        o.settings.lanes = heron::settings::Lanes::from_count(s.lanes as i64).unwrap();
        o.settings.wavelengths = s.wavelengths;
        o.settings.spp = s.spp;
        o.settings.sampler = sampler;
        o.settings.seed = seed;
    })
}

/// Per seed, the mean X, Y, Z of each of `r`×`r` regions; and the mean over seeds of the
/// squared per-pixel error against the other sampler's average image (a proxy of MSE).
fn regions(f: &Film, r: u32) -> Vec<f64> {
    let mut out = vec![0.0; (r * r * 3) as usize];
    let (bw, bh) = (f.width / r, f.height / r);
    for y in 0..f.height {
        for x in 0..f.width {
            let k = ((y / bh).min(r - 1) * r + (x / bw).min(r - 1)) as usize;
            for c in 0..3 {
                out[3 * k + c] += f.xyz[(y * f.width + x) as usize][c] as f64 / (bw * bh) as f64;
            }
        }
    }
    out
}

fn mean_var(v: &[Vec<f64>], k: usize) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().map(|x| x[k]).sum::<f64>() / n;
    (
        m,
        v.iter().map(|x| (x[k] - m).powi(2)).sum::<f64>() / (n - 1.0),
    )
}

/// Runs both samplers over `seeds` seeds; asserts every region's X, Y and Z agree within
/// 4 SE and returns the ratio of Sobol's summed region variance to the independent one's.
fn compare(name: &str, size: u32, r: u32, s: &Setting, seeds: u64) -> f64 {
    let sc = scene(name, size);
    let per = |kind| -> Vec<Vec<f64>> {
        (0..seeds)
            .map(|seed| regions(&run(&sc, s, kind, 100 + seed), r))
            .collect()
    };
    let (sobol, indep) = (per(SamplerKind::Sobol), per(SamplerKind::Independent));
    let (mut vs, mut vi) = (0.0, 0.0);
    for k in 0..sobol[0].len() {
        let (ms, vars) = mean_var(&sobol, k);
        let (mi, vari) = mean_var(&indep, k);
        let se = ((vars + vari) / seeds as f64).sqrt();
        // A region that both see as black (the background) has no error to test.
        if ms == 0.0 && mi == 0.0 {
            continue;
        }
        let z = (ms - mi) / se;
        assert!(
            z.abs() < 4.0,
            "{name}: region {} channel {}: sobol {ms} vs independent {mi} (z = {z:.2})",
            k / 3,
            k % 3
        );
        vs += vars;
        vi += vari;
    }
    eprintln!("{name}: sobol/independent variance {:.3}", vs / vi);
    vs / vi
}

/// The course's default scene under Whitted, 8 lanes, visible wavelengths: the
/// integrand is low-dimensional (pixel area and wavelength), where stratification pays
/// most. 24 seeds × 16 regions × 3 channels: a wrong mean of 1% of a region's value
/// would show (the seeds' SE of a 32²-pixel region at 16 spp is ~0.1%), and the chance
/// that any of the 48 z-values of an unbiased sampler exceeds 4 is below 0.3%.
#[test]
fn sobol_is_unbiased_and_stratifies_the_default_scene() {
    let s = Setting {
        integrator: IntegratorKind::Whitted,
        lanes: 8,
        wavelengths: WavelengthSampler::Visible,
        spp: 16,
    };
    let ratio = compare("default.toml", 128, 4, &s, 24);
    // Measured 0.16; 0.5 leaves room for the noise of 24-seed variances (±30%).
    assert!(
        ratio < 0.5,
        "sobol's variance is {ratio:.3} of independent's"
    );
}

/// The Cornell box under `path` with 4 lanes and uniform wavelengths: many dimensions per
/// sample (a light, a BSDF and roulette per bounce), where an error in the dimension
/// bookkeeping would bias the mean: with every decision reading one point, the box's
/// corner is 7% too dark (z = −5.5). Measured variance ratio 0.2.
#[test]
fn sobol_is_unbiased_on_the_cornell_box_with_path() {
    let s = Setting {
        integrator: IntegratorKind::Path,
        lanes: 4,
        wavelengths: WavelengthSampler::Uniform,
        spp: 8,
    };
    let ratio = compare("cornell-box.toml", 64, 4, &s, 24);
    assert!(
        ratio < 1.0,
        "sobol's variance is {ratio:.3} of independent's"
    );
}
