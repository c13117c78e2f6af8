//! Null-collision tracking through a heterogeneous medium (`medium::density`), with the
//! wavelength lanes' spectral MIS (Miller, Georgiev & Jarosz 2019, "A null-scattering
//! path integral formulation of light transport", ACM TOG 38(4); pbrt-v4 §14.1's
//! `SampleT_maj` and the rescaled path probabilities r_u, r_l of §14.2).
//!
//! The medium's extinction is σ_t(x, λ) = ρ(x) k_λ (k: σ_t at density 1) and the
//! majorant grid gives ρ̄ ≥ ρ per cell, so the lanes' majorants σ̄_λ = ρ̄ k_λ all bound
//! their σ_t and the null coefficients σ_n,λ = (ρ̄ − ρ) k_λ are ≥ 0 in every lane (no
//! negative weights, whatever the hero). Tentative collisions are drawn with the hero's
//! majorant (lane 0) and T̄_λ = exp(−k_λ ∫ρ̄) is each lane's majorant transmittance
//! since the last one.
//!
//! - **Delta tracking** ([`delta_tracking`], free flights): at a tentative collision the
//!   event is real with probability ρ/ρ̄ (the same for every hero: the density scales
//!   all lanes alike), else null; a null collision multiplies the path's weight and its
//!   unidirectional probability ratio r_u by T̄_λ σ_n,λ / (T̄_h σ_n,h) and its
//!   light-sampling ratio r_l by T̄_λ σ̄_λ / (T̄_h σ_n,h): the density with which ratio
//!   tracking would have made the same null vertex, so that next-event estimation and
//!   phase sampling stay weighted by the balance heuristic over (technique, hero).
//! - **Ratio tracking** ([`ratio_tracking`], shadow rays; Novák, Selle & Jarosz 2014,
//!   "Residual ratio tracking for estimating attenuation in participating media", §3):
//!   every tentative collision is null; it returns each lane's transmittance estimate
//!   T̂_λ = Π T̄_λ σ_n,λ / (T̄_h σ̄_h) · T̄_λ,end / T̄_h,end (the hero's is the classic
//!   Π (1 − ρ/ρ̄)), unbiased for every lane, and the light technique's own relative
//!   density of those null vertices, Π T̄_λ σ̄_λ / (T̄_h σ̄_h) · T̄_λ,end / T̄_h,end, which
//!   the balance heuristic's denominator needs (`integrator::toolkit::Finish`).
//!
//! Random numbers: a tracker draws as many as its ray meets tentative collisions, from
//! a stream keyed by the ray ([`crate::math::Rng::keyed`]); the first distance uses the
//! sampler's number where one is given.
use super::density::Density;
use crate::math::Rng;
use crate::spectrum::SampledSpectrum;
use glam::Vec3;

/// What a path carries through null collisions: its weight and its rescaled
/// probabilities (`integrator::path`).
#[derive(Clone, Copy, Debug)]
pub struct Weights<const N: usize> {
    pub beta: SampledSpectrum<N>,
    pub r_u: SampledSpectrum<N>,
    pub r_l: SampledSpectrum<N>,
}

/// How a free flight ended.
#[derive(Clone, Copy, Debug)]
pub enum Flight<const N: usize> {
    /// A real collision at distance `t` with density `rho`; `tr` is T̄_λ since the last
    /// null collision, to be divided as the homogeneous flight's transmittance is.
    Collided {
        t: f32,
        rho: f32,
        tr: SampledSpectrum<N>,
    },
    /// The end of the segment reached; `tr` is T̄_λ since the last null collision.
    Escaped { tr: SampledSpectrum<N> },
}

/// exp(−k_λ τ) per lane.
#[inline]
fn majorant_tr<const N: usize>(k: SampledSpectrum<N>, tau: f32) -> SampledSpectrum<N> {
    SampledSpectrum(std::array::from_fn(|i| (-k.0[i] * tau).exp()))
}

/// Delta tracking of the hero's free flight along o + t d (d unit), t ∈ [0, len], in a
/// medium of density `density` and extinction `k` per unit density; `u0` draws the first
/// distance and `rng` the rest. Null collisions update `w` (module docs).
pub fn delta_tracking<const N: usize>(
    density: &Density,
    (o, d, len): (Vec3, Vec3, f32),
    k: SampledSpectrum<N>,
    u0: f32,
    rng: &mut Rng,
    w: &mut Weights<N>,
) -> Flight<N> {
    let kh = k.0[0];
    let mut tau = 0.0f32;
    let mut u_next = Some(u0);
    let mut found = None;
    density.majorants.walk(o, d, len, |a, b, rho_bar| {
        let rate = rho_bar * kh;
        let mut t = a;
        loop {
            if !(rate > 0.0) {
                tau += rho_bar * (b - t);
                return true;
            }
            let u = u_next.take().unwrap_or_else(|| rng.uniform());
            let step = -(-u).ln_1p() / rate;
            if t + step >= b {
                tau += rho_bar * (b - t);
                return true;
            }
            t += step;
            tau += rho_bar * step;
            let rho = density.eval(o + d * t).min(rho_bar);
            let tr = majorant_tr(k, tau);
            if rng.uniform() * rho_bar < rho {
                found = Some(Flight::Collided { t, rho, tr });
                return false;
            }
            // A null collision: σ_n,λ/σ_n,h = k_λ/k_h, σ̄_λ/σ_n,h = ρ̄ k_λ/((ρ̄ − ρ) k_h).
            let th = tr.0[0];
            let ratio = SampledSpectrum(std::array::from_fn(|i| tr.0[i] * k.0[i] / (th * kh)));
            w.beta *= ratio;
            w.r_u *= ratio;
            w.r_l *= ratio * (rho_bar / (rho_bar - rho));
            tau = 0.0;
        }
    });
    found.unwrap_or_else(|| Flight::Escaped {
        tr: majorant_tr(k, tau),
    })
}

/// Ratio tracking along o + t d (d unit), t ∈ [0, len]: each lane's transmittance
/// estimate and the light technique's relative density of the null vertices (module
/// docs), as (T̂, a). Stops early once every lane's estimate is 0.
pub fn ratio_tracking<const N: usize>(
    density: &Density,
    (o, d, len): (Vec3, Vec3, f32),
    k: SampledSpectrum<N>,
    rng: &mut Rng,
) -> (SampledSpectrum<N>, SampledSpectrum<N>) {
    let kh = k.0[0];
    let mut tau = 0.0f32;
    let mut tr = SampledSpectrum::splat(1.0);
    let mut a = SampledSpectrum::splat(1.0);
    density.majorants.walk(o, d, len, |s0, s1, rho_bar| {
        let rate = rho_bar * kh;
        let mut t = s0;
        loop {
            if !(rate > 0.0) {
                tau += rho_bar * (s1 - t);
                return true;
            }
            let step = -(-rng.uniform()).ln_1p() / rate;
            if t + step >= s1 {
                tau += rho_bar * (s1 - t);
                return true;
            }
            t += step;
            tau += rho_bar * step;
            let rho = density.eval(o + d * t).min(rho_bar);
            let tb = majorant_tr(k, tau);
            let th = tb.0[0];
            let ratio = SampledSpectrum(std::array::from_fn(|i| tb.0[i] * k.0[i] / (th * kh)));
            a *= ratio;
            tr *= ratio * ((rho_bar - rho) / rho_bar);
            tau = 0.0;
            if tr.is_zero() {
                return false;
            }
        }
    });
    if tr.is_zero() {
        return (tr, a);
    }
    let end = majorant_tr(k, tau);
    let end = end * (1.0 / end.0[0]);
    (tr * end, a * end)
}
