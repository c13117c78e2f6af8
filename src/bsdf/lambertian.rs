//! Perfectly diffuse reflector, f_d = ρd/π (seed, "Interaction of eye rays"), sampled
//! with the cosine-weighted hemisphere (pdf cos θi/π), so f cos θi / pdf = ρd.
//!
//! Two-sided, as the seed's shading with the normal turned toward the viewer is: light
//! and viewer on the same side of the surface, either side.
use super::{same_hemisphere, BsdfContext, BsdfEval, BsdfModel, BsdfSample, LobeFlags};
use crate::math::warp::{cosine_hemisphere, cosine_hemisphere_pdf};
use crate::spectrum::{DenseSpectrum, SampledSpectrum, SampledWavelengths};
use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_1_PI;

#[derive(Clone, Debug)]
pub struct Lambertian {
    /// Diffuse reflectance ρd(λ) in [0, 1].
    pub rho_d: DenseSpectrum,
}

pub(super) const LOBE: LobeFlags = LobeFlags::DIFFUSE.union(LobeFlags::REFLECTION);

impl BsdfModel for Lambertian {
    #[inline]
    fn flags(&self) -> LobeFlags {
        LOBE
    }

    #[inline]
    fn eval<const N: usize>(
        &self,
        wo: Vec3,
        wi: Vec3,
        wl: &SampledWavelengths<N>,
        _: &BsdfContext,
    ) -> BsdfEval<N> {
        diffuse_eval(wo, wi, || wl.eval(&self.rho_d))
    }

    #[inline]
    fn sample<const N: usize>(
        &self,
        wo: Vec3,
        _: f32,
        u: Vec2,
        wl: &SampledWavelengths<N>,
        ctx: &BsdfContext,
    ) -> Option<BsdfSample<N>> {
        diffuse_sample(wo, u, ctx, || wl.eval(&self.rho_d))
    }

    #[inline]
    fn pdf<const N: usize>(
        &self,
        wo: Vec3,
        wi: Vec3,
        _: &SampledWavelengths<N>,
        ctx: &BsdfContext,
    ) -> f32 {
        diffuse_pdf(wo, wi, ctx)
    }
}

/// f = ρ/π on the side of ωo ([`Lambertian`] and the textured diffuse reflector, whose
/// ρ comes from an image); `rho` is only evaluated when f is not zero.
#[inline(always)]
pub(super) fn diffuse_eval<const N: usize>(
    wo: Vec3,
    wi: Vec3,
    rho: impl FnOnce() -> SampledSpectrum<N>,
) -> BsdfEval<N> {
    if !same_hemisphere(wo, wi) {
        return BsdfEval::zero();
    }
    BsdfEval::keep(rho() * FRAC_1_PI)
}

/// A cosine-weighted ωi on the side of ωo, f = ρ/π.
#[inline(always)]
pub(super) fn diffuse_sample<const N: usize>(
    wo: Vec3,
    u: Vec2,
    ctx: &BsdfContext,
    rho: impl FnOnce() -> SampledSpectrum<N>,
) -> Option<BsdfSample<N>> {
    if !ctx.lobes.allows(LOBE) {
        return None;
    }
    let mut wi = cosine_hemisphere(u);
    if wo.z < 0.0 {
        wi.z = -wi.z;
    }
    let pdf = cosine_hemisphere_pdf(wi.z.abs());
    if pdf == 0.0 {
        return None;
    }
    Some(BsdfSample {
        wi,
        f: rho() * FRAC_1_PI,
        pdf,
        flags: LOBE,
        eta: 1.0,
        ended_companions: false,
    })
}

/// The density of [`diffuse_sample`].
#[inline(always)]
pub(super) fn diffuse_pdf(wo: Vec3, wi: Vec3, ctx: &BsdfContext) -> f32 {
    if !ctx.lobes.allows(LOBE) || !same_hemisphere(wo, wi) {
        return 0.0;
    }
    cosine_hemisphere_pdf(wi.z.abs())
}
