//! Diffuse transmission: a Lambertian reflector ρ_r/π on the side of ωo and a
//! Lambertian transmitter τ/π to the other side (pbrt-v4 `DiffuseTransmissionBxDF`,
//! §9.3 of the 4th edition's online chapters): paper, leaves, a lampshade. Two-sided by
//! nature; the same from either side.
//!
//! Sampling chooses reflection with probability ρ_r(λ₀)/(ρ_r(λ₀) + τ(λ₀)) (the hero's,
//! as pbrt-v4 does with its sampled spectrum's first lane, restricted to the lobes
//! `ctx.lobes` allows) and then a cosine-weighted direction on the chosen side, so the
//! density is that probability × |cos θi|/π and f |cos θi| / pdf = (ρ_r + τ)(λ₀) on
//! the hero. Neither direction depends on λ: every lane keeps its own f. The loader
//! checks ρ_r + τ ≤ 1 at every wavelength (energy conservation).
use super::{same_hemisphere, BsdfContext, BsdfEval, BsdfModel, BsdfSample, LobeFlags};
use crate::math::warp::{cosine_hemisphere, cosine_hemisphere_pdf};
use crate::spectrum::{DenseSpectrum, SampledWavelengths};
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

#[derive(Clone, Debug)]
pub struct DiffuseTransmission {
    /// Diffuse reflectance ρ_r(λ) in [0, 1].
    pub reflectance: DenseSpectrum,
    /// Diffuse transmittance τ(λ) in [0, 1], ρ_r + τ ≤ 1.
    pub transmittance: DenseSpectrum,
}

const REFL: LobeFlags = LobeFlags::DIFFUSE.union(LobeFlags::REFLECTION);
const TRANS: LobeFlags = LobeFlags::DIFFUSE.union(LobeFlags::TRANSMISSION);

impl DiffuseTransmission {
    /// The probabilities of choosing reflection and transmission under `ctx.lobes`,
    /// from the hero's ρ_r and τ; None when neither may be chosen.
    #[inline]
    fn lobe_probabilities<const N: usize>(
        &self,
        wl: &SampledWavelengths<N>,
        ctx: &BsdfContext,
    ) -> Option<(f32, f32)> {
        let pr = if ctx.lobes.allows(REFL) {
            self.reflectance.eval(wl.lambda[0])
        } else {
            0.0
        };
        let pt = if ctx.lobes.allows(TRANS) {
            self.transmittance.eval(wl.lambda[0])
        } else {
            0.0
        };
        let sum = pr + pt;
        (sum > 0.0).then(|| (pr / sum, pt / sum))
    }
}

impl BsdfModel for DiffuseTransmission {
    #[inline]
    fn flags(&self) -> LobeFlags {
        REFL | TRANS
    }

    #[inline]
    fn eval<const N: usize>(
        &self,
        wo: Vec3,
        wi: Vec3,
        wl: &SampledWavelengths<N>,
        _: &BsdfContext,
    ) -> BsdfEval<N> {
        if wo.z == 0.0 || wi.z == 0.0 {
            return BsdfEval::zero();
        }
        let rho = if same_hemisphere(wo, wi) {
            &self.reflectance
        } else {
            &self.transmittance
        };
        BsdfEval::keep(wl.eval(rho) * FRAC_1_PI)
    }

    #[inline]
    fn sample<const N: usize>(
        &self,
        wo: Vec3,
        uc: f32,
        u: Vec2,
        wl: &SampledWavelengths<N>,
        ctx: &BsdfContext,
    ) -> Option<BsdfSample<N>> {
        let (pr, pt) = self.lobe_probabilities(wl, ctx)?;
        let reflect = uc < pr;
        let mut wi = cosine_hemisphere(u);
        // Reflection stays on ωo's side, transmission crosses to the other.
        if (wo.z < 0.0) == reflect {
            wi.z = -wi.z;
        }
        let pdf = if reflect { pr } else { pt } * cosine_hemisphere_pdf(wi.z.abs());
        if !(pdf > 0.0) {
            return None;
        }
        let (rho, flags) = if reflect {
            (&self.reflectance, REFL)
        } else {
            (&self.transmittance, TRANS)
        };
        Some(BsdfSample {
            wi,
            f: wl.eval(rho) * FRAC_1_PI,
            pdf,
            flags,
            eta: 1.0,
            ended_companions: false,
        })
    }

    #[inline]
    fn pdf<const N: usize>(
        &self,
        wo: Vec3,
        wi: Vec3,
        wl: &SampledWavelengths<N>,
        ctx: &BsdfContext,
    ) -> f32 {
        if wo.z == 0.0 || wi.z == 0.0 {
            return 0.0;
        }
        let Some((pr, pt)) = self.lobe_probabilities(wl, ctx) else {
            return 0.0;
        };
        let p = if same_hemisphere(wo, wi) { pr } else { pt };
        p * cosine_hemisphere_pdf(wi.z.abs())
    }
}
