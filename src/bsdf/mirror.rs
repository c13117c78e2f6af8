//! Perfect specular reflector (seed, "Reflected rays"): the law of reflection,
//! ωr = 2(ωi·n)n − ωi, with ωi pointing away from the surface. As a BSDF it is the
//! delta ρs δ(ωi − ωr)/|cos θi|, so the throughput changes by ρs. ρs may be a texture
//! over the surface (src/bsdf/texture_params.rs).
use super::polarization::{s_of_plane, Polarizing};
use super::texture_params::reflectance_at;
use super::{reflect_local, BsdfContext, BsdfModel, BsdfSample, LobeFlags};
use crate::math::Frame;
use crate::spectrum::{DenseSpectrum, SampledWavelengths};
use crate::texture::Texture;
use glam::Mat4;
use glam::{Vec2, Vec3};
use std::sync::Arc;

pub use super::reflect;

#[derive(Clone, Debug)]
pub struct Mirror {
    /// Specular reflectance ρs(λ) in [0, 1]; 1 for the lecture's ideal mirror.
    pub rho_s: DenseSpectrum,
    /// ρs over the surface's uv, replacing `rho_s` (None: the constant).
    pub texture: Option<Arc<Texture>>,
}

const LOBE: LobeFlags = LobeFlags::SPECULAR.union(LobeFlags::REFLECTION);

impl BsdfModel for Mirror {
    #[inline]
    fn flags(&self) -> LobeFlags {
        LOBE
    }

    #[inline]
    fn sample<const N: usize>(
        &self,
        wo: Vec3,
        _: f32,
        _: Vec2,
        wl: &SampledWavelengths<N>,
        ctx: &BsdfContext,
    ) -> Option<BsdfSample<N>> {
        if !ctx.lobes.allows(LOBE) {
            return None;
        }
        let wi = reflect_local(wo);
        Some(BsdfSample {
            wi,
            f: match &self.texture {
                None => wl.eval(&self.rho_s),
                Some(t) => reflectance_at(t, ctx, wl),
            } / wi.z.abs(),
            pdf: 1.0,
            flags: LOBE,
            eta: 1.0,
            ended_companions: false,
        })
    }

    /// The ideal mirror (r_s = −r_p = −1): diag(1, 1, −1, −1), a half-wave retarder in
    /// Collett's frames, which turns the handedness of circular light.
    #[inline]
    fn mueller<const N: usize>(
        &self,
        _: Vec3,
        wi: Vec3,
        _: LobeFlags,
        _: &SampledWavelengths<N>,
        _: &Frame,
    ) -> Polarizing<N> {
        let x = s_of_plane(wi);
        let m = Mat4::from_diagonal(glam::Vec4::new(1.0, 1.0, -1.0, -1.0));
        Polarizing::Mueller {
            m: [m; N],
            x_in: x,
            x_out: x,
        }
    }
}
