//! Perfect specular reflector (seed, "Reflected rays"): the law of reflection,
//! ωr = 2(ωi·n)n − ωi, with ωi pointing away from the surface. As a BSDF it is the
//! delta ρs δ(ωi − ωr)/|cos θi|, so the throughput changes by ρs.
use super::{reflect_local, BsdfContext, BsdfModel, BsdfSample, LobeFlags};
use crate::spectrum::{DenseSpectrum, SampledWavelengths};
use glam::{Vec2, Vec3};

pub use super::reflect;

#[derive(Clone, Debug)]
pub struct Mirror {
    /// Specular reflectance ρs(λ) in [0, 1]; 1 for the lecture's ideal mirror.
    pub rho_s: DenseSpectrum,
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
            f: wl.eval(&self.rho_s) / wi.z.abs(),
            pdf: 1.0,
            flags: LOBE,
            eta: 1.0,
            ended_companions: false,
        })
    }
}
