//! A smooth metal: a delta reflection weighted by the conductor Fresnel reflectance
//! R(θ, λ) of its complex index n(λ) + i k(λ) ([`super::fresnel::fresnel_conductor`]),
//! per lane (pbrt-v4 `ConductorBxDF`, smooth case; Mitsuba 3 `conductor`).
//!
//! The index comes from measurements tabulated in `spectra/metals/` (Johnson & Christy
//! 1972 for Au, Ag, Cu; Rakić et al. 1998 for Al; see spectra/README.md) or from a
//! user's table. A metal's reflectance depends on wavelength but its direction does
//! not, so every lane is kept.
use super::fresnel::fresnel_conductor;
use super::polarization::{normalized, s_of_plane, Polarizing};
use super::{reflect_local, BsdfContext, BsdfModel, BsdfSample, LobeFlags};
use crate::math::Frame;
use crate::optics::mueller;
use crate::spectrum::metals::ComplexIor;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use glam::{Vec2, Vec3};
use num_complex::Complex64;

impl ComplexIor {
    /// R(cos θ) per lane.
    #[inline]
    pub fn reflectance<const N: usize>(
        &self,
        cos: f32,
        wl: &SampledWavelengths<N>,
    ) -> SampledSpectrum<N> {
        let mut r = SampledSpectrum::<N>::zero();
        for i in 0..N {
            let l = wl.lambda[i];
            r.0[i] = fresnel_conductor(cos, self.n.eval(l), self.k.eval(l));
        }
        r
    }

    /// The normalised Mueller matrix of reflection at `cos` and `lambda` nm.
    #[inline]
    pub fn mueller(&self, cos: f32, lambda: f32) -> glam::Mat4 {
        let eta = Complex64::new(self.n.eval(lambda) as f64, self.k.eval(lambda) as f64);
        normalized(&mueller::reflection(cos as f64, eta))
    }
}

#[derive(Clone, Debug)]
pub struct Conductor {
    pub ior: ComplexIor,
}

const LOBE: LobeFlags = LobeFlags::SPECULAR.union(LobeFlags::REFLECTION);

impl BsdfModel for Conductor {
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
        let c = wi.z.abs();
        Some(BsdfSample {
            wi,
            f: self.ior.reflectance(c, wl) / c,
            pdf: 1.0,
            flags: LOBE,
            eta: 1.0,
            ended_companions: false,
        })
    }

    /// Fresnel reflection of the complex index n(λ) + i k(λ), with its retardance
    /// (`optics::mueller::reflection`), in the s/p frame.
    #[inline]
    fn mueller<const N: usize>(
        &self,
        _: Vec3,
        wi: Vec3,
        _: LobeFlags,
        wl: &SampledWavelengths<N>,
        _: &Frame,
    ) -> Polarizing<N> {
        let x = s_of_plane(wi);
        let m = std::array::from_fn(|i| self.ior.mueller(wi.z.abs(), wl.lambda[i]));
        Polarizing::Mueller {
            m,
            x_in: x,
            x_out: x,
        }
    }
}
