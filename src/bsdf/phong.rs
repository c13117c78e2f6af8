//! The modified Phong model of the seed ("Glossy materials"; Lewis 1994, Lafortune and
//! Willems 1994):
//!
//! f(ωi, ωo) = ρd/π + ρs (s+2)/(2π) (ωo·ωr)^s,  ωr = 2(ωi·n)n − ωi,
//!
//! which, as a BRDF on its own, loses energy but never creates it when ρd + ρs ≤ 1.
//!
//! Sampled as a mixture (Lafortune & Willems 1994, §4): the diffuse term by the cosine
//! hemisphere, the specular lobe about the mirror direction ωr(ωo) with density
//! (s+1)/(2π) cos^s α, cos α = u^(1/(s+1)), each chosen in proportion to its weight (ρd
//! averaged over the lanes, ρs). A lobe direction below the surface carries no energy
//! (the model's loss).
//!
//! The course's glossy-over-refractive combination (`base`) adds the dielectric's
//! delta lobes at full weight on top of the Phong lobes. The Whitted integrator takes
//! the Phong part from the lights and continues through the base, as the course does;
//! with ρd > 0 that combination can reflect more than it receives (the course's scenes
//! use ρd = 0). The path tracer samples the same sum, base weight 1.
//!
//! **Textures** ([`GlossyTextures`]): ρd may be a reflectance texture and ρs a texture
//! read as a number (its luminance, [`crate::texture::Texture::eval_scalar`]: ρs is one
//! number per point in the model, and the luminance is the value the eye weighs). The
//! constants' check ρd + ρs ≤ 1 cannot be made at load for a texture short of refusing
//! a whole image for one bright texel, so a textured material clamps at the hit
//! instead: ρs to [0, 1], then ρd per lane to [0, 1 − ρs], which keeps the model
//! energy-conserving wherever it is looked up (tests/texture_params.rs's furnace).
use super::polarization::Polarizing;
use super::texture_params::{reflectance_at, unit_at};
use super::{
    reflect_local, same_hemisphere, BsdfContext, BsdfEval, BsdfModel, BsdfSample, Dielectric,
    LobeFlags,
};
use crate::math::warp::{cosine_hemisphere, cosine_hemisphere_pdf};
use crate::math::Frame;
use crate::spectrum::{DenseSpectrum, SampledSpectrum, SampledWavelengths};
use crate::texture::Texture;
use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, PI};
use std::sync::Arc;

#[derive(Clone, Debug)]
pub struct Glossy {
    pub rho_d: DenseSpectrum,
    /// Specular reflectance ρs; ρd + ρs ≤ 1.
    pub rho_s: f32,
    /// Phong exponent s (shininess).
    pub shininess: f32,
    /// The seed's glossy-over-refractive combination: highlights from the lights, and the
    /// path continues through this dielectric.
    pub base: Option<Dielectric>,
    /// Textures that replace `rho_d` and/or `rho_s` (None: both constant).
    pub textures: Option<Box<GlossyTextures>>,
}

/// The textured parameters of a [`Glossy`]; a parameter without one keeps its constant.
#[derive(Clone, Debug, Default)]
pub struct GlossyTextures {
    pub rho_d: Option<Arc<Texture>>,
    pub rho_s: Option<Arc<Texture>>,
}

const DIFFUSE: LobeFlags = LobeFlags::DIFFUSE.union(LobeFlags::REFLECTION);
const LOBE: LobeFlags = LobeFlags::GLOSSY.union(LobeFlags::REFLECTION);

/// The specular lobe ρs (s+2)/(2π) max(0, ωo·ωr)^s for unit ωi, ωo (away from the
/// surface) and unit normal n on their side.
#[inline]
pub fn phong_specular(rho_s: f32, s: f32, wi: Vec3, wo: Vec3, n: Vec3) -> f32 {
    let wr = super::reflect(wi, n);
    let c = wo.dot(wr);
    if c <= 0.0 {
        return 0.0;
    }
    rho_s * (s + 2.0) / (2.0 * PI) * c.powf(s)
}

/// Density (s+1)/(2π) cos^s α of the lobe sampled about ωr.
#[inline]
fn lobe_pdf(s: f32, wr: Vec3, wi: Vec3) -> f32 {
    let c = wr.dot(wi);
    if c <= 0.0 {
        return 0.0;
    }
    (s + 1.0) / (2.0 * PI) * c.powf(s)
}

impl Glossy {
    /// ρd per lane and ρs at the hit: the constants, or the textures clamped so that
    /// ρd + ρs ≤ 1 (module doc).
    #[inline]
    fn params<const N: usize>(
        &self,
        wl: &SampledWavelengths<N>,
        ctx: &BsdfContext,
    ) -> (SampledSpectrum<N>, f32) {
        let Some(t) = &self.textures else {
            return (wl.eval(&self.rho_d), self.rho_s);
        };
        let rho_s = t.rho_s.as_ref().map_or(self.rho_s, |t| unit_at(t, ctx));
        let rho_d = match &t.rho_d {
            Some(t) => reflectance_at(t, ctx, wl),
            None => wl.eval(&self.rho_d),
        };
        (SampledSpectrum(rho_d.0.map(|x| x.min(1.0 - rho_s))), rho_s)
    }

    /// Selection weights of the diffuse term, the lobe and the base under `ctx.lobes`:
    /// the mean of ρd over the lanes (so that a lane whose ρd is positive is never left
    /// without a sampling strategy), ρs, and 1 for the base's R + T.
    #[inline]
    fn weights<const N: usize>(
        &self,
        rho_d: &SampledSpectrum<N>,
        rho_s: f32,
        ctx: &BsdfContext,
    ) -> (f32, f32, f32) {
        let wd = if ctx.lobes.allows(DIFFUSE) {
            rho_d.0.iter().sum::<f32>() / N as f32
        } else {
            0.0
        };
        let ws = if ctx.lobes.allows(LOBE) { rho_s } else { 0.0 };
        // The base is two delta lobes: it may be chosen when the mask allows either.
        let base_allowed = ctx
            .lobes
            .allows(LobeFlags::SPECULAR | LobeFlags::REFLECTION)
            || ctx
                .lobes
                .allows(LobeFlags::SPECULAR | LobeFlags::TRANSMISSION);
        let wb = if self.base.is_some() && base_allowed {
            1.0
        } else {
            0.0
        };
        (wd, ws, wb)
    }

    #[inline]
    fn pdf_mix(&self, wo: Vec3, wi: Vec3, wd: f32, ws: f32, total: f32) -> f32 {
        if !same_hemisphere(wo, wi) || total <= 0.0 {
            return 0.0;
        }
        (wd * cosine_hemisphere_pdf(wi.z.abs())
            + ws * lobe_pdf(self.shininess, reflect_local(wo), wi))
            / total
    }
}

impl BsdfModel for Glossy {
    #[inline]
    fn flags(&self) -> LobeFlags {
        let mut f = LobeFlags::NONE;
        let t = self.textures.as_deref();
        if self.rho_d.max_value() > 0.0 || t.is_some_and(|t| t.rho_d.is_some()) {
            f = f | DIFFUSE;
        }
        if self.rho_s > 0.0 || t.is_some_and(|t| t.rho_s.is_some()) {
            f = f | LOBE;
        }
        if let Some(b) = &self.base {
            f = f | b.flags();
        }
        f
    }

    #[inline]
    fn eval<const N: usize>(
        &self,
        wo: Vec3,
        wi: Vec3,
        wl: &SampledWavelengths<N>,
        ctx: &BsdfContext,
    ) -> BsdfEval<N> {
        if !same_hemisphere(wo, wi) {
            return BsdfEval::zero();
        }
        let (rho_d, rho_s) = self.params(wl, ctx);
        let fd = rho_d * FRAC_1_PI;
        let fs = phong_specular(rho_s, self.shininess, wi, wo, Vec3::Z);
        BsdfEval::keep(fd + SampledSpectrum::splat(fs))
    }

    #[inline]
    fn pdf<const N: usize>(
        &self,
        wo: Vec3,
        wi: Vec3,
        wl: &SampledWavelengths<N>,
        ctx: &BsdfContext,
    ) -> f32 {
        let (rho_d, rho_s) = self.params(wl, ctx);
        let (wd, ws, wb) = self.weights(&rho_d, rho_s, ctx);
        self.pdf_mix(wo, wi, wd, ws, wd + ws + wb)
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
        let (rho_d, rho_s) = self.params(wl, ctx);
        let (wd, ws, wb) = self.weights(&rho_d, rho_s, ctx);
        let total = wd + ws + wb;
        if total <= 0.0 {
            return None;
        }
        let (pd, ps) = (wd / total, ws / total);
        if uc >= pd + ps {
            // The refractive base; its own choice reuses what is left of uc.
            let pb = wb / total;
            let b = self.base.as_ref()?;
            let uc = ((uc - pd - ps) / pb).min(1.0 - f32::EPSILON / 2.0);
            let mut s = b.sample(wo, uc, u, wl, ctx)?;
            s.pdf *= pb;
            return Some(s);
        }
        let wi = if uc < pd {
            let mut wi = cosine_hemisphere(u);
            if wo.z < 0.0 {
                wi.z = -wi.z;
            }
            wi
        } else {
            let s = self.shininess;
            let cos_a = u.x.powf(1.0 / (s + 1.0));
            let sin_a = (1.0 - cos_a * cos_a).max(0.0).sqrt();
            let phi = 2.0 * PI * u.y;
            Frame::from_z(reflect_local(wo)).to_world(Vec3::new(
                sin_a * phi.cos(),
                sin_a * phi.sin(),
                cos_a,
            ))
        };
        if !same_hemisphere(wo, wi) {
            return None;
        }
        let pdf = self.pdf_mix(wo, wi, wd, ws, total);
        if pdf <= 0.0 {
            return None;
        }
        let fs = phong_specular(rho_s, self.shininess, wi, wo, Vec3::Z);
        Some(BsdfSample {
            wi,
            f: rho_d * FRAC_1_PI + SampledSpectrum::splat(fs),
            pdf,
            flags: if uc < pd { DIFFUSE } else { LOBE },
            eta: 1.0,
            ended_companions: false,
        })
    }

    /// The refractive base's Fresnel matrices for its specular events; the diffuse and
    /// Phong lobes depolarise.
    #[inline]
    fn mueller<const N: usize>(
        &self,
        wo: Vec3,
        wi: Vec3,
        lobe: LobeFlags,
        wl: &SampledWavelengths<N>,
        frame: &Frame,
    ) -> Polarizing<N> {
        match &self.base {
            Some(b) if lobe.is_specular() => b.mueller(wo, wi, lobe, wl, frame),
            _ => Polarizing::Depolarizing,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Directional albedo ∫ f_s(ωi, ωo) cos θi dωi over the hemisphere, by a midpoint
    /// rule in (θ, φ) fine enough to resolve a lobe of exponent `s`.
    fn specular_albedo(s: f32, theta_o: f32) -> f64 {
        let wo = Vec3::new(theta_o.sin(), 0.0, theta_o.cos());
        let n = Vec3::Z;
        let nt = 2000;
        let np = 1000;
        let (dt, dp) = (
            std::f64::consts::FRAC_PI_2 / nt as f64,
            2.0 * std::f64::consts::PI / np as f64,
        );
        let mut sum = 0.0;
        for i in 0..nt {
            let t = (i as f64 + 0.5) * dt;
            for j in 0..np {
                let p = (j as f64 + 0.5) * dp;
                let wi = Vec3::new(
                    (t.sin() * p.cos()) as f32,
                    (t.sin() * p.sin()) as f32,
                    t.cos() as f32,
                );
                let f = phong_specular(1.0, s, wi, wo, n) as f64;
                sum += f * t.cos() * t.sin() * dt * dp;
            }
        }
        sum
    }

    #[test]
    fn modified_phong_albedo_never_exceeds_one() {
        for &s in &[1.0f32, 2.0, 10.0, 42.0, 100.0, 1000.0] {
            let mut at_normal = 0.0;
            for &deg in &[0.0f32, 30.0, 60.0, 85.0] {
                let a = specular_albedo(s, deg.to_radians());
                assert!(a <= 1.0 + 2e-3, "s = {s}, θo = {deg}°: albedo {a}");
                if deg == 0.0 {
                    at_normal = a;
                }
            }
            // At normal incidence the normalisation (s+2)/(2π) makes the lobe exactly
            // energy conserving: ∫ (s+2)/(2π) cos^s θ cos θ dω = 1.
            assert!((at_normal - 1.0).abs() < 5e-3, "s = {s}: {at_normal}");
        }
    }

    #[test]
    fn lobe_peaks_in_the_mirror_direction() {
        let n = Vec3::Z;
        let wi = Vec3::new(0.6, 0.0, 0.8);
        let wr = super::super::reflect(wi, n);
        let peak = phong_specular(1.0, 42.0, wi, wr, n);
        assert!((peak - 44.0 / (2.0 * PI)).abs() < 1e-4);
        let off = phong_specular(1.0, 42.0, wi, (wr + 0.1 * Vec3::X).normalize(), n);
        assert!(off < peak);
    }
}
