//! A thin dielectric sheet: a pane of glass modelled by one surface, with no thickness.
//! Light reflects in the mirror direction or passes straight through (ωi = −ωo, no
//! refraction: the two faces' deflections cancel), and the sheet's internal reflections
//! are summed incoherently (pbrt-v4 `ThinDielectricBxDF`, Mitsuba 3 `thindielectric`;
//! Hecht, "Optics", 5th ed., §9.7.1 for the series). With R the Fresnel reflectance of
//! one face and T = 1 − R, the paths R, TRT, TR³T, … and TT, TR²T, … sum to
//!
//!   R' = R + T²R / (1 − R²) = 2R / (1 + R),   T' = 1 − R'.
//!
//! R is the same from either side (entering the sheet from the outside medium, or
//! leaving it, at the same angle inside), so the sheet is symmetric. It is not an
//! interface between media: a ray leaves in the medium it came from, and
//! [`super::Material::ior1_over_ior2`] stays 1.
//!
//! **Wavelengths.** Neither direction depends on λ, so a dispersive sheet keeps every
//! lane, each with its own R'(λᵢ) or T'(λᵢ), while the lobe is chosen with the hero's
//! R'(λ₀) (lane i's weight R'(λᵢ)/R'(λ₀)); no companion ends.
//!
//! **Polarisation.** For each of s and p the same series gives R'_s = 2R_s/(1 + R_s),
//! R'_p = 2R_p/(1 + R_p) and T' = 1 − R' per component: reflection and transmission are
//! diattenuators in the s/p frame of the plane of incidence. Their cross terms (the
//! Mueller matrix's [2][2] = [3][3]) are the incoherent sum of each path's r_s r_p (or
//! t_s t_p) product: with r' = −r inside and t t' = T (Stokes' relations),
//! c_R = r_s r_p (1 + T_s T_p / (1 − R_s R_p)) and c_T = T_s T_p / (1 − R_s R_p). They are
//! at most √(R'_s R'_p) (√(T'_s T'_p)), by Cauchy–Schwarz: summing paths of different
//! diattenuation depolarises slightly (by under 1 % for glass below 80°). No retardance
//! below total internal reflection; past it (a sheet less dense than its surroundings)
//! the first face reflects everything, with the retardance of
//! `optics::mueller::reflection`.
use super::fresnel::fresnel_dielectric;
use super::polarization::{normalized, s_of_plane, Polarizing};
use super::{reflect_local, BsdfContext, BsdfModel, BsdfSample, LobeFlags};
use crate::math::Frame;
use crate::optics::mueller::{self, Mueller};
use crate::spectrum::ior::Ior;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use glam::{Mat4, Vec2, Vec3};
use num_complex::Complex64;

#[derive(Clone, Debug)]
pub struct ThinDielectric {
    /// Index of the sheet, a function of wavelength.
    pub ior: Ior,
    /// Index of the medium on both sides (default 1).
    pub outside: Ior,
}

const REFL: LobeFlags = LobeFlags::SPECULAR.union(LobeFlags::REFLECTION);
const TRANS: LobeFlags = LobeFlags::SPECULAR.union(LobeFlags::TRANSMISSION);

/// The reflectance 2R/(1 + R) of a sheet whose faces reflect R each.
#[inline]
pub fn sheet_reflectance(r: f32) -> f32 {
    if r >= 1.0 {
        return 1.0;
    }
    2.0 * r / (1.0 + r)
}

impl ThinDielectric {
    /// A sheet of index `ior` in vacuum (n = 1).
    pub fn new(ior: Ior) -> Self {
        ThinDielectric {
            ior,
            outside: Ior::Constant(1.0),
        }
    }

    /// True when the relative index depends on wavelength.
    #[inline]
    pub fn is_dispersive(&self) -> bool {
        self.ior.is_dispersive() || self.outside.is_dispersive()
    }

    /// Relative index n_sheet/n_outside at `lambda` nm.
    #[inline]
    pub fn eta(&self, lambda: f32) -> f32 {
        match self.outside {
            Ior::Constant(1.0) => self.ior.eval(lambda),
            _ => self.ior.eval(lambda) / self.outside.eval(lambda),
        }
    }

    /// The sheet's reflectance R' for light at |cos θ| = `cos` and `lambda` nm.
    #[inline]
    pub fn reflectance(&self, cos: f32, lambda: f32) -> f32 {
        sheet_reflectance(fresnel_dielectric(cos, 1.0 / self.eta(lambda)))
    }

    /// The normalised Mueller matrix of the sheet's reflection (`reflect`) or
    /// transmission at |cos θ| = `cos` and relative index `eta` (module documentation).
    pub fn sheet_mueller(cos: f64, eta: f64, reflect: bool) -> Mat4 {
        let cos = cos.clamp(0.0, 1.0);
        if eta * eta < 1.0 - cos * cos {
            // Total reflection at the first face: no light enters the sheet.
            return if reflect {
                normalized(&mueller::reflection(cos, Complex64::new(eta, 0.0)))
            } else {
                Mat4::IDENTITY
            };
        }
        let (rs, rp, _) = mueller::fresnel_amplitudes(cos, Complex64::new(eta, 0.0));
        let (r_s, r_p) = (rs.norm_sqr(), rp.norm_sqr());
        let (t_s, t_p) = (1.0 - r_s, 1.0 - r_p);
        // The sum of the geometric series in R_s R_p (< 1 below total reflection).
        let series = 1.0 / (1.0 - r_s * r_p);
        let sheet = |r: f64| 2.0 * r / (1.0 + r);
        let (s2, p2, c) = if reflect {
            let x = (rs.conj() * rp).re;
            (sheet(r_s), sheet(r_p), x * (1.0 + t_s * t_p * series))
        } else {
            (1.0 - sheet(r_s), 1.0 - sheet(r_p), t_s * t_p * series)
        };
        let (a, b) = (0.5 * (s2 + p2), 0.5 * (s2 - p2));
        normalized(&Mueller([
            [a, b, 0.0, 0.0],
            [b, a, 0.0, 0.0],
            [0.0, 0.0, c, 0.0],
            [0.0, 0.0, 0.0, c],
        ]))
    }
}

impl BsdfModel for ThinDielectric {
    #[inline]
    fn flags(&self) -> LobeFlags {
        REFL | TRANS
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
        let cos = wo.z.abs();
        let r = self.reflectance(cos, wl.lambda[0]);
        let pr = if ctx.lobes.allows(REFL) { r } else { 0.0 };
        let pt = if ctx.lobes.allows(TRANS) {
            1.0 - r
        } else {
            0.0
        };
        if !(pr + pt > 0.0) {
            return None;
        }
        let reflect = uc < pr / (pr + pt);
        // Every lane keeps its own R'(λ) (T'(λ)): the directions are the same for all.
        let mut f = SampledSpectrum::<N>::splat(if reflect { r } else { 1.0 - r });
        if self.is_dispersive() {
            for i in 1..N {
                let ri = self.reflectance(cos, wl.lambda[i]);
                f.0[i] = if reflect { ri } else { 1.0 - ri };
            }
        }
        let (wi, pdf, flags) = if reflect {
            (reflect_local(wo), pr / (pr + pt), REFL)
        } else {
            (-wo, pt / (pr + pt), TRANS)
        };
        Some(BsdfSample {
            wi,
            f: f * (1.0 / cos),
            pdf,
            flags,
            eta: 1.0,
            ended_companions: false,
        })
    }

    /// The sheet's reflection or transmission, per lane's η(λ), in the s/p frame of the
    /// plane of incidence (module documentation).
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
        let reflect = wi.z * wo.z > 0.0;
        let cos = wi.z.abs() as f64;
        let m = std::array::from_fn(|i| {
            Self::sheet_mueller(cos, self.eta(wl.lambda[i]) as f64, reflect)
        });
        Polarizing::Mueller {
            m,
            x_in: x,
            x_out: x,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_series_sums_to_the_closed_form() {
        for &r in &[0.0f32, 0.04, 0.2, 0.7, 0.99] {
            let t = 1.0 - r;
            let (mut refl, mut trans, mut inner) = (r, 0.0f32, t);
            for _ in 0..2000 {
                trans += inner * t;
                inner *= r;
                refl += inner * t;
                inner *= r;
            }
            assert!((refl - sheet_reflectance(r)).abs() < 1e-5, "{r}");
            assert!((trans - (1.0 - sheet_reflectance(r))).abs() < 1e-5, "{r}");
        }
    }

    #[test]
    fn mueller_intensities_are_the_unpolarised_ones() {
        // The matrices' [0][0] before normalising would be R' and T'; their
        // diattenuation is (R'_s − R'_p)/(R'_s + R'_p).
        for &cos in &[1.0f64, 0.8, 0.5, 0.2, 0.05] {
            let eta = 1.5;
            let m = ThinDielectric::sheet_mueller(cos, eta, true);
            let (rs, rp) = crate::bsdf::fresnel::fresnel_dielectric_sp(cos as f32, 1.0 / 1.5);
            let (a, b) = (sheet_reflectance(rs), sheet_reflectance(rp));
            assert!((m.col(1).x - (a - b) / (a + b)).abs() < 1e-4, "{cos}");
            // Cross terms no larger than a pure diattenuator's.
            assert!(m.col(2).z.abs() <= 2.0 * (a * b).sqrt() / (a + b) + 1e-5);
            let t = ThinDielectric::sheet_mueller(cos, eta, false);
            let (ta, tb) = (1.0 - a, 1.0 - b);
            assert!((t.col(1).x - (ta - tb) / (ta + tb)).abs() < 1e-4, "{cos}");
            assert!(t.col(2).z <= 2.0 * (ta * tb).sqrt() / (ta + tb) + 1e-5);
        }
    }
}
