//! A rough metal: the Torrance–Sparrow microfacet BRDF with the Trowbridge–Reitz (GGX)
//! distribution (Walter et al. 2007, eq. 20):
//!
//! f(ωo, ωi) = D(ωm) G(ωo, ωi) F(ωo·ωm) / (4 |cos θo| |cos θi|),  ωm = (ωo + ωi)/‖ωo + ωi‖,
//!
//! with the conductor Fresnel term per lane and directions sampled from the visible
//! normals (Heitz 2018): pdf = D_ωo(ωm)/(4 |ωo·ωm|). Single scattering only, so energy
//! is lost at high roughness (tests/bsdf.rs states how much). α may be a texture over
//! the surface (`alpha_texture`, read as a number: its luminance;
//! src/bsdf/texture_params.rs), looked up at each hit.
use super::microfacet::TrowbridgeReitz;
use super::polarization::{s_of_pair, Polarizing};
use super::texture_params::alpha_at;
use super::{reflect, same_hemisphere, BsdfContext, BsdfEval, BsdfModel, BsdfSample, LobeFlags};
use crate::math::Frame;
use crate::spectrum::metals::ComplexIor;
use crate::spectrum::SampledWavelengths;
use crate::texture::Texture;
use glam::{Vec2, Vec3};
use std::sync::Arc;

#[derive(Clone, Debug)]
pub struct RoughConductor {
    pub ior: ComplexIor,
    pub distribution: TrowbridgeReitz,
    /// α over the surface's uv, replacing `distribution` (None: the constant).
    pub alpha_texture: Option<Arc<Texture>>,
}

const LOBE: LobeFlags = LobeFlags::GLOSSY.union(LobeFlags::REFLECTION);

impl RoughConductor {
    /// The distribution at the hit.
    #[inline]
    fn distribution_at(&self, ctx: &BsdfContext) -> TrowbridgeReitz {
        match &self.alpha_texture {
            None => self.distribution,
            Some(t) => alpha_at(t, ctx),
        }
    }

    /// The half vector of a reflection pair, on the outward side; None when degenerate.
    #[inline]
    fn half(wo: Vec3, wi: Vec3) -> Option<Vec3> {
        if !same_hemisphere(wo, wi) {
            return None;
        }
        let h = wo + wi;
        if h.length_squared() == 0.0 {
            return None;
        }
        let h = h.normalize();
        Some(if h.z < 0.0 { -h } else { h })
    }
}

impl BsdfModel for RoughConductor {
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
        ctx: &BsdfContext,
    ) -> BsdfEval<N> {
        let Some(wm) = Self::half(wo, wi) else {
            return BsdfEval::zero();
        };
        let d = &self.distribution_at(ctx);
        let k = d.d(wm) * d.g(wo, wi) / (4.0 * wo.z.abs() * wi.z.abs());
        BsdfEval::keep(self.ior.reflectance(wo.dot(wm).abs(), wl) * k)
    }

    #[inline]
    fn pdf<const N: usize>(
        &self,
        wo: Vec3,
        wi: Vec3,
        _: &SampledWavelengths<N>,
        ctx: &BsdfContext,
    ) -> f32 {
        if !ctx.lobes.allows(LOBE) {
            return 0.0;
        }
        let Some(wm) = Self::half(wo, wi) else {
            return 0.0;
        };
        self.distribution_at(ctx).d_visible(wo, wm) / (4.0 * wo.dot(wm).abs())
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
        if !ctx.lobes.allows(LOBE) {
            return None;
        }
        let d = &self.distribution_at(ctx);
        let wm = d.sample_wm(wo, u);
        let wi = reflect(wo, wm);
        if !same_hemisphere(wo, wi) || wi.z == 0.0 {
            return None;
        }
        let pdf = d.d_visible(wo, wm) / (4.0 * wo.dot(wm).abs());
        if !(pdf > 0.0) {
            return None;
        }
        let k = d.d(wm) * d.g(wo, wi) / (4.0 * wo.z.abs() * wi.z.abs());
        Some(BsdfSample {
            wi,
            f: self.ior.reflectance(wo.dot(wm).abs(), wl) * k,
            pdf,
            flags: LOBE,
            eta: 1.0,
            ended_companions: false,
        })
    }

    /// The microfacet's Fresnel reflection, in the frame of the plane that holds ωi, ωo
    /// and the microfacet normal ωm (the s direction ωi × ωo), at ωi·ωm.
    #[inline]
    fn mueller<const N: usize>(
        &self,
        wo: Vec3,
        wi: Vec3,
        _: LobeFlags,
        wl: &SampledWavelengths<N>,
        _: &Frame,
    ) -> Polarizing<N> {
        let Some(wm) = Self::half(wo, wi) else {
            return Polarizing::Depolarizing;
        };
        let x = s_of_pair(wi, wo);
        let cos = wi.dot(wm).abs();
        let m = std::array::from_fn(|i| self.ior.mueller(cos, wl.lambda[i]));
        Polarizing::Mueller {
            m,
            x_in: x,
            x_out: x,
        }
    }
}
