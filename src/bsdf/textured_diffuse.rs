//! A diffuse reflector whose ρd(λ) is a texture over the surface (Mitsuba 3 `diffuse`
//! with a `bitmap` or `checkerboard` reflectance, pbrt-v4 `diffuse` with a `reflectance`
//! texture): the [`super::Lambertian`] lobe with ρ looked up at the hit's uv
//! ([`BsdfContext::uv`]). A tree that can exceed 1 (a product) is clamped to [0, 1], as
//! pbrt-v4's `DiffuseMaterial` clamps its reflectance; an image, a checkerboard or a mix
//! of reflectances cannot, and is not touched, so that an image's value is its own.
use super::lambertian::{diffuse_eval, diffuse_pdf, diffuse_sample, LOBE};
use super::{BsdfContext, BsdfEval, BsdfModel, BsdfSample, LobeFlags};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::texture::{Node, Texture};
use glam::{Vec2, Vec3};
use std::sync::Arc;

#[derive(Clone, Debug)]
pub struct TexturedDiffuse {
    texture: Arc<Texture>,
    /// The tree has a product (`scale`), whose value may pass 1.
    clamp: bool,
}

impl TexturedDiffuse {
    pub fn new(texture: Arc<Texture>) -> TexturedDiffuse {
        let clamp = texture
            .nodes()
            .iter()
            .any(|n| matches!(n, Node::Scale { .. }));
        TexturedDiffuse { texture, clamp }
    }

    pub fn texture(&self) -> &Texture {
        &self.texture
    }

    /// ρd at the hit, per lane.
    #[inline]
    fn rho<const N: usize>(
        &self,
        ctx: &BsdfContext,
        wl: &SampledWavelengths<N>,
    ) -> SampledSpectrum<N> {
        let r = self.texture.eval(ctx.uv, wl);
        if self.clamp {
            SampledSpectrum(r.0.map(|x| x.clamp(0.0, 1.0)))
        } else {
            r
        }
    }
}

impl BsdfModel for TexturedDiffuse {
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
        diffuse_eval(wo, wi, || self.rho(ctx, wl))
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
        diffuse_sample(wo, u, ctx, || self.rho(ctx, wl))
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
