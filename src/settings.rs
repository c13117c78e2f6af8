//! Render settings: the choices a scene file's `[render]` table, the CLI's flags and the
//! Python module's keyword arguments make, as plain data at the bottom of the layer table
//! (ARCHITECTURE.md, "Layers"), so that the scene, the integrators, the renderer and the
//! provenance all read them without importing each other.
//!
//! Each enum's name list, `parse` and `name` live here; what a choice does lives in its
//! layer (`WavelengthSampler::sample` in `spectrum`, `RayOffset::of` in `geometry`, the
//! kernels in `integrator`).

mod filter;
pub use filter::{FilterParams, PixelFilter, MAX_FILTER_RADIUS};

/// The integrators a scene or the CLI can choose.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum IntegratorKind {
    /// The seed's Whitted tracer: shadow rays to the lights at diffuse and glossy
    /// surfaces, specular continuation; the default for the course's scenes.
    #[default]
    Whitted,
    /// Unidirectional path tracing with next-event estimation and MIS.
    Path,
    /// Paths from the lights, every diffuse or glossy vertex connected to the camera.
    LightTrace,
    /// Bidirectional path tracing, every strategy, power-heuristic MIS.
    Bdpt,
    /// Stochastic progressive photon mapping: visible points from the camera, photons
    /// from the lights, radii shrinking per pixel (`integrator::sppm`).
    Sppm,
}

impl IntegratorKind {
    pub const NAMES: &'static [&'static str] = &["whitted", "path", "lighttrace", "bdpt", "sppm"];

    pub fn parse(name: &str) -> Result<IntegratorKind, String> {
        match name {
            "whitted" => Ok(IntegratorKind::Whitted),
            "path" => Ok(IntegratorKind::Path),
            "lighttrace" => Ok(IntegratorKind::LightTrace),
            "bdpt" => Ok(IntegratorKind::Bdpt),
            "sppm" => Ok(IntegratorKind::Sppm),
            other => Err(format!(
                "expected one of {}, got {other:?}",
                Self::NAMES.join(", ")
            )),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            IntegratorKind::Whitted => "whitted",
            IntegratorKind::Path => "path",
            IntegratorKind::LightTrace => "lighttrace",
            IntegratorKind::Bdpt => "bdpt",
            IntegratorKind::Sppm => "sppm",
        }
    }
}

/// Which sampler a render uses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SamplerKind {
    /// Independent uniform numbers per (seed, pixel, sample).
    Independent,
    /// Owen-scrambled Sobol' points along a Morton curve.
    #[default]
    Sobol,
}

impl SamplerKind {
    pub fn parse(name: &str) -> Result<SamplerKind, String> {
        match name {
            "independent" => Ok(SamplerKind::Independent),
            "sobol" => Ok(SamplerKind::Sobol),
            other => Err(format!("expected sobol or independent, got {other:?}")),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            SamplerKind::Independent => "independent",
            SamplerKind::Sobol => "sobol",
        }
    }
}

/// How the hero wavelength is drawn; chosen once per render. The sampling itself is in
/// `spectrum::sampled`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum WavelengthSampler {
    /// Uniform over 360–830 nm.
    Uniform,
    /// p(λ) ∝ 1/cosh²(0.0072 (λ − 538 nm)) over 360–830 nm, the visible-importance
    /// density of pbrt-v4 and Mitsuba 3, sampled by inverting its CDF (derived here:
    /// ∫ sech²(a x) dx = tanh(a x)/a). The default: measured better than uniform with
    /// 8 lanes and Sobol' points (BENCHMARKS.md "Defaults").
    #[default]
    Visible,
}

/// How the light sampler of the path tracer and BDPT chooses a light.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LightSamplerKind {
    /// In proportion to each light's power.
    #[default]
    Power,
    Uniform,
}

impl LightSamplerKind {
    pub const NAMES: &'static [&'static str] = &["power", "uniform"];

    pub fn parse(name: &str) -> Result<LightSamplerKind, String> {
        match name {
            "power" => Ok(LightSamplerKind::Power),
            "uniform" => Ok(LightSamplerKind::Uniform),
            other => {
                let (last, rest) = Self::NAMES.split_last().unwrap();
                Err(format!(
                    "expected {} or {last}, got {other:?}",
                    rest.join(", ")
                ))
            }
        }
    }
}

/// The `offset` setting: which ray offset a render uses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum OffsetMode {
    /// The seed's ε for the `whitted` integrator, robust offsets for the physically
    /// based ones.
    #[default]
    Auto,
    Epsilon,
    Robust,
}

impl OffsetMode {
    pub const NAMES: &'static [&'static str] = &["auto", "epsilon", "robust"];

    pub fn parse(name: &str) -> Result<OffsetMode, String> {
        match name {
            "auto" => Ok(OffsetMode::Auto),
            "epsilon" => Ok(OffsetMode::Epsilon),
            "robust" => Ok(OffsetMode::Robust),
            other => {
                let (last, rest) = Self::NAMES.split_last().unwrap();
                Err(format!(
                    "expected {} or {last}, got {other:?}",
                    rest.join(", ")
                ))
            }
        }
    }

    /// Whether rays leave surfaces by the seed's ε (else by robust offsets) in a render
    /// by `integrator`: `auto` is ε for the seed's tracer only.
    pub fn is_epsilon(self, integrator: IntegratorKind) -> bool {
        matches!(
            (self, integrator),
            (OffsetMode::Epsilon, _) | (OffsetMode::Auto, IntegratorKind::Whitted)
        )
    }
}

/// A set of transport features a kernel is compiled for, as bits (a `const` generic);
/// `scene::features` says which a scene needs.
pub type KernelFlags = u32;

/// Shadow rays / next-event estimation at diffuse and glossy hits.
pub const SHADOWS: KernelFlags = 1 << 0;
/// Specular continuation in the Whitted tracer.
pub const SPECULAR: KernelFlags = 1 << 1;
/// Emission of area lights found at hits.
pub const EMITTERS: KernelFlags = 1 << 2;
/// Radiance of the lights at infinity along escaping rays.
pub const ESCAPE: KernelFlags = 1 << 3;
/// Participating media (path tracer only).
pub const MEDIA: KernelFlags = 1 << 4;
/// The general kernel: every flag on.
pub const ALL: KernelFlags = SHADOWS | SPECULAR | EMITTERS | ESCAPE | MEDIA;

/// The flags this build was made without (`HERON_STRIP`, see `scene::features`).
pub const STRIPPED: KernelFlags = (if cfg!(heron_strip_shadows) {
    SHADOWS
} else {
    0
}) | (if cfg!(heron_strip_specular) {
    SPECULAR
} else {
    0
}) | (if cfg!(heron_strip_emitters) {
    EMITTERS
} else {
    0
}) | (if cfg!(heron_strip_escape) { ESCAPE } else { 0 });

/// Whether kernel `k` has `flag`'s code. With `k` a const generic this folds to a
/// constant, so a kernel without the flag has no trace of the code behind it.
#[inline(always)]
pub const fn on(k: KernelFlags, flag: KernelFlags) -> bool {
    k & flag & !STRIPPED != 0
}

/// The flags' names joined by '+' ("none" for none), for messages and the render summary.
pub fn flag_names(k: KernelFlags) -> String {
    let names: Vec<&str> = [
        (SHADOWS, "shadows"),
        (SPECULAR, "specular"),
        (EMITTERS, "emitters"),
        (ESCAPE, "escape"),
        (MEDIA, "media"),
    ]
    .iter()
    .filter(|(f, _)| k & f != 0)
    .map(|&(_, n)| n)
    .collect();
    if names.is_empty() {
        "none".into()
    } else {
        names.join("+")
    }
}

/// Which kernel a render runs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum KernelChoice {
    /// The kernel specialised to the scene's features.
    #[default]
    Auto,
    /// The kernel with every feature compiled in.
    General,
    /// Exactly these flags, whatever the scene needs (not offered by the CLI): for tests
    /// that show a missing flag changes the image, and for benchmarks.
    Forced(KernelFlags),
}

impl KernelChoice {
    pub fn parse(name: &str) -> Result<KernelChoice, String> {
        match name {
            "auto" => Ok(KernelChoice::Auto),
            "general" => Ok(KernelChoice::General),
            other => Err(format!("expected auto or general, got {other:?}")),
        }
    }
}

/// Where the path tracer samples the lights from a segment of a path through a medium
/// (issue 21; `integrator::path`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum MediumNee {
    /// One light sample per segment, from a point drawn within the segment (free
    /// flight truncated to it: a forced collision), weighted by the balance heuristic
    /// against phase sampling from the free-flight collision that continues the path.
    /// Every segment through a medium contributes, collided or not.
    #[default]
    Forced,
    /// One light sample at each free-flight collision (a segment the path flies through
    /// unscattered contributes nothing): the estimator before issue 21.
    Collision,
}

impl MediumNee {
    pub fn parse(name: &str) -> Result<MediumNee, String> {
        match name {
            "forced" => Ok(MediumNee::Forced),
            "collision" => Ok(MediumNee::Collision),
            other => Err(format!("expected forced or collision, got {other:?}")),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            MediumNee::Forced => "forced",
            MediumNee::Collision => "collision",
        }
    }
}

/// The default fraction of phase samples drawn about the sun's direction at medium
/// vertices (`RenderSettings::sun_guide`), chosen by measurement (BENCHMARKS.md,
/// "Rain and fog that converge").
pub const DEFAULT_SUN_GUIDE: f32 = 0.25;

/// The sun guide from a flag or key: a probability below 1.
pub fn parse_sun_guide(v: f64) -> Result<f32, String> {
    if (0.0..1.0).contains(&v) {
        Ok(v as f32)
    } else {
        Err(format!(
            "expected a fraction in [0, 1) (0: phase sampling alone), got {v}"
        ))
    }
}

/// The options of stochastic progressive photon mapping (`integrator = "sppm"`;
/// Hachisuka & Jensen 2009), read only by that integrator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SppmSettings {
    /// Photons traced per iteration; 0: one per pixel (pbrt-v4's default).
    pub photons: u32,
    /// The fraction α of each iteration's new photons a pixel keeps, which sets how fast
    /// its radius shrinks: R² ← R² (N + αM)/(N + M) (Hachisuka & Jensen 2009, eq. 5).
    pub alpha: f32,
    /// The initial gather radius in scene units; 0: this many pixel footprints at the
    /// first visible point ([`SppmSettings::RADIUS_PIXELS`]).
    pub radius: f32,
}

impl SppmSettings {
    /// The initial radius in pixel footprints when `radius` is 0 (BENCHMARKS.md,
    /// "Photon mapping", chose it).
    pub const RADIUS_PIXELS: f32 = 4.0;

    /// Photons per iteration for a film of `pixels` pixels.
    pub fn photons_for(&self, pixels: u32) -> u32 {
        if self.photons == 0 {
            pixels.max(1)
        } else {
            self.photons
        }
    }
}

impl Default for SppmSettings {
    fn default() -> Self {
        SppmSettings {
            photons: 0,
            alpha: 2.0 / 3.0,
            radius: 0.0,
        }
    }
}

/// α from a flag or key: in (0, 1).
pub fn parse_sppm_alpha(v: f64) -> Result<f32, String> {
    if v > 0.0 && v < 1.0 {
        Ok(v as f32)
    } else {
        Err(format!(
            "expected a fraction in (0, 1) (the share of new photons a pixel keeps; 2/3 is usual), got {v}"
        ))
    }
}

/// The initial radius from a flag or key: 0 (automatic) or a positive finite length.
pub fn parse_sppm_radius(v: f64) -> Result<f32, String> {
    if v >= 0.0 && v.is_finite() && (v as f32).is_finite() {
        Ok(v as f32)
    } else {
        Err(format!(
            "expected 0 (automatic: pixel footprints) or a positive radius in scene units, got {v}"
        ))
    }
}

/// Photons per iteration from a flag or key: 0 (one per pixel) to 2³¹.
pub fn parse_sppm_photons(v: i64) -> Result<u32, String> {
    if (0..=1i64 << 31).contains(&v) {
        Ok(v as u32)
    } else {
        Err(format!(
            "expected 0 (one per pixel) or a photon count up to 2147483648, got {v}"
        ))
    }
}

/// How rays go to Embree. Embree's packet kernels return the same hits as its single-ray
/// kernel up to the last bits of t, u and v (tests/embree.rs), so the choices give the
/// same image up to those bits (tests/packets.rs bounds the difference).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Packets {
    /// `Paths` under `whitted`, `Camera` otherwise: the faster on this project's scenes
    /// (BENCHMARKS.md, "Packets of paths"). A render resolves it before it starts, so
    /// the provenance names what ran.
    #[default]
    Auto,
    /// Every ray alone (`rtcIntersect1`, `rtcOccluded1`).
    Off,
    /// Camera rays as 8-wide packets, every later ray alone: the one-path-at-a-time
    /// engine, kept as the reference of the packet engine.
    Camera,
    /// Packets of paths: the 8 paths of a packet advance together, their closest-hit
    /// rays go to Embree as 8-wide packets (camera rays in one, later rays in another)
    /// and their shadow rays as `rtcOccluded8` rounds, and a path that ends is replaced
    /// by the tile's next sample (`whitted` and `path`; the others, and polarised
    /// renders, run camera packets instead, or none under light tracing).
    Paths,
}

impl Packets {
    pub const NAMES: &'static [&'static str] = &["auto", "paths", "camera", "off"];

    pub fn parse(name: &str) -> Result<Packets, String> {
        match name {
            "auto" => Ok(Packets::Auto),
            "paths" => Ok(Packets::Paths),
            "camera" => Ok(Packets::Camera),
            "off" => Ok(Packets::Off),
            other => Err(format!(
                "expected auto, paths, camera or off, got {other:?}"
            )),
        }
    }

    /// The name in the provenance: `camera` and `off` keep the values the older boolean
    /// wrote (`true`, `false`), so that their EXRs keep their bytes.
    pub fn provenance(self) -> &'static str {
        match self {
            Packets::Off => "false",
            Packets::Camera => "true",
            Packets::Paths => "paths",
            Packets::Auto => "auto",
        }
    }

    /// Whether camera rays go to Embree in packets.
    pub fn camera(self) -> bool {
        !matches!(self, Packets::Off)
    }
}

/// Everything that decides a render's pixels: the scene file's `[render]` table (the
/// first eight fields) and the choices only flags or keyword arguments make, with their
/// defaults. A scene holds the file's; a render holds the scene's with
/// [`SettingsArgs`] applied. (What a render does besides, threads, checkpoints, shards,
/// time limits, is `render::RenderOptions`'s.)
#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    pub spp: u32,
    /// Maximum path depth (the lecture's `depth` limit on continued rays).
    pub max_depth: u32,
    /// Ray offset ε for rays leaving surfaces (seed: 1e-4), where offsets are ε.
    pub epsilon: f32,
    pub seed: u64,
    /// The integrator.
    pub integrator: IntegratorKind,
    /// Path depth from which Russian roulette may end a path (path integrator).
    pub rr_depth: u32,
    /// How the light sampler chooses (read when the scene is built).
    pub light_sampler: LightSamplerKind,
    /// How rays leave surfaces ([`OffsetMode`]).
    pub offset: OffsetMode,
    /// Wavelength lanes per path.
    pub lanes: Lanes,
    /// How rays go to Embree.
    pub packets: Packets,
    /// How hero wavelengths are drawn.
    pub wavelengths: WavelengthSampler,
    /// Accumulate the mean spectral radiance in this many equal bins over 360–830 nm
    /// (0: none).
    pub spectral_bins: usize,
    /// Where the random numbers come from.
    pub sampler: SamplerKind,
    /// The kernel specialised to the scene's features, or the general one.
    pub kernel: KernelChoice,
    /// Where light is sampled along segments through media.
    pub medium_nee: MediumNee,
    /// The fraction of phase samples at a path's first two medium vertices drawn from
    /// the phase function about the direction toward the sun (the rest about the path's
    /// direction), so that the directions from which the next vertex's light sample
    /// toward the sun is bright (near the phase function's forward peak) are drawn as
    /// often as they matter (0: off; ignored without a sun; `integrator::path`).
    pub sun_guide: f32,
    /// Stochastic progressive photon mapping's options.
    pub sppm: SppmSettings,
    /// Polarised transport (`[render] polarization`, `--polarization`): every lane
    /// carries a Stokes vector and every event applies a Mueller matrix
    /// (`integrator::polarized`); the film gains S1–S3.
    pub polarization: bool,
    /// An analyser in front of the camera at this angle (radians from the image's
    /// horizontal, counter-clockwise as the photographer sees it), in place of the
    /// scene's `[camera] polarizer` (`--polarizer`); polarised renders only.
    pub polarizer: Option<f32>,
    /// Emitters seen directly by the camera contribute nothing (`[render]
    /// hide_emitters`, `--hide-emitters`; Mitsuba 3's `hide_emitters`): an area light
    /// a camera ray hits before any scattering, and what a camera ray that escapes sees
    /// (background, environment map, sky, the sun's disk). Light reaching the camera
    /// through any scattering event, and all lighting of surfaces, are unchanged.
    pub hide_emitters: bool,
    /// The pixel reconstruction filter (`[render] filter`, `--filter`): camera samples
    /// are drawn from it and weighted by f/p (filter importance sampling), so that each
    /// pixel's plain mean estimates ∫ f L / ∫ f. Default: the box of radius 0.5.
    pub filter: PixelFilter,
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            spp: 16,
            max_depth: 10,
            epsilon: 1e-4,
            seed: 0,
            integrator: IntegratorKind::Whitted,
            rr_depth: 5,
            light_sampler: LightSamplerKind::Power,
            offset: OffsetMode::Auto,
            // The defaults with the lowest RMSE·√t over the course scenes, the Cornell
            // box and a rainbow (scripts/bench_defaults.py, BENCHMARKS.md "Defaults").
            lanes: Lanes::Eight,
            packets: Packets::Auto,
            wavelengths: WavelengthSampler::Visible,
            spectral_bins: 0,
            sampler: SamplerKind::Sobol,
            kernel: KernelChoice::Auto,
            medium_nee: MediumNee::Forced,
            sun_guide: DEFAULT_SUN_GUIDE,
            sppm: SppmSettings::default(),
            polarization: false,
            polarizer: None,
            hide_emitters: false,
            filter: PixelFilter::BOX,
        }
    }
}

/// Wavelengths carried per path, each count its own monomorphised kernel. The one
/// place a lane count is checked: the CLI's `--lanes`, `heron converge --lanes`, the
/// Python module's `lanes=` and [`RenderSettings::apply`] all parse through
/// [`Lanes::from_count`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Lanes {
    One,
    Four,
    Eight,
}

impl Lanes {
    pub const ALL: [Lanes; 3] = [Lanes::One, Lanes::Four, Lanes::Eight];

    /// The number of wavelengths.
    pub fn count(self) -> usize {
        match self {
            Lanes::One => 1,
            Lanes::Four => 4,
            Lanes::Eight => 8,
        }
    }

    /// The lane count `n`, or what was expected.
    pub fn from_count(n: i64) -> Result<Lanes, String> {
        match n {
            1 => Ok(Lanes::One),
            4 => Ok(Lanes::Four),
            8 => Ok(Lanes::Eight),
            n => Err(format!("expected 1, 4 or 8, got {n}")),
        }
    }

    /// A lane count written as text (a flag's value).
    pub fn parse(s: &str) -> Result<Lanes, String> {
        match s.trim().parse::<i64>() {
            Ok(n) => Lanes::from_count(n),
            Err(_) => Err(format!("expected 1, 4 or 8, got {s}")),
        }
    }
}

impl std::fmt::Display for Lanes {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.count())
    }
}

/// Changes to a scene's settings as the CLI's flags and the Python module's keyword
/// arguments give them (numbers as given, names as strings); `None` keeps the scene's.
/// [`RenderSettings::apply`] is the one place their rules are written. Its messages
/// name the CLI's flags; the Python module renames them to its arguments.
#[derive(Clone, Debug, Default)]
pub struct SettingsArgs<'a> {
    pub spp: Option<i64>,
    pub seed: Option<u64>,
    pub lanes: Option<i64>,
    pub integrator: Option<&'a str>,
    pub sampler: Option<&'a str>,
    pub wavelengths: Option<&'a str>,
    pub spectral_bins: Option<i64>,
    pub max_depth: Option<i64>,
    pub offset: Option<&'a str>,
    pub kernel: Option<&'a str>,
    /// `--packets` (CLI only).
    pub packets: Option<&'a str>,
    /// `--no-packets` (CLI only): `--packets off`.
    pub no_packets: bool,
    pub medium_nee: Option<&'a str>,
    pub sun_guide: Option<f64>,
    pub sppm_photons: Option<i64>,
    pub sppm_alpha: Option<f64>,
    pub sppm_radius: Option<f64>,
    /// `--polarization` (true turns it on; a scene's `true` stays on without it).
    pub polarization: Option<bool>,
    /// `--polarizer` in degrees.
    pub polarizer: Option<f64>,
    /// `--hide-emitters` (true hides them; a scene's `true` stays on without it).
    pub hide_emitters: Option<bool>,
    /// `--filter` (`PixelFilter::parse`'s syntax).
    pub filter: Option<&'a str>,
}

impl SettingsArgs<'_> {
    /// The arguments' errors, without a scene: what [`RenderSettings::apply`] would say.
    pub fn check(&self) -> Result<(), String> {
        RenderSettings::default().apply(self)
    }
}

impl RenderSettings {
    /// Applies flags or keyword arguments; the first bad one is an error naming its flag,
    /// and then nothing is changed.
    pub fn apply(&mut self, a: &SettingsArgs) -> Result<(), String> {
        let mut s = self.clone();
        if let Some(v) = a.spp {
            if v < 1 {
                return Err("--spp: expected at least 1".into());
            }
            s.spp = u32::try_from(v)
                .map_err(|_| format!("--spp: expected at most {}, got {v}", u32::MAX))?;
        }
        if let Some(v) = a.lanes {
            s.lanes = Lanes::from_count(v).map_err(|e| format!("--lanes: {e}"))?;
        }
        if let Some(w) = a.wavelengths {
            s.wavelengths = match w {
                "visible" => WavelengthSampler::Visible,
                "uniform" => WavelengthSampler::Uniform,
                other => {
                    return Err(format!(
                        "--wavelengths: expected uniform or visible, got {other:?}"
                    ))
                }
            };
        }
        if let Some(b) = a.spectral_bins {
            if !(0..=470).contains(&b) {
                return Err(format!(
                    "--spectral-bins: expected 0 (none) or 1 to 470 bins, got {b}"
                ));
            }
            s.spectral_bins = b as usize;
        }
        if let Some(d) = a.max_depth {
            if d < 1 || d > u32::MAX as i64 {
                return Err(format!("--max-depth: expected at least 1, got {d}"));
            }
            s.max_depth = d as u32;
        }
        if let Some(o) = a.offset {
            s.offset = OffsetMode::parse(o).map_err(|e| format!("--offset: {e}"))?;
        }
        if let Some(i) = a.integrator {
            s.integrator = IntegratorKind::parse(i).map_err(|e| format!("--integrator: {e}"))?;
        }
        if let Some(n) = a.sampler {
            s.sampler = SamplerKind::parse(n).map_err(|e| format!("--sampler: {e}"))?;
        }
        if let Some(k) = a.kernel {
            s.kernel = KernelChoice::parse(k).map_err(|e| format!("--kernel: {e}"))?;
        }
        if let Some(v) = a.seed {
            s.seed = v;
        }
        if let Some(p) = a.packets {
            s.packets = Packets::parse(p).map_err(|e| format!("--packets: {e}"))?;
        }
        if a.no_packets {
            s.packets = Packets::Off;
        }
        if let Some(m) = a.medium_nee {
            s.medium_nee = MediumNee::parse(m).map_err(|e| format!("--medium-nee: {e}"))?;
        }
        if let Some(g) = a.sun_guide {
            s.sun_guide = parse_sun_guide(g).map_err(|e| format!("--sun-guide: {e}"))?;
        }
        if let Some(n) = a.sppm_photons {
            s.sppm.photons = parse_sppm_photons(n).map_err(|e| format!("--sppm-photons: {e}"))?;
        }
        if let Some(v) = a.sppm_alpha {
            s.sppm.alpha = parse_sppm_alpha(v).map_err(|e| format!("--sppm-alpha: {e}"))?;
        }
        if let Some(v) = a.sppm_radius {
            s.sppm.radius = parse_sppm_radius(v).map_err(|e| format!("--sppm-radius: {e}"))?;
        }
        if let Some(p) = a.polarization {
            s.polarization = p;
        }
        if let Some(deg) = a.polarizer {
            if !deg.is_finite() {
                return Err(format!(
                    "--polarizer: expected the analyser's angle in degrees from the image's horizontal, got {deg}"
                ));
            }
            s.polarizer = Some((deg as f32).to_radians());
        }
        if let Some(h) = a.hide_emitters {
            s.hide_emitters = h;
        }
        if let Some(f) = a.filter {
            s.filter = PixelFilter::parse(f).map_err(|e| format!("--filter: {e}"))?;
        }
        *self = s;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flags_apply_in_one_place_and_a_bad_one_changes_nothing() {
        let mut s = RenderSettings::default();
        s.apply(&SettingsArgs {
            spp: Some(3),
            lanes: Some(4),
            integrator: Some("bdpt"),
            wavelengths: Some("uniform"),
            max_depth: Some(2),
            offset: Some("robust"),
            no_packets: true,
            ..SettingsArgs::default()
        })
        .unwrap();
        assert_eq!(
            (s.spp, s.lanes, s.integrator, s.max_depth, s.packets),
            (3, Lanes::Four, IntegratorKind::Bdpt, 2, Packets::Off)
        );
        assert_eq!(s.wavelengths, WavelengthSampler::Uniform);
        assert!(!s.offset.is_epsilon(s.integrator));
        let before = s.clone();
        for (args, message) in [
            (
                SettingsArgs {
                    spp: Some(0),
                    ..SettingsArgs::default()
                },
                "--spp: expected at least 1",
            ),
            (
                SettingsArgs {
                    seed: Some(9),
                    lanes: Some(3),
                    ..SettingsArgs::default()
                },
                "--lanes: expected 1, 4 or 8, got 3",
            ),
            (
                SettingsArgs {
                    spectral_bins: Some(471),
                    ..SettingsArgs::default()
                },
                "--spectral-bins: expected 0 (none) or 1 to 470 bins, got 471",
            ),
            (
                SettingsArgs {
                    integrator: Some("nope"),
                    ..SettingsArgs::default()
                },
                "--integrator: expected one of whitted, path, lighttrace, bdpt, sppm, got \"nope\"",
            ),
            (
                SettingsArgs {
                    packets: Some("sideways"),
                    ..SettingsArgs::default()
                },
                "--packets: expected auto, paths, camera or off, got \"sideways\"",
            ),
        ] {
            assert_eq!(s.apply(&args), Err(message.to_string()));
            assert_eq!(args.check(), Err(message.to_string()));
            // The seed of the second case was valid, but the call failed as a whole.
            assert_eq!(s, before);
        }
    }
}
