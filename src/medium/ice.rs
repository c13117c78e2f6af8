//! A medium of ice crystals in random orientation (diamond dust, ice fog, a cirrus
//! layer's crystals tumbling): hexagonal prisms of Warren & Brandt's ice (2008, the
//! catalogue's `ice`) traced by geometric optics ([`crate::optics::ice`]), with their
//! diffraction, as a participating medium (issue 40, part 4).
//!
//! **Coefficients.** Crystals many wavelengths across remove twice their geometric
//! cross-section from a beam (the extinction paradox: the light they refract and reflect,
//! and as much again diffracted about their shadow; van de Hulst 1957, §8.22), so with
//! N crystals per m³ of which a share x_i are population i,
//!
//!   σ_t = 2 N Σ_i x_i ⟨A_i⟩,  σ_s = σ_t,
//!
//! ⟨A_i⟩ the mean projected area of a randomly oriented convex body, a quarter of its
//! surface (Cauchy's theorem): for a prism of semi-diameter a and half-length c,
//! ⟨A⟩ = (3√3 a² + 12 a c)/4. Ice's absorption is neglected, as in the halo tracer
//! (k ≤ 1.5·10⁻⁷ up to 840 nm: under 1% over the largest crystals the spec allows), so
//! σ_s = σ_t and the medium is white: it conserves energy exactly, which the white
//! furnace checks. Neither depends on λ.
//!
//! **Phase function.** Half geometric optics, half diffraction, both normalised to 1:
//! per wavelength node (every 20 nm from 360 nm to 840 nm), `rays` rays traced through
//! crystals drawn by [`Crystals::scatter`] (each population by its share of the
//! cross-section, x_i⟨A_i⟩, each crystal with probability ∝ the area it presents), one
//! hashed stream per ray and the same rays at every node (they part only where n(λ)
//! parts them, so the nodes' noise is common and the colours of the halos' edges are
//! not), histogrammed in the scattering angle; plus Rayleigh's encircled energy of the
//! crystals' circular aperture of the same area ([`diffraction_encircled`]) per bin.
//! The bins are 0.02° up to 2° (the diffraction peak and the light through parallel
//! faces, which leaves undeviated) and 0.1° beyond (the 22° and 46° halos' edges to a
//! tenth of a degree). Between nodes the table mixes two nodes' functions, so an edge
//! there is two half-steps as far apart as the nodes' edges: 0.02–0.13° for the 22°
//! halo and 0.06–0.38° for the 46° halo (widest in the blue), the stated blur of 20 nm
//! nodes. The histogram *is*
//! the phase function ([`PhaseTable::from_masses`]): it is evaluated and sampled
//! exactly, so next-event estimation and phase sampling see the same function.
//! Rays trapped by total internal reflection beyond the tracer's event limit (a few in
//! 10⁵) are left out of the histogram's normalisation: without absorption they would
//! leave eventually.
//!
//! **Forward cutoff** (`forward_cutoff_deg`, off by default): as for the Lorenz–Mie
//! media (delta-M, Wiscombe 1977), the share f of the scattering within θ_c of forward
//! (diffraction and the undeviated rays: 62–65% within 1° for plates of a = 60 µm,
//! c/a = 0.5) is
//! counted as unscattered light: σ_s' = (1 − f) σ_s, σ_t' = σ_t − f σ_s, p' = 0 inside
//! the cone. θ_c is rounded to the nearest bin edge; f varies with λ, σ' with it.
//!
//! **Not modelled:** oriented crystals (plates and columns falling flat, whose phase
//! function and cross-section depend on the direction of the light: the halo sky renders
//! them), ice's birefringence, and the phase matrix (the medium depolarises).
//!
//! Units: sizes in µm as the halo skies give them, lengths in metres, N per m³, σ in m⁻¹.
use super::phase_table::PhaseTable;
use crate::math::recent::Recent;
use crate::math::rng::Rng;
use crate::optics::ice::scatter::diffraction_encircled;
use crate::optics::ice::{Crystals, HexPrism, Orientation, Population};
use crate::spectrum::DenseSpectrum;
use glam::DVec3;
use rayon::prelude::*;

/// The first wavelength node and the nodes' spacing, nm.
pub const LAMBDA0: f32 = 360.0;
pub const DLAMBDA: f32 = 20.0;
/// Nodes: 360 nm to 840 nm.
pub const NODES: usize = 25;
/// Rays per node by default: 2^20 (about 5.5 s on 2 cores; BENCHMARKS.md, "Ice crystals
/// as a medium").
pub const DEFAULT_RAYS: usize = 1 << 20;
/// The bins: `FINE_BINS` of `FINE_STEP` degrees to `FINE_TO`, then `STEP` to 180°.
const FINE_TO: f64 = 2.0;
const FINE_STEP: f64 = 0.02;
const FINE_BINS: usize = 100;
const STEP: f64 = 0.1;
pub const BINS: usize = FINE_BINS + 1780;
/// Tables a process keeps (`math::recent`).
const CACHED: usize = 4;
/// Orientations drawn for each population's diffraction area.
const DIFFRACTION_SAMPLES: usize = 20_000;

/// What an ice medium is made of.
#[derive(Clone, Debug, PartialEq)]
pub struct IceSpec {
    /// The populations, each `weight` its share of the crystals by number (normalised);
    /// every one in random orientation.
    pub populations: Vec<Population>,
    /// Crystals per m³.
    pub number_density: f64,
    /// Rays per wavelength node.
    pub rays: usize,
    pub seed: u64,
    /// Degrees; 0 keeps the whole phase function.
    pub forward_cutoff_deg: f64,
}

/// The tabulated medium.
#[derive(Clone, Debug)]
pub struct IceMedium {
    pub spec: IceSpec,
    /// m⁻¹, after the forward cutoff.
    pub sigma_t: DenseSpectrum,
    pub sigma_s: DenseSpectrum,
    pub phase: PhaseTable,
    /// σ_t before the cutoff, m⁻¹.
    pub sigma_t_full: f64,
    /// The share of the scattering the cutoff removed, per node.
    pub forward_fraction: Vec<f64>,
    /// The share of the traced rays trapped in their crystal (left out).
    pub trapped: f64,
}

/// The bin edges, radians.
pub fn theta_edges() -> Vec<f64> {
    (0..=BINS)
        .map(|j| {
            if j <= FINE_BINS {
                j as f64 * FINE_STEP
            } else {
                FINE_TO + (j - FINE_BINS) as f64 * STEP
            }
            .min(180.0)
            .to_radians()
        })
        .collect()
}

/// The bin of a scattering angle in degrees.
#[inline]
fn bin(theta_deg: f64) -> usize {
    if theta_deg < FINE_TO {
        (theta_deg / FINE_STEP) as usize
    } else {
        FINE_BINS + ((theta_deg - FINE_TO) / STEP) as usize
    }
    .min(BINS - 1)
}

/// ⟨A⟩ of a randomly oriented prism of population `p`, µm²: a quarter of its surface.
pub fn mean_projected_area_um2(p: &Population) -> f64 {
    0.25 * HexPrism::new(p.aspect).surface_area() * p.size_um * p.size_um
}

/// What the tracing gives, whatever the number density (which only scales σ).
#[derive(Clone, Debug)]
struct Traced {
    phase: PhaseTable,
    forward_fraction: Vec<f64>,
    trapped: f64,
    /// Σ xᵢ ⟨Aᵢ⟩, m².
    mean_area_m2: f64,
}

impl IceMedium {
    /// The medium of `spec` (every population random: the loader checks). Its phase
    /// function is traced once per process for the same crystals, rays and cutoff
    /// (`math::recent`): media that differ only in their number density share it.
    pub fn new(spec: IceSpec) -> IceMedium {
        static CACHE: Recent<Traced> = Recent::new(CACHED);
        let key = format!(
            "{:?} {} {} {:e}",
            spec.populations, spec.rays, spec.seed, spec.forward_cutoff_deg
        );
        let t = CACHE.get_or_build(key, || trace(&spec));
        IceMedium::with(spec, (*t).clone())
    }

    /// The medium of `spec`, traced (no cache: for checks of determinism).
    pub fn traced(spec: IceSpec) -> IceMedium {
        let t = trace(&spec);
        IceMedium::with(spec, t)
    }

    fn with(spec: IceSpec, t: Traced) -> IceMedium {
        assert!(spec.number_density.is_finite() && spec.number_density > 0.0);
        let sigma_t_full = 2.0 * spec.number_density * t.mean_area_m2;
        let f = &t.forward_fraction;
        // σ_s' = (1 − f) σ_s and σ_t' = σ_t − f σ_s, equal without absorption; f linear
        // in λ between nodes.
        let sigma_s = DenseSpectrum::from_fn(|l| {
            let s = ((l - LAMBDA0) / DLAMBDA).clamp(0.0, (NODES - 1) as f32) as f64;
            let i = (s as usize).min(NODES - 2);
            let w = s - i as f64;
            ((1.0 - (f[i] * (1.0 - w) + f[i + 1] * w)) * sigma_t_full) as f32
        });
        IceMedium {
            spec,
            sigma_t: sigma_s.clone(),
            sigma_s,
            phase: t.phase,
            sigma_t_full,
            forward_fraction: t.forward_fraction,
            trapped: t.trapped,
        }
    }
}

/// Traces the phase function of `spec`'s crystals (module docs).
fn trace(spec: &IceSpec) -> Traced {
    assert!(!spec.populations.is_empty() && spec.rays > 0);
    assert!(spec
        .populations
        .iter()
        .all(|p| p.orientation == Orientation::Random));
    assert!((0.0..=10.0).contains(&spec.forward_cutoff_deg));
    let total: f64 = spec.populations.iter().map(|p| p.weight).sum();
    let areas: Vec<f64> = spec
        .populations
        .iter()
        .map(mean_projected_area_um2)
        .collect();
    // Σ x_i ⟨A_i⟩, m²; the populations scatter in proportion to x_i ⟨A_i⟩.
    let mean_area_m2: f64 = (spec.populations.iter().zip(&areas))
        .map(|(p, a)| p.weight / total * a * 1e-12)
        .sum();
    let crystals = Crystals::new(
        (spec.populations.iter().zip(&areas))
            .map(|(p, a)| Population {
                weight: p.weight / total * a,
                ..p.clone()
            })
            .collect(),
    );
    // Random orientation: any direction of incidence will do.
    let incident = -DVec3::Z;
    let diffraction: Vec<f64> = (0..crystals.populations.len())
        .map(|i| crystals.diffraction_area_um2(i, incident, DIFFRACTION_SAMPLES))
        .collect();
    let ior = crate::spectrum::ior::named("ice").expect("ice in the catalogue");
    let edges = theta_edges();
    let per_node: Vec<(Vec<f64>, usize)> = (0..NODES)
        .into_par_iter()
        .map(|node| {
            let lambda = LAMBDA0 + node as f32 * DLAMBDA;
            let n = ior.eval(lambda) as f64;
            let mut counts = vec![0.0f64; BINS];
            let mut trapped = 0usize;
            for i in 0..spec.rays {
                let mut rng = Rng::keyed(spec.seed, i as u64);
                let mut u = || rng.uniform_f64();
                match crystals.scatter(incident, n, false, &mut u) {
                    Some(s) => {
                        let theta = 2.0 * (0.5 * (s.dir - incident).length()).min(1.0).asin();
                        counts[bin(theta.to_degrees())] += 1.0;
                    }
                    None => trapped += 1,
                }
            }
            let out = (spec.rays - trapped).max(1) as f64;
            let masses = (0..BINS)
                .map(|j| {
                    let diff: f64 = (diffraction.iter().enumerate())
                        .map(|(i, &a)| {
                            crystals.share(i)
                                * (diffraction_encircled(edges[j + 1], a, lambda as f64)
                                    - diffraction_encircled(edges[j], a, lambda as f64))
                        })
                        .sum();
                    0.5 * (counts[j] / out + diff)
                })
                .collect();
            (masses, trapped)
        })
        .collect();
    let trapped =
        per_node.iter().map(|n| n.1).sum::<usize>() as f64 / (spec.rays * NODES).max(1) as f64;
    let mut masses: Vec<Vec<f64>> = per_node.into_iter().map(|n| n.0).collect();
    // The forward cutoff: the bins below the nearest edge to θ_c.
    let cut = (0..=BINS)
        .min_by(|&a, &b| {
            let d = |j: usize| (edges[j].to_degrees() - spec.forward_cutoff_deg).abs();
            d(a).total_cmp(&d(b))
        })
        .unwrap_or(0);
    let forward_fraction: Vec<f64> = masses
        .iter_mut()
        .map(|m| {
            let total: f64 = m.iter().sum();
            let f: f64 = m[..cut].iter().sum::<f64>() / total;
            m[..cut].iter_mut().for_each(|x| *x = 0.0);
            f
        })
        .collect();
    Traced {
        phase: PhaseTable::from_masses(LAMBDA0, DLAMBDA, &edges, &masses),
        forward_fraction,
        trapped,
        mean_area_m2,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bins_tile_the_sphere() {
        let e = theta_edges();
        assert_eq!(e.len(), BINS + 1);
        assert!(e.windows(2).all(|w| w[1] > w[0]));
        assert!((e[BINS] - std::f64::consts::PI).abs() < 1e-12);
        // Each edge's angle falls in the bin it opens.
        for j in [0, 1, 99, 100, 101, 500, BINS - 1] {
            assert_eq!(bin(e[j].to_degrees() + 1e-9), j);
        }
        assert_eq!(bin(180.0), BINS - 1);
        // Cauchy: a cube-like prism (c/a = 1) of a = 1 µm presents (3√3 + 12)/4.
        let p = Population {
            orientation: Orientation::Random,
            aspect: 1.0,
            size_um: 1.0,
            weight: 1.0,
        };
        let want = (3.0 * 3f64.sqrt() + 12.0) / 4.0;
        assert!((mean_projected_area_um2(&p) - want).abs() < 1e-9);
    }
}
