//! Material parameters looked up in a texture at the hit's uv ([`BsdfContext::uv`]):
//! the glossy model's ρd and ρs, the coated material's reflectance and roughness, the
//! rough metal's and rough dielectric's roughness, the mirror's ρs (pbrt-v4's
//! `TextureEvaluator` in `materials.h`: every parameter of a material is a texture,
//! evaluated when the BSDF is built at a hit).
//!
//! A material whose parameters are all constants holds no texture (`None`) and takes the
//! constant unchanged, as before textures: the same arithmetic and the same bytes. A
//! textured value is clamped to the parameter's domain — a reflectance to [0, 1] per
//! lane, a roughness to [[`MIN_ALPHA`], 1] — since a product (`scale`) of textures can
//! leave it, and a roughness below `MIN_ALPHA` is narrower than f32 resolves (a
//! constant that small loads as the smooth model instead; a texture cannot switch
//! models per hit, so its α is raised to `MIN_ALPHA`).
use super::microfacet::{TrowbridgeReitz, MIN_ALPHA};
use super::BsdfContext;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::texture::Texture;

/// A reflectance texture at the hit, per lane, clamped to [0, 1].
#[inline]
pub(crate) fn reflectance_at<const N: usize>(
    t: &Texture,
    ctx: &BsdfContext,
    wl: &SampledWavelengths<N>,
) -> SampledSpectrum<N> {
    SampledSpectrum(t.eval(ctx.uv, wl).0.map(|x| x.clamp(0.0, 1.0)))
}

/// A number in [0, 1] at the hit: the texture's luminance ([`Texture::eval_scalar`]).
#[inline]
pub(crate) fn unit_at(t: &Texture, ctx: &BsdfContext) -> f32 {
    t.eval_scalar(ctx.uv).clamp(0.0, 1.0)
}

/// The GGX distribution whose α is the texture's luminance at the hit.
#[inline]
pub(crate) fn alpha_at(t: &Texture, ctx: &BsdfContext) -> TrowbridgeReitz {
    let a = t.eval_scalar(ctx.uv);
    // Written out rather than clamp: a NaN gives MIN_ALPHA, not NaN.
    let alpha = if a >= MIN_ALPHA {
        a.min(1.0)
    } else {
        MIN_ALPHA
    };
    TrowbridgeReitz { alpha }
}
