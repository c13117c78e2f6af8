//! `density = { type = ..., ... }` in a shape's `medium`: the field that scales the
//! medium's coefficients (`medium::density`), tagged by `type`.
use super::*;

/// A medium's density field.
#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(tag = "type", rename_all = "kebab-case")]
pub enum DensityFile {
    HeightFog(HeightFogFile),
    RainShaft(RainShaftFile),
    Noise(NoiseFile),
    Grid(GridFile),
}

impl DensityFile {
    /// The `type` values, in declaration order (`tests::names_are_the_serde_tags`).
    pub const NAMES: &'static [&'static str] = &["height-fog", "rain-shaft", "noise", "grid"];
}

/// `aloft = { ... }` in a `mie` medium: a second population of drops that takes over
/// with height, from the medium's own below `from` to this one above `to` (a smoothstep
/// of the height along `up` between them). Its drops and their number as the medium's
/// own keys give them.
#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct AloftFile {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius_mm: Option<PositiveNumber>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub drops: Option<crate::drops::DropsFile>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub number_density: Option<PositiveNumber>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub liquid_water_content: Option<PositiveNumber>,
    /// The height below which only the medium's own drops are.
    pub from: f64,
    /// The height above which only these drops are.
    pub to: f64,
    /// The direction of increasing height; default [0, 1, 0].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub up: Option<Direction3>,
}

/// ρ = exp(−(h − base)/scale_height), h the height along `up`.
#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct HeightFogFile {
    /// The height where ρ = 1; default 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub base: Option<f64>,
    pub scale_height: PositiveNumber,
    /// The direction of increasing height; default [0, 1, 0] (heron's scenes are y-up).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub up: Option<Direction3>,
}

/// Rain under a cloud base, in a vertical cylinder or a downward-widening cone.
#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct RainShaftFile {
    /// A point on the axis at the cloud base.
    pub center: Point3,
    /// The radius at the cloud base.
    pub radius: PositiveNumber,
    /// The width of the soft edge; default 0 (a sharp edge).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub edge: Option<NonNegativeNumber>,
    /// The cone's half-angle in degrees, in [0, 60); default 0 (a cylinder).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spread: Option<NonNegativeNumber>,
    /// The e-folding depth of the rain's thinning below the cloud base; default none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub falloff: Option<PositiveNumber>,
    /// The direction of increasing height; default [0, 1, 0].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub up: Option<Direction3>,
}

/// Seeded fractal value noise, thresholded, baked into a grid over the medium's box.
#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct NoiseFile {
    /// The largest features' size in scene units.
    pub scale: PositiveNumber,
    /// Default 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seed: Option<u32>,
    /// Octaves in 1..=8; default 4.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub octaves: Option<PositiveCount>,
    /// The part of the noise's range that is clear air, in [0, 1); default 0.5.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub threshold: Option<UnitNumber>,
    /// Cells of the baked grid along the box's longest side, in 2..=512; default 64.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub resolution: Option<PositiveCount>,
    /// Fade the noise out toward the ellipsoid inscribed in the medium's box; default
    /// false.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub taper: Option<bool>,
}

/// A grid of densities at the centres of its cells: from a Mitsuba `.vol` file, placed in
/// the box `min`–`max` (default the box in the file's header), or written as `values`
/// (x fastest, then y, then z) with its `resolution`, `min` and `max`.
#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct GridFile {
    /// The `.vol` file, relative to the scene file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<String>,
    /// `[nx, ny, nz]` of `values`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub resolution: Option<[PositiveCount; 3]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub values: Option<Vec<f64>>,
    /// Beyond the cells' centres: `"clamp"` (the edge cells' values continue, Mitsuba 3's
    /// default) or `"zero"` (zeros beyond the edge cells and nothing outside the box,
    /// pbrt-v4's); default clamp.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub outside: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min: Option<Point3>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max: Option<Point3>,
}
