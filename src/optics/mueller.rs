//! Stokes vectors and Mueller matrices: the algebra of polarised light, in f64, from
//! which the materials build the matrices of polarised transport
//! (`crate::bsdf::polarization`, `crate::integrator::polarized`).
//!
//! # Convention
//!
//! Collett 2005 ("Field Guide to Polarization", SPIE FG05, §§ "Stokes parameters" and
//! "Mueller matrices"), the convention Mitsuba 3 follows (`include/mitsuba/render/
//! mueller.h`): a Stokes vector S = (S0, S1, S2, S3) is given in a frame (x̂, ŷ)
//! perpendicular to the direction of travel; S1 > 0 is linear polarisation along x̂,
//! S2 > 0 along (x̂ + ŷ)/√2, S3 > 0 right-circular. At an interface x̂ is the s
//! direction (perpendicular to the plane of incidence), so S1 > 0 is s-polarised light.
//! Angles of polarisers and fast axes are measured from x̂ toward ŷ.
//!
//! # Fresnel
//!
//! For a ray arriving at cos θi on an interface of relative index η = n_t / n_i
//! (complex for a conductor), the amplitude coefficients are (Born & Wolf, §1.5.2, with
//! the sign of r_p that makes r_s = −r_p at normal incidence, as Collett and Mitsuba
//! write them)
//!
//!   r_s = (cos θi − η cos θt) / (cos θi + η cos θt),
//!   r_p = (η cos θi − cos θt) / (η cos θi + cos θt),
//!
//! with η cos θt = √(η² − sin² θi) on the branch of non-negative imaginary part (an
//! evanescent wave under total internal reflection, an absorbing metal). The Mueller
//! matrix of the reflection is that of a diattenuating retarder (Collett's eq. for
//! reflection, Mitsuba's `specular_reflection`):
//!
//!   ½ (|r_s|² + |r_p|²)  ½ (|r_s|² − |r_p|²)  0   0
//!   ½ (|r_s|² − |r_p|²)  ½ (|r_s|² + |r_p|²)  0   0
//!   0                    0                    C   S
//!   0                    0                   −S   C
//!
//! with C = Re(r_s r_p*), S = −Im(r_s r_p*) = Im(r_s* r_p). The minus: Born & Wolf's
//! amplitudes belong to the time dependence e^{−iωt} (an absorbing index n + ik), and
//! Collett's S3 > 0 for right-circular light is written for the opposite one, whose
//! amplitudes are these' complex conjugates (Mitsuba's `fresnel_polarized` takes
//! n − ik for the same reason; `mueller.h`'s `specular_reflection` has −c sin δ at
//! [2][3] with δ = arg a_p − arg a_s). So at normal incidence on glass it is
//! R · diag(1, 1, −1, −1), a half-wave retarder, and at Brewster's angle (r_p = 0) a
//! polariser along s.
use num_complex::Complex64;

/// A Stokes vector (S0, S1, S2, S3) in the frame of the module's convention.
pub type Stokes = [f64; 4];

/// A 4 × 4 Mueller matrix, row by row.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mueller(pub [[f64; 4]; 4]);

impl Mueller {
    pub const IDENTITY: Mueller = Mueller([
        [1.0, 0.0, 0.0, 0.0],
        [0.0, 1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0],
        [0.0, 0.0, 0.0, 1.0],
    ]);

    /// An ideal depolariser that keeps the fraction `albedo` of the intensity (what a
    /// Lambertian surface or a Henyey–Greenstein phase function does to polarisation).
    pub fn depolarizer(albedo: f64) -> Mueller {
        let mut m = [[0.0; 4]; 4];
        m[0][0] = albedo;
        Mueller(m)
    }

    /// The matrix product `self · other` (`other` acts first).
    pub fn then_after(&self, other: &Mueller) -> Mueller {
        let mut m = [[0.0; 4]; 4];
        for (i, row) in m.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                *v = (0..4).map(|k| self.0[i][k] * other.0[k][j]).sum();
            }
        }
        Mueller(m)
    }

    pub fn apply(&self, s: &Stokes) -> Stokes {
        let mut out = [0.0; 4];
        for (i, o) in out.iter_mut().enumerate() {
            *o = (0..4).map(|k| self.0[i][k] * s[k]).sum();
        }
        out
    }

    /// The rotation of the Stokes frame by θ (radians, x̂ toward ŷ): a state given in a
    /// frame turned by θ (Collett's rotation matrix, R(θ) with 2θ).
    pub fn rotator(theta: f64) -> Mueller {
        let (s, c) = (2.0 * theta).sin_cos();
        Mueller([
            [1.0, 0.0, 0.0, 0.0],
            [0.0, c, s, 0.0],
            [0.0, -s, c, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ])
    }

    /// `self` turned about the direction of travel by θ: R(−θ) · M · R(θ).
    pub fn rotated(&self, theta: f64) -> Mueller {
        Mueller::rotator(-theta)
            .then_after(self)
            .then_after(&Mueller::rotator(theta))
    }

    /// An ideal linear polariser with its transmission axis at θ from x̂.
    pub fn linear_polarizer(theta: f64) -> Mueller {
        Mueller::diattenuator(1.0, 0.0).rotated(theta)
    }

    /// A linear polariser of intensity transmittances `tx` along its axis and `ty`
    /// across it (a sheet with a finite extinction ratio tx/ty), axis along x̂.
    pub fn diattenuator(tx: f64, ty: f64) -> Mueller {
        let (a, b, c) = (0.5 * (tx + ty), 0.5 * (tx - ty), (tx * ty).sqrt());
        Mueller([
            [a, b, 0.0, 0.0],
            [b, a, 0.0, 0.0],
            [0.0, 0.0, c, 0.0],
            [0.0, 0.0, 0.0, c],
        ])
    }

    /// A linear retarder of retardance δ (radians; π/2 a quarter-wave plate) with its
    /// fast axis at θ from x̂.
    pub fn linear_retarder(delta: f64, theta: f64) -> Mueller {
        let (s, c) = delta.sin_cos();
        Mueller([
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, c, s],
            [0.0, 0.0, -s, c],
        ])
        .rotated(theta)
    }
}

/// The degree of polarisation √(S1² + S2² + S3²)/S0 (0 for no light).
pub fn degree_of_polarization(s: &Stokes) -> f64 {
    if s[0] <= 0.0 {
        return 0.0;
    }
    (s[1] * s[1] + s[2] * s[2] + s[3] * s[3]).sqrt() / s[0]
}

/// Fresnel amplitudes (r_s, r_p) and η cos θt for a ray at `cos_i` (in (0, 1]) onto an
/// interface of relative index `eta` (see the module documentation).
pub fn fresnel_amplitudes(cos_i: f64, eta: Complex64) -> (Complex64, Complex64, Complex64) {
    let cos_i = cos_i.clamp(0.0, 1.0);
    let sin2 = 1.0 - cos_i * cos_i;
    let mut eta_cos_t = (eta * eta - sin2).sqrt();
    if eta_cos_t.im < 0.0 {
        eta_cos_t = -eta_cos_t;
    }
    // cos θt itself is η cos θt / η; r_p's numerator uses it divided once more by η.
    let cos_t = eta_cos_t / eta;
    let rs = (cos_i - eta_cos_t) / (cos_i + eta_cos_t);
    let rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    (rs, rp, eta_cos_t)
}

/// The Mueller matrix of reflection at `cos_i` from an interface of relative index
/// `eta` (a dielectric, with TIR's retardance, or a conductor n + ik).
pub fn reflection(cos_i: f64, eta: Complex64) -> Mueller {
    let (rs, rp, _) = fresnel_amplitudes(cos_i, eta);
    let (s2, p2) = (rs.norm_sqr(), rp.norm_sqr());
    // r_s* r_p: the conjugate time convention's r_s r_p* (module docs).
    let x = rs.conj() * rp;
    let (a, b) = (0.5 * (s2 + p2), 0.5 * (s2 - p2));
    Mueller([
        [a, b, 0.0, 0.0],
        [b, a, 0.0, 0.0],
        [0.0, 0.0, x.re, x.im],
        [0.0, 0.0, -x.im, x.re],
    ])
}

/// The Mueller matrix of transmission into a dielectric of relative index `eta` (real)
/// at `cos_i`, for the transmitted power: |t|² scaled by η cos θt / cos θi, so that its
/// [0][0] and reflection's add to 1 (radiance's (n_t/n_i)² is the transport's, not this
/// matrix's). Zero under total internal reflection.
pub fn transmission(cos_i: f64, eta: f64) -> Mueller {
    let cos_i = cos_i.clamp(0.0, 1.0);
    let sin2 = 1.0 - cos_i * cos_i;
    let k = eta * eta - sin2;
    if k <= 0.0 || cos_i == 0.0 {
        return Mueller([[0.0; 4]; 4]);
    }
    let eta_cos_t = k.sqrt();
    let cos_t = eta_cos_t / eta;
    let ts = 2.0 * cos_i / (cos_i + eta_cos_t);
    let tp = 2.0 * cos_i / (eta * cos_i + cos_t);
    let factor = eta_cos_t / cos_i;
    let (s2, p2) = (factor * ts * ts, factor * tp * tp);
    let (a, b, c) = (0.5 * (s2 + p2), 0.5 * (s2 - p2), (s2 * p2).sqrt());
    Mueller([
        [a, b, 0.0, 0.0],
        [b, a, 0.0, 0.0],
        [0.0, 0.0, c, 0.0],
        [0.0, 0.0, 0.0, c],
    ])
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

    const UNPOLARISED: Stokes = [1.0, 0.0, 0.0, 0.0];

    fn close(a: &Mueller, b: &Mueller, tol: f64) -> bool {
        a.0.iter()
            .flatten()
            .zip(b.0.iter().flatten())
            .all(|(x, y)| (x - y).abs() <= tol)
    }

    #[test]
    fn glass_at_normal_incidence_is_a_half_wave_retarder_of_four_percent() {
        let m = reflection(1.0, Complex64::new(1.5, 0.0));
        let want = Mueller([
            [0.04, 0.0, 0.0, 0.0],
            [0.0, 0.04, 0.0, 0.0],
            [0.0, 0.0, -0.04, 0.0],
            [0.0, 0.0, 0.0, -0.04],
        ]);
        assert!(close(&m, &want, 1e-12), "{m:?}");
        // Half-wave: right-circular light comes back left-circular.
        let s = m.apply(&[1.0, 0.0, 0.0, 1.0]);
        assert!((s[3] + 0.04).abs() < 1e-12);
    }

    #[test]
    fn at_brewster_s_alone_is_reflected_and_fully_polarised() {
        let n = 1.5f64;
        let cos_b = (1.0 / (1.0 + n * n)).sqrt(); // tan θB = n
        let m = reflection(cos_b, Complex64::new(n, 0.0));
        let s = m.apply(&UNPOLARISED);
        assert!((degree_of_polarization(&s) - 1.0).abs() < 1e-12, "{s:?}");
        assert!(s[1] > 0.0, "polarised along s (x̂): {s:?}");
        let (_, rp, _) = fresnel_amplitudes(cos_b, Complex64::new(n, 0.0));
        assert!(rp.norm() < 1e-12);
    }

    #[test]
    fn reflected_and_transmitted_power_add_to_one() {
        for n in [1.33, 1.5, 2.4] {
            for k in 0..=20 {
                let cos_i = (k as f64 / 20.0).max(1e-3);
                let (r, t) = (
                    reflection(cos_i, Complex64::new(n, 0.0)),
                    transmission(cos_i, n),
                );
                // For unpolarised light, and for each of s and p alone.
                assert!(
                    (r.0[0][0] + t.0[0][0] - 1.0).abs() < 1e-12,
                    "n {n} cos {cos_i}"
                );
                assert!((r.0[0][1] + t.0[0][1]).abs() < 1e-12, "n {n} cos {cos_i}");
            }
        }
    }

    #[test]
    fn total_internal_reflection_is_a_lossless_retarder_with_born_and_wolf_s_phase() {
        // Glass to air (η = 1/1.5), beyond the critical angle 41.8°: tan(δ/2) =
        // cos θ √(sin² θ − η²) / sin² θ (Born & Wolf §1.5.4, eq. 64).
        let eta = 1.0 / 1.5;
        for deg in [45.0f64, 50.0, 60.0, 75.0] {
            let th = deg.to_radians();
            let m = reflection(th.cos(), Complex64::new(eta, 0.0));
            assert!((m.0[0][0] - 1.0).abs() < 1e-12 && m.0[0][1].abs() < 1e-12);
            let delta = m.0[2][3].atan2(m.0[2][2]);
            let s2 = th.sin().powi(2);
            let want = 2.0 * (th.cos() * (s2 - eta * eta).sqrt() / s2).atan();
            assert!(
                (delta.abs() - want).abs() < 1e-12,
                "{deg}°: {} vs {}",
                delta.abs(),
                want
            );
            assert!(transmission(th.cos(), eta).0[0][0] == 0.0);
        }
    }

    /// The sign of the retardance (S3's handedness) against Mitsuba 3.9.1's
    /// `mi.mueller.specular_reflection` in `scalar_spectral_polarized`, evaluated at 60°
    /// (values printed by it, to its f32 precision): a conductor n = 1, k = 2.5, and
    /// total internal reflection at η = 1/1.5.
    #[test]
    fn retardance_has_mitsubas_sign() {
        let c = 60f64.to_radians().cos();
        let m = reflection(c, Complex64::new(1.0, 2.5));
        let want = [0.6145143, 0.17434072, -0.33963892, -0.4815376];
        let got = [m.0[0][0], m.0[0][1], m.0[2][2], m.0[2][3]];
        for (g, w) in got.iter().zip(want) {
            assert!((g - w).abs() < 1e-6, "{got:?} vs {want:?}");
        }
        assert!((m.0[3][2] + m.0[2][3]).abs() < 1e-15);
        let m = reflection(c, Complex64::new(1.0 / 1.5, 0.0));
        assert!((m.0[2][2] - 0.76086962).abs() < 1e-6, "{:?}", m.0);
        assert!((m.0[2][3] + 0.64890486).abs() < 1e-6, "{:?}", m.0);
    }

    #[test]
    fn a_conductor_at_45_degrees_is_a_pure_mueller_matrix_with_its_reflectances() {
        // Gold at 600 nm, n ≈ 0.25, k ≈ 2.98: a non-depolarising matrix has
        // M00² = M01² + M22² + M23², and M00 ± M01 are R_s and R_p of the real-arithmetic
        // form for metals (Born & Wolf §14.2; a² and b² from n, k and θ).
        let (n, k) = (0.25f64, 2.98f64);
        let cos_i = FRAC_PI_4.cos();
        let m = reflection(cos_i, Complex64::new(n, k));
        let lhs = m.0[0][0].powi(2);
        let rhs = m.0[0][1].powi(2) + m.0[2][2].powi(2) + m.0[2][3].powi(2);
        assert!((lhs - rhs).abs() < 1e-12);
        let th = FRAC_PI_4;
        let (st, ct, tt) = (th.sin(), th.cos(), th.tan());
        let w = n * n - k * k - st * st;
        let root = (w * w + 4.0 * n * n * k * k).sqrt();
        let (a2, b2) = (0.5 * (root + w), 0.5 * (root - w));
        let a = a2.sqrt();
        let rs = (a2 + b2 - 2.0 * a * ct + ct * ct) / (a2 + b2 + 2.0 * a * ct + ct * ct);
        let rp = rs * (a2 + b2 - 2.0 * a * st * tt + st * st * tt * tt)
            / (a2 + b2 + 2.0 * a * st * tt + st * st * tt * tt);
        assert!(
            (m.0[0][0] + m.0[0][1] - rs).abs() < 1e-12,
            "R_s {} vs {rs}",
            m.0[0][0] + m.0[0][1]
        );
        assert!(
            (m.0[0][0] - m.0[0][1] - rp).abs() < 1e-12,
            "R_p {} vs {rp}",
            m.0[0][0] - m.0[0][1]
        );
        // A metal turns linear light at 45° into elliptical light: S3 ≠ 0.
        let s = m.apply(&[1.0, 0.0, 1.0, 0.0]);
        assert!(s[3].abs() > 0.05, "{s:?}");
    }

    #[test]
    fn malus_law_and_a_quarter_wave_plate() {
        for deg in [0.0f64, 30.0, 45.0, 60.0, 90.0] {
            let th = deg.to_radians();
            let m = Mueller::linear_polarizer(th).then_after(&Mueller::linear_polarizer(0.0));
            let s = m.apply(&UNPOLARISED);
            assert!(
                (s[0] - 0.5 * th.cos().powi(2)).abs() < 1e-12,
                "{deg}°: {s:?}"
            );
        }
        // Horizontal linear light through a quarter-wave plate at 45°: circular.
        let s = Mueller::linear_retarder(FRAC_PI_2, FRAC_PI_4).apply(&[1.0, 1.0, 0.0, 0.0]);
        assert!(
            (s[3].abs() - 1.0).abs() < 1e-12 && s[1].abs() < 1e-12,
            "{s:?}"
        );
        // A half-wave plate at 22.5° turns horizontal into +45° linear.
        let s = Mueller::linear_retarder(PI, PI / 8.0).apply(&[1.0, 1.0, 0.0, 0.0]);
        assert!((s[2] - 1.0).abs() < 1e-12, "{s:?}");
        // A sheet with extinction ratio 1000: crossed, 1/1000 of the parallel light.
        let sheet = |t: f64| Mueller::diattenuator(1.0, 1e-3).rotated(t);
        let par = sheet(0.0).then_after(&sheet(0.0)).apply(&UNPOLARISED)[0];
        let crossed = sheet(FRAC_PI_2).then_after(&sheet(0.0)).apply(&UNPOLARISED)[0];
        assert!(
            (crossed / par - 2e-3 / (1.0 + 1e-6)).abs() < 1e-6,
            "{}",
            crossed / par
        );
        // A depolariser leaves unpolarised light.
        let s = Mueller::depolarizer(0.7).apply(&[1.0, 0.3, -0.2, 0.9]);
        assert_eq!(s, [0.7, 0.0, 0.0, 0.0]);
    }
}
