//! Null-collision tracking through a heterogeneous medium (`medium::density`), with the
//! wavelength lanes' spectral MIS (Miller, Georgiev & Jarosz 2019, "A null-scattering
//! path integral formulation of light transport", ACM TOG 38(4); pbrt-v4 §14.1's
//! `SampleT_maj` and the rescaled path probabilities r_u, r_l of §14.2).
//!
//! The medium's extinction σ_t(x, λ) is bounded per lane by ρ̄ k_λ, with ρ̄ ≥ ρ the
//! density's majorant per cell and k_λ ≥ σ_t at unit density for every population of
//! drops the medium holds (`Medium::majorant_sigma_t`), so the null coefficients
//! σ_n,λ = ρ̄ k_λ − σ_t(x, λ) are ≥ 0 in every lane (no negative weights, whatever the
//! hero). Tentative collisions are drawn with the hero's majorant (lane 0) and T̄_λ =
//! exp(−k_λ ∫ρ̄) is each lane's majorant transmittance since the last one.
//!
//! - **Delta tracking** ([`delta_tracking`], free flights): at a tentative collision the
//!   event is real with probability σ_t,h/σ̄_h, else null; a null collision multiplies the path's weight and its
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
//! a stream keyed by the pixel sample and decision ([`crate::math::Rng::keyed`]); the
//! first distance uses the sampler's number where one is given.
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
    /// A real collision at distance `t`, where the extinction is `sigma_t`; `tr` is T̄_λ
    /// since the last null collision, to be divided as the homogeneous flight's
    /// transmittance is.
    Collided {
        t: f32,
        sigma_t: SampledSpectrum<N>,
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

/// The majorants σ̄ = ρ̄ k and null coefficients σ̄ − σ_t (≥ 0) per lane.
#[inline]
fn null<const N: usize>(
    rho_bar: f32,
    k: SampledSpectrum<N>,
    sigma_t: SampledSpectrum<N>,
) -> (SampledSpectrum<N>, SampledSpectrum<N>) {
    let bar = k * rho_bar;
    (
        bar,
        SampledSpectrum(std::array::from_fn(|i| (bar.0[i] - sigma_t.0[i]).max(0.0))),
    )
}

/// Delta tracking of the hero's free flight along o + t d (d unit), t ∈ [0, len],
/// through a medium whose density has the majorants of `density`, whose extinction at
/// unit density is at most `k` per lane and at a point `sigma_t_at`; `u0` draws the
/// first distance and `rng` the rest. Null collisions update `w` (module docs).
pub fn delta_tracking<const N: usize>(
    density: &Density,
    (o, d, len): (Vec3, Vec3, f32),
    k: SampledSpectrum<N>,
    sigma_t_at: impl Fn(Vec3) -> SampledSpectrum<N>,
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
            let sigma_t = sigma_t_at(o + d * t);
            let tr = majorant_tr(k, tau);
            let (bar, n) = null(rho_bar, k, sigma_t);
            if rng.uniform() * bar.0[0] < sigma_t.0[0] {
                found = Some(Flight::Collided { t, sigma_t, tr });
                return false;
            }
            // A null collision, of density T̄_h σ_n,h.
            let pdf = tr.0[0] * n.0[0];
            w.beta *= tr * n / pdf;
            w.r_u *= tr * n / pdf;
            w.r_l *= tr * bar / pdf;
            tau = 0.0;
        }
    });
    found.unwrap_or_else(|| Flight::Escaped {
        tr: majorant_tr(k, tau),
    })
}

/// Ratio tracking along o + t d (d unit), t ∈ [0, len], through a medium as in
/// [`delta_tracking`]: each lane's transmittance estimate and the light technique's
/// relative density of the null vertices (module docs), as (T̂, a). Stops early once
/// every lane's estimate is 0.
pub fn ratio_tracking<const N: usize>(
    density: &Density,
    (o, d, len): (Vec3, Vec3, f32),
    k: SampledSpectrum<N>,
    sigma_t_at: impl Fn(Vec3) -> SampledSpectrum<N>,
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
            let tb = majorant_tr(k, tau);
            let (bar, n) = null(rho_bar, k, sigma_t_at(o + d * t));
            // Every tentative collision is null, of density T̄_h σ̄_h.
            let pdf = tb.0[0] * bar.0[0];
            a *= tb * bar / pdf;
            tr *= tb * n / pdf;
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
