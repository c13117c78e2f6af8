//! A diffuse reflector whose ρd(λ) is an image over the surface (Mitsuba 3 `diffuse`
//! with a `bitmap` reflectance, pbrt-v4 `diffuse` with an `imagemap` texture): the
//! [`super::Lambertian`] lobe with ρ looked up at the hit's uv ([`BsdfContext::uv`]).
use super::lambertian::{diffuse_eval, diffuse_pdf, diffuse_sample, LOBE};
use super::texture::ImageTexture;
use super::{BsdfContext, BsdfEval, BsdfModel, BsdfSample, LobeFlags};
use crate::spectrum::SampledWavelengths;
use glam::{Vec2, Vec3};
use std::sync::Arc;

#[derive(Clone, Debug)]
pub struct TexturedDiffuse {
    pub texture: Arc<ImageTexture>,
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
        diffuse_eval(wo, wi, || self.texture.eval(ctx.uv, wl))
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
        diffuse_sample(wo, u, ctx, || self.texture.eval(ctx.uv, wl))
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
