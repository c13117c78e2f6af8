//! Materials, one file per model, behind a closed enum dispatched by `match`.
//!
//! Every material evaluates, samples and gives the density of its BSDF in a local
//! shading frame whose z axis is the surface's outward normal (pbrt-v4 §9.1; Mitsuba 3
//! `BSDF::eval/sample/pdf`). Directions ωo and ωi point away from the surface, as in the
//! seed; ωo is where the light goes (toward the camera for radiance), ωi where it comes
//! from. A direction with z < 0 is on the inside (the back) of the surface.
//!
//! Every model implements the one signature of [`BsdfModel`] (`flags`, `eval`,
//! `sample`, `pdf`; pbrt-v4's `BxDF`, Mitsuba 3's `BSDF`), and [`Material`] only
//! dispatches to it. Integrators and `heron trace` only call [`Material::eval`],
//! [`Material::sample`], [`Material::pdf`] and [`Material::flags`]: no integrator holds a
//! material's formula, nor its rule for ending the companion wavelengths.
//!
//! **Wavelengths.** The result is a [`SampledSpectrum`], one value per lane. A scattering
//! event whose *direction* depends on wavelength (refraction by a dispersive interface)
//! cannot send every lane the same way: the sampled direction is the hero's (lane 0)
//! and the other lanes end there. The ending is folded into f (hero × N, others × 0) and
//! reported in [`BsdfSample::ended_companions`] (and, for an evaluation in a given
//! direction, [`BsdfEval::ended_companions`]), so the integrator stops treating the
//! companions as alive ([`BsdfContext::companions_alive`]); see
//! [`crate::spectrum::SampledSpectrum::terminate_secondary`] for why this is unbiased.
//! Lobes whose direction does not depend on wavelength (any reflection) keep every lane,
//! each with its own value of f, while the pdf is the hero's.
//!
//! A light-sampling and a BSDF-sampling strategy combined by MIS stay unbiased because
//! both treat a given (ωo, ωi) the same way: `eval` ends the companions on a
//! dispersive transmission exactly as `sample` does.
pub mod coated_diffuse;
pub mod conductor;
pub mod dielectric;
pub mod diffuse_transmission;
pub mod fresnel;
pub mod lambertian;
pub mod microfacet;
pub mod mirror;
pub mod phong;
pub mod polarization;
pub mod polarizer;
pub mod retarder;
pub mod rough_conductor;
pub mod rough_dielectric;
pub mod texture_params;
pub mod textured_diffuse;
pub mod thin_dielectric;

pub use coated_diffuse::CoatedDiffuse;
pub use conductor::Conductor;
pub use dielectric::Dielectric;
pub use diffuse_transmission::DiffuseTransmission;
pub use lambertian::Lambertian;
pub use mirror::Mirror;
pub use phong::{Glossy, GlossyTextures};
pub use polarization::Polarizing;
pub use polarizer::Polarizer;
pub use retarder::Retarder;
pub use rough_conductor::RoughConductor;
pub use rough_dielectric::RoughDielectric;
pub use textured_diffuse::TexturedDiffuse;
pub use thin_dielectric::ThinDielectric;

use crate::math::Frame;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use glam::{Vec2, Vec3};

/// What a path carries (Veach 1997, §5.2): radiance from the camera's side, importance
/// from the lights' side. They differ only at a transmission, where radiance is scaled
/// by (n_i/n_t)² and importance is not.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TransportMode {
    #[default]
    Radiance,
    Importance,
}

/// Properties of a lobe (pbrt-v4 `BxDFFlags`), also used as a mask of the lobes that
/// [`Material::sample`] may choose.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct LobeFlags(u8);

impl LobeFlags {
    pub const NONE: LobeFlags = LobeFlags(0);
    pub const REFLECTION: LobeFlags = LobeFlags(1);
    pub const TRANSMISSION: LobeFlags = LobeFlags(2);
    pub const DIFFUSE: LobeFlags = LobeFlags(4);
    pub const GLOSSY: LobeFlags = LobeFlags(8);
    /// A Dirac delta: the lobe scatters into one direction (mirror, smooth dielectric).
    pub const SPECULAR: LobeFlags = LobeFlags(16);
    /// The scattered direction depends on wavelength (refraction at a dispersive
    /// interface): the lanes would part, so the companions end.
    pub const WAVELENGTH_DEPENDENT: LobeFlags = LobeFlags(32);
    /// Every lobe may be sampled.
    pub const ALL: LobeFlags = LobeFlags(63);

    #[inline]
    pub const fn bits(self) -> u8 {
        self.0
    }
    #[inline]
    pub const fn from_bits(b: u8) -> LobeFlags {
        LobeFlags(b & 63)
    }

    #[inline]
    pub const fn union(self, o: LobeFlags) -> LobeFlags {
        LobeFlags(self.0 | o.0)
    }
    #[inline]
    pub const fn contains(self, o: LobeFlags) -> bool {
        self.0 & o.0 == o.0
    }
    #[inline]
    pub const fn intersects(self, o: LobeFlags) -> bool {
        self.0 & o.0 != 0
    }
    #[inline]
    pub const fn is_specular(self) -> bool {
        self.intersects(Self::SPECULAR)
    }
    /// True when some lobe is not a delta (diffuse or glossy), i.e. `eval` can be
    /// non-zero and light sampling makes sense.
    #[inline]
    pub const fn has_non_specular(self) -> bool {
        self.intersects(LobeFlags(Self::DIFFUSE.0 | Self::GLOSSY.0))
    }
    #[inline]
    pub const fn is_transmission(self) -> bool {
        self.intersects(Self::TRANSMISSION)
    }
    /// Whether a lobe with these flags may be sampled under the mask `self`: its kind
    /// (diffuse, glossy, specular) and its side (reflection, transmission) must both be
    /// in the mask.
    #[inline]
    pub const fn allows(self, lobe: LobeFlags) -> bool {
        let kind = LobeFlags(lobe.0 & (Self::DIFFUSE.0 | Self::GLOSSY.0 | Self::SPECULAR.0));
        let side = LobeFlags(lobe.0 & (Self::REFLECTION.0 | Self::TRANSMISSION.0));
        self.intersects(kind) && self.contains(side)
    }
}

impl std::ops::BitAnd for LobeFlags {
    type Output = LobeFlags;
    fn bitand(self, o: LobeFlags) -> LobeFlags {
        LobeFlags(self.0 & o.0)
    }
}

impl std::ops::BitOr for LobeFlags {
    type Output = LobeFlags;
    fn bitor(self, o: LobeFlags) -> LobeFlags {
        self.union(o)
    }
}

/// How a BSDF query is made.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfContext {
    pub mode: TransportMode,
    /// False once a wavelength-dependent event has ended the companion lanes on this
    /// path (or with one lane): they are not ended twice.
    pub companions_alive: bool,
    /// Lobes `sample` may choose; the pdf it returns is conditioned on this choice.
    pub lobes: LobeFlags,
    /// The hit's texture coordinates ([`crate::geometry::Interaction::uv`]), for the
    /// materials whose reflectance is an image (pbrt-v4's `MaterialEvalContext::uv`).
    /// Integrators set it at each surface vertex; only textured materials read it.
    pub uv: Vec2,
}

impl BsdfContext {
    /// Radiance transport, every lobe, companions alive when there are any (N > 1).
    pub fn radiance<const N: usize>() -> BsdfContext {
        BsdfContext {
            mode: TransportMode::Radiance,
            companions_alive: N > 1,
            lobes: LobeFlags::ALL,
            uv: Vec2::ZERO,
        }
    }

    /// The context at a hit whose texture coordinates are `uv`.
    #[inline]
    pub fn at(mut self, uv: Vec2) -> BsdfContext {
        self.uv = uv;
        self
    }

    pub fn with_lobes(mut self, lobes: LobeFlags) -> BsdfContext {
        self.lobes = lobes;
        self
    }

    pub fn with_mode(mut self, mode: TransportMode) -> BsdfContext {
        self.mode = mode;
        self
    }
}

/// f(ωo, ωi) per lane and whether scattering from ωo into ωi ends the companion lanes
/// (a dispersive transmission with the companions alive: f is then hero × N, others ×
/// 0), so that a bidirectional connection through this event knows, as a path sampled
/// through it does from [`BsdfSample::ended_companions`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfEval<const N: usize> {
    pub f: SampledSpectrum<N>,
    pub ended_companions: bool,
}

impl<const N: usize> BsdfEval<N> {
    /// A value that keeps every lane.
    #[inline]
    pub fn keep(f: SampledSpectrum<N>) -> Self {
        BsdfEval {
            f,
            ended_companions: false,
        }
    }

    /// Nothing: a delta lobe, or a direction the model does not scatter into.
    #[inline]
    pub fn zero() -> Self {
        Self::keep(SampledSpectrum::zero())
    }
}

/// The one signature of every material model, in the local frame (z = outward normal;
/// ωo, ωi pointing away from the surface). pbrt-v4 `BxDF::Flags/f/Sample_f/PDF`,
/// Mitsuba 3 `BSDF::flags/eval/sample/pdf`.
pub trait BsdfModel {
    /// Every lobe the model may scatter into.
    fn flags(&self) -> LobeFlags;

    /// f(ωo, ωi) per lane (zero for delta lobes), and whether the event ends the
    /// companions. The default, zero, is the value of a model with delta lobes only
    /// (mirror, smooth conductor, smooth dielectric); every other model overrides it,
    /// and `tests/bsdf.rs` holds each sampled f against it.
    #[inline]
    fn eval<const N: usize>(
        &self,
        _wo: Vec3,
        _wi: Vec3,
        _wl: &SampledWavelengths<N>,
        _ctx: &BsdfContext,
    ) -> BsdfEval<N> {
        BsdfEval::zero()
    }

    /// Samples ωi for ωo from `uc` (the choice of lobe) and `u` (the direction); None
    /// when the sample carries no energy. The pdf is the hero's, conditioned on
    /// `ctx.lobes`. `wo.z` is not zero.
    fn sample<const N: usize>(
        &self,
        wo: Vec3,
        uc: f32,
        u: Vec2,
        wl: &SampledWavelengths<N>,
        ctx: &BsdfContext,
    ) -> Option<BsdfSample<N>>;

    /// Density (hero wavelength, solid angle) with which `sample` under `ctx.lobes`
    /// returns ωi. The default, zero, is a delta-only model's, as for `eval`.
    #[inline]
    fn pdf<const N: usize>(
        &self,
        _wo: Vec3,
        _wi: Vec3,
        _wl: &SampledWavelengths<N>,
        _ctx: &BsdfContext,
    ) -> f32 {
        0.0
    }

    /// The Mueller matrix of scattering light arriving along ωi into ωo by the lobe
    /// `lobe` (a sample's flags; for an evaluation, the model's non-delta lobes), per
    /// lane, divided by its [0][0], with its frames ([`polarization`]). `frame` is the
    /// local frame in world space, for a model whose axes the scene gives in world
    /// space (a polariser sheet). The default depolarises (diffuse and Phong lobes).
    #[inline]
    fn mueller<const N: usize>(
        &self,
        _wo: Vec3,
        _wi: Vec3,
        _lobe: LobeFlags,
        _wl: &SampledWavelengths<N>,
        _frame: &Frame,
    ) -> Polarizing<N> {
        Polarizing::Depolarizing
    }
}

/// A sampled direction (pbrt-v4 `BSDFSample`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfSample<const N: usize> {
    /// Incident direction, local frame, unit length.
    pub wi: Vec3,
    /// The BSDF value f(ωo, ωi) per lane (for a delta lobe: the delta's weight, so that
    /// f |cos θi| / pdf is the throughput factor).
    pub f: SampledSpectrum<N>,
    /// Density of ωi with respect to solid angle (for a delta lobe: the probability of
    /// choosing it).
    pub pdf: f32,
    /// The lobe the direction came from.
    pub flags: LobeFlags,
    /// Relative index n_t/n_i of a transmission (1 for a reflection), for Russian
    /// roulette's η² bookkeeping.
    pub eta: f32,
    /// This event ended the companion lanes (f is hero × N, others × 0).
    pub ended_companions: bool,
}

impl<const N: usize> BsdfSample<N> {
    /// f |cos θi| / pdf: the factor by which the path throughput changes.
    #[inline]
    pub fn weight(&self) -> SampledSpectrum<N> {
        self.f * (self.wi.z.abs() / self.pdf)
    }
    #[inline]
    pub fn is_specular(&self) -> bool {
        self.flags.is_specular()
    }
    #[inline]
    pub fn is_transmission(&self) -> bool {
        self.flags.is_transmission()
    }
}

#[inline]
pub(crate) fn same_hemisphere(a: Vec3, b: Vec3) -> bool {
    a.z * b.z > 0.0
}

/// Mirror image of `wo` about the local normal (0, 0, 1).
#[inline]
pub(crate) fn reflect_local(wo: Vec3) -> Vec3 {
    Vec3::new(-wo.x, -wo.y, wo.z)
}

/// Mirror direction of `wi` (unit, pointing away from the surface) about the unit
/// normal `n`, in any frame: the seed's ωr = 2(ωi·n)n − ωi.
#[inline]
pub fn reflect(wi: Vec3, n: Vec3) -> Vec3 {
    2.0 * wi.dot(n) * n - wi
}

/// Refracts `wo` (pointing away from the surface) through a surface with normal `n`
/// (either side) where `eta` = n_inside/n_outside relative to the side `n` points to.
/// Returns the transmitted direction and the relative index n_t/n_i it crossed, or
/// None on total internal reflection (the seed's cos²θt < 0). pbrt-v4 `Refract`.
#[inline]
pub(crate) fn refract_eta(wo: Vec3, n: Vec3, eta: f32) -> Option<(Vec3, f32)> {
    let mut cos_i = wo.dot(n);
    let (mut etap, mut n) = (eta, n);
    if cos_i < 0.0 {
        etap = 1.0 / etap;
        cos_i = -cos_i;
        n = -n;
    }
    let sin2_i = (1.0 - cos_i * cos_i).max(0.0);
    let sin2_t = sin2_i / (etap * etap);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some((-wo / etap + (cos_i / etap - cos_t) * n, etap))
}

/// A material: the closed set heron's scenes can name.
#[derive(Clone, Debug)]
pub enum Material {
    Lambertian(Lambertian),
    Mirror(Mirror),
    /// A smooth dielectric interface, optionally dispersive (n(λ)).
    Dielectric(Dielectric),
    /// The seed's modified Phong model, optionally over a smooth refractive base.
    Glossy(Glossy),
    /// A smooth metal with a spectral complex index n(λ) + i k(λ).
    Conductor(Conductor),
    /// A Trowbridge–Reitz (GGX) microfacet metal.
    RoughConductor(RoughConductor),
    /// A Trowbridge–Reitz (GGX) microfacet dielectric interface.
    RoughDielectric(RoughDielectric),
    /// A diffuse reflector whose ρd is a texture over the surface's uv.
    TexturedDiffuse(TexturedDiffuse),
    /// A Lambertian base under a smooth or rough dielectric coat (plastic, paint).
    CoatedDiffuse(CoatedDiffuse),
    /// A linear polariser sheet (light passes straight through).
    Polarizer(Polarizer),
    /// A linear retarder, a wave plate (light passes straight through).
    Retarder(Retarder),
    /// A dielectric sheet of no thickness: mirror reflection and straight-through
    /// transmission, with the sheet's internal reflections summed.
    ThinDielectric(ThinDielectric),
    /// Lambertian reflection and Lambertian transmission (paper, leaves).
    DiffuseTransmission(DiffuseTransmission),
}

/// `match` over the models, the same call in every arm.
macro_rules! dispatch {
    ($self:expr, $m:ident => $call:expr) => {
        match $self {
            Material::Lambertian($m) => $call,
            Material::TexturedDiffuse($m) => $call,
            Material::Mirror($m) => $call,
            Material::Dielectric($m) => $call,
            Material::Glossy($m) => $call,
            Material::Conductor($m) => $call,
            Material::RoughConductor($m) => $call,
            Material::RoughDielectric($m) => $call,
            Material::CoatedDiffuse($m) => $call,
            Material::Polarizer($m) => $call,
            Material::Retarder($m) => $call,
            Material::ThinDielectric($m) => $call,
            Material::DiffuseTransmission($m) => $call,
        }
    };
}

impl Material {
    /// Whether the material reads the hit's uv ([`BsdfContext::uv`]), so that the
    /// scene computes it at a hit (only then: a sphere's uv costs two arctangents).
    #[inline]
    pub fn is_textured(&self) -> bool {
        match self {
            Material::TexturedDiffuse(_) => true,
            Material::Glossy(g) => g.textures.is_some(),
            Material::Mirror(m) => m.texture.is_some(),
            Material::RoughConductor(c) => c.alpha_texture.is_some(),
            Material::RoughDielectric(d) => d.alpha_texture.is_some(),
            Material::CoatedDiffuse(c) => c.is_textured(),
            _ => false,
        }
    }

    /// Every lobe this material may scatter into.
    #[inline]
    pub fn flags(&self) -> LobeFlags {
        dispatch!(self, m => m.flags())
    }

    /// f(ωo, ωi) per lane, local frame (zero for delta lobes), and whether the event
    /// ends the companions.
    #[inline]
    pub fn eval<const N: usize>(
        &self,
        wo: Vec3,
        wi: Vec3,
        wl: &SampledWavelengths<N>,
        ctx: &BsdfContext,
    ) -> BsdfEval<N> {
        dispatch!(self, m => m.eval(wo, wi, wl, ctx))
    }

    /// Samples ωi for ωo ([`BsdfModel::sample`]); None also for a grazing ωo (z = 0),
    /// which no model can scatter.
    #[inline]
    pub fn sample<const N: usize>(
        &self,
        wo: Vec3,
        uc: f32,
        u: Vec2,
        wl: &SampledWavelengths<N>,
        ctx: &BsdfContext,
    ) -> Option<BsdfSample<N>> {
        if wo.z == 0.0 {
            return None;
        }
        dispatch!(self, m => m.sample(wo, uc, u, wl, ctx))
    }

    /// The event's normalised Mueller matrix and frames ([`BsdfModel::mueller`]).
    #[inline]
    pub fn mueller<const N: usize>(
        &self,
        wo: Vec3,
        wi: Vec3,
        lobe: LobeFlags,
        wl: &SampledWavelengths<N>,
        frame: &Frame,
    ) -> Polarizing<N> {
        dispatch!(self, m => m.mueller(wo, wi, lobe, wl, frame))
    }

    /// Density (hero wavelength, solid angle) with which `sample` under `ctx.lobes`
    /// returns ωi; zero for delta lobes.
    #[inline]
    pub fn pdf<const N: usize>(
        &self,
        wo: Vec3,
        wi: Vec3,
        wl: &SampledWavelengths<N>,
        ctx: &BsdfContext,
    ) -> f32 {
        dispatch!(self, m => m.pdf(wo, wi, wl, ctx))
    }

    /// The smooth refractive interface of this material, if it has one (a dielectric, or
    /// the seed's glossy-over-refractive base): for [`Material::ior1_over_ior2`] and for
    /// `heron trace`'s report.
    #[inline]
    pub fn interface(&self) -> Option<&Dielectric> {
        match self {
            Material::Dielectric(d) => Some(d),
            Material::Glossy(g) => g.base.as_ref(),
            _ => None,
        }
    }

    /// The seed's HitInfo `ior1_over_ior2` for a hit on this material at `lambda` nm:
    /// n_i/n_t of a ray crossing it from the side `front_face` says (1 for a material
    /// that refracts nothing).
    #[inline]
    pub fn ior1_over_ior2(&self, lambda: f32, front_face: bool) -> f32 {
        match self {
            Material::Dielectric(d) => d.ior1_over_ior2(lambda, front_face),
            Material::RoughDielectric(d) => d.interface.ior1_over_ior2(lambda, front_face),
            Material::Glossy(g) => g
                .base
                .as_ref()
                .map_or(1.0, |b| b.ior1_over_ior2(lambda, front_face)),
            _ => 1.0,
        }
    }

    /// Whether light this material transmits stays on the side it came from as far as
    /// volumes go: a sheet of no thickness (thin dielectric, diffuse transmitter,
    /// polariser, retarder) is not the boundary of a volume, so a path passing it stays
    /// in the medium it was in. Only a dielectric (smooth, rough, or a glossy material's
    /// refractive base) encloses a volume light enters.
    #[inline]
    pub fn is_sheet(&self) -> bool {
        matches!(
            self,
            Material::ThinDielectric(_)
                | Material::DiffuseTransmission(_)
                | Material::Polarizer(_)
                | Material::Retarder(_)
        )
    }
}
