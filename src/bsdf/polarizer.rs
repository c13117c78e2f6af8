//! A linear polariser sheet: light passes straight through, its component along the
//! transmission axis with intensity transmittance t_x, the one across it with t_y
//! (t_x / t_y is the sheet's extinction ratio; an ideal polariser has t_y = 0).
//!
//! Its Mueller matrix in the frame x̂ = the axis is the diattenuator (Collett 2005,
//! "Linear diattenuator"; `optics::mueller::Mueller::diattenuator`)
//!
//!   ½ (t_x + t_y)  ½ (t_x − t_y)  0          0
//!   ½ (t_x − t_y)  ½ (t_x + t_y)  0          0
//!   0              0              √(t_x t_y)  0
//!   0              0              0          √(t_x t_y)
//!
//! the same seen from either side (turning the sheet over flips ŷ, which changes the
//! signs of S2 and S3 together). Unpolarised light keeps ½ (t_x + t_y) of its
//! intensity, which is what an unpolarised render sees: a neutral-density sheet.
//!
//! The axis is given in world space (`axis`, projected onto the sheet) and turned by
//! `angle` about the sheet's outward normal, counter-clockwise as seen from the side
//! the normal points to (Mitsuba 3's `polarizer` measures its angle from the shape's
//! tangent instead). An oblique ray is transmitted along the axis of Korger et al.
//! 2013 (`polarization::polarizer_axis`: perpendicular to the ray and to the absorption
//! axis, the in-sheet axis across the transmission axis, projected across the ray), as
//! Mitsuba's `polarizer` does. As a BSDF it is a delta transmission ωi = −ωo of weight
//! ½ (t_x + t_y), wavelength-independent.
use super::polarization::{normalized, polarizer_axis, Polarizing};
use super::{BsdfContext, BsdfModel, BsdfSample, LobeFlags};
use crate::math::Frame;
use crate::optics::mueller::Mueller;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use glam::{Mat4, Vec2, Vec3};

#[derive(Clone, Debug)]
pub struct Polarizer {
    /// The world direction whose projection onto the sheet is the axis at angle 0.
    pub axis: Vec3,
    /// The transmission axis's angle from `axis`'s projection, radians.
    pub angle: f32,
    /// Intensity transmittance along the axis, in (0, 1].
    pub t_x: f32,
    /// Intensity transmittance across it, in [0, t_x].
    pub t_y: f32,
}

const LOBE: LobeFlags = LobeFlags::SPECULAR.union(LobeFlags::TRANSMISSION);

/// Straight through with weight `w` (the intensity an unpolarised beam keeps).
#[inline]
pub(crate) fn pass_through<const N: usize>(
    wo: Vec3,
    w: f32,
    ctx: &BsdfContext,
) -> Option<BsdfSample<N>> {
    if !ctx.lobes.allows(LOBE) || !(w > 0.0) {
        return None;
    }
    let wi = -wo;
    Some(BsdfSample {
        wi,
        f: SampledSpectrum::splat(w / wi.z.abs()),
        pdf: 1.0,
        flags: LOBE,
        eta: 1.0,
        ended_companions: false,
    })
}

impl Polarizer {
    /// The matrix in the frame of its axis.
    pub fn matrix(&self) -> Mueller {
        Mueller::diattenuator(self.t_x as f64, self.t_y as f64)
    }
}

impl BsdfModel for Polarizer {
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
        pass_through(wo, 0.5 * (self.t_x + self.t_y), ctx)
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
        let x = polarizer_axis(frame.to_local(self.axis), self.angle, wi);
        let m: Mat4 = normalized(&self.matrix());
        Polarizing::Mueller {
            m: [m; N],
            x_in: x,
            x_out: x,
        }
    }
}
