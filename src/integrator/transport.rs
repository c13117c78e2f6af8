//! Unpolarised or polarised transport, as one type parameter of every integrator (the
//! role Mitsuba 3 gives its `Spectrum` type), and the [`Tracer`] that bundles what every
//! vertex of a camera path needs.
//!
//! Every integrator computes each contribution as a scalar per lane (throughput, BSDF or
//! phase value, MIS weight, transmittance, radiance) with the same sampling, MIS and
//! roulette whatever the transport, and hands it to its [`Transport`] with the event it
//! came through. [`Unpolarized`] adds it to the radiance; polarised transport
//! (`integrator::polarized::Polarized`) multiplies it by the path's normalised Mueller
//! product, or the light path's normalised Stokes vector, so both share the integrators
//! line for line. Each event's full Mueller matrix is its scalar weight times its matrix
//! divided by its [0][0] element (`bsdf::polarization`), which is why the two factor.
use super::bdpt::{Bdpt, Subpaths};
use super::toolkit::{next_hit, Immediate, PathState, Vertex};
use super::{Context, TraceCounters};
use crate::accel::embree::Hit;
use crate::bsdf::{LobeFlags, Material};
use crate::camera::CameraRay;
use crate::film::tile::SampleValue;
use crate::geometry::Ray;
use crate::math::Frame;
use crate::sampler::Sampler;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use glam::Vec3;

/// Where a path scatters and in which direction the light it carries arrives: the
/// event `v` (a surface or a point in a medium), `wi` in world space and, at a surface,
/// in the surface's frame (`wi_local`; in a medium the same as `wi`).
#[derive(Clone, Copy)]
pub(crate) struct Scatter<'v> {
    pub v: &'v Vertex<'v>,
    pub wi: Vec3,
    pub wi_local: Vec3,
}

impl<'v> Scatter<'v> {
    #[inline(always)]
    pub fn new(v: &'v Vertex<'v>, wi: Vec3, wi_local: Vec3) -> Self {
        Scatter { v, wi, wi_local }
    }
}

/// A surface event of a light path: the material and its frame, the direction the light
/// leaves along (`to_local`) and the one it came from (`from_local`), both local.
#[derive(Clone, Copy)]
pub(crate) struct LightEvent<'m> {
    pub material: &'m Material,
    pub frame: &'m Frame,
    pub to_local: Vec3,
    pub from_local: Vec3,
}

/// Unpolarised or polarised transport: what a camera path, a light path and a BDPT
/// sample carry besides their scalar throughputs, and what their contributions become.
/// Both implementations trace the same paths with the same random numbers.
pub(crate) trait Transport<const N: usize>: 'static {
    /// Whether contributions need their light one by one (the Whitted tracer sums its
    /// lights' before scaling them when they do not).
    const POLARIZED: bool;
    /// What a pixel sample or a connection carries: radiance or Stokes radiance.
    type Value: SampleValue<N>;
    /// A camera path's state besides its scalar throughput and radiance.
    type Camera;
    /// A light path's state besides its scalar throughput, on its current segment.
    type Light: Copy;
    /// BDPT's: what both subpaths carry, once traced.
    type Bdpt;

    /// A camera path's state at the camera ray `cam`.
    fn at_camera(ctx: &Context, cam: &CameraRay) -> Self::Camera;

    /// What the camera path delivers: `l` is the radiance its scalar contributions
    /// summed (the unpolarised value).
    fn delivered(cam: Self::Camera, l: SampledSpectrum<N>) -> Self::Value;

    /// The path reached light `light` along its ray `dir` (by BSDF or phase sampling, or
    /// escaping); `c` is the contribution.
    fn found(
        cam: &mut Self::Camera,
        ctx: &Context,
        l: &mut SampledSpectrum<N>,
        c: SampledSpectrum<N>,
        light: usize,
        dir: Vec3,
        wl: &SampledWavelengths<N>,
    );

    /// Light `light`, sampled along `at.wi` from the event `at.v`, scattered there
    /// toward the path's previous vertex; `c` is the contribution.
    fn lit(
        cam: &mut Self::Camera,
        ctx: &Context,
        l: &mut SampledSpectrum<N>,
        c: SampledSpectrum<N>,
        at: Scatter,
        light: usize,
        wl: &SampledWavelengths<N>,
    );

    /// The path continues from `at.v` along `at.wi` by a lobe of `flags` (empty in a
    /// medium).
    fn scattered(cam: &mut Self::Camera, at: Scatter, flags: LobeFlags, wl: &SampledWavelengths<N>);

    /// A light path leaving light `light` along the unit `d`.
    fn emitted(ctx: &Context, light: usize, d: Vec3, wl: &SampledWavelengths<N>) -> Self::Light;

    /// The light path scatters at a surface event `e` by a lobe of `flags`.
    fn light_scattered(
        b: &mut Self::Light,
        e: &LightEvent,
        flags: LobeFlags,
        wl: &SampledWavelengths<N>,
    );

    /// What the camera receives of a connection whose scalar value is `c`, the light
    /// travelling along the unit `d` to the camera: from the light itself (`at` None),
    /// or scattered toward it at the surface event `at` by the material's non-delta
    /// lobes.
    fn seen(
        b: &Self::Light,
        ctx: &Context,
        at: Option<&LightEvent>,
        d: Vec3,
        c: SampledSpectrum<N>,
        wl: &SampledWavelengths<N>,
    ) -> Self::Value;

    /// BDPT's state from the two subpaths, once traced; `dir` is the camera ray's
    /// direction.
    fn subpaths(b: &Bdpt<N>, paths: &Subpaths<N>, dir: Vec3) -> Self::Bdpt;

    /// The value of BDPT's strategy `st` = (s, t) whose scalar contribution is `c`, with
    /// the vertex `sampled` for it (s = 1: the light's; t = 1: the camera's).
    fn strategy(
        x: &Self::Bdpt,
        b: &Bdpt<N>,
        paths: &Subpaths<N>,
        st: (usize, usize),
        sampled: Option<&super::bdpt::Vertex<N>>,
        c: SampledSpectrum<N>,
    ) -> Self::Value;
}

/// What every vertex of a camera path needs besides the path's own state: the render's
/// context, the sample's wavelengths and sampler, the worker's counters, where shadow
/// rays go (`S`: traced at once, or deferred to the packet engine's packets) and the
/// transport's camera state.
pub(crate) struct Tracer<'t, const N: usize, S, T: Transport<N>> {
    pub ctx: &'t Context<'t>,
    pub wl: &'t SampledWavelengths<N>,
    pub sampler: &'t mut Sampler,
    pub counters: &'t mut TraceCounters,
    pub shadows: &'t mut S,
    pub carry: &'t mut T::Camera,
}

impl<const N: usize, S, T: Transport<N>> Tracer<'_, N, S, T> {
    /// [`Transport::found`].
    #[inline(always)]
    pub fn found(
        &mut self,
        l: &mut SampledSpectrum<N>,
        c: SampledSpectrum<N>,
        light: usize,
        dir: Vec3,
    ) {
        T::found(self.carry, self.ctx, l, c, light, dir, self.wl);
    }

    /// [`Transport::lit`].
    #[inline(always)]
    pub fn lit(
        &mut self,
        l: &mut SampledSpectrum<N>,
        c: SampledSpectrum<N>,
        at: Scatter,
        light: usize,
    ) {
        T::lit(self.carry, self.ctx, l, c, at, light, self.wl);
    }

    /// [`Transport::scattered`].
    #[inline(always)]
    pub fn scattered(&mut self, at: Scatter, flags: LobeFlags) {
        T::scattered(self.carry, at, flags, self.wl);
    }
}

/// The one-path-at-a-time loop: the path in state `s` takes `step` after step from the
/// ray `ray` (whose closest hit `first_hit` holds when already traced) until it ends.
#[inline(always)]
pub(crate) fn follow<const N: usize, T: Transport<N>>(
    t: &mut Tracer<N, Immediate, T>,
    mut ray: Ray,
    s: &mut PathState<N>,
    first_hit: Option<Option<Hit>>,
    step: impl Fn(&mut Tracer<N, Immediate, T>, &mut PathState<N>, &mut Ray, Option<Hit>) -> bool,
) {
    let mut pending = first_hit;
    loop {
        let hit = next_hit(t.ctx, &ray, &mut pending, t.counters);
        if !step(t, s, &mut ray, hit) {
            break;
        }
    }
}

/// Unpolarised transport: contributions are summed, events change nothing else.
#[derive(Clone, Copy)]
pub(crate) struct Unpolarized;

impl<const N: usize> Transport<N> for Unpolarized {
    const POLARIZED: bool = false;
    type Value = SampledSpectrum<N>;
    type Camera = ();
    type Light = ();
    type Bdpt = ();

    #[inline(always)]
    fn at_camera(_: &Context, _: &CameraRay) {}

    #[inline(always)]
    fn delivered(_: (), l: SampledSpectrum<N>) -> SampledSpectrum<N> {
        l
    }

    #[inline(always)]
    fn found(
        _: &mut (),
        _: &Context,
        l: &mut SampledSpectrum<N>,
        c: SampledSpectrum<N>,
        _: usize,
        _: Vec3,
        _: &SampledWavelengths<N>,
    ) {
        *l += c;
    }

    #[inline(always)]
    fn lit(
        _: &mut (),
        _: &Context,
        l: &mut SampledSpectrum<N>,
        c: SampledSpectrum<N>,
        _: Scatter,
        _: usize,
        _: &SampledWavelengths<N>,
    ) {
        *l += c;
    }

    #[inline(always)]
    fn scattered(_: &mut (), _: Scatter, _: LobeFlags, _: &SampledWavelengths<N>) {}

    #[inline(always)]
    fn emitted(_: &Context, _: usize, _: Vec3, _: &SampledWavelengths<N>) {}

    #[inline(always)]
    fn light_scattered(_: &mut (), _: &LightEvent, _: LobeFlags, _: &SampledWavelengths<N>) {}

    #[inline(always)]
    fn seen(
        _: &(),
        _: &Context,
        _: Option<&LightEvent>,
        _: Vec3,
        c: SampledSpectrum<N>,
        _: &SampledWavelengths<N>,
    ) -> SampledSpectrum<N> {
        c
    }

    #[inline(always)]
    fn subpaths(_: &Bdpt<N>, _: &Subpaths<N>, _: Vec3) {}

    #[inline(always)]
    fn strategy(
        _: &(),
        _: &Bdpt<N>,
        _: &Subpaths<N>,
        _: (usize, usize),
        _: Option<&super::bdpt::Vertex<N>>,
        c: SampledSpectrum<N>,
    ) -> SampledSpectrum<N> {
        c
    }
}
