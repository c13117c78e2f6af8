//! Integrators, one file each, chosen once per render by [`IntegratorKind`]:
//!
//! - `whitted`: the seed lecture's recursive tracer written as the lecture's loop: the
//!   shader overwrites the ray and increments the depth;
//! - `path`: a spectral unidirectional path tracer with next-event estimation and
//!   multiple importance sampling;
//! - `lighttrace`: paths from the lights, connected to the camera and splatted;
//! - `bdpt`: bidirectional path tracing with every connection strategy and MIS;
//! - `sppm`: stochastic progressive photon mapping, which `render/` runs as
//!   iterations of a camera pass and a photon pass rather than per pixel sample.
//!
//! Each is a type implementing [`Integrator`] (what it supports: `capabilities.rs`
//! holds the rules that read it) and [`PixelIntegrator`] (a value per pixel sample; the
//! packet engine also steps a [`StepIntegrator`]'s paths) or, for photon mapping,
//! [`PassIntegrator`]. Each is generic over its [`Transport`]: unpolarised, or
//! polarised (`polarized.rs`).
//!
//! All five see materials and lights only through their methods (`Material::eval`,
//! `sample`, `pdf`, `flags`; `Light::sample_li`, `pdf_li`, `l`, `le`, `sample_le`), take
//! what they share from `toolkit` (the next hit, a light chosen and sampled with its
//! density, that density for MIS, Russian roulette, the start of a light path, the
//! camera's pixel, shadow rays and media transmittance), and draw every random number
//! through the [`Sampler`] interface. `render/` owns tiles, packets, passes and the
//! film, and calls the [`kernel`] chosen for the render once per pixel sample.
pub mod bdpt;
pub mod capabilities;
pub mod lighttrace;
pub mod path;
pub mod polarized;
pub mod sppm;
pub(crate) mod toolkit;
pub(crate) mod transport;
pub mod whitted;

use crate::accel::embree::{self, Hit};
use crate::camera::CameraRay;
use crate::film::state::IntegratorPlane;
use crate::film::Splats;
use crate::geometry::{Ray, RayOffset};
use crate::sampler::Sampler;
use crate::scene::Scene;
use crate::settings::{IntegratorKind, RenderSettings};
use crate::settings::{KernelFlags, ALL, MEDIA, SPECULAR};
use crate::spectrum::stokes::StokesSpectrum;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

use bdpt::Bidirectional;
pub use capabilities::{choose_kernel, kernel_flags, Capabilities, Support};
use lighttrace::LightTracer;
use path::PathTracer;
use polarized::Polarized;
use sppm::PhotonMapping;
pub(crate) use toolkit::WALKS;
pub use toolkit::{Deferred, PathState};
use toolkit::{Immediate, ShadowSink};
pub(crate) use transport::Tracer;
use transport::{follow, Transport, Unpolarized};
use whitted::Whitted;

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

/// Every integrator: what it supports, which the render's rules read
/// (`capabilities.rs`).
pub trait Integrator {
    const CAPABILITIES: Capabilities;
}

/// An integrator that returns a value per pixel sample (pbrt-v4's `RayIntegrator`):
/// whitted, path, lighttrace and bdpt. The engines call [`PixelIntegrator::sample`]
/// through a [`KernelFn`] chosen once per render for the lanes `N`, the kernel flags `K`
/// and the transport `T`.
pub(crate) trait PixelIntegrator: Integrator {
    /// One pixel sample along the camera ray `ray` at the wavelengths `wl`: its value
    /// for the pixel (radiance, or Stokes radiance), contributions to other pixels in
    /// `splats`. `first_hit` is the camera ray's closest hit when it was already traced
    /// (in an Embree packet); `None` traces it here.
    fn sample<const N: usize, const K: KernelFlags, T: Transport<N>>(
        ctx: &Context,
        ray: CameraRay,
        first_hit: Option<Option<Hit>>,
        wl: &SampledWavelengths<N>,
        sampler: &mut Sampler,
        counters: &mut TraceCounters,
        splats: &mut Splats,
    ) -> T::Value;
}

/// A pixel integrator whose camera paths the packet engine can advance step by step
/// (whitted, path): a path's state at the camera, and one step of it.
pub(crate) trait StepIntegrator: PixelIntegrator {
    fn start<const N: usize>(cam: &CameraRay) -> PathState<N>;

    /// One step of the path in state `s` whose ray `ray` has the closest hit `hit`;
    /// `ray` becomes the next ray. Returns false when the path has ended.
    fn step<const N: usize, const K: KernelFlags, S: ShadowSink<N>, T: Transport<N>>(
        t: &mut Tracer<N, S, T>,
        s: &mut PathState<N>,
        ray: &mut Ray,
        hit: Option<Hit>,
    ) -> bool;

    /// A whole pixel sample taken step by step, one path at a time with each shadow ray
    /// traced as it is made: [`PixelIntegrator::sample`] of a step integrator.
    #[inline(always)]
    fn sample_by_steps<const N: usize, const K: KernelFlags, T: Transport<N>>(
        ctx: &Context,
        cam: CameraRay,
        first_hit: Option<Option<Hit>>,
        wl: &SampledWavelengths<N>,
        sampler: &mut Sampler,
        counters: &mut TraceCounters,
    ) -> T::Value {
        let mut carry = T::at_camera(ctx, &cam);
        let mut s = Self::start::<N>(&cam);
        let mut t = Tracer {
            ctx,
            wl,
            sampler,
            counters,
            shadows: &mut Immediate,
            carry: &mut carry,
        };
        follow(
            &mut t,
            cam.ray,
            &mut s,
            first_hit,
            Self::step::<N, K, Immediate, T>,
        );
        T::delivered(carry, s.l)
    }
}

/// A progressive integrator, run as passes whose per-pixel state carries over from one
/// pass to the next (pbrt-v4's `SPPMIntegrator`, which overrides `Integrator::Render`):
/// photon mapping. The film keeps that state as its opaque integrator plane, so a
/// checkpoint resumes it.
pub trait PassIntegrator: Integrator {
    /// The name of the film's plane that keeps the per-pixel state, and its values per
    /// pixel.
    const PLANE: (&'static str, usize);

    /// The per-pixel state before the first pass, as that plane.
    fn initial_plane(pixels: usize) -> IntegratorPlane;

    /// Pass `k` from the per-pixel state `plane`, which it updates, on the current rayon
    /// pool. `cancelled` is polled as it goes: once it says so the pass returns early,
    /// and its result must be thrown away.
    fn pass<const N: usize>(
        ctx: &Context,
        plane: &mut IntegratorPlane,
        k: u32,
        cancelled: &(dyn Fn() -> bool + Sync),
    ) -> Pass<N>;
}

/// What one pass of a [`PassIntegrator`] gives the film.
pub struct Pass<const N: usize> {
    /// The wavelengths every sample of the pass carries.
    pub wl: SampledWavelengths<N>,
    /// Each pixel's own sample of the pass (row by row), for the film's sums.
    pub l: Vec<SampledSpectrum<N>>,
    /// What the pass adds to the film's splat planes, already in the film's fixed point
    /// (`film/fixed.rs`): XYZ per pixel, and the spectral bins.
    pub splat: Vec<i128>,
    pub splat_bins: Vec<i128>,
    /// Contributions to those planes left out as not finite or out of range.
    pub nonfinite: u64,
    pub counters: TraceCounters,
}

/// The declared capabilities of integrator `kind`.
pub fn capabilities(kind: IntegratorKind) -> Capabilities {
    match kind {
        IntegratorKind::Whitted => Whitted::CAPABILITIES,
        IntegratorKind::Path => PathTracer::CAPABILITIES,
        IntegratorKind::LightTrace => LightTracer::CAPABILITIES,
        IntegratorKind::Bdpt => Bidirectional::CAPABILITIES,
        IntegratorKind::Sppm => PhotonMapping::CAPABILITIES,
    }
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
/// [`stokes_flags`]); `None` for an integrator without polarised transport
/// (`capabilities::check_camera` refuses it first).
pub fn stokes_kernel<const N: usize>(kind: IntegratorKind, k: KernelFlags) -> Option<StokesFn<N>> {
    Some(match kind {
        IntegratorKind::Path if k & MEDIA != 0 => {
            PathTracer::sample::<N, { ALL & !SPECULAR }, Polarized>
        }
        IntegratorKind::Path => PathTracer::sample::<N, { ALL & !SPECULAR & !MEDIA }, Polarized>,
        IntegratorKind::Whitted => Whitted::sample::<N, { ALL & !MEDIA }, Polarized>,
        IntegratorKind::LightTrace => LightTracer::sample::<N, ALL, Polarized>,
        IntegratorKind::Bdpt => Bidirectional::sample::<N, ALL, Polarized>,
        IntegratorKind::Sppm => return None,
    })
}

/// One step of a path whose ray has the closest hit given, for the packet engine (see
/// `whitted::step`, `path::step`): the tracer's shadow rays are deferred to its
/// `Deferred`, which the engine traces with the packet's and resolves before the next
/// step.
pub(crate) type StepFn<const N: usize> = for<'t> fn(
    &mut Tracer<'t, N, Deferred<N>, Unpolarized>,
    &mut PathState<N>,
    &mut Ray,
    Option<Hit>,
) -> bool;

/// A path at the camera, ready for its first step along the camera ray.
pub type StartFn<const N: usize> = fn(&CameraRay) -> PathState<N>;

/// What the packet engine needs of an integrator: its start and its step, specialised
/// to the kernel flags as [`RadianceFn`]s are.
#[derive(Clone, Copy)]
pub(crate) struct PathFns<const N: usize> {
    pub start: StartFn<N>,
    pub step: StepFn<N>,
}

/// Every kernel of one integrator, indexed by its flags (`ALL` is 31), as radiance
/// functions or as packet-engine steps. The path tracer has no `SPECULAR` flag, so its
/// entries with that bit are the ones without it; the Whitted tracer has no `MEDIA`
/// flag (scenes with media are refused under it).
macro_rules! kernels {
    ($i:ident, $n:ident, $drop:expr) => {
        kernels!(@sample $i, $n, $drop; 0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15
            16 17 18 19 20 21 22 23 24 25 26 27 28 29 30 31)
    };
    ($i:ident, $n:ident, $drop:expr, step) => {
        kernels!(@step $i, $n, $drop; 0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15
            16 17 18 19 20 21 22 23 24 25 26 27 28 29 30 31)
    };
    (@sample $i:ident, $n:ident, $drop:expr; $($k:literal)*) => {
        [$($i::sample::<$n, { $k & !$drop }, Unpolarized> as RadianceFn<$n>),*]
    };
    (@step $i:ident, $n:ident, $drop:expr; $($k:literal)*) => {
        [$($i::step::<$n, { $k & !$drop }, Deferred<$n>, Unpolarized> as StepFn<$n>),*]
    };
}

/// The radiance function of integrator `kind` with `N` lanes, specialised to the kernel
/// flags `k` (from [`capabilities::choose_kernel`]). Light tracing and BDPT have one
/// kernel.
pub fn kernel<const N: usize>(kind: IntegratorKind, k: KernelFlags) -> RadianceFn<N> {
    let k = (k & ALL) as usize;
    match kind {
        IntegratorKind::Whitted => kernels!(Whitted, N, MEDIA)[k],
        IntegratorKind::Path => kernels!(PathTracer, N, SPECULAR)[k],
        IntegratorKind::LightTrace => LightTracer::sample::<N, ALL, Unpolarized>,
        IntegratorKind::Bdpt => Bidirectional::sample::<N, ALL, Unpolarized>,
        // Photon mapping runs in passes (`PassIntegrator`), not a function per pixel
        // sample; this entry, the general path tracer, is never called for it.
        IntegratorKind::Sppm => PathTracer::sample::<N, { ALL & !SPECULAR }, Unpolarized>,
    }
}

/// The start and step of integrator `kind` with `N` lanes and kernel flags `k`, for the
/// packet engine; `None` for an integrator without steps (`Capabilities::steps`).
pub(crate) fn path_fns<const N: usize>(kind: IntegratorKind, k: KernelFlags) -> Option<PathFns<N>> {
    let k = (k & ALL) as usize;
    match kind {
        IntegratorKind::Whitted => Some(PathFns {
            start: Whitted::start::<N>,
            step: kernels!(Whitted, N, MEDIA, step)[k],
        }),
        IntegratorKind::Path => Some(PathFns {
            start: PathTracer::start::<N>,
            step: kernels!(PathTracer, N, SPECULAR, step)[k],
        }),
        IntegratorKind::LightTrace | IntegratorKind::Bdpt | IntegratorKind::Sppm => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The packet engine's steps exist for exactly the integrators that declare them.
    #[test]
    fn declared_steps_match_the_step_functions() {
        for &name in IntegratorKind::NAMES {
            let kind = IntegratorKind::parse(name).unwrap();
            assert_eq!(
                capabilities(kind).steps,
                path_fns::<1>(kind, 0).is_some(),
                "{name}"
            );
            assert_eq!(
                capabilities(kind).polarization == Support::Yes,
                stokes_kernel::<1>(kind, 0).is_some(),
                "{name}"
            );
        }
    }
}
