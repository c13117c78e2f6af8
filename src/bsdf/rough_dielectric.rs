//! A rough dielectric interface: Walter, Marschner, Li & Torrance 2007 ("Microfacet
//! Models for Refraction through Rough Surfaces", EGSR), with the Trowbridge–Reitz
//! (GGX) distribution, the height-correlated Smith G and visible-normal sampling
//! (Heitz 2018). For a microfacet normal ωm:
//!
//! - reflection (eq. 20): f_r = D(ωm) G F(ωo·ωm) / (4 |cos θo| |cos θi|);
//! - transmission (eq. 21): f_t = D G (1 − F) |ωi·ωm| |ωo·ωm| / (|cos θi| |cos θo|
//!   (ωi·ωm + ωo·ωm/η′)²), divided by η′² for radiance (η′ = n_t/n_i; eq. 21 is written
//!   for importance/radiance with the (n_o/n_i)² convention of pbrt-v4 §9.7);
//! - ωm = ±(η′ ωi + ωo) normalised, on the outward side; microfacets that face away from
//!   either direction contribute nothing.
//!
//! Sampling draws ωm from the visible normals of ωo, then reflects with probability
//! F and refracts otherwise; pdf = D_ωo(ωm) · |∂ωm/∂ωi| · (F or 1 − F), with
//! |∂ωm/∂ωi| = 1/(4 |ωo·ωm|) for reflection and |ωi·ωm|/(ωi·ωm + ωo·ωm/η′)² for
//! transmission (Walter et al. eqs. 14, 17).
//!
//! Dispersion as for the smooth dielectric ([`super::dielectric`]): reflections keep
//! every lane with its own F(λᵢ); transmissions follow the hero and end the companions.
//! Single scattering only, so energy is lost at high roughness.
//!
//! α may be a texture over the surface (`alpha_texture`, read as a number: its
//! luminance; src/bsdf/texture_params.rs), looked up at each hit.
use super::fresnel::fresnel_dielectric_signed;
use super::microfacet::TrowbridgeReitz;
use super::polarization::{s_of_pair, Polarizing};
use super::texture_params::alpha_at;
use super::{
    reflect, refract_eta, same_hemisphere, BsdfContext, BsdfEval, BsdfModel, BsdfSample,
    Dielectric, LobeFlags, TransportMode,
};
use crate::math::Frame;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::texture::Texture;
use glam::{Vec2, Vec3};
use std::sync::Arc;

#[derive(Clone, Debug)]
pub struct RoughDielectric {
    /// The interface's indices (inside and outside).
    pub interface: Dielectric,
    pub distribution: TrowbridgeReitz,
    /// α over the surface's uv, replacing `distribution` (None: the constant).
    pub alpha_texture: Option<Arc<Texture>>,
}

const REFL: LobeFlags = LobeFlags::GLOSSY.union(LobeFlags::REFLECTION);
const TRANS: LobeFlags = LobeFlags::GLOSSY.union(LobeFlags::TRANSMISSION);

/// The generalised half vector of (ωo, ωi) for relative index `eta` (inside/outside):
/// (ωm on the outward side, η′ = n_t/n_i, reflection?), or None for a degenerate or
/// back-facing configuration.
#[inline]
fn half(wo: Vec3, wi: Vec3, eta: f32) -> Option<(Vec3, f32, bool)> {
    let (co, ci) = (wo.z, wi.z);
    if co == 0.0 || ci == 0.0 {
        return None;
    }
    let reflect = co * ci > 0.0;
    let etap = if reflect {
        1.0
    } else if co > 0.0 {
        eta
    } else {
        1.0 / eta
    };
    let wm = wi * etap + wo;
    if wm.length_squared() == 0.0 {
        return None;
    }
    let mut wm = wm.normalize();
    if wm.z < 0.0 {
        wm = -wm;
    }
    if wm.dot(wi) * ci < 0.0 || wm.dot(wo) * co < 0.0 {
        return None;
    }
    Some((wm, etap, reflect))
}

impl RoughDielectric {
    /// The distribution at the hit.
    #[inline]
    fn distribution_at(&self, ctx: &BsdfContext) -> TrowbridgeReitz {
        match &self.alpha_texture {
            None => self.distribution,
            Some(t) => alpha_at(t, ctx),
        }
    }

    /// Probabilities of reflection and transmission for Fresnel reflectance `r`.
    #[inline]
    fn choice(r: f32, ctx: &BsdfContext) -> (f32, f32) {
        let pr = if ctx.lobes.allows(REFL) { r } else { 0.0 };
        let pt = if ctx.lobes.allows(TRANS) {
            1.0 - r
        } else {
            0.0
        };
        (pr, pt)
    }

    /// F(ωo·ωm) per lane at a reflection, when the companions are alive and the index is
    /// dispersive; otherwise the hero's value in every lane.
    #[inline]
    fn fresnel_lanes<const N: usize>(
        &self,
        cos_om: f32,
        r_hero: f32,
        wl: &SampledWavelengths<N>,
        split: bool,
    ) -> SampledSpectrum<N> {
        let mut f = SampledSpectrum::<N>::splat(r_hero);
        if split {
            for i in 1..N {
                f.0[i] = fresnel_dielectric_signed(cos_om, self.interface.eta(wl.lambda[i]));
            }
        }
        f
    }

    #[inline]
    fn transmission_value(
        d: &TrowbridgeReitz,
        wo: Vec3,
        wi: Vec3,
        wm: Vec3,
        etap: f32,
        mode: TransportMode,
    ) -> f32 {
        let denom = (wi.dot(wm) + wo.dot(wm) / etap).powi(2) * wi.z * wo.z;
        let mut f = d.d(wm) * d.g(wo, wi) * (wi.dot(wm) * wo.dot(wm) / denom).abs();
        if mode == TransportMode::Radiance {
            f /= etap * etap;
        }
        f
    }
}

impl BsdfModel for RoughDielectric {
    #[inline]
    fn flags(&self) -> LobeFlags {
        if self.interface.is_dispersive() {
            REFL | TRANS | LobeFlags::WAVELENGTH_DEPENDENT
        } else {
            REFL | TRANS
        }
    }

    #[inline]
    fn eval<const N: usize>(
        &self,
        wo: Vec3,
        wi: Vec3,
        wl: &SampledWavelengths<N>,
        ctx: &BsdfContext,
    ) -> BsdfEval<N> {
        let eta = self.interface.eta(wl.lambda[0]);
        if eta == 1.0 {
            return BsdfEval::zero();
        }
        let Some((wm, etap, is_reflection)) = half(wo, wi, eta) else {
            return BsdfEval::zero();
        };
        let split = ctx.companions_alive && self.interface.is_dispersive();
        let cos_om = wo.dot(wm);
        let r = fresnel_dielectric_signed(cos_om, eta);
        let d = &self.distribution_at(ctx);
        if is_reflection {
            let k = d.d(wm) * d.g(wo, wi) / (4.0 * wi.z.abs() * wo.z.abs());
            return BsdfEval::keep(self.fresnel_lanes(cos_om, r, wl, split) * k);
        }
        let mut f = SampledSpectrum::splat(
            (1.0 - r) * Self::transmission_value(d, wo, wi, wm, etap, ctx.mode),
        );
        if split {
            f.terminate_secondary();
        }
        BsdfEval {
            f,
            ended_companions: split,
        }
    }

    #[inline]
    fn pdf<const N: usize>(
        &self,
        wo: Vec3,
        wi: Vec3,
        wl: &SampledWavelengths<N>,
        ctx: &BsdfContext,
    ) -> f32 {
        let eta = self.interface.eta(wl.lambda[0]);
        if eta == 1.0 {
            return 0.0;
        }
        let Some((wm, etap, is_reflection)) = half(wo, wi, eta) else {
            return 0.0;
        };
        let r = fresnel_dielectric_signed(wo.dot(wm), eta);
        let (pr, pt) = Self::choice(r, ctx);
        if pr + pt <= 0.0 {
            return 0.0;
        }
        let dv = self.distribution_at(ctx).d_visible(wo, wm);
        if is_reflection {
            dv / (4.0 * wo.dot(wm).abs()) * pr / (pr + pt)
        } else {
            let denom = (wi.dot(wm) + wo.dot(wm) / etap).powi(2);
            dv * wi.dot(wm).abs() / denom * pt / (pr + pt)
        }
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
        let eta = self.interface.eta(wl.lambda[0]);
        if eta == 1.0 {
            // Equal indices are no interface, however rough: light passes straight
            // through, a delta (pbrt-v4 `DielectricBxDF` does the same). The microfacet
            // lobe would divide by the zero half vector ωo + ωi (found by heron stress).
            return self.interface.sample(wo, uc, u, wl, ctx);
        }
        let d = &self.distribution_at(ctx);
        let wm = d.sample_wm(wo, u);
        let cos_om = wo.dot(wm);
        let r = fresnel_dielectric_signed(cos_om, eta);
        let (pr, pt) = Self::choice(r, ctx);
        if pr + pt <= 0.0 {
            return None;
        }
        let dv = d.d_visible(wo, wm);
        let split = ctx.companions_alive && self.interface.is_dispersive();
        if uc < pr / (pr + pt) {
            let wi = reflect(wo, wm);
            if !same_hemisphere(wo, wi) {
                return None;
            }
            let pdf = dv / (4.0 * cos_om.abs()) * pr / (pr + pt);
            let k = d.d(wm) * d.g(wo, wi) / (4.0 * wi.z.abs() * wo.z.abs());
            if !(pdf > 0.0) {
                return None;
            }
            return Some(BsdfSample {
                wi,
                f: self.fresnel_lanes(cos_om, r, wl, split) * k,
                pdf,
                flags: REFL,
                eta: 1.0,
                ended_companions: false,
            });
        }
        let (wi, etap) = refract_eta(wo, wm, eta)?;
        if same_hemisphere(wo, wi) || wi.z == 0.0 {
            return None;
        }
        let denom = (wi.dot(wm) + cos_om / etap).powi(2);
        let pdf = dv * wi.dot(wm).abs() / denom * pt / (pr + pt);
        if !(pdf > 0.0) {
            return None;
        }
        let mut f = SampledSpectrum::splat(
            (1.0 - r) * Self::transmission_value(d, wo, wi, wm, etap, ctx.mode),
        );
        if split {
            f.terminate_secondary();
        }
        Some(BsdfSample {
            wi,
            f,
            pdf,
            flags: self.flags() & TRANS_MASK,
            eta: etap,
            ended_companions: split,
        })
    }

    /// The microfacet's Fresnel reflection or transmission per lane's n(λ), in the frame
    /// of the plane that holds ωi, ωo and ωm (the s direction ωi × ωo), at ωi·ωm: the
    /// rough interface polarises as each of its facets does (single scattering).
    #[inline]
    fn mueller<const N: usize>(
        &self,
        wo: Vec3,
        wi: Vec3,
        _: LobeFlags,
        wl: &SampledWavelengths<N>,
        _: &Frame,
    ) -> Polarizing<N> {
        let eta = self.interface.eta(wl.lambda[0]);
        let Some((wm, _, _)) = half(wo, wi, eta) else {
            return Polarizing::Depolarizing;
        };
        let x = s_of_pair(wi, wo);
        // Signed by the side the light arrives from (ωm points outward).
        let cos = wi.dot(wm).abs() * wi.z.signum();
        let m =
            std::array::from_fn(|i| self.interface.interface_mueller(wo, wi, cos, wl.lambda[i]));
        Polarizing::Mueller {
            m,
            x_in: x,
            x_out: x,
        }
    }
}

/// The transmission lobe's flags, with the wavelength-dependence bit kept.
const TRANS_MASK: LobeFlags = TRANS.union(LobeFlags::WAVELENGTH_DEPENDENT);
