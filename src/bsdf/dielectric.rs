//! Smooth dielectric interface: refraction after the seed ("Refraction and total internal
//! reflection"), with a Fresnel-weighted choice between reflection and refraction.
//!
//! As a BSDF (pbrt-v4 §9.5) it is two deltas: reflection with weight R and transmission
//! with weight T = 1 − R, where R is the unpolarised Fresnel reflectance
//! ([`super::fresnel`]). Sampling picks reflection with probability R, so each branch
//! has throughput 1 (the seed's tracer with Fresnel weighting, estimated with one ray).
//! Transmitted radiance is scaled by (n_i/n_t)² (radiance is not invariant across an
//! interface; Veach 1997 §5.2), importance is not.
//!
//! With `fresnel = false` the lecture's pure refraction: always refract, reflect only on
//! total internal reflection.
//!
//! **Dispersion.** With n(λ) the direction of refraction differs per lane; the
//! refraction follows the hero (lane 0) and ends the companions (hero × N, others × 0).
//! A reflection sends every lane the same way, so they stay, each weighted by its own
//! R(λᵢ) while the choice was made with the hero's R(λ₀): lane i's factor is
//! R(λᵢ)/R(λ₀). With `fresnel = false` the choice between the two is deterministic in the
//! hero (TIR or not), so a companion whose own choice would differ cannot be weighted;
//! both branches then end the companions. This is the one place in heron where that
//! decision is written.
use super::fresnel::fresnel_dielectric;
use super::polarization::{normalized, s_of_plane, Polarizing};
use super::{reflect_local, BsdfContext, BsdfModel, BsdfSample, LobeFlags, TransportMode};
use crate::math::Frame;
use crate::optics::mueller;
use crate::spectrum::ior::Ior;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use glam::Mat4;
use glam::{Vec2, Vec3};
use num_complex::Complex64;

#[derive(Clone, Debug)]
pub struct Dielectric {
    /// Index of refraction inside (on the side opposite the outward normal), a function
    /// of wavelength.
    pub ior: Ior,
    /// Index of the medium outside (default 1, air or vacuum); e.g. water around a glass.
    pub outside: Ior,
    /// Weight reflection and refraction by the Fresnel equations (default). When false,
    /// the lecture's pure refraction: always refract, reflect only on total internal
    /// reflection.
    pub fresnel: bool,
}

const REFL: LobeFlags = LobeFlags::SPECULAR.union(LobeFlags::REFLECTION);
const TRANS: LobeFlags = LobeFlags::SPECULAR.union(LobeFlags::TRANSMISSION);

impl Dielectric {
    /// An interface between `ior` inside and vacuum (n = 1) outside.
    pub fn new(ior: Ior, fresnel: bool) -> Self {
        Dielectric {
            ior,
            outside: Ior::Constant(1.0),
            fresnel,
        }
    }

    /// True when the relative index depends on wavelength.
    #[inline]
    pub fn is_dispersive(&self) -> bool {
        self.ior.is_dispersive() || self.outside.is_dispersive()
    }

    /// Relative index n_inside/n_outside at `lambda` nm.
    #[inline]
    pub fn eta(&self, lambda: f32) -> f32 {
        match self.outside {
            Ior::Constant(1.0) => self.ior.eval(lambda),
            _ => self.ior.eval(lambda) / self.outside.eval(lambda),
        }
    }

    /// (n_i, n_t): the indices on the incident side and beyond, for a ray arriving from
    /// outside (`front_face`) or inside.
    #[inline]
    pub fn indices(&self, lambda: f32, front_face: bool) -> (f32, f32) {
        let (n_in, n_out) = (self.ior.eval(lambda), self.outside.eval(lambda));
        if front_face {
            (n_out, n_in)
        } else {
            (n_in, n_out)
        }
    }

    /// The seed's ior1_over_ior2 = n_i/n_t.
    #[inline]
    pub fn ior1_over_ior2(&self, lambda: f32, front_face: bool) -> f32 {
        let eta = self.eta(lambda);
        if front_face {
            1.0 / eta
        } else {
            eta
        }
    }

    /// The normalised Mueller matrix of light arriving along `wi` and leaving along `wo`
    /// at `lambda` nm, where `cos_i` is the cosine of the light's incidence on the
    /// (macro- or micro-) surface, signed: positive when it arrives from outside.
    #[inline]
    pub(crate) fn interface_mueller(&self, wo: Vec3, wi: Vec3, cos_i: f32, lambda: f32) -> Mat4 {
        let eta = self.eta(lambda) as f64;
        // The light goes from ωi's side into the other: n_t/n_i.
        let eta = if cos_i > 0.0 { eta } else { 1.0 / eta };
        let cos = cos_i.abs() as f64;
        if wi.z * wo.z > 0.0 {
            normalized(&mueller::reflection(cos, Complex64::new(eta, 0.0)))
        } else if self.fresnel {
            normalized(&mueller::transmission(cos, eta))
        } else {
            Mat4::IDENTITY
        }
    }

    /// Unpolarised Fresnel reflectance for light leaving along local `wo`.
    #[inline]
    pub fn fresnel_r(&self, wo: Vec3, lambda: f32) -> f32 {
        fresnel_dielectric(wo.z.abs(), self.ior1_over_ior2(lambda, wo.z > 0.0))
    }
}

impl BsdfModel for Dielectric {
    #[inline]
    fn flags(&self) -> LobeFlags {
        let t = if self.is_dispersive() {
            TRANS | LobeFlags::WAVELENGTH_DEPENDENT
        } else {
            TRANS
        };
        REFL | t
    }

    #[inline]
    fn sample<const N: usize>(
        &self,
        wo: Vec3,
        uc: f32,
        _: Vec2,
        wl: &SampledWavelengths<N>,
        ctx: &BsdfContext,
    ) -> Option<BsdfSample<N>> {
        let front = wo.z > 0.0;
        let eta_io = self.ior1_over_ior2(wl.lambda[0], front);
        let n = if front { Vec3::Z } else { Vec3::NEG_Z };
        let cos_o = wo.z.abs();
        let wt = refract(wo, n, eta_io);
        let r = if self.fresnel {
            fresnel_dielectric(cos_o, eta_io)
        } else if wt.is_none() {
            1.0
        } else {
            0.0
        };
        let pr = if ctx.lobes.allows(REFL) { r } else { 0.0 };
        let pt = if ctx.lobes.allows(TRANS) {
            1.0 - r
        } else {
            0.0
        };
        if pr + pt <= 0.0 {
            return None;
        }
        let split = ctx.companions_alive && self.is_dispersive();
        if uc < pr / (pr + pt) {
            let wi = reflect_local(wo);
            let mut f = SampledSpectrum::<N>::splat(r / cos_o);
            if split && self.fresnel {
                for i in 1..N {
                    f.0[i] =
                        fresnel_dielectric(cos_o, self.ior1_over_ior2(wl.lambda[i], front)) / cos_o;
                }
            } else if split {
                f.terminate_secondary();
            }
            return Some(BsdfSample {
                wi,
                f,
                pdf: pr / (pr + pt),
                flags: REFL,
                eta: 1.0,
                ended_companions: split && !self.fresnel,
            });
        }
        let wi = wt?;
        let etap = 1.0 / eta_io;
        let mut ft = (1.0 - r) / wi.z.abs();
        if ctx.mode == TransportMode::Radiance {
            ft /= etap * etap;
        }
        let mut f = SampledSpectrum::<N>::splat(ft);
        if split {
            f.terminate_secondary();
        }
        Some(BsdfSample {
            wi,
            f,
            pdf: pt / (pr + pt),
            flags: if self.is_dispersive() {
                TRANS | LobeFlags::WAVELENGTH_DEPENDENT
            } else {
                TRANS
            },
            eta: etap,
            ended_companions: split,
        })
    }

    /// Fresnel reflection (with total internal reflection's retardance) or
    /// transmission in the s/p frame of the plane of incidence, per lane's n(λ)
    /// (`optics::mueller::reflection`, `transmission`); the lecture's pure refraction
    /// (`fresnel = false`) transmits unchanged.
    #[inline]
    fn mueller<const N: usize>(
        &self,
        wo: Vec3,
        wi: Vec3,
        _: LobeFlags,
        wl: &SampledWavelengths<N>,
        _: &Frame,
    ) -> Polarizing<N> {
        let x = s_of_plane(wi);
        let m = std::array::from_fn(|i| self.interface_mueller(wo, wi, wi.z, wl.lambda[i]));
        Polarizing::Mueller {
            m,
            x_in: x,
            x_out: x,
        }
    }
}

/// Refracted direction after the seed's formula
/// ωt = η((ωi·n)n − ωi) − n √(1 − η²(1 − (ωi·n)²)), with η = n_i/n_t (the lecture's
/// ior1_over_ior2), ωi the unit direction toward the incident side and n the unit normal
/// on that side (ωi·n ≥ 0). Returns None on total internal reflection, when
/// cos²θt < 0.
#[inline]
pub fn refract(wi: Vec3, n: Vec3, eta: f32) -> Option<Vec3> {
    let cos_i = wi.dot(n);
    let cos2_t = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
    if cos2_t < 0.0 {
        return None;
    }
    Some(eta * (cos_i * n - wi) - n * cos2_t.sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Rng;

    fn random_unit_toward(n: Vec3, rng: &mut Rng) -> Vec3 {
        loop {
            let v = Vec3::new(
                2.0 * rng.uniform() - 1.0,
                2.0 * rng.uniform() - 1.0,
                2.0 * rng.uniform() - 1.0,
            );
            let l = v.length();
            if l > 1e-3 && l <= 1.0 {
                let v = v / l;
                return if v.dot(n) >= 0.0 { v } else { -v };
            }
        }
    }

    #[test]
    fn snell_holds_at_random_angles_both_ways() {
        let mut rng = Rng::new(42, 1);
        for &(ni, nt) in &[(1.0f32, 1.5f32), (1.5, 1.0), (1.0, 2.42), (1.333, 1.0)] {
            let mut refracted = 0;
            for _ in 0..10_000 {
                let n = random_unit_toward(Vec3::Y, &mut rng);
                let wi = random_unit_toward(n, &mut rng);
                let Some(wt) = refract(wi, n, ni / nt) else {
                    continue;
                };
                refracted += 1;
                assert!((wt.length() - 1.0).abs() < 1e-5);
                // Transmitted ray leaves on the other side, in the plane of incidence.
                assert!(wt.dot(n) <= 0.0);
                assert!(wi.cross(n).dot(wt).abs() < 1e-5);
                let sin_i = wi.cross(n).length();
                let sin_t = wt.cross(n).length();
                assert!(
                    (ni * sin_i - nt * sin_t).abs() < 1e-5,
                    "n_i sin θi = {} vs n_t sin θt = {}",
                    ni * sin_i,
                    nt * sin_t
                );
            }
            assert!(refracted > 1000);
        }
    }

    #[test]
    fn total_internal_reflection_exactly_past_the_critical_angle() {
        let (ni, nt) = (1.5f64, 1.0f64);
        let crit = (nt / ni).asin();
        for &d in &[1e-4f64, 1e-3, 1e-2, 0.3] {
            let below = crit - d;
            let above = crit + d;
            let wi_below = Vec3::new(below.sin() as f32, below.cos() as f32, 0.0);
            let wi_above = Vec3::new(above.sin() as f32, above.cos() as f32, 0.0);
            assert!(
                refract(wi_below, Vec3::Y, (ni / nt) as f32).is_some(),
                "{d}"
            );
            assert!(
                refract(wi_above, Vec3::Y, (ni / nt) as f32).is_none(),
                "{d}"
            );
        }
    }

    #[test]
    fn reflection_law_angle_in_equals_angle_out() {
        use crate::bsdf::reflect;
        let mut rng = Rng::new(3, 9);
        for _ in 0..10_000 {
            let n = random_unit_toward(Vec3::Z, &mut rng);
            let wi = random_unit_toward(n, &mut rng);
            let wr = reflect(wi, n);
            assert!((wr.dot(n) - wi.dot(n)).abs() < 1e-5);
            assert!((wr.length() - 1.0).abs() < 1e-5);
            assert!(wi.cross(n).dot(wr).abs() < 1e-5, "plane of incidence");
            assert!((wr + wi).cross(n).length() < 1e-5, "symmetric about n");
        }
    }
}
