//! The Debye series of the Lorenz–Mie coefficients: each partial wave a_n, b_n split into
//! the waves that leave a sphere after p internal passes (van de Hulst, *Light Scattering
//! by Small Particles*, 1957, §12.3; Hovenac & Lock 1992, "Assessing the contributions of
//! surface waves and complex rays to far-field Mie scattering by use of the Debye series",
//! JOSA A 9(5), 781, eqs. 2–9).
//!
//! Riccati–Hankel functions (Bohren & Huffman's convention, time factor e^{−iωt}):
//! ξ⁽¹⁾_n(z) = ψ_n(z) − iχ_n(z) is the outgoing wave, ξ⁽²⁾_n(z) = ψ_n(z) + iχ_n(z) the
//! incoming one, ψ_n = (ξ⁽¹⁾ + ξ⁽²⁾)/2. Region 1 is outside (argument x), region 2 inside
//! (argument y = mx). Matching u and K u′ across the surface (K = m for a_n, 1/m for b_n,
//! the ratio that makes a_n, b_n equal to Bohren & Huffman eq. 4.53) gives, per n, the
//! spherical interface's reflection and transmission coefficients:
//!
//! - an incoming wave from outside, ξ⁽²⁾(x) + R₂₂ ξ⁽¹⁾(x) = T₂₁ ξ⁽²⁾(y):
//!   R₂₂ = −(ξ⁽²⁾(x)/ξ⁽¹⁾(x)) [G⁽²⁾(y) − K G⁽²⁾(x)] / [G⁽²⁾(y) − K G⁽¹⁾(x)];
//! - an outgoing wave from inside, ξ⁽¹⁾(y) + R₁₁ ξ⁽²⁾(y) = T₁₂ ξ⁽¹⁾(x):
//!   R₁₁ = −(ξ⁽¹⁾(y)/ξ⁽²⁾(y)) [K G⁽¹⁾(x) − G⁽¹⁾(y)] / [K G⁽¹⁾(x) − G⁽²⁾(y)];
//! - T₂₁ T₁₂ = [ξ⁽²⁾(x)/ξ⁽¹⁾(x) + R₂₂] [ξ⁽¹⁾(y)/ξ⁽²⁾(y) + R₁₁],
//!
//! with G = ξ′/ξ the logarithmic derivatives. Written with G and ratios of ξ of modulus 1
//! (ξ⁽²⁾ = conj ξ⁽¹⁾ for real arguments), nothing overflows. An incoming wave inside
//! passes the centre and leaves as ξ⁽¹⁾(y), so the outgoing wave outside is
//! ½[R₂₂ + Σ_{p≥1} T₂₁ R₁₁^{p−1} T₁₂] ξ⁽¹⁾(x); the scattered wave is that minus the
//! incident's own outgoing half, hence (Hovenac & Lock eq. 8)
//!
//!   a_n = ½ [1 − R₂₂ − Σ_{p=1}^∞ T₂₁ (R₁₁)^{p−1} T₁₂],
//!
//! and b_n alike with K = 1/m. Terms:
//!
//! - p = 0: ½(1 − R₂₂), the external reflection **with** the diffraction term ½ (one term
//!   in Hovenac & Lock; the ½ alone is the diffraction of the sphere's shadow, forward
//!   peaked);
//! - p ≥ 1: −½ T₂₁ R₁₁^{p−1} T₁₂: p = 1 direct transmission, p = 2 one internal
//!   reflection (the primary bow), p = 3 two (the secondary bow).
//!
//! The series converges to a_n, b_n geometrically in |R₁₁| < 1 (`tests/debye.rs` checks
//! the sum to 1e-10); [`coefficients`] returns one term, scaled by (2n+1)/(n(n+1)) like
//! [`mie::coefficients`], so [`mie::amplitudes`] gives its S₁, S₂.
use super::mie::{self, MieCoefficients};
use num_complex::Complex64;

/// One partial wave's interface coefficients for one polarisation.
#[derive(Clone, Copy, Debug)]
pub struct Interface {
    pub r22: Complex64,
    pub r11: Complex64,
    /// T₂₁ T₁₂.
    pub t21_t12: Complex64,
}

impl Interface {
    /// The unscaled Debye term p of the partial-wave coefficient.
    pub fn term(&self, p: u32) -> Complex64 {
        if p == 0 {
            0.5 * (Complex64::new(1.0, 0.0) - self.r22)
        } else {
            -0.5 * self.t21_t12 * self.r11.powu(p - 1)
        }
    }

    /// The full coefficient ½[1 − R₂₂ − T₂₁T₁₂/(1 − R₁₁)] (the series summed).
    pub fn total(&self) -> Complex64 {
        0.5 * (Complex64::new(1.0, 0.0)
            - self.r22
            - self.t21_t12 / (Complex64::new(1.0, 0.0) - self.r11))
    }
}

/// ξ⁽¹⁾_n(z) = ψ_n − iχ_n and G⁽¹⁾_n = ξ⁽¹⁾′_n / ξ⁽¹⁾_n for n = 1…nmax: ψ_n from the
/// downward logarithmic derivative (stable for n > z, where upward ψ is not), χ_n by its
/// (stable) upward recurrence, ξ′_n = ξ_{n−1} − n ξ_n / z.
fn riccati_xi(z: f64, nmax: usize) -> (Vec<Complex64>, Vec<Complex64>) {
    let d = mie::log_derivative(z, nmax);
    let mut psi = z.sin();
    let (mut chi0, mut chi1) = (-z.sin(), z.cos());
    let mut xi_prev = Complex64::new(psi, -chi1);
    let mut xi = Vec::with_capacity(nmax);
    let mut g = Vec::with_capacity(nmax);
    for (n, &dn) in d.iter().enumerate().take(nmax + 1).skip(1) {
        let nf = n as f64;
        psi /= dn + nf / z;
        let chi = (2.0 * nf - 1.0) * chi1 / z - chi0;
        let x = Complex64::new(psi, -chi);
        let dx = xi_prev - x * (nf / z);
        xi.push(x);
        g.push(dx / x);
        chi0 = chi1;
        chi1 = chi;
        xi_prev = x;
    }
    (xi, g)
}

/// The interface coefficients of partial waves n = 1…`nmax` for a_n (first) and b_n
/// (second), for a sphere of real relative index `m` and size parameter `x`.
pub fn interfaces(m: f64, x: f64, nmax: usize) -> Vec<[Interface; 2]> {
    let y = m * x;
    let (xi_x, g_x) = riccati_xi(x, nmax);
    let (xi_y, g_y) = riccati_xi(y, nmax);
    (0..nmax)
        .map(|i| {
            let ratio_x = xi_x[i].conj() / xi_x[i]; // ξ⁽²⁾(x)/ξ⁽¹⁾(x)
            let ratio_y = xi_y[i] / xi_y[i].conj(); // ξ⁽¹⁾(y)/ξ⁽²⁾(y)
            let (g1x, g2x) = (g_x[i], g_x[i].conj());
            let (g1y, g2y) = (g_y[i], g_y[i].conj());
            let one = |k: f64| {
                let r22 = -ratio_x * (g2y - g2x * k) / (g2y - g1x * k);
                let r11 = -ratio_y * (g1x * k - g1y) / (g1x * k - g2y);
                Interface {
                    r22,
                    r11,
                    t21_t12: (ratio_x + r22) * (ratio_y + r11),
                }
            };
            [one(m), one(1.0 / m)]
        })
        .collect()
}

/// The Debye term p of the scaled coefficients (2n+1)/(n(n+1)) a_n, b_n, n = 1…N with
/// N = [`mie::n_terms`]`(x)`, ready for [`mie::amplitudes`].
pub fn coefficients(m: f64, x: f64, p: u32) -> MieCoefficients {
    let nstop = mie::n_terms(x);
    let f = interfaces(m, x, nstop);
    let scale = |i: usize| {
        let n = (i + 1) as f64;
        (2.0 * n + 1.0) / (n * (n + 1.0))
    };
    MieCoefficients {
        a: f.iter()
            .enumerate()
            .map(|(i, c)| c[0].term(p) * scale(i))
            .collect(),
        b: f.iter()
            .enumerate()
            .map(|(i, c)| c[1].term(p) * scale(i))
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn riccati_functions_match_closed_forms() {
        // ψ_1 = sin z/z − cos z, χ_1 = cos z/z + sin z (B&H 4.47 with χ = −z y_n).
        let z = 3.7;
        let (xi, g) = riccati_xi(z, 3);
        let psi1 = z.sin() / z - z.cos();
        let chi1 = z.cos() / z + z.sin();
        assert!((xi[0] - Complex64::new(psi1, -chi1)).norm() < 1e-14);
        // ψ_1′ = sin z − ψ_1/z … G = ξ′/ξ with ξ′_1 = ξ_0 − ξ_1/z.
        let xi0 = Complex64::new(z.sin(), -z.cos());
        assert!((g[0] - (xi0 - xi[0] / z) / xi[0]).norm() < 1e-13);
    }
}
