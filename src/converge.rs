//! `heron converge`: run time against error. Renders a reference at many samples per
//! pixel (8 lanes, independent numbers, another seed), then the same scene at each
//! (lanes, spp) setting, and reports the wall time, the time per sample and the error
//! against the reference.
//!
//! Error: relative RMSE of linear sRGB over all pixels and channels,
//! sqrt(Σ (x − x_ref)²) / sqrt(Σ x_ref²). The reference's own noise is part of the
//! measured error; with a reference of k times the samples of a run, it inflates the
//! run's error by a factor of about sqrt(1 + 1/k), which the report states.
use crate::film::Film;
use crate::render::{RenderOptions, Renderer};
use crate::scene::Scene;
use crate::Result;
use serde::Serialize;

#[derive(Clone, Debug, Serialize)]
pub struct ConvergeRow {
    pub lanes: usize,
    pub spp: u32,
    pub wall_s: f64,
    pub ns_per_sample: f64,
    pub rel_rmse: f64,
    /// Error × sqrt(time): constant for an unbiased estimator whose variance falls as
    /// 1/time; smaller is more efficient.
    pub rmse_sqrt_time: f64,
}

/// Relative RMSE of `a` against `reference` over linear sRGB.
pub fn rel_rmse(a: &Film, reference: &Film) -> f64 {
    let (x, r) = (a.linear_srgb(), reference.linear_srgb());
    let mut num = 0.0f64;
    let mut den = 0.0f64;
    for (p, q) in x.iter().zip(&r) {
        for c in 0..3 {
            num += ((p[c] - q[c]) as f64).powi(2);
            den += (q[c] as f64).powi(2);
        }
    }
    (num / den.max(1e-300)).sqrt()
}

/// Renders the reference (`ref_spp`, 8 lanes, seed `seed + 1`) and one run per
/// (lanes, spp) with `seed`.
pub fn converge(
    scene: &Scene,
    base: &RenderOptions,
    ref_spp: u32,
    lanes: &[usize],
    spps: &[u32],
) -> Result<(f64, Vec<ConvergeRow>)> {
    let renderer = Renderer::with_threads(scene, base.threads)?;
    let mut o = base.clone();
    o.progress = None;
    o.settings.spp = ref_spp;
    o.settings.lanes = 8;
    o.settings.seed = base.settings.seed.wrapping_add(1);
    o.settings.sampler = crate::settings::SamplerKind::Independent;
    let (reference, ref_stats) = renderer.render(&o)?;
    let mut rows = Vec::new();
    for &l in lanes {
        for &spp in spps {
            let mut o = base.clone();
            o.progress = None;
            o.settings.lanes = l;
            o.settings.spp = spp;
            let (film, stats) = renderer.render(&o)?;
            let wall = stats.wall.as_secs_f64();
            let e = rel_rmse(&film, &reference);
            rows.push(ConvergeRow {
                lanes: l,
                spp,
                wall_s: wall,
                ns_per_sample: wall * 1e9 / stats.samples as f64,
                rel_rmse: e,
                rmse_sqrt_time: e * wall.sqrt(),
            });
        }
    }
    Ok((ref_stats.wall.as_secs_f64(), rows))
}
