//! The halo sky: sunlight scattered by a thin layer of hexagonal ice crystals
//! ([`crate::optics::ice`]), one or more populations of shapes and orientations mixed by
//! weight. Oriented crystals make the pattern depend on the sun's elevation and on the
//! direction about the sun, not only on the angle from it, so the sky is a table over
//! the whole sphere per wavelength ([`table::HaloTable`]), traced once per scene for
//! its sun (seconds), and read by the renderer in every direction and sampled for
//! next-event estimation by its cells.
//!
//! Sun dogs, the circumzenithal arc, tangent arcs and the parhelic circle come out of
//! the populations' orientations; the 22° and 46° halos out of random ones. What the
//! closed forms say about where they are is tested in `tests/halo.rs`.
//!
//! The forward peak: within [`FORWARD_CUT_DEG`] of the sun the crystals send the core of
//! their diffraction and the light that passed two parallel faces undeviated. In an
//! optically thin layer that light makes up for what the layer takes out of the direct
//! beam, and heron's sun light is not dimmed by the sky's layer, so the rendered sky
//! leaves that peak to the sun: inside the cone, and out to the centre of the first
//! table cell beyond it ([`CAP_DEG`]), it reads that cell's value (a flat cap, 1e-3 sr,
//! rather than a hole around the sun); `heron halo profile` prints the whole table.
//!
//! Tables are kept for the life of the process by what they were traced from (the
//! crystals, the sun, the rays and the seed), the last [`CACHED_TABLES`] of them, so a
//! program that loads one scene many times (the tests, `heron converge`) traces once.
pub mod profile;
pub mod spec;
pub mod table;

pub use spec::{CrystalFile, HaloKey, HaloSpec};
pub use table::HaloTable;

use crate::math::recent::Recent;
use crate::optics::ice::Crystals;
use glam::Vec3;
use std::sync::{Arc, OnceLock};

/// The cone about the sun the rendered sky leaves to the sun light, degrees.
pub const FORWARD_CUT_DEG: f64 = 1.0;
/// Where the cap's value is read: the centre of the first cell outside the cone, so
/// that no cell inside it contributes (the halo sampler weights the cap by that cell).
pub const CAP_DEG: f64 = FORWARD_CUT_DEG + 0.5 * table::THETA_STEP;

/// Tables a process keeps.
pub const CACHED_TABLES: usize = 4;

/// Rays per wavelength row by default: 2^20 (a table builds in about 7.5 s on 2 cores,
/// whatever its populations; BENCHMARKS.md, "Halo sky tables").
pub const DEFAULT_RAYS: usize = 1 << 20;

/// Ice's refractive index at `lambda` nm (Warren & Brandt 2008, the catalogue's `ice`).
pub fn ice_n(lambda: f32) -> f64 {
    static ICE: OnceLock<crate::spectrum::ior::Ior> = OnceLock::new();
    ICE.get_or_init(|| crate::spectrum::ior::named("ice").expect("ice in the catalogue"))
        .eval(lambda) as f64
}

/// A halo sky: its crystals, its sun and its table (built on first use).
#[derive(Debug)]
pub struct HaloSky {
    pub crystals: Crystals,
    /// The sun's elevation above the horizon, radians.
    pub sun_elevation: f64,
    /// The sun's angular radius, radians.
    pub sun_radius: f64,
    /// Rays per wavelength row.
    pub rays: usize,
    pub seed: u64,
    table: OnceLock<Arc<HaloTable>>,
}

impl HaloSky {
    pub fn new(
        crystals: Crystals,
        sun_elevation: f64,
        sun_radius: f64,
        rays: usize,
        seed: u64,
    ) -> HaloSky {
        HaloSky {
            crystals,
            sun_elevation,
            sun_radius,
            rays,
            seed,
            table: OnceLock::new(),
        }
    }

    /// The table, traced on first call (or found among the process's last tables).
    pub fn table(&self) -> &Arc<HaloTable> {
        self.table.get_or_init(|| {
            let key = format!(
                "{:?} {:e} {:e} {} {}",
                self.crystals.populations,
                self.sun_elevation,
                self.sun_radius,
                self.rays,
                self.seed
            );
            static CACHE: Recent<HaloTable> = Recent::new(CACHED_TABLES);
            CACHE.get_or_build(key, || {
                HaloTable::build(
                    &self.crystals,
                    &ice_n,
                    self.sun_elevation,
                    self.sun_radius,
                    self.rays,
                    self.seed,
                )
            })
        })
    }
}

/// A halo sky placed in a scene: its table, the sun and the zenith.
#[derive(Clone, Debug)]
pub struct PlacedHalo {
    pub table: Arc<HaloTable>,
    pub placed: table::Placed,
}

impl PlacedHalo {
    pub fn new(table: Arc<HaloTable>, sun_dir: Vec3, zenith: Vec3) -> PlacedHalo {
        PlacedHalo {
            table,
            placed: table::Placed::new(sun_dir, zenith),
        }
    }

    /// The table's value at (θ, ψ) = `coords` (degrees) and λ, read at [`CAP_DEG`]
    /// closer to the sun.
    #[inline]
    pub fn eval(&self, coords: (f64, f64), lambda: f32) -> f32 {
        self.table.eval(coords.0.max(CAP_DEG), coords.1, lambda)
    }
}
