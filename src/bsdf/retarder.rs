//! A linear retarder (a wave plate): light passes straight through, unattenuated, its
//! component along the slow axis delayed by the retardance δ against the one along the
//! fast axis (δ = π/2: a quarter-wave plate, which turns linear light at 45° to its
//! axes circular; δ = π: a half-wave plate, which mirrors linear light about its axis).
//!
//! Its Mueller matrix in the frame x̂ = the fast axis (Collett 2005, "Linear
//! retarder"; `optics::mueller::Mueller::linear_retarder`) is
//!
//!   1  0  0       0
//!   0  1  0       0
//!   0  0  cos δ   sin δ
//!   0  0  −sin δ  cos δ
//!
//! the same seen from either side. The retardance is achromatic (the same at every
//! wavelength, as a Fresnel rhomb's nearly is; a zero-order crystal plate's falls as
//! 1/λ, which this model does not follow). The fast axis is given as the polariser's
//! transmission axis is ([`super::polarizer`]). As a BSDF it is a delta transmission
//! ωi = −ωo of weight 1.
use super::polarization::{normalized, retarder_axis, Polarizing};
use super::polarizer::pass_through;
use super::{BsdfContext, BsdfModel, BsdfSample, LobeFlags};
use crate::math::Frame;
use crate::optics::mueller::Mueller;
use crate::spectrum::SampledWavelengths;
use glam::{Vec2, Vec3};

#[derive(Clone, Debug)]
pub struct Retarder {
    /// The world direction whose projection onto the sheet is the fast axis at angle 0.
    pub axis: Vec3,
    /// The fast axis's angle from `axis`'s projection, radians.
    pub angle: f32,
    /// Retardance δ, radians.
    pub retardance: f32,
}

const LOBE: LobeFlags = LobeFlags::SPECULAR.union(LobeFlags::TRANSMISSION);

impl BsdfModel for Retarder {
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
        _: &SampledWavelengths<N>,
        ctx: &BsdfContext,
    ) -> Option<BsdfSample<N>> {
        pass_through(wo, 1.0, ctx)
    }

    #[inline]
    fn mueller<const N: usize>(
        &self,
        _: Vec3,
        wi: Vec3,
        _: LobeFlags,
        _: &SampledWavelengths<N>,
        frame: &Frame,
    ) -> Polarizing<N> {
        let x = retarder_axis(frame.to_local(self.axis), self.angle, wi);
        let m = normalized(&Mueller::linear_retarder(self.retardance as f64, 0.0));
        Polarizing::Mueller {
            m: [m; N],
            x_in: x,
            x_out: x,
        }
    }
}
