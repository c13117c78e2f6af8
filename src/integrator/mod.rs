//! Integrators, one file each, chosen once per render by [`IntegratorKind`]:
//!
//! - `whitted`: the seed lecture's recursive tracer written as the lecture's loop: the
//!   shader overwrites the ray and increments the depth;
//! - `path`: a spectral unidirectional path tracer with next-event estimation and
//!   multiple importance sampling;
//! - `lighttrace`: paths from the lights, connected to the camera and splatted;
//! - `bdpt`: bidirectional path tracing with every connection strategy and MIS;
//! - `sppm`: stochastic progressive photon mapping, which `render.rs` runs as
//!   iterations of a camera pass and a photon pass rather than per pixel sample.
//!
//! All five see materials and lights only through their methods (`Material::eval`,
//! `sample`, `pdf`, `flags`; `Light::sample_li`, `pdf_li`, `l`, `le`, `sample_le`), take
//! what they share from `toolkit` (the next hit, a light chosen and sampled with its
//! density, that density for MIS, Russian roulette, the start of a light path, the
//! camera's pixel, shadow rays and media transmittance), and draw every random number
//! through the [`Sampler`] interface. `render.rs` owns tiles, packets, passes and the
//! film, and calls the [`kernel`] chosen for the render once per pixel sample.
pub mod bdpt;
pub mod lighttrace;
pub mod path;
pub mod polarized;
pub mod sppm;
pub(crate) mod toolkit;
pub mod whitted;

use crate::accel::embree::{self, Hit};
use crate::camera::CameraRay;
use crate::film::Splats;
use crate::geometry::{Ray, RayOffset};
use crate::sampler::Sampler;
use crate::scene::Scene;
use crate::settings::{IntegratorKind, RenderSettings};
use crate::settings::{KernelFlags, ALL, MEDIA, SPECULAR};
use crate::spectrum::stokes::StokesSpectrum;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

pub(crate) use toolkit::WALKS;
pub use toolkit::{Deferred, PathState};

/// What an integrator needs to trace: the scene, its committed Embree scene and the
/// render's settings (the scene's, with flags applied).
#[derive(Clone, Copy)]
pub struct Context<'a> {
    pub scene: &'a Scene,
    pub accel: &'a embree::Scene,
    pub settings: &'a RenderSettings,
    /// How rays leave surfaces in this render.
    pub offset: RayOffset,
}

/// Counters one worker keeps while tracing (summed per tile, never shared).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TraceCounters {
    /// Closest-hit rays (camera rays included).
    pub rays: u64,
    /// Occlusion (shadow) rays.
    pub shadow_rays: u64,
}

/// What one pixel sample computes: radiance along the camera ray `ray` (times its
/// weight; its companions ended when the lens dispersed them) at the
/// wavelengths `wl`; contributions to other pixels go to `splats`. `first_hit` is the
/// camera ray's closest hit when it was already traced (in an Embree packet); `None`
/// traces it here. One function per (integrator, lanes, kernel), chosen once per render
/// by [`kernel`] (pbrt-v4's `RayIntegrator::EvaluatePixelSample`).
pub type RadianceFn<const N: usize> = KernelFn<N, SampledSpectrum<N>>;

/// A pixel sample's function returning `O`: radiance ([`RadianceFn`]) or, in a
/// polarised render, Stokes radiance ([`StokesFn`]).
pub type KernelFn<const N: usize, O> = fn(
    &Context,
    CameraRay,
    Option<Option<Hit>>,
    &SampledWavelengths<N>,
    &mut Sampler,
    &mut TraceCounters,
    &mut Splats,
) -> O;

/// What one pixel sample of a polarised render computes: the Stokes radiance along the
/// camera ray in the camera's frame (`integrator::polarized`).
pub type StokesFn<const N: usize> = KernelFn<N, StokesSpectrum<N>>;

fn polarized_path<const N: usize, const K: KernelFlags>(
    ctx: &Context,
    ray: CameraRay,
    first_hit: Option<Option<Hit>>,
    wl: &SampledWavelengths<N>,
    sampler: &mut Sampler,
    counters: &mut TraceCounters,
    _: &mut Splats,
) -> StokesSpectrum<N> {
    polarized::radiance::<N, K>(ctx, ray, first_hit, wl, sampler, counters)
}

fn polarized_whitted<const N: usize, const K: KernelFlags>(
    ctx: &Context,
    ray: CameraRay,
    first_hit: Option<Option<Hit>>,
    wl: &SampledWavelengths<N>,
    sampler: &mut Sampler,
    counters: &mut TraceCounters,
    _: &mut Splats,
) -> StokesSpectrum<N> {
    polarized::whitted_radiance::<N, K>(ctx, ray, first_hit, wl, sampler, counters)
}

/// The kernel flags a polarised render with integrator `kind` of a scene whose flags
/// are `k` runs with: every feature on but media, which only the path tracer's scenes
/// with media pay for (two kernels per lane count, rather than 32, keep the build's
/// time and size).
pub fn stokes_flags(kind: IntegratorKind, k: KernelFlags) -> KernelFlags {
    match kind {
        IntegratorKind::Whitted => ALL & !MEDIA,
        _ if k & MEDIA != 0 => ALL & !SPECULAR,
        _ => ALL & !SPECULAR & !MEDIA,
    }
}

/// The polarised kernel of integrator `kind` with `N` lanes for kernel flags `k` (from
/// [`stokes_flags`]), or why there is none.
pub fn stokes_kernel<const N: usize>(
    kind: IntegratorKind,
    k: KernelFlags,
) -> Result<StokesFn<N>, String> {
    match kind {
        IntegratorKind::Path if k & MEDIA != 0 => {
            Ok(polarized_path::<N, { ALL & !SPECULAR }>)
        }
        IntegratorKind::Path => Ok(polarized_path::<N, { ALL & !SPECULAR & !MEDIA }>),
        IntegratorKind::Whitted => Ok(polarized_whitted::<N, { ALL & !MEDIA }>),
        IntegratorKind::LightTrace => Ok(polarized_lighttrace::<N>),
        IntegratorKind::Bdpt => Ok(bdpt::polarized_radiance::<N>),
        IntegratorKind::Sppm => Err(
            "integrator sppm: polarised transport (polarization = true) is implemented for integrator = \"path\", \"whitted\", \"lighttrace\" and \"bdpt\"; photon mapping's photons carry no Stokes vectors".into(),
        ),
    }
}

fn polarized_lighttrace<const N: usize>(
    ctx: &Context,
    _: CameraRay,
    _: Option<Option<Hit>>,
    wl: &SampledWavelengths<N>,
    sampler: &mut Sampler,
    counters: &mut TraceCounters,
    splats: &mut Splats,
) -> StokesSpectrum<N> {
    lighttrace::radiance_carrying::<N, polarized::Beam<N>>(ctx, wl, sampler, counters, splats)
}

fn whitted_k<const N: usize, const K: KernelFlags>(
    ctx: &Context,
    ray: CameraRay,
    first_hit: Option<Option<Hit>>,
    wl: &SampledWavelengths<N>,
    sampler: &mut Sampler,
    counters: &mut TraceCounters,
    _: &mut Splats,
) -> SampledSpectrum<N> {
    whitted::radiance::<N, K>(ctx, ray, first_hit, wl, sampler, counters)
}

fn path_k<const N: usize, const K: KernelFlags>(
    ctx: &Context,
    ray: CameraRay,
    first_hit: Option<Option<Hit>>,
    wl: &SampledWavelengths<N>,
    sampler: &mut Sampler,
    counters: &mut TraceCounters,
    _: &mut Splats,
) -> SampledSpectrum<N> {
    path::radiance::<N, K>(ctx, ray, first_hit, wl, sampler, counters)
}

fn lighttrace_any<const N: usize>(
    ctx: &Context,
    _: CameraRay,
    _: Option<Option<Hit>>,
    wl: &SampledWavelengths<N>,
    sampler: &mut Sampler,
    counters: &mut TraceCounters,
    splats: &mut Splats,
) -> SampledSpectrum<N> {
    lighttrace::radiance(ctx, wl, sampler, counters, splats)
}

fn bdpt_any<const N: usize>(
    ctx: &Context,
    ray: CameraRay,
    first_hit: Option<Option<Hit>>,
    wl: &SampledWavelengths<N>,
    sampler: &mut Sampler,
    counters: &mut TraceCounters,
    splats: &mut Splats,
) -> SampledSpectrum<N> {
    bdpt::radiance(ctx, ray, first_hit, wl, sampler, counters, splats)
}

/// One step of a path whose ray has the closest hit given, for the packet engine (see
/// `whitted::step`, `path::step`): shadow rays are deferred to `Deferred`, which the
/// engine traces with the packet's and resolves before the next step.
pub type StepFn<const N: usize> = fn(
    &Context,
    &mut PathState<N>,
    &mut Ray,
    Option<Hit>,
    &SampledWavelengths<N>,
    &mut Sampler,
    &mut TraceCounters,
    &mut Deferred<N>,
) -> bool;

/// A path at the camera, ready for its first step along the camera ray.
pub type StartFn<const N: usize> = fn(&CameraRay) -> PathState<N>;

/// What the packet engine needs of an integrator: its start and its step, specialised
/// to the kernel flags as [`RadianceFn`]s are.
#[derive(Clone, Copy)]
pub struct PathFns<const N: usize> {
    pub start: StartFn<N>,
    pub step: StepFn<N>,
}

#[allow(clippy::too_many_arguments)]
fn whitted_step<const N: usize, const K: KernelFlags>(
    ctx: &Context,
    s: &mut PathState<N>,
    ray: &mut Ray,
    hit: Option<Hit>,
    wl: &SampledWavelengths<N>,
    sampler: &mut Sampler,
    counters: &mut TraceCounters,
    shadows: &mut Deferred<N>,
) -> bool {
    whitted::step::<N, K, _>(ctx, s, ray, hit, wl, sampler, counters, shadows)
}

#[allow(clippy::too_many_arguments)]
fn path_step<const N: usize, const K: KernelFlags>(
    ctx: &Context,
    s: &mut PathState<N>,
    ray: &mut Ray,
    hit: Option<Hit>,
    wl: &SampledWavelengths<N>,
    sampler: &mut Sampler,
    counters: &mut TraceCounters,
    shadows: &mut Deferred<N>,
) -> bool {
    path::step::<N, K, _>(ctx, s, ray, hit, wl, sampler, counters, shadows)
}

/// Every kernel of one integrator, indexed by its flags (`ALL` is 31). The path tracer
/// has no `SPECULAR` flag, so its entries with that bit are the ones without it; the
/// Whitted tracer has no `MEDIA` flag (scenes with media are refused under it).
macro_rules! kernels {
    ($f:ident, $n:ident, $drop:expr; $($k:literal)*) => {
        kernels!($f, $n, $drop, RadianceFn; $($k)*)
    };
    ($f:ident, $n:ident, $drop:expr, $t:ident; $($k:literal)*) => {
        [$($f::<$n, { $k & !$drop }> as $t<$n>),*]
    };
}

/// The radiance function of integrator `kind` with `N` lanes, specialised to the kernel
/// flags `k` (from [`crate::scene::Features::choose`]). Light tracing and BDPT have one
/// kernel.
pub fn kernel<const N: usize>(kind: IntegratorKind, k: KernelFlags) -> RadianceFn<N> {
    let k = (k & ALL) as usize;
    match kind {
        IntegratorKind::Whitted => {
            kernels!(whitted_k, N, MEDIA; 0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15
                16 17 18 19 20 21 22 23 24 25 26 27 28 29 30 31)[k]
        }
        IntegratorKind::Path => kernels!(path_k, N, SPECULAR; 0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15
                16 17 18 19 20 21 22 23 24 25 26 27 28 29 30 31)[k],
        IntegratorKind::LightTrace => lighttrace_any::<N>,
        IntegratorKind::Bdpt => bdpt_any::<N>,
        // Photon mapping runs its own iterations (`sppm::iteration`, called by
        // `render.rs`), not a function per pixel sample; this entry, the general path
        // tracer, is never called for it.
        IntegratorKind::Sppm => path_k::<N, { ALL & !SPECULAR }>,
    }
}

/// The start and step of integrator `kind` with `N` lanes and kernel flags `k`, for the
/// packet engine; `None` for light tracing, BDPT and photon mapping, which run one path
/// at a time.
pub fn path_fns<const N: usize>(kind: IntegratorKind, k: KernelFlags) -> Option<PathFns<N>> {
    let k = (k & ALL) as usize;
    match kind {
        IntegratorKind::Whitted => Some(PathFns {
            start: whitted::start::<N>,
            step: kernels!(whitted_step, N, MEDIA, StepFn; 0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15
                16 17 18 19 20 21 22 23 24 25 26 27 28 29 30 31)[k],
        }),
        IntegratorKind::Path => Some(PathFns {
            start: path::start::<N>,
            step: kernels!(path_step, N, SPECULAR, StepFn; 0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15
                16 17 18 19 20 21 22 23 24 25 26 27 28 29 30 31)[k],
        }),
        IntegratorKind::LightTrace | IntegratorKind::Bdpt | IntegratorKind::Sppm => None,
    }
}
