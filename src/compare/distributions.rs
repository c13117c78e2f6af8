//! The normal and Student's t distributions the tests need: two-sided tail
//! probabilities and critical values, through the regularised incomplete beta function.

/// P(|Z| ≥ |z|) for a standard normal Z: erfc(|z|/√2) (Abramowitz & Stegun 7.1.2,
/// 26.2.29), with musl's erfc (through the `libm` crate), accurate in the far tail.
pub fn normal_two_sided(z: f64) -> f64 {
    libm::erfc(z.abs() / std::f64::consts::SQRT_2)
}

/// P(|T| ≥ |t|) for Student's t with ν degrees of freedom: the regularised incomplete
/// beta function I_x(ν/2, 1/2) at x = ν/(ν + t²) (Abramowitz & Stegun 26.7.1 with
/// 26.5.27).
pub fn student_two_sided(t: f64, nu: f64) -> f64 {
    if !t.is_finite() {
        return 0.0;
    }
    incomplete_beta(nu / (nu + t * t), 0.5 * nu, 0.5)
}

/// The |z| at which a two-sided normal test has p-value `p`, by bisection on
/// [`normal_two_sided`] (which decreases in |z|).
pub fn normal_critical(p: f64) -> f64 {
    let (mut lo, mut hi) = (0.0f64, 40.0f64);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if normal_two_sided(mid) > p {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The |t| at which a two-sided Student t test with ν degrees of freedom has p-value
/// `p`, by bisection on [`student_two_sided`].
pub fn student_critical(p: f64, nu: f64) -> f64 {
    let (mut lo, mut hi) = (0.0f64, 1e6f64);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if student_two_sided(mid, nu) > p {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// The regularised incomplete beta function I_x(a, b), from its continued fraction
/// (Abramowitz & Stegun 26.5.8) evaluated by the modified Lentz method (Lentz 1976,
/// Applied Optics 15(3); Thompson & Barnett 1986, J. Comput. Phys. 64), on the side of
/// x where it converges fast: I_x(a, b) = 1 − I_{1−x}(b, a) (26.5.2) beyond
/// x = (a + 1)/(a + b + 2).
pub fn incomplete_beta(x: f64, a: f64, b: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if x >= 1.0 {
        return 1.0;
    }
    if x > (a + 1.0) / (a + b + 2.0) {
        return 1.0 - incomplete_beta(1.0 - x, b, a);
    }
    // x^a (1 − x)^b / (a B(a, b)), in logarithms.
    let ln_front =
        libm::lgamma(a + b) - libm::lgamma(a) - libm::lgamma(b) + a * x.ln() + b * (-x).ln_1p();
    ln_front.exp() / a * beta_fraction(x, a, b)
}

/// 1/(1 + d₁/(1 + d₂/(1 + …))) with A&S 26.5.8's coefficients
/// d₂ₘ₊₁ = −(a + m)(a + b + m) x / ((a + 2m)(a + 2m + 1)),
/// d₂ₘ = m (b − m) x / ((a + 2m − 1)(a + 2m)), by the modified Lentz method.
pub(super) fn beta_fraction(x: f64, a: f64, b: f64) -> f64 {
    const TINY: f64 = 1e-300;
    let nonzero = |v: f64| if v.abs() < TINY { TINY } else { v };
    // The convergents' ratios C = Aₖ/Aₖ₋₁ and D = Bₖ₋₁/Bₖ, starting from the first
    // term 1 + d₁.
    let mut c = 1.0f64;
    let mut d = 1.0 / nonzero(1.0 - (a + b) * x / (a + 1.0));
    let mut f = d;
    for m in 1..1000 {
        let m = m as f64;
        for coeff in [
            m * (b - m) * x / ((a + 2.0 * m - 1.0) * (a + 2.0 * m)),
            -(a + m) * (a + b + m) * x / ((a + 2.0 * m) * (a + 2.0 * m + 1.0)),
        ] {
            d = 1.0 / nonzero(1.0 + coeff * d);
            c = nonzero(1.0 + coeff / c);
            f *= c * d;
        }
        if (c * d - 1.0).abs() < 1e-15 {
            break;
        }
    }
    f
}
