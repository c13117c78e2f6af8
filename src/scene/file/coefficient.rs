//! A medium's scattering or absorption coefficient σ(λ) per scene unit: a number
//! (grey), `[r, g, b]` or a table of samples. An RGB coefficient is uplifted unbounded
//! (`rgb_to_unbounded`), as pbrt-v4 reads its media's `rgb sigma_a` and Mitsuba 3's
//! spectral variants a homogeneous medium's RGB `sigma_t`: a coefficient has no upper
//! bound, so the reflectance uplift does not apply.
use super::colour::{colour, Colour};
use super::leaves::raw;
use super::show::show;
use super::*;
use serde::ser::{Serialize, Serializer};

/// σ(λ) ≥ 0, finite, as written.
#[derive(Clone, Debug, PartialEq)]
pub struct Coefficient(pub Colour);

impl Coefficient {
    /// A grey coefficient.
    pub fn grey(x: f64) -> Coefficient {
        Coefficient(Colour::Grey(x))
    }

    /// σ(λ) on heron's 1 nm grid: a number is constant (so a grey medium's spectrum is
    /// exactly its number), `[r, g, b]` uplifted unbounded, samples linear between them.
    pub fn spectrum(&self) -> DenseSpectrum {
        self.0.index_spectrum()
    }

    /// The number, when the coefficient is grey.
    pub fn as_grey(&self) -> Option<f64> {
        match self.0 {
            Colour::Grey(g) => Some(g),
            _ => None,
        }
    }
}

impl<'de> Deserialize<'de> for Coefficient {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let v = raw(d)?;
        let expected = || {
            format!(
                "expected a coefficient per scene unit: a finite number >= 0, [r, g, b] (each >= 0) or {{ samples = [[nm, value], ...], scale = number }}, got {}",
                show(&v)
            )
        };
        let c = colour(&v).map_err(|_| D::Error::custom(expected()))?;
        if matches!(c, Colour::Named { .. } | Colour::Blackbody { .. }) {
            return Err(D::Error::custom(expected()));
        }
        if let Colour::Grey(g) = c {
            if !(g as f32 >= 0.0) {
                return Err(D::Error::custom(expected()));
            }
        }
        c.check_index(false)
            .map_err(|e| D::Error::custom(format!("{e}, got {}", show(&v))))?;
        Ok(Coefficient(c))
    }
}

impl Serialize for Coefficient {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.0.serialize(s)
    }
}
