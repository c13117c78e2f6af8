//! Sunlight scattered by a mixture of crystal populations: a population drawn by its
//! weight (its share of the layer's geometric cross-section), an orientation drawn from
//! it with probability proportional to the area the crystal presents to the light
//! (rejection against the largest projected area), then one ray traced through it. Every
//! ray so carries the same power, and a histogram of the directions, divided by the
//! number of rays and the bins' solid angles, is the geometric-optics part of the
//! phase function per unit geometric cross-section; it integrates to 1 (no absorption).
use super::crystal::HexPrism;
use super::orientation::Orientation;
use super::trace::{scattering_plane_stokes, trace, Exit};
use glam::{DMat3, DVec3};

/// One population: a shape, an orientation, a size and a weight.
#[derive(Clone, Debug, PartialEq)]
pub struct Population {
    pub orientation: Orientation,
    /// c/a: the prism's half-length over the hexagon's semi-diameter.
    pub aspect: f64,
    /// The hexagon's semi-diameter a, µm (diffraction only: geometric optics does not
    /// depend on size).
    pub size_um: f64,
    /// Share of the layer's geometric cross-section (normalised over the populations).
    pub weight: f64,
}

/// A ray scattered by a crystal.
#[derive(Clone, Copy, Debug)]
pub struct Scattered {
    /// Direction of travel after the crystal, world frame.
    pub dir: DVec3,
    /// The population the crystal came from.
    pub population: usize,
    /// The trace in the crystal's frame (faces, reflections, Stokes vector).
    pub exit: Exit,
    /// S1/S0 and S2/S0 about the scattering plane (S1 > 0 perpendicular to it), when
    /// traced polarised; (0, 0) otherwise.
    pub s1: f64,
    pub s2: f64,
}

/// A mixture of populations, ready to scatter rays.
#[derive(Clone, Debug)]
pub struct Crystals {
    pub populations: Vec<Population>,
    prisms: Vec<HexPrism>,
    /// Cumulative normalised weights.
    cdf: Vec<f64>,
}

impl Crystals {
    /// The mixture of `populations` (weights > 0, aspect ratios > 0; the callers check).
    pub fn new(populations: Vec<Population>) -> Crystals {
        let total: f64 = populations.iter().map(|p| p.weight).sum();
        let mut acc = 0.0;
        let cdf = populations
            .iter()
            .map(|p| {
                acc += p.weight / total;
                acc
            })
            .collect();
        let prisms = populations
            .iter()
            .map(|p| HexPrism::new(p.aspect))
            .collect();
        Crystals {
            populations,
            prisms,
            cdf,
        }
    }

    /// The normalised weight of population `i`.
    pub fn share(&self, i: usize) -> f64 {
        self.cdf[i] - if i == 0 { 0.0 } else { self.cdf[i - 1] }
    }

    fn pick(&self, x: f64) -> usize {
        self.cdf
            .iter()
            .position(|&c| x < c)
            .unwrap_or(self.cdf.len() - 1)
    }

    /// A crystal of population `i` for light travelling along `incident` (world),
    /// drawn with probability ∝ its projected area: its rotation and that area (in
    /// units of a²).
    pub fn sample_crystal(
        &self,
        i: usize,
        incident: DVec3,
        u: &mut impl FnMut() -> f64,
    ) -> (DMat3, f64) {
        let prism = &self.prisms[i];
        let bound = prism.max_projected_area();
        loop {
            let r = self.populations[i].orientation.sample(u);
            let area = prism.projected_area(r.transpose() * incident);
            // The smallest projected area of a prism is a fixed fraction of the bound:
            // a few draws for most shapes, about 40 for the flattest plates edge-on
            // (c/a = 0.02, 2.7% accepted) and 120 for the longest columns end-on (c/a =
            // 50, 0.9%), the extremes the spec allows.
            if u() * bound < area {
                return (r, area);
            }
        }
    }

    /// One ray of light travelling along the unit `incident` (world frame) scattered by
    /// a crystal of index `n`; None when the ray stayed trapped ([`super::trace`]).
    pub fn scatter(
        &self,
        incident: DVec3,
        n: f64,
        polarised: bool,
        u: &mut impl FnMut() -> f64,
    ) -> Option<Scattered> {
        let i = self.pick(u());
        let (r, _) = self.sample_crystal(i, incident, u);
        let local = r.transpose() * incident;
        let exit = trace(&self.prisms[i], local, n, polarised, u)?;
        let (s1, s2) = if polarised {
            scattering_plane_stokes(&exit, local)
        } else {
            (0.0, 0.0)
        };
        Some(Scattered {
            dir: r * exit.dir,
            population: i,
            exit,
            s1,
            s2,
        })
    }

    /// The projected area the crystals of population `i` present on average to light
    /// along `incident`, weighted as they scatter (by their area): ⟨A²⟩/⟨A⟩ in µm², the
    /// area of the circular aperture whose diffraction stands for theirs. Estimated from
    /// `samples` orientations drawn with a fixed seed.
    pub fn diffraction_area_um2(&self, i: usize, incident: DVec3, samples: usize) -> f64 {
        let mut rng = crate::math::rng::Rng::new(0x9e37_79b9_7f4a_7c15, i as u64);
        let mut u = || rng.uniform_f64();
        let mut sum = 0.0;
        for _ in 0..samples {
            sum += self.sample_crystal(i, incident, &mut u).1;
        }
        let a = self.populations[i].size_um;
        sum / samples as f64 * a * a
    }
}

/// The fraction of the light diffracted by a circular aperture of area `area_um2` at
/// `lambda_nm` that falls within `theta` (radians) of the forward direction: Rayleigh's
/// encircled energy E(θ) = 1 − J₀²(x sin θ) − J₁²(x sin θ), x = 2π r/λ (Born & Wolf
/// §8.5.2, eq. 8.5.2 (21)), Fraunhofer diffraction, divided by E(90°) so that the whole
/// of it lies in the forward hemisphere (E(90°) falls short of 1 by about 2/(πx), a
/// tail that would otherwise have to be put somewhere). For sizes of 10 µm and more
/// (x ≳ 80) almost all of it is within a few degrees.
pub fn diffraction_encircled(theta: f64, area_um2: f64, lambda_nm: f64) -> f64 {
    let r = (area_um2 / std::f64::consts::PI).sqrt();
    let x = 2.0 * std::f64::consts::PI * r / (lambda_nm * 1e-3);
    let e = |t: f64| {
        let v = x * t.sin();
        if v < 1e-8 {
            return 0.0;
        }
        let (j0, j1) = (libm::j0(v), libm::j1(v));
        (1.0 - j0 * j0 - j1 * j1).max(0.0)
    };
    (e(theta.min(0.5 * std::f64::consts::PI)) / e(0.5 * std::f64::consts::PI)).clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn encircled_energy_rises_to_one() {
        let (a, l) = (std::f64::consts::PI * 25.0 * 25.0, 550.0);
        let mut last = 0.0;
        for k in 1..400 {
            let e = diffraction_encircled((k as f64 * 0.01f64).to_radians(), a, l);
            assert!(e >= last - 1e-12);
            last = e;
        }
        // The first dark ring of a 25 µm radius aperture: sin θ = 0.61 λ / r.
        let first = (0.6098 * 0.55 / 25.0f64).asin();
        assert!((diffraction_encircled(first, a, l) - 0.838).abs() < 4e-3);
        // The tail falls off as 2/(πx sin θ): 3% outside 4°, under 1% outside 40°, and
        // all of it is in the forward hemisphere.
        let x = 285.6;
        let tail = |deg: f64| 2.0 / (std::f64::consts::PI * x * deg.to_radians().sin());
        assert!(((1.0 - last) - (tail(4.0) - tail(90.0))).abs() < 5e-3);
        assert!(diffraction_encircled(40f64.to_radians(), a, l) > 0.99);
        assert_eq!(diffraction_encircled(0.5 * std::f64::consts::PI, a, l), 1.0);
        assert_eq!(diffraction_encircled(2.0, a, l), 1.0);
    }
}
