//! Media: each shape's `medium` table to a [`Medium`] (water drops by Lorenz–Mie theory,
//! Henyey–Greenstein, or ice crystals), checked against its type, and given to closed shapes whose
//! surface lets light in; each distinct medium is tabulated once.
use super::materials::Materials;
use super::shapes::{grow_box, EMPTY_BOX};
use super::SkyTables;
use crate::bsdf::Material;
use crate::geometry::Shape;
use crate::medium::density::{grid::Edge, Density, Field, Grid, HeightFog, Noise, RainShaft};
use crate::medium::{Aloft, HgMedium, IceMedium, IceSpec, LorenzMieMedium, Medium, Optics};
use crate::optics::ice::Orientation;
use crate::scene::file::{DensityFile, Direction3, MediumFile, MediumType, ShapeFile};
use crate::sky::halo::HaloKey;
use crate::spectrum::DenseSpectrum;
use glam::Vec3;
use std::path::Path;

/// Drop-size quadrature nodes of a medium's distribution when its table gives none:
/// each node is one Lorenz–Mie tabulation (about 16 s for 0.5 mm drops).
pub const MEDIUM_DEFAULT_NODES: usize = 8;

/// What a `medium` table builds: its optics and, for a heterogeneous medium, its
/// density field (built once its shapes' box is known).
#[derive(Clone, Debug, PartialEq)]
pub(super) struct MediumPlan {
    optics: OpticsPlan,
    density: Option<DensityPlan>,
    aloft: Option<AloftPlan>,
}

/// A population of drops aloft (`Medium::aloft`).
#[derive(Clone, Debug, PartialEq)]
pub(super) struct AloftPlan {
    optics: OpticsPlan,
    up: Vec3,
    from: f32,
    to: f32,
}

/// A medium's optics: the key path is `at` (`shapes[i].medium`).
#[derive(Clone, Debug, PartialEq)]
pub(super) enum OpticsPlan {
    Mie(crate::medium::MieSpec),
    Hg {
        sigma_a: DenseSpectrum,
        sigma_s: DenseSpectrum,
        g: f32,
    },
    Ice(IceSpec),
}

impl OpticsPlan {
    /// The medium (for Lorenz–Mie, its tabulation: seconds for rain drops).
    fn build(&self) -> Medium {
        match self {
            OpticsPlan::Mie(spec) => {
                Medium::homogeneous(Optics::LorenzMie(LorenzMieMedium::new(spec.clone())))
            }
            OpticsPlan::Hg {
                sigma_a,
                sigma_s,
                g,
            } => Medium::homogeneous(Optics::HenyeyGreenstein(HgMedium::new(
                sigma_a.clone(),
                sigma_s.clone(),
                *g,
            ))),
            OpticsPlan::Ice(spec) => Medium::homogeneous(Optics::Ice(IceMedium::new(spec.clone()))),
        }
    }
}

/// The plan of each entry's `medium` table (None: the entry has none), checked; density
/// grids are read from files relative to `base_dir`, which join `inputs`.
pub(super) fn plan_media(
    entries: &[ShapeFile],
    base_dir: &Path,
    inputs: &mut Vec<String>,
) -> Result<Vec<Option<MediumPlan>>, String> {
    entries
        .iter()
        .enumerate()
        .map(|(i, s)| {
            s.medium()
                .map(|m| {
                    let at = format!("shapes[{i}].medium");
                    let optics = plan_optics(&at, m)?;
                    let density = m
                        .density
                        .as_ref()
                        .map(|d| plan_density(&format!("{at}.density"), d, base_dir, inputs))
                        .transpose()?;
                    let aloft = m
                        .aloft
                        .as_ref()
                        .map(|a| plan_aloft(&format!("{at}.aloft"), m, a))
                        .transpose()?;
                    Ok(MediumPlan {
                        optics,
                        density,
                        aloft,
                    })
                })
                .transpose()
        })
        .collect()
}

/// Checks a `medium` table's optics against its type.
fn plan_optics(at: &str, m: &MediumFile) -> std::result::Result<OpticsPlan, String> {
    match MediumType::from_name(&m.kind) {
        Some(MediumType::Mie) => plan_mie(at, m),
        Some(MediumType::HenyeyGreenstein) => plan_hg(at, m),
        Some(MediumType::Ice) => plan_ice(at, m),
        None => Err(format!(
            "{at}.type: expected one of {}, got {:?}",
            MediumType::NAMES.join(", "),
            m.kind
        )),
    }
}

/// `Some(name)` when the key `name` is given.
fn given(name: &'static str, v: bool) -> Option<&'static str> {
    if v {
        Some(name)
    } else {
        None
    }
}

/// A `type = "mie"` medium: water drops, one radius or a distribution's nodes, with a
/// number density or a liquid water content. Radii are limited to 0.1 µm–1 mm: the
/// Lorenz–Mie series has x + 4x^{1/3} + 2 terms per angle (x = 2πr/λ, 17 500 at 1 mm and
/// 360 nm), so larger drops would take minutes to tabulate.
fn plan_mie(at: &str, m: &MediumFile) -> std::result::Result<OpticsPlan, String> {
    if let Some(k) = given("sigma_a", m.sigma_a.is_some())
        .or(given("sigma_s", m.sigma_s.is_some()))
        .or(given("g", m.g.is_some()))
    {
        return Err(format!(
            "{at}.{k}: applies to type = \"henyey-greenstein\", not to type = \"mie\" (whose coefficients come from Lorenz-Mie theory)"
        ));
    }
    refuse_ice_keys(at, m, "mie")?;
    // The drops: one radius, or a distribution's quadrature nodes (number
    // fractions summing to 1).
    let (nodes, dist) = match (m.radius_mm, &m.drops) {
        (Some(r), None) => (
            vec![crate::drops::DropNode {
                radius_mm: r.get() as f64,
                weight: 1.0,
            }],
            None,
        ),
        (None, Some(d)) => {
            let (dist, n) = d.parse(&format!("{at}.drops"))?;
            // Each node is a Lorenz–Mie tabulation (seconds for rain drops), so
            // media default to fewer nodes than skies.
            let n = if d.nodes.is_none() {
                MEDIUM_DEFAULT_NODES
            } else {
                n
            };
            (dist.nodes(n), Some(dist))
        }
        (Some(_), Some(_)) => {
            return Err(format!(
                "{at}: expected one of radius_mm (one drop radius) or drops (a distribution), got both"
            ))
        }
        (None, None) => {
            return Err(format!(
                "{at}.radius_mm: missing required key (expected the drop radius in mm, or a drops table)"
            ))
        }
    };
    for n in &nodes {
        // The bounds as f32, as the scene's numbers are read: 0.0001 is then allowed.
        if !((1e-4f32 as f64)..=1.0).contains(&n.radius_mm) {
            return Err(if dist.is_some() {
                format!(
                    "{at}.drops: expected drop radii in [0.0001, 1] mm (larger drops take minutes to tabulate), but the distribution has a quadrature node at {:.4} mm",
                    n.radius_mm
                )
            } else {
                format!(
                    "{at}.radius_mm: expected a drop radius in [0.0001, 1] mm, got {}",
                    n.radius_mm
                )
            });
        }
    }
    // Σ wᵢ (4/3) π rᵢ³: the mean drop volume in m³.
    let mean_volume: f64 = nodes
        .iter()
        .map(|n| n.weight * 4.0 / 3.0 * std::f64::consts::PI * (n.radius_mm * 1e-3).powi(3))
        .sum();
    let density = match (m.number_density, m.liquid_water_content) {
        (Some(n), None) => n.get() as f64,
        // N = LWC / (ρ_water ⟨V⟩), ρ_water = 10⁶ g/m³.
        (None, Some(w)) => w.get() as f64 / (1e6 * mean_volume),
        (Some(_), Some(_)) => {
            return Err(format!(
                "{at}: expected one of number_density (drops per m³) or liquid_water_content (g/m³), got both"
            ))
        }
        // Marshall–Palmer defines its own number density (N0/Λ).
        (None, None) => match dist.as_ref().and_then(|d| d.number_density()) {
            Some(n) => n,
            None => {
                return Err(format!(
                    "{at}.number_density: missing required key (expected drops per m³, or liquid_water_content in g/m³)"
                ))
            }
        },
    };
    let step = m.lambda_step.map_or(10.0, |s| s.get());
    if !(1.0..=50.0).contains(&step) {
        return Err(format!(
            "{at}.lambda_step: expected nm between wavelength nodes in [1, 50], got {step}"
        ));
    }
    let cutoff = forward_cutoff(at, m)?;
    Ok(OpticsPlan::Mie(crate::medium::MieSpec {
        population: nodes
            .iter()
            .map(|n| crate::medium::PopulationNode {
                radius_m: n.radius_mm * 1e-3,
                number_density: density * n.weight,
            })
            .collect(),
        absorption: m.absorption.unwrap_or(true),
        lambda_step_nm: step,
        forward_cutoff_deg: cutoff,
    }))
}

/// A medium's `forward_cutoff` in degrees (default 0), at most 10.
fn forward_cutoff(at: &str, m: &MediumFile) -> std::result::Result<f64, String> {
    let cutoff = m.forward_cutoff.map_or(0.0, |c| c.get() as f64);
    if cutoff > 10.0 {
        return Err(format!(
            "{at}.forward_cutoff: expected degrees in [0, 10] (the forward peak counted as unscattered), got {cutoff}"
        ));
    }
    Ok(cutoff)
}

/// A `type = "henyey-greenstein"` medium: σ_a, σ_s and g given.
fn plan_hg(at: &str, m: &MediumFile) -> std::result::Result<OpticsPlan, String> {
    if let Some(k) = given("radius_mm", m.radius_mm.is_some())
        .or(given("drops", m.drops.is_some()))
        .or(given("number_density", m.number_density.is_some()))
        .or(given(
            "liquid_water_content",
            m.liquid_water_content.is_some(),
        ))
        .or(given("absorption", m.absorption.is_some()))
        .or(given("lambda_step", m.lambda_step.is_some()))
        .or(given("forward_cutoff", m.forward_cutoff.is_some()))
    {
        let types = match k {
            "number_density" | "forward_cutoff" => "\"mie\" or \"ice\"",
            _ => "\"mie\"",
        };
        return Err(format!(
            "{at}.{k}: applies to type = {types}, not to type = \"henyey-greenstein\""
        ));
    }
    refuse_ice_keys(at, m, "henyey-greenstein")?;
    let g = m.g.unwrap_or(0.0);
    if !(g.is_finite() && g.abs() < 1.0) {
        return Err(format!(
            "{at}.g: expected a mean cosine in (-1, 1), got {g}"
        ));
    }
    let zero = crate::scene::file::Coefficient::grey(0.0);
    let sigma_a = m.sigma_a.as_ref().unwrap_or(&zero).spectrum();
    let sigma_s = m.sigma_s.as_ref().unwrap_or(&zero).spectrum();
    // Each is finite and ≥ 0 at every wavelength (`Coefficient`); the medium must
    // interact somewhere. A grey pair keeps its message in numbers.
    let peak = (sigma_a.values().iter())
        .zip(sigma_s.values())
        .map(|(a, s)| a + s)
        .fold(0.0f32, f32::max);
    if !peak.is_finite() || peak <= 0.0 {
        let show = |c: &Option<crate::scene::file::Coefficient>| {
            c.as_ref().map_or("0".to_string(), |c| c.0.describe())
        };
        return Err(format!(
            "{at}: expected sigma_a + sigma_s finite and > 0, got {} + {}",
            show(&m.sigma_a),
            show(&m.sigma_s)
        ));
    }
    Ok(OpticsPlan::Hg {
        sigma_a,
        sigma_s,
        g,
    })
}

/// The ice medium's own keys, refused on a medium of another `kind`.
fn refuse_ice_keys(at: &str, m: &MediumFile, kind: &str) -> std::result::Result<(), String> {
    match given("crystals", m.crystals.is_some())
        .or(given("rays", m.rays.is_some()))
        .or(given("seed", m.seed.is_some()))
    {
        Some(k) => Err(format!(
            "{at}.{k}: applies to type = \"ice\", not to type = \"{kind}\""
        )),
        None => Ok(()),
    }
}

/// A `type = "ice"` medium: the `crystals` populations of a halo sky (each `weight`
/// its share of the crystals by number), all in random orientation, `number_density`
/// crystals per m³ in all, and optional `rays`, `seed` and `forward_cutoff`.
fn plan_ice(at: &str, m: &MediumFile) -> std::result::Result<OpticsPlan, String> {
    if let Some(k) = given("radius_mm", m.radius_mm.is_some())
        .or(given("drops", m.drops.is_some()))
        .or(given(
            "liquid_water_content",
            m.liquid_water_content.is_some(),
        ))
        .or(given("absorption", m.absorption.is_some()))
        .or(given("lambda_step", m.lambda_step.is_some()))
    {
        return Err(format!(
            "{at}.{k}: applies to type = \"mie\", not to type = \"ice\""
        ));
    }
    if let Some(k) = given("sigma_a", m.sigma_a.is_some())
        .or(given("sigma_s", m.sigma_s.is_some()))
        .or(given("g", m.g.is_some()))
    {
        return Err(format!(
            "{at}.{k}: applies to type = \"henyey-greenstein\", not to type = \"ice\" (whose coefficients come from the crystals' projected areas)"
        ));
    }
    let name = |k: HaloKey| match k {
        HaloKey::Crystals => format!("{at}.crystals"),
        HaloKey::Crystal(j, key) => format!("{at}.crystals[{j}].{key}"),
        HaloKey::Rays => format!("{at}.rays"),
        HaloKey::SunElevation => at.to_string(),
    };
    let Some(crystals) = &m.crystals else {
        return Err(format!(
            "{at}.crystals: missing required key (expected the populations of ice crystals, e.g. [{{ orientation = \"random\", aspect = 0.5, size_um = 60 }}])"
        ));
    };
    let populations = crate::sky::halo::spec::populations(crystals, &name)?;
    if let Some(j) = populations
        .iter()
        .position(|p| p.orientation != Orientation::Random)
    {
        return Err(format!(
            "{}: an ice medium takes orientation = \"random\", got {:?} (oriented crystals, whose phase function depends on the light's direction, render as a halo sky: [sky] model = \"halo\")",
            name(HaloKey::Crystal(j, "orientation")),
            crystals[j].orientation
        ));
    }
    let Some(density) = m.number_density else {
        return Err(format!(
            "{at}.number_density: missing required key (expected crystals per m³)"
        ));
    };
    let cutoff = forward_cutoff(at, m)?;
    Ok(OpticsPlan::Ice(IceSpec {
        populations,
        number_density: density.get() as f64,
        rays: crate::sky::halo::spec::rays(m.rays, crate::medium::ice::DEFAULT_RAYS, &name)?,
        seed: m.seed.unwrap_or(0),
        forward_cutoff_deg: cutoff,
    }))
}

/// Gives each shape its entry's medium (`plans`, by `shape_entry`) and returns the media.
/// A medium sits in a closed shape whose surface lets light in: no material (an
/// index-matched boundary, `Shape::interface`) or a smooth or rough dielectric (a glass of
/// milk); one medium per entry, tabulated once per distinct medium. With
/// [`SkyTables::Skip`] (the fuzzing harness, which never renders) Lorenz–Mie and ice media are
/// checked but not tabulated, which takes seconds: their shapes are left without one.
pub(super) fn assign_media(
    entries: &[ShapeFile],
    shape_entry: &[usize],
    plans: &[Option<MediumPlan>],
    shapes: &mut [Shape],
    materials: &Materials,
    sky_tables: SkyTables,
) -> Result<Vec<Medium>, String> {
    let mut media: Vec<Medium> = Vec::new();
    let mut medium_plans: Vec<&MediumPlan> = Vec::new();
    let mut boxes = Vec::new();
    for k in 0..shapes.len() {
        let i = shape_entry[k];
        let Some(plan) = &plans[i] else { continue };
        let at = format!("shapes[{i}]");
        let entry = &entries[i];
        if entry.emission().1.is_some() {
            return Err(format!(
                "{at}.medium: a shape with a medium cannot also emit (emission is given)"
            ));
        }
        if shape_entry.iter().filter(|&&e| e == i).count() > 1 {
            return Err(format!(
                "{at}.medium: expected a mesh of one material around the medium, got a mesh whose groups use several"
            ));
        }
        let shape = &mut shapes[k];
        if !shape.is_closed() {
            return Err(format!(
                "{at}.medium: expected a closed shape (a sphere, or a mesh whose every edge is shared by two triangles) around the medium, got an open {}",
                entry.name()
            ));
        }
        match &materials.list[shape.material as usize] {
            _ if entry.emission().0.is_none() => shape.interface = true,
            Material::Dielectric(_) | Material::RoughDielectric(_) => {}
            Material::ThinDielectric(_) => {
                return Err(format!(
                    "{at}.material: a shape with a medium needs a surface light can enter: no material (an index-matched boundary) or a dielectric, got the thin-dielectric {:?} (a sheet of no thickness, not an interface between media: light passing it stays in the medium it came from)",
                    materials.names[shape.material as usize]
                ))
            }
            _ => {
                return Err(format!(
                    "{at}.material: a shape with a medium needs a surface light can enter: no material (an index-matched boundary) or a dielectric, got {:?}",
                    materials.names[shape.material as usize]
                ))
            }
        }
        if sky_tables == SkyTables::Skip
            && matches!(plan.optics, OpticsPlan::Mie(_) | OpticsPlan::Ice(_))
        {
            continue;
        }
        let id = match medium_plans.iter().position(|p| *p == plan) {
            Some(id) => id,
            None => {
                media.push(plan.optics.build());
                medium_plans.push(plan);
                boxes.push(EMPTY_BOX);
                media.len() - 1
            }
        };
        boxes[id] = grow_box(boxes[id], shape);
        shape.medium = id as u32;
    }
    // A heterogeneous medium's majorants cover the box of every shape that holds it.
    for ((m, plan), (lo, hi)) in media.iter_mut().zip(&medium_plans).zip(boxes) {
        if let Some(d) = &plan.density {
            m.density = Some(d.build(lo, hi));
        }
        if let Some(a) = &plan.aloft {
            m.aloft = Some(Aloft {
                optics: a.optics.build().optics,
                up: a.up,
                from: a.from,
                to: a.to,
            });
            // Drops that vary make the medium heterogeneous even at a uniform density.
            if m.density.is_none() {
                m.density = Some(Density::new(Field::Uniform, lo, hi));
            }
        }
    }
    Ok(media)
}

/// A density field as planned: built once the medium's box is known (noise is baked
/// over it).
#[derive(Clone, Debug, PartialEq)]
pub(super) enum DensityPlan {
    Field(Field),
    Noise(Noise),
}

impl DensityPlan {
    fn build(&self, lo: Vec3, hi: Vec3) -> Density {
        let field = match self {
            DensityPlan::Field(f) => f.clone(),
            DensityPlan::Noise(n) => Field::Grid(n.bake(lo, hi)),
        };
        Density::new(field, lo, hi)
    }
}

/// The drops aloft of a `type = "mie"` medium `m`: checked as the medium's own drops
/// are (the same keys, `absorption`, `lambda_step` and `forward_cutoff` shared).
fn plan_aloft(
    at: &str,
    m: &MediumFile,
    a: &crate::scene::file::AloftFile,
) -> std::result::Result<AloftPlan, String> {
    if MediumType::from_name(&m.kind) != Some(MediumType::Mie) {
        return Err(format!(
            "{at}: applies to type = \"mie\" (drops that vary with height), not to type = {:?}",
            m.kind
        ));
    }
    let drops = MediumFile {
        kind: m.kind.clone(),
        radius_mm: a.radius_mm,
        drops: a.drops.clone(),
        number_density: a.number_density,
        liquid_water_content: a.liquid_water_content,
        absorption: m.absorption,
        lambda_step: m.lambda_step,
        forward_cutoff: m.forward_cutoff,
        sigma_a: None,
        sigma_s: None,
        g: None,
        crystals: None,
        rays: None,
        seed: None,
        density: None,
        aloft: None,
    };
    let optics = plan_mie(at, &drops)?;
    let (from, to) = (a.from as f32, a.to as f32);
    if !(from.is_finite() && to.is_finite() && from < to) {
        return Err(format!(
            "{at}: expected heights from < to (finite), got from = {} and to = {}",
            a.from, a.to
        ));
    }
    Ok(AloftPlan {
        optics,
        up: a.up.map_or(Vec3::Y, |u| u.unit()),
        from,
        to,
    })
}

/// A grid written in the scene: `values` with its `resolution`, `min` and `max`.
fn inline_grid(
    at: &str,
    g: &crate::scene::file::GridFile,
    values: &[f64],
) -> std::result::Result<Grid, String> {
    let Some(res) = g.resolution else {
        return Err(format!(
            "{at}.resolution: missing required key (expected [nx, ny, nz] of the values)"
        ));
    };
    let res = res.map(|n| n.0 as usize);
    let count = res[0] * res[1] * res[2];
    if values.len() != count {
        return Err(format!(
            "{at}.values: expected {count} values for a {} x {} x {} grid, got {}",
            res[0],
            res[1],
            res[2],
            values.len()
        ));
    }
    let (Some(lo), Some(hi)) = (g.min, g.max) else {
        return Err(format!(
            "{at}.min: missing required key (a grid written as values needs its box, min and max)"
        ));
    };
    let grid = Grid {
        res,
        lo: lo.get(),
        hi: hi.get(),
        values: values.iter().map(|&v| v as f32).collect(),
        edge: Edge::Clamp,
    };
    grid.check().map_err(|e| format!("{at}.values: {e}"))?;
    Ok(grid)
}

/// Checks a `density` table: the key path is `at` (`shapes[i].medium.density`).
fn plan_density(
    at: &str,
    d: &DensityFile,
    base_dir: &Path,
    inputs: &mut Vec<String>,
) -> std::result::Result<DensityPlan, String> {
    let up = |u: &Option<Direction3>| u.map_or(Vec3::Y, |u| u.unit());
    Ok(match d {
        DensityFile::HeightFog(f) => DensityPlan::Field(Field::HeightFog(HeightFog {
            up: up(&f.up),
            base: f.base.unwrap_or(0.0) as f32,
            scale_height: f.scale_height.get(),
        })),
        DensityFile::RainShaft(f) => {
            let spread = f.spread.map_or(0.0, |s| s.get());
            if spread >= 60.0 {
                return Err(format!(
                    "{at}.spread: expected the cone's half-angle in degrees in [0, 60), got {spread}"
                ));
            }
            DensityPlan::Field(Field::RainShaft(RainShaft {
                center: f.center.get(),
                up: up(&f.up),
                radius: f.radius.get(),
                edge: f.edge.map_or(0.0, |e| e.get()),
                spread: spread.to_radians().tan(),
                falloff: f.falloff.map_or(f32::INFINITY, |f| f.get()),
            }))
        }
        DensityFile::Noise(n) => {
            let octaves = n.octaves.map_or(4, |o| o.0);
            if octaves > 8 {
                return Err(format!(
                    "{at}.octaves: expected 1 to 8 octaves, got {octaves}"
                ));
            }
            let threshold = n.threshold.map_or(0.5, |t| t.get());
            if threshold >= 1.0 {
                return Err(format!(
                    "{at}.threshold: expected the clear part of the noise's range in [0, 1), got {threshold}"
                ));
            }
            let resolution = n.resolution.map_or(64, |r| r.0);
            if !(2..=512).contains(&resolution) {
                return Err(format!(
                    "{at}.resolution: expected 2 to 512 cells along the box's longest side, got {resolution}"
                ));
            }
            DensityPlan::Noise(Noise {
                seed: n.seed.unwrap_or(0),
                scale: n.scale.get(),
                octaves,
                threshold,
                resolution,
                taper: n.taper.unwrap_or(false),
            })
        }
        DensityFile::Grid(g) => {
            let mut grid = match (&g.file, &g.values) {
                (Some(file), None) => {
                    if g.resolution.is_some() {
                        return Err(format!(
                            "{at}.resolution: applies to values written in the scene, not to a file (whose header gives it)"
                        ));
                    }
                    let path = base_dir.join(file);
                    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
                    if ["vdb", "nvdb"].contains(&ext.to_ascii_lowercase().as_str()) {
                        return Err(format!(
                            "{at}.file: {}: OpenVDB and NanoVDB grids are not read (no maintained Rust crate reads them); expected a Mitsuba .vol grid (float32, one channel) or values written in the scene",
                            path.display()
                        ));
                    }
                    let bytes = std::fs::read(&path)
                        .map_err(|e| format!("{at}.file: cannot read {}: {e}", path.display()))?;
                    inputs.push(file.clone());
                    Grid::from_vol(&bytes)
                        .map_err(|e| format!("{at}.file: {}: {e}", path.display()))?
                }
                (None, Some(values)) => inline_grid(at, g, values)?,
                (Some(_), Some(_)) => {
                    return Err(format!(
                        "{at}: expected one of file (a .vol grid) or values, got both"
                    ))
                }
                (None, None) => {
                    return Err(format!(
                        "{at}.file: missing required key (expected a .vol file, or values with their resolution, min and max)"
                    ))
                }
            };
            if let Some(lo) = g.min {
                grid.lo = lo.get();
            }
            if let Some(hi) = g.max {
                grid.hi = hi.get();
            }
            if !grid.lo.cmplt(grid.hi).all() {
                return Err(format!(
                    "{at}: expected min < max in each axis, got min {} and max {}",
                    grid.lo, grid.hi
                ));
            }
            grid.edge = match g.outside.as_deref() {
                None | Some("clamp") => Edge::Clamp,
                Some("zero") => Edge::Zero,
                Some(o) => {
                    return Err(format!(
                        "{at}.outside: expected one of clamp, zero, got {o:?}"
                    ))
                }
            };
            DensityPlan::Field(Field::Grid(grid))
        }
    })
}
