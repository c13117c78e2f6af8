//! The scene file format (TOML, serde).
//!
//! A scene file is a TOML document whose top level is [`SceneFile`]. Materials, shapes
//! and lights are internally tagged by their `type` key. Every struct denies unknown
//! keys, so a misspelt key is an error rather than a silently ignored default.
//!
//! The leaf types of this module ([`Point2`], [`Point3`], [`Direction3`], [`PositiveNumber`],
//! [`UnitNumber`], [`PositiveCount`], [`Resolution`], [`Reflectance`], [`Emission`])
//! check their own range while they are deserialized, so that an out-of-range number is
//! reported with the key path serde is at, in the words "expected …, got …". Checks that
//! involve several keys (ρd + ρs ≤ 1, zero-area triangles, material names) are in
//! [`super::load`]. The leaves keep their numbers as written (f64) and give them in f32
//! (`get`), the precision heron renders in.
//!
//! The schema serialises too, each optional key left out when unset: the importers
//! ([`super::import`]) build these structs rather than tables of string keys, so that a
//! renamed or retyped key is a compile error there, and `heron convert` writes them.
//! Serialising what was read gives the same values back.
//!
//! Example (the seed lecture's default scene is `scenes/default.toml`):
//!
//! ```toml
//! background = [0.1, 0.3, 0.6]      # optional colour (emission), default black
//!
//! [camera]
//! eye = [2.0, 1.5, 2.0]
//! look_at = [0.0, 0.5, 0.0]
//! up = [0.0, 1.0, 0.0]              # optional, default [0, 1, 0]
//! d = 1.0                           # camera constant, optional, default 1
//! resolution = [512, 512]           # [width, height]
//!
//! [render]                          # optional, defaults from RenderSettings::default()
//! spp = 16
//! max_depth = 10
//! epsilon = 1e-4                   # the seed's ray offset, where offsets are epsilon
//! offset = "auto"                   # auto | epsilon | robust (auto: epsilon for whitted)
//! seed = 0
//!
//! [materials.floor]
//! type = "lambertian"
//! rho_d = [0.1, 0.7, 0.0]
//!
//! [[shapes]]
//! type = "plane"
//! point = [0.0, 0.0, 0.0]
//! normal = [0.0, 1.0, 0.0]
//! material = "floor"
//!
//! [[lights]]
//! type = "point"
//! position = [0.0, 1.0, 0.0]
//! intensity = 3.14159265
//! ```
//!
//! A colour is a number (grey), `[r, g, b]` in linear sRGB, or
//! `{ spectrum = "E" | "D65" | "A", scale = 1.0 }` (scale optional, default 1).
use crate::spectrum::uplift::{named, rgb_to_illuminant, rgb_to_reflectance, NAMED_SPECTRA};
use crate::spectrum::DenseSpectrum;
use glam::Vec3;
use serde::de::{Deserialize, Deserializer, Error as _};
use std::collections::BTreeMap;
use std::fmt::Write as _;

mod coefficient;
mod colour;
mod density;
mod emission;
mod leaves;
mod metal;
mod show;
mod texture;

pub use coefficient::Coefficient;
pub use colour::{Colour, Emission, Reflectance};
pub use density::{AloftFile, DensityFile, GridFile, HeightFogFile, NoiseFile, RainShaftFile};
pub use emission::ShapeEmission;
pub use leaves::{
    Direction3, IorSpec, Point2, Point3, PositiveCount, PositiveNumber, Resolution, UnitNumber,
};
pub(crate) use show::fmt_f32;
pub use show::show;
pub use texture::{
    CheckerboardFile, ImageTextureFile, MixTextureFile, ScaleTextureFile, TextureFile, Textured,
    UvMatrix,
};

/// Largest accepted image width or height.
pub const MAX_RESOLUTION: u32 = 16384;

/// The whole scene file.
#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// Radiance of rays that leave the scene; default black.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub background: Option<Emission>,
    pub camera: CameraFile,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub render: Option<RenderFile>,
    /// Materials by name. A TOML table has no order that survives parsing, so the loaded
    /// scene lists materials sorted by name (the order of this map).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub materials: BTreeMap<String, MaterialFile>,
    /// Textures by name (`[textures.NAME]`), which materials' keys name with
    /// `{ texture = "NAME" }`.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub textures: BTreeMap<String, TextureFile>,
    #[serde(default)]
    pub shapes: Vec<ShapeFile>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub lights: Vec<LightFile>,
    /// A rainbow sky over the background; needs a `sun` light.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sky: Option<SkyFile>,
    /// An environment map in place of the background.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub environment: Option<EnvironmentFile>,
}

/// `[environment]`: radiance at infinity from an image (src/light/envmap.rs), e.g.
/// `map = "sky.exr"`, importance-sampled by its texels.
#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct EnvironmentFile {
    /// The image, relative to the scene file: OpenEXR (`.exr`, its R, G, B channels),
    /// Radiance HDR (`.hdr`) or PNG (`.png`, sRGB-encoded, decoded to linear), linear
    /// sRGB primaries.
    pub map: String,
    /// `latlong` (default; Mitsuba's equirectangular layout, +y up) or `equal-area`
    /// (pbrt-v4's octahedral square).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mapping: Option<String>,
    /// Multiplies the image's radiance; default 1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale: Option<NonNegativeNumber>,
    /// The map's orientation: a 4 × 4 affine matrix (rows) whose 3 × 3 part is
    /// orthogonal (a rotation, or a mirror); the translation is ignored (the map is at
    /// infinity). Default the identity.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub transform: Option<Vec<Vec<f64>>>,
}

/// `[sky]`: a sky model seen by rays that leave the scene (src/sky).
#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct SkyFile {
    /// constant, aristotle, descartes, airy, mie or halo.
    pub model: String,
    /// Drop radius in mm (airy, mie).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub droplet_radius: Option<PositiveNumber>,
    /// Internal reflections to include (descartes, airy): a subset of [1, 2]; default
    /// both.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub orders: Option<Vec<u32>>,
    /// unpolarised (default), s or p (descartes, airy, mie).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub polarisation: Option<String>,
    /// Multiplies the model's radiance; default 1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale: Option<PositiveNumber>,
    /// A drop-size distribution (airy, mie) instead of `droplet_radius`, e.g.
    /// `{ distribution = "lognormal", median_mm = 0.5, sigma = 0.1 }` (crate::drops).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub drops: Option<crate::drops::DropsFile>,
    /// Only this term p of the Debye series (mie): 2 the primary bow, 3 the secondary.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub debye: Option<u32>,
    /// The halo sky's populations of ice crystals (`crate::sky::halo::spec`), e.g.
    /// `[{ orientation = "plates", aspect = 0.2, tilt_deg = 0.5 }]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub crystals: Option<Vec<crate::sky::halo::CrystalFile>>,
    /// The zenith's direction (halo): the crystals' orientations are about it; default
    /// [0, 1, 0], heron's up.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub zenith: Option<[f32; 3]>,
    /// Rays per wavelength row of the halo table (default 2^20).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rays: Option<u64>,
    /// The seed of the halo table's random numbers (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seed: Option<u64>,
}

/// `[camera]`: the seed's pinhole camera, or (`type = "lens"`) a film behind a lens
/// prescription (`lens = "file"` or `[[camera.surface]]` tables), or (`type =
/// "orthographic"`) parallel rays from an image plane `height` scene units high.
#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct CameraFile {
    pub eye: Point3,
    pub look_at: Point3,
    /// Default `[0, 1, 0]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub up: Option<Direction3>,
    /// Camera constant d (distance to an image plane of height 1); default 1. Pinhole
    /// only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub d: Option<PositiveNumber>,
    pub resolution: Resolution,
    /// "pinhole" (the default), "lens" or "orthographic".
    #[serde(default, rename = "type", skip_serializing_if = "Option::is_none")]
    pub kind: Option<String>,
    /// The orthographic camera's image plane: its height in scene units (its width
    /// height × the image's aspect ratio). Orthographic only, required.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub height: Option<PositiveNumber>,
    /// The lens: a prescription file (heron's TOML or pbrt-v4's `.dat`), relative to
    /// the scene file …
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lens: Option<String>,
    /// … or its surfaces inline.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub surface: Option<Vec<toml::Value>>,
    /// Film diagonal in mm; default 43.27 (35 mm film, 36 × 24).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub film_diagonal: Option<PositiveNumber>,
    /// Film behind the last vertex (mm) …
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub film_distance: Option<PositiveNumber>,
    /// … or focused on a point this far in front of the film (scene units).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub focus_distance: Option<PositiveNumber>,
    /// Wavelength (nm) of the focus and of the exposure's normalisation; default the
    /// prescription's reference wavelength.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub focus_wavelength: Option<PositiveNumber>,
    /// Millimetres per scene unit; default 1000 (the scene in metres).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mm_per_unit: Option<PositiveNumber>,
    /// Stop the lens down (or open it) to this f-number (paraxial, at the focus
    /// wavelength, object at infinity).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub f_number: Option<PositiveNumber>,
    /// An ideal linear polariser in front of the lens, its axis this many degrees from
    /// the image's horizontal, counter-clockwise as the photographer sees it (polarised
    /// renders only: `[render] polarization`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub polarizer: Option<f32>,
    /// Exit-pupil sampling: "bounds" (default) or "rear-element".
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pupil: Option<String>,
    /// Where the film's centre sits in the image plane (mm from the optical axis, +x
    /// toward the image's right, +y toward its top); default [0, 0].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub film_offset: Option<Point2>,
}

/// `[render]`: every key optional, defaults from `RenderSettings::default()`.
#[derive(Clone, Debug, Default, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct RenderFile {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spp: Option<PositiveCount>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_depth: Option<PositiveCount>,
    /// The seed's ray offset ε.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub epsilon: Option<PositiveNumber>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seed: Option<u64>,
    /// whitted (the seed's tracer, the default) or path.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub integrator: Option<String>,
    /// Path depth from which Russian roulette may end paths (path integrator); default 5.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rr_depth: Option<u32>,
    /// How the path integrator picks a light: power (default) or uniform.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub light_sampler: Option<String>,
    /// How rays leave surfaces: auto (default: epsilon for whitted, robust otherwise),
    /// epsilon or robust.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub offset: Option<String>,
    /// Where the path tracer samples lights from a segment through a medium: forced
    /// (default) or collision.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub medium_nee: Option<String>,
    /// The fraction of phase samples drawn about the sun at medium vertices, in [0, 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sun_guide: Option<f64>,
    /// SPPM: photons per iteration (0: one per pixel).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sppm_photons: Option<i64>,
    /// SPPM: the share α of new photons a pixel keeps, in (0, 1) (default 2/3).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sppm_alpha: Option<f64>,
    /// SPPM: the initial gather radius in scene units (0: automatic).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sppm_radius: Option<f64>,
    /// Accumulate the mean spectral radiance in this many equal bins over 360–830 nm
    /// (0, the default: none); `--spectral-bins` overrides it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spectral_bins: Option<i64>,
    /// Polarised transport (default false); `--polarization` turns it on.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub polarization: Option<bool>,
    /// Emitters seen directly by the camera contribute nothing (default false);
    /// `--hide-emitters` turns it on.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hide_emitters: Option<bool>,
    /// The pixel reconstruction filter: box (default), tent, gaussian or mitchell.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub filter: Option<String>,
    /// The filter's radius in pixels (default per filter: box 0.5, tent 2, gaussian
    /// 3 filter_stddev, mitchell 2).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub filter_radius: Option<f64>,
    /// The Gaussian's standard deviation in pixels (default 0.5).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub filter_stddev: Option<f64>,
    /// Mitchell–Netravali's B (default 1/3).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub filter_b: Option<f64>,
    /// Mitchell–Netravali's C (default 1/3).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub filter_c: Option<f64>,
}

/// `[materials.NAME]`, tagged by `type`.
#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(tag = "type", rename_all = "lowercase")]
pub enum MaterialFile {
    Lambertian(LambertianFile),
    Mirror(MirrorFile),
    Dielectric(DielectricFile),
    Glossy(GlossyFile),
    Conductor(ConductorFile),
    Coated(CoatedFile),
    Polarizer(PolarizerFile),
    Retarder(RetarderFile),
    #[serde(rename = "thin-dielectric")]
    ThinDielectric(ThinDielectricFile),
    #[serde(rename = "diffuse-transmission")]
    DiffuseTransmission(DiffuseTransmissionFile),
}

impl MaterialFile {
    /// The `type` values, in declaration order (serde's `rename_all = "lowercase"` of the
    /// variants; `tests::names_are_the_serde_tags` holds them to it).
    pub const NAMES: &'static [&'static str] = &[
        "lambertian",
        "mirror",
        "dielectric",
        "glossy",
        "conductor",
        "coated",
        "polarizer",
        "retarder",
        "thin-dielectric",
        "diffuse-transmission",
    ];
}

/// A dielectric sheet of no thickness (src/bsdf/thin_dielectric.rs): a window pane
/// modelled by one surface.
#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct ThinDielectricFile {
    /// The sheet's index, as a dielectric's.
    pub ior: IorSpec,
    /// Index of the medium on both sides of the sheet; default 1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub outside_ior: Option<IorSpec>,
}

/// Lambertian reflection and transmission (src/bsdf/diffuse_transmission.rs), with
/// reflectance + transmittance ≤ 1 at every wavelength.
#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct DiffuseTransmissionFile {
    /// ρ_r, reflected back to the side the light came from.
    pub reflectance: Reflectance,
    /// τ, transmitted diffusely to the other side.
    pub transmittance: Reflectance,
}

/// A linear polariser sheet (src/bsdf/polarizer.rs): light passes straight through.
#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct PolarizerFile {
    /// The transmission axis's angle in degrees from `axis` projected onto the sheet,
    /// counter-clockwise seen from the side the normal points to (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angle: Option<f32>,
    /// A world direction whose projection onto the sheet is the axis at angle 0
    /// (default [0, 1, 0]; the sheet's own first axis where it is parallel to the normal).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axis: Option<Direction3>,
    /// Intensity transmittance along the axis, in (0, 1] (default 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub transmittance: Option<f32>,
    /// t_along / t_across, at least 1 (default: an ideal polariser, t_across = 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub extinction_ratio: Option<f32>,
}

/// A linear retarder, a wave plate (src/bsdf/retarder.rs): light passes straight through.
#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct RetarderFile {
    /// Retardance in waves (0.25: a quarter-wave plate, 0.5: a half-wave plate; default
    /// 0.25), the same at every wavelength.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub retardance: Option<f32>,
    /// The fast axis's angle in degrees, as a polarizer's `angle`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angle: Option<f32>,
    /// As a polarizer's `axis`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axis: Option<Direction3>,
}

#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct LambertianFile {
    /// ρd: a reflectance or `{ texture = "NAME" }`; or, instead, `texture`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rho_d: Option<Textured<Reflectance>>,
    /// ρd over the surface's uv: the name of a `[textures]` table, or else an image file
    /// (src/texture/image.rs), relative to the scene file: PNG or JPEG (sRGB-decoded),
    /// OpenEXR, Radiance HDR or PFM (linear); linear sRGB, components clamped to [0, 1].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub texture: Option<String>,
}

#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct MirrorFile {
    /// Default 1 (the lecture's ideal mirror); a reflectance or `{ texture = "NAME" }`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rho_s: Option<Textured<Reflectance>>,
}

#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct DielectricFile {
    pub ior: IorSpec,
    /// Default true; false is the lecture's pure refraction.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fresnel: Option<bool>,
    /// GGX roughness α in [0, 1]; 0 (default) is the smooth interface; or
    /// `{ texture = "NAME" }` (its luminance per point).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub roughness: Option<Textured<UnitNumber>>,
    /// Index of the medium outside the surface (the side its normal points to); default 1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub outside_ior: Option<IorSpec>,
}

/// A metal with a spectral complex index, smooth or rough.
#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct ConductorFile {
    pub metal: MetalSpec,
    /// GGX roughness α in [0, 1]; 0 (default) is the smooth metal; or
    /// `{ texture = "NAME" }` (its luminance per point).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub roughness: Option<Textured<UnitNumber>>,
}

/// A metal's complex index: a catalogue name (Ag, Al, Au, Cu), `{ table = "nk.csv" }`
/// (rows `wavelength_nm,n,k` covering 360–830 nm, relative to the scene file) or
/// `{ n = .., k = .. }` (constant).
#[derive(Clone, Debug, PartialEq)]
pub enum MetalSpec {
    Named(String),
    Table(String),
    /// Kept as written, read in f32.
    Constant {
        n: f64,
        k: f64,
    },
    /// n and k over wavelength, each a number, `[r, g, b]` (uplifted unbounded, as
    /// pbrt-v4's `RGBUnboundedSpectrum`) or `{ samples = [[nm, value], ...] }`; at least
    /// one of them is not a plain number (that is [`MetalSpec::Constant`]).
    Curves {
        n: Colour,
        k: Colour,
    },
}

/// A Lambertian base under a dielectric coat (src/bsdf/coated_diffuse.rs): plastic,
/// paint, varnish.
#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct CoatedFile {
    /// The base's reflectance ρ, or `{ texture = "NAME" }`.
    pub reflectance: Textured<Reflectance>,
    /// The coat's refractive index (relative to the outside), possibly dispersive;
    /// default 1.5.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ior: Option<IorSpec>,
    /// The coat's GGX roughness α in [0, 1]; 0 (default) is a smooth coat; or
    /// `{ texture = "NAME" }` (its luminance per point).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub roughness: Option<Textured<UnitNumber>>,
    /// Optical depth τ ≥ 0 of an absorbing layer between coat and base (pbrt-v4's
    /// `thickness`); default 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thickness: Option<f64>,
    /// Count the base's repeated reflections under the coat as ρ/(1 − ρK) (default
    /// true, physical); false is Mitsuba's plastic default, ρ/(1 − K).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nonlinear: Option<bool>,
}

/// The seed's modified Phong model, optionally over a refractive base (`ior`).
#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct GlossyFile {
    /// A reflectance or `{ texture = "NAME" }`.
    pub rho_d: Textured<Reflectance>,
    /// A number in [0, 1] or `{ texture = "NAME" }` (its luminance per point).
    pub rho_s: Textured<UnitNumber>,
    pub shininess: PositiveNumber,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ior: Option<IorSpec>,
    /// Only allowed together with `ior`; default true.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fresnel: Option<bool>,
}

/// `[[shapes]]`, tagged by `type`.
#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(tag = "type", rename_all = "lowercase")]
pub enum ShapeFile {
    Sphere(SphereFile),
    Triangle(TriangleFile),
    Plane(PlaneFile),
    Quad(QuadFile),
    Mesh(MeshFile),
    Waves(WavesFile),
}

impl ShapeFile {
    /// The `type` values, in declaration order (serde's `rename_all = "lowercase"` of the
    /// variants; `tests::names_are_the_serde_tags` holds them to it).
    pub const NAMES: &'static [&'static str] =
        &["sphere", "triangle", "plane", "quad", "mesh", "waves"];

    /// The entry's material name, emission and two-sidedness.
    pub fn emission(&self) -> (Option<&String>, Option<&ShapeEmission>, Option<bool>) {
        match self {
            ShapeFile::Sphere(x) => (x.material.as_ref(), x.emission.as_ref(), x.two_sided),
            ShapeFile::Triangle(x) => (x.material.as_ref(), x.emission.as_ref(), x.two_sided),
            ShapeFile::Plane(x) => (x.material.as_ref(), x.emission.as_ref(), x.two_sided),
            ShapeFile::Quad(x) => (x.material.as_ref(), x.emission.as_ref(), x.two_sided),
            ShapeFile::Mesh(x) => (x.material.as_ref(), x.emission.as_ref(), x.two_sided),
            ShapeFile::Waves(x) => (x.material.as_ref(), x.emission.as_ref(), x.two_sided),
        }
    }

    /// The entry's material name, emission and two-sidedness, to be set (as the
    /// importers give every shape of an element its surface).
    pub fn surface_mut(
        &mut self,
    ) -> (
        &mut Option<String>,
        &mut Option<ShapeEmission>,
        &mut Option<bool>,
    ) {
        match self {
            ShapeFile::Sphere(x) => (&mut x.material, &mut x.emission, &mut x.two_sided),
            ShapeFile::Triangle(x) => (&mut x.material, &mut x.emission, &mut x.two_sided),
            ShapeFile::Plane(x) => (&mut x.material, &mut x.emission, &mut x.two_sided),
            ShapeFile::Quad(x) => (&mut x.material, &mut x.emission, &mut x.two_sided),
            ShapeFile::Mesh(x) => (&mut x.material, &mut x.emission, &mut x.two_sided),
            ShapeFile::Waves(x) => (&mut x.material, &mut x.emission, &mut x.two_sided),
        }
    }

    /// The entry's medium.
    pub fn medium(&self) -> Option<&MediumFile> {
        match self {
            ShapeFile::Sphere(x) => x.medium.as_ref(),
            ShapeFile::Triangle(x) => x.medium.as_ref(),
            ShapeFile::Plane(x) => x.medium.as_ref(),
            ShapeFile::Quad(x) => x.medium.as_ref(),
            ShapeFile::Mesh(x) => x.medium.as_ref(),
            ShapeFile::Waves(x) => x.medium.as_ref(),
        }
    }

    /// The entry's medium, to be set (as the importers give a closed shape its
    /// interior medium).
    pub fn medium_mut(&mut self) -> &mut Option<MediumFile> {
        match self {
            ShapeFile::Sphere(x) => &mut x.medium,
            ShapeFile::Triangle(x) => &mut x.medium,
            ShapeFile::Plane(x) => &mut x.medium,
            ShapeFile::Quad(x) => &mut x.medium,
            ShapeFile::Mesh(x) => &mut x.medium,
            ShapeFile::Waves(x) => &mut x.medium,
        }
    }

    /// The entry's `type` value.
    pub fn name(&self) -> &'static str {
        let i = match self {
            ShapeFile::Sphere(_) => 0,
            ShapeFile::Triangle(_) => 1,
            ShapeFile::Plane(_) => 2,
            ShapeFile::Quad(_) => 3,
            ShapeFile::Mesh(_) => 4,
            ShapeFile::Waves(_) => 5,
        };
        Self::NAMES[i]
    }
}

#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct SphereFile {
    pub center: Point3,
    pub radius: PositiveNumber,
    /// Required unless `emission` is given (then default: black, a pure emitter).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub material: Option<String>,
    /// Radiance emitted from the surface: the shape becomes an area light.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub emission: Option<ShapeEmission>,
    /// Emit from both sides (default: only the side the outward normal points to).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub two_sided: Option<bool>,
    /// A participating medium inside the shape (closed shapes only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub medium: Option<MediumFile>,
}

#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct TriangleFile {
    /// Counter-clockwise seen from the front: the geometric normal is
    /// (v1 − v0) × (v2 − v0).
    pub vertices: [Point3; 3],
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub material: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub emission: Option<ShapeEmission>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub two_sided: Option<bool>,
    /// A participating medium inside the shape (closed shapes only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub medium: Option<MediumFile>,
}

/// An infinite plane, stored as a square of half-extent `size` centred at `point`.
#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct PlaneFile {
    pub point: Point3,
    pub normal: Direction3,
    /// Half-extent of the square; default 1000.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub size: Option<PositiveNumber>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub material: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub emission: Option<ShapeEmission>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub two_sided: Option<bool>,
    /// A participating medium inside the shape (closed shapes only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub medium: Option<MediumFile>,
}

/// The parallelogram origin + s·edge1 + t·edge2, s, t ∈ [0, 1]; normal edge1 × edge2.
#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct QuadFile {
    pub origin: Point3,
    pub edge1: Direction3,
    pub edge2: Direction3,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub material: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub emission: Option<ShapeEmission>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub two_sided: Option<bool>,
    /// A participating medium inside the shape (closed shapes only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub medium: Option<MediumFile>,
}

/// A water surface: the quad `origin`, `edge1`, `edge2` cut into `resolution` cells of
/// two triangles each, its vertices moved along the quad's normal (edge1 × edge2) by
/// h = Σ aᵢ sin(2π (dᵢ · x)/λᵢ + φᵢ), x the vertex's position in the quad's plane (along
/// edge1 and edge2, from the origin) and dᵢ a unit direction in that plane (a sum of
/// sine waves, the simplest ocean of Tessendorf 2001's §3).
#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct WavesFile {
    pub origin: Point3,
    pub edge1: Direction3,
    pub edge2: Direction3,
    /// Cells along edge1 and edge2 (default [128, 128]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub resolution: Option<[PositiveCount; 2]>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub waves: Vec<WaveFile>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub material: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub emission: Option<ShapeEmission>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub two_sided: Option<bool>,
    /// A participating medium inside the shape (closed shapes only, which a sheet of
    /// waves is not: given here so that the error says so).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub medium: Option<MediumFile>,
}

/// One sine wave of a `waves` surface.
#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct WaveFile {
    /// Height of the crest above the mean surface, in scene units (≥ 0).
    pub amplitude: f32,
    /// Crest-to-crest distance, in scene units.
    pub wavelength: PositiveNumber,
    /// The direction of travel in the quad's plane: [along edge1, along edge2].
    pub direction: Point2,
    /// Phase at the origin, in degrees (default 0).
    #[serde(default)]
    pub phase: f32,
}

/// A triangle mesh: a Wavefront OBJ file, a PLY file (by its `.ply` extension), a
/// Mitsuba serialized file (by its `.serialized` extension), or triangles written in
/// the scene (`vertices` and `triangles`, as the importers write a closed shape around
/// a medium).
#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct MeshFile {
    /// Relative to the folder of the scene file; left out when the triangles are
    /// written in the scene (`vertices` and `triangles`).
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub file: String,
    /// The mesh written in the scene instead of a file: its vertex positions …
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vertices: Option<Vec<Point3>>,
    /// … and its triangles, three vertex indices each (from 0); a triangle (a, b, c)
    /// faces (b − a) × (c − a), as a file's do.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub triangles: Option<Vec<[u32; 3]>>,
    /// Which shape of a serialized file (which may hold several), from 0 (the default,
    /// as Mitsuba's `shape_index`); an error for other files.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shape_index: Option<u32>,
    /// Material of the OBJ objects/groups not listed in `groups`; may be left out when
    /// `groups` covers every object of the file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub material: Option<String>,
    /// OBJ object or group name (`o NAME` / `g NAME`) -> material name.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub groups: BTreeMap<String, String>,
    /// Uniform scale, applied before the translation; default 1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale: Option<PositiveNumber>,
    /// Default `[0, 0, 0]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub translate: Option<Point3>,
    /// An affine 4×4 matrix, row by row (last row `[0, 0, 0, 1]`), applied after
    /// `scale` and `translate`: Mitsuba's `to_world`, as `heron convert` writes it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub transform: Option<Vec<Vec<f64>>>,
    /// The texture coordinates (u, v) of each of `vertices`, for a mesh written in the
    /// scene (a file's come from the file); used as given unless `flip_tex_coords`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub uv: Option<Vec<[f64; 2]>>,
    /// Use the file's texture coordinates (u, v) as (u, 1 − v): default true for OBJ
    /// (whose images start at the bottom row), false for PLY and serialized meshes, as
    /// Mitsuba 3 reads them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub flip_tex_coords: Option<bool>,
    /// Radiance emitted by every triangle of the mesh: it becomes an area light.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub emission: Option<ShapeEmission>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub two_sided: Option<bool>,
    /// A participating medium inside the shape (closed shapes only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub medium: Option<MediumFile>,
}

/// `medium = { type = ..., ... }` on a shape: a homogeneous participating medium inside
/// it. `type = "mie"`: water drops of `radius_mm` (monodisperse), with either
/// `number_density` (drops per m³) or `liquid_water_content` (g/m³); optional
/// `absorption` (default true: water's imaginary index), `lambda_step` (nm between
/// the Lorenz–Mie wavelength nodes, default 10) and `forward_cutoff` (degrees, default
/// 0: scattering within it of forward counts as unscattered, `medium::homogeneous`). `type = "henyey-greenstein"`:
/// `sigma_a`, `sigma_s` (per scene unit; each a number, `[r, g, b]` or samples) and `g`
/// in (−1, 1). `type = "ice"`: randomly oriented ice crystals (`medium::ice`), the
/// `crystals` tables of a halo sky with `number_density` (crystals per m³), and
/// optional `rays`, `seed` and `forward_cutoff`. The keys are checked
/// against the type in `load/media.rs`.
#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct MediumFile {
    #[serde(rename = "type")]
    pub kind: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius_mm: Option<PositiveNumber>,
    /// A drop-size distribution instead of one radius (the `[sky] drops` table).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub drops: Option<crate::drops::DropsFile>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub number_density: Option<PositiveNumber>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub liquid_water_content: Option<PositiveNumber>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub absorption: Option<bool>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lambda_step: Option<PositiveNumber>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub forward_cutoff: Option<NonNegativeNumber>,
    /// Absorption coefficient per scene unit: a number, `[r, g, b]` or samples
    /// ([`Coefficient`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sigma_a: Option<Coefficient>,
    /// Scattering coefficient per scene unit, as `sigma_a`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sigma_s: Option<Coefficient>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub g: Option<f32>,
    /// Ice crystals (`type = "ice"`): the populations, as a halo sky's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub crystals: Option<Vec<crate::sky::halo::CrystalFile>>,
    /// Rays per wavelength node of an ice medium's phase function.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rays: Option<u64>,
    /// The seed of an ice medium's traced rays.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seed: Option<u64>,
    /// A density field scaling the coefficients (a heterogeneous medium); default none
    /// (homogeneous).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density: Option<DensityFile>,
    /// Drops that vary with height (`type = "mie"`): another population aloft.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub aloft: Option<AloftFile>,
}

/// The `type` of a [`MediumFile`] (read as a string and matched in the loader's media
/// room, whose messages name the keys that do not apply to the type).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MediumType {
    /// Water drops, coefficients from Lorenz–Mie theory.
    Mie,
    /// Given σ_a, σ_s and the Henyey–Greenstein g.
    HenyeyGreenstein,
    /// Ice crystals in random orientation, traced by geometric optics.
    Ice,
}

impl MediumType {
    /// The `type` values, in declaration order.
    pub const NAMES: &'static [&'static str] = &["mie", "henyey-greenstein", "ice"];
    const ALL: [MediumType; 3] = [
        MediumType::Mie,
        MediumType::HenyeyGreenstein,
        MediumType::Ice,
    ];

    /// The type named `name`, if any.
    pub fn from_name(name: &str) -> Option<MediumType> {
        Self::NAMES
            .iter()
            .position(|n| *n == name)
            .map(|i| Self::ALL[i])
    }
}

/// `[[lights]]`, tagged by `type`.
#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(tag = "type", rename_all = "lowercase")]
pub enum LightFile {
    Point(PointLightFile),
    Directional(DirectionalLightFile),
    Sun(SunLightFile),
    Spot(SpotLightFile),
}

impl LightFile {
    /// The `type` values, in declaration order (serde's `rename_all = "lowercase"` of the
    /// variants; `tests::names_are_the_serde_tags` holds them to it).
    pub const NAMES: &'static [&'static str] = &["point", "directional", "sun", "spot"];
}

/// A spot light (pbrt-v4's falloff): full intensity within cone_angle − cone_delta of
/// its axis, smoothly down to 0 at cone_angle.
#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct SpotLightFile {
    pub position: Point3,
    /// The axis, the direction the light travels; normalised on load.
    pub direction: Direction3,
    /// Radiant intensity on the axis, a colour.
    pub intensity: Emission,
    /// Half-angle of the cone in degrees, in (0, 90]; default 30.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cone_angle: Option<PositiveNumber>,
    /// Width of the falloff ring in degrees, in [0, cone_angle]; default 5.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cone_delta: Option<NonNegativeNumber>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub polarization: Option<LightPolarizationFile>,
}

/// `polarization = { axis = [x, y, z], linear = 1.0, circular = 0.0 }` on a point, spot
/// or directional light: the light's Stokes vector S0 (1, linear, 0, circular) in the
/// frame of `axis` projected across each ray (`light::polarization`). `linear` and
/// `circular` are in [−1, 1] with linear² + circular² ≤ 1; `linear` defaults to 1
/// without `circular`, else to 0; `circular` to 0. Read only by polarised renders.
#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct LightPolarizationFile {
    pub axis: Direction3,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub linear: Option<f32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub circular: Option<f32>,
}

/// A finite number ≥ 0 (for angles that may be 0).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NonNegativeNumber(pub f64);

impl NonNegativeNumber {
    /// The number in f32.
    pub fn get(&self) -> f32 {
        self.0 as f32
    }
}

#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct PointLightFile {
    pub position: Point3,
    /// Radiant intensity, a colour.
    pub intensity: Emission,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub polarization: Option<LightPolarizationFile>,
}

/// The sun: a directional light with the solar disk's extent.
#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct SunLightFile {
    /// The direction the light travels; normalised on load.
    pub direction: Direction3,
    /// Irradiance at normal incidence, a colour; the disk's radiance is E/Ω.
    pub irradiance: Emission,
    /// Angular radius in degrees, in (0, 90); default 0.2666.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angular_radius: Option<PositiveNumber>,
    /// The opening through which all sunlight that reaches the scene passes (a window, a
    /// slit); light tracing and BDPT start the sun's paths on it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub portal: Option<PortalFile>,
}

/// A parallelogram origin + s·edge1 + t·edge2, s, t ∈ [0, 1].
#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct PortalFile {
    pub origin: Point3,
    pub edge1: Direction3,
    pub edge2: Direction3,
}

#[derive(Clone, Debug, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct DirectionalLightFile {
    /// The direction the light travels; normalised on load.
    pub direction: Direction3,
    pub radiance: Emission,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub polarization: Option<LightPolarizationFile>,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The names serde's derived deserializer lists for an unknown `type` of the tagged
    /// enum `T` (its error reads "unknown variant `x`, expected one of `a`, `b`, …").
    fn serde_tags<T: serde::de::DeserializeOwned + std::fmt::Debug>() -> Vec<String> {
        let v: toml::Value = toml::from_str("type = \"\"").unwrap();
        let e = T::deserialize(v).unwrap_err().to_string();
        let list = e
            .split("expected one of ")
            .nth(1)
            .unwrap_or_else(|| panic!("{e}"));
        list.lines()
            .next()
            .unwrap()
            .split(", ")
            .map(|n| n.trim().trim_matches('`').to_string())
            .collect()
    }

    #[test]
    fn names_are_the_serde_tags() {
        assert_eq!(serde_tags::<MaterialFile>(), MaterialFile::NAMES);
        assert_eq!(serde_tags::<ShapeFile>(), ShapeFile::NAMES);
        assert_eq!(serde_tags::<LightFile>(), LightFile::NAMES);
        assert_eq!(serde_tags::<TextureFile>(), TextureFile::NAMES);
        assert_eq!(serde_tags::<DensityFile>(), DensityFile::NAMES);
        // Each shape type's entry reports its own name.
        for (name, keys) in [
            ("sphere", "center = [0, 0, 0]\nradius = 1"),
            ("triangle", "vertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]"),
            ("plane", "point = [0, 0, 0]\nnormal = [0, 1, 0]"),
            (
                "quad",
                "origin = [0, 0, 0]\nedge1 = [1, 0, 0]\nedge2 = [0, 1, 0]",
            ),
            ("mesh", "file = \"m.obj\""),
            (
                "waves",
                "origin = [0, 0, 0]\nedge1 = [1, 0, 0]\nedge2 = [0, 0, 1]",
            ),
        ] {
            let v: toml::Value = toml::from_str(&format!("type = \"{name}\"\n{keys}")).unwrap();
            assert_eq!(ShapeFile::deserialize(v).unwrap().name(), name);
        }
        assert_eq!(
            ShapeFile::NAMES.len(),
            6,
            "a new shape type needs a line above"
        );
        for (i, n) in MediumType::NAMES.iter().enumerate() {
            assert_eq!(MediumType::from_name(n), Some(MediumType::ALL[i]));
        }
        assert_eq!(MediumType::from_name("fog"), None);
    }
}
