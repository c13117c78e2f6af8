//! What the tile engine's lanes run: [`Whole`] pixel samples of any pixel integrator (one
//! path at a time, camera rays in packets with `--packets camera`), or the [`Steps`] of a
//! step integrator, whose rays and shadow rays all go to Embree as packets
//! (`--packets paths`).
use super::tile::{Lane, Program};
use super::*;

/// Whole pixel samples: one call of the integrator's `sample` per lane and round, which
/// traces everything after the camera ray itself; the lanes advance in lockstep so that
/// a round's camera rays are a row of neighbouring pixels.
pub(super) struct Whole<'f, const N: usize, O> {
    sample: &'f integrator::KernelFn<N, O>,
    packets: bool,
    splats: Splats,
    splat_sq: Vec<(u32, [SquareSum; 3])>,
    scratch: Vec<(u32, [f32; 3])>,
}

impl<'f, const N: usize, O> Whole<'f, N, O> {
    pub(super) fn new(
        ctx: &Context,
        opts: &RenderOptions,
        sample: &'f integrator::KernelFn<N, O>,
    ) -> Self {
        let cam = &ctx.scene.camera;
        Whole {
            sample,
            packets: opts.settings.packets.camera()
                && integrator::capabilities(opts.settings.integrator).camera_rays,
            splats: Splats::with_bins(
                cam.width * cam.height,
                (opts.settings.spectral_bins > 0).then_some(SpectralBins {
                    count: opts.settings.spectral_bins,
                }),
            ),
            splat_sq: Vec::new(),
            scratch: Vec::new(),
        }
    }
}

/// A whole sample's camera ray, then its value.
pub(super) struct WholeSample<O> {
    cam: CameraRay,
    value: O,
}

impl<const N: usize, O: SampleValue<N>> Program<N> for Whole<'_, N, O> {
    type Value = O;
    type State = WholeSample<O>;
    const LOCKSTEP: bool = true;

    #[inline(always)]
    fn packets(&self) -> bool {
        self.packets
    }

    #[inline(always)]
    fn begin(&self, cam: &CameraRay) -> WholeSample<O> {
        WholeSample {
            cam: *cam,
            value: O::zero(),
        }
    }

    #[inline(always)]
    fn advance<const VARIANCE: bool>(
        &mut self,
        ctx: &Context,
        _: usize,
        lane: &mut Lane<N, WholeSample<O>>,
        sampler: &mut Sampler,
        counters: &mut TraceCounters,
        hit: Option<Option<embree::Hit>>,
    ) -> bool {
        let splats_before = if VARIANCE { self.splats.list.len() } else { 0 };
        let s = &mut lane.state;
        s.value = (self.sample)(
            ctx,
            s.cam,
            hit,
            &lane.wl,
            sampler,
            counters,
            &mut self.splats,
        );
        if VARIANCE && self.splats.list.len() > splats_before {
            add_splat_squares(
                &self.splats.list[splats_before..],
                &mut self.scratch,
                &mut self.splat_sq,
            );
        }
        false
    }

    #[inline(always)]
    fn settle(
        &mut self,
        _: &Context,
        _: &[Option<Lane<N, WholeSample<O>>>; PACKET],
        _: &mut [RayQuery; PACKET],
        _: &mut TraceCounters,
    ) {
    }

    #[inline(always)]
    fn finish(&mut self, _: usize, lane: &mut Lane<N, WholeSample<O>>, _: bool) -> Option<O> {
        Some(lane.state.value)
    }

    fn into_splats(self) -> (Splats, Vec<(u32, [SquareSum; 3])>) {
        (self.splats, self.splat_sq)
    }
}

/// A step integrator's paths (whitted, path) advanced one step per round: each round's
/// closest-hit rays go as one packet, then each lane takes a step
/// (`integrator::StepFn`), then the steps' shadow rays go as packets (one per round
/// when a step has several, the seed's one per light) and what the unblocked ones carry
/// is added. Each pixel sample draws its own random numbers and the sums are exact, so
/// the image is the one-path-at-a-time [`Whole`]'s, up to the last bits of Embree's
/// packet kernels.
pub(super) struct Steps<'f, const N: usize> {
    fns: &'f integrator::PathFns<N>,
    shadows: [Deferred<N>; PACKET],
}

impl<'f, const N: usize> Steps<'f, N> {
    pub(super) fn new(fns: &'f integrator::PathFns<N>) -> Self {
        Steps {
            fns,
            shadows: std::array::from_fn(|_| Deferred::default()),
        }
    }
}

impl<const N: usize> Program<N> for Steps<'_, N> {
    type Value = SampledSpectrum<N>;
    type State = PathState<N>;
    const LOCKSTEP: bool = false;

    #[inline(always)]
    fn packets(&self) -> bool {
        true
    }

    #[inline(always)]
    fn begin(&self, cam: &CameraRay) -> PathState<N> {
        (self.fns.start)(cam)
    }

    #[inline(always)]
    fn advance<const VARIANCE: bool>(
        &mut self,
        ctx: &Context,
        k: usize,
        lane: &mut Lane<N, PathState<N>>,
        sampler: &mut Sampler,
        counters: &mut TraceCounters,
        hit: Option<Option<embree::Hit>>,
    ) -> bool {
        self.shadows[k].clear();
        let mut t = Tracer {
            ctx,
            wl: &lane.wl,
            sampler,
            counters,
            shadows: &mut self.shadows[k],
            carry: &mut (),
        };
        // This program's rounds always trace their packet (`packets`).
        let hit = hit.expect("the paths' rays are traced as packets");
        (self.fns.step)(&mut t, &mut lane.state, &mut lane.ray, hit)
    }

    #[inline(always)]
    fn settle(
        &mut self,
        ctx: &Context,
        lanes: &[Option<Lane<N, PathState<N>>>; PACKET],
        queries: &mut [RayQuery; PACKET],
        counters: &mut TraceCounters,
    ) {
        let rounds = self.shadows.iter().map(|s| s.tests.len()).max();
        trace_shadows(
            ctx,
            &mut self.shadows,
            queries,
            rounds.unwrap_or(0),
            counters,
        );
        walk_shadows(ctx, &mut self.shadows, lanes, queries, counters);
    }

    #[inline(always)]
    fn finish(
        &mut self,
        k: usize,
        lane: &mut Lane<N, PathState<N>>,
        going: bool,
    ) -> Option<SampledSpectrum<N>> {
        self.shadows[k].resolve(&mut lane.state.l);
        if going {
            return None;
        }
        self.shadows[k].clear();
        Some(lane.state.radiance())
    }

    fn into_splats(self) -> (Splats, Vec<(u32, [SquareSum; 3])>) {
        (Splats::default(), Vec::new())
    }
}

/// The steps' shadow rays, the r-th of every lane's in the r-th packet, for `rounds`
/// rounds.
#[inline(always)]
fn trace_shadows<const N: usize>(
    ctx: &Context,
    shadows: &mut [Deferred<N>; PACKET],
    queries: &mut [RayQuery; PACKET],
    rounds: usize,
    counters: &mut TraceCounters,
) {
    for r in 0..rounds {
        let mut mask = 0u8;
        for k in 0..PACKET {
            if let Some(q) = shadows[k].tests.get(r).and_then(|t| t.query) {
                queries[k] = q;
                mask |= 1 << k;
            }
        }
        if mask == 0 {
            continue;
        }
        counters.shadow_rays += mask.count_ones() as u64;
        let blocked = ctx
            .accel
            .occluded8_with(queries, mask, RayCoherence::Incoherent);
        for (k, sh) in shadows.iter_mut().enumerate() {
            if mask & (1 << k) != 0 {
                sh.tests[r].blocked = blocked & (1 << k) != 0;
            }
        }
    }
}

/// Shadow rays through media walk boundary by boundary: one closest-hit packet per
/// crossing, until every lane's walk has ended; a lane's first walk before its second,
/// so contributions add in the order they were made.
#[inline(always)]
fn walk_shadows<const N: usize, S>(
    ctx: &Context,
    shadows: &mut [Deferred<N>; PACKET],
    lanes: &[Option<Lane<N, S>>; PACKET],
    queries: &mut [RayQuery; PACKET],
    counters: &mut TraceCounters,
) {
    for slot in 0..WALKS {
        loop {
            let mut mask = 0u8;
            for (k, sh) in shadows.iter().enumerate() {
                if let Some((w, _)) = &sh.walks[slot] {
                    queries[k] = w.q;
                    mask |= 1 << k;
                }
            }
            if mask == 0 {
                break;
            }
            counters.shadow_rays += mask.count_ones() as u64;
            let hits = ctx
                .accel
                .intersect8_with(queries, mask, RayCoherence::Incoherent);
            for (k, sh) in shadows.iter_mut().enumerate() {
                if mask & (1 << k) != 0 {
                    let wl = &lanes[k].as_ref().expect("a walking lane is live").wl;
                    sh.advance_walk(ctx, slot, hits[k], wl);
                }
            }
        }
    }
}
