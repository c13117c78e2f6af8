//! The packets-of-paths engine: 8 paths of a tile advance together, their rays and
//! shadow rays sent to Embree as 8-wide packets.
use super::*;

/// A path of the packet engine: its pixel sample (tile coordinates and sample index),
/// its state, the ray it traces next and its wavelengths.
pub(super) struct Lane<const N: usize> {
    pixel: (u32, u32, u32),
    state: PathState<N>,
    ray: Ray,
    wl: SampledWavelengths<N>,
    /// Whether `ray` is the camera ray (not yet traced).
    camera: bool,
}

/// One tile's samples of one pass with packets of paths (`Packets::Paths`): PACKET
/// paths advance together, their closest-hit rays go to Embree as one packet, then each
/// takes a step (integrator::StepFn), then their shadow rays go as packets (one per
/// round when a step has several, the seed's one per light) and what the unblocked ones
/// carry is added; a path that has ended gives its pixel its sample and its lane the
/// tile's next pixel sample, in the one-path-at-a-time engine's order. Every pixel
/// sample draws its own random numbers (start_pixel_sample), and the film's sums are
/// exact, so the image is the one-path-at-a-time engine's, up to the last bits of
/// Embree's packet kernels.
pub(super) fn render_tile_paths<const N: usize, const VARIANCE: bool>(
    ctx: &Context,
    opts: &RenderOptions,
    x0: u32,
    y0: u32,
    samples: std::ops::Range<u32>,
    fns: &integrator::PathFns<N>,
) -> TileResult {
    let cam = &ctx.scene.camera;
    let w = TILE.min(cam.width - x0);
    let h = TILE.min(cam.height - y0);
    let mut sums = TileSums::new(&layout(ctx.scene, opts), (x0, y0, w, h), PACKET as u32);
    let mut counters = TraceCounters::default();
    let base = Sampler::new(
        opts.settings.sampler,
        opts.settings.seed,
        cam.width,
        cam.height,
        opts.settings.spp,
    );
    let mut samplers: [Sampler; PACKET] = std::array::from_fn(|_| base.clone());
    let mut lanes: [Option<Lane<N>>; PACKET] = std::array::from_fn(|_| None);
    let mut shadows: [Deferred<N>; PACKET] = std::array::from_fn(|_| Deferred::default());
    let mut queries = [RayQuery {
        origin: cam.eye,
        dir: glam::Vec3::Z,
        tnear: 0.0,
        tfar: f32::INFINITY,
    }; PACKET];
    // Lane k takes the samples of the pixels in columns k, k + PACKET, … in the
    // one-path-at-a-time engine's order (rows, packets of PACKET pixels, samples), as
    // that engine's lane k does: a pixel's samples follow each other on one sampler,
    // whose per-pixel caches (sampler/sobol.rs) then serve them all.
    let ns = samples.len() as u32;
    let blocks = w.div_ceil(PACKET as u32);
    let mut next = [0u32; PACKET];
    let mut take = |k: usize| -> Option<(u32, u32, u32)> {
        let x = |n: u32| (n / ns % blocks) * PACKET as u32 + k as u32;
        // A lane past the tile's right edge has no pixels.
        while next[k] < h * blocks * ns && x(next[k]) >= w {
            next[k] += ns;
        }
        let n = next[k];
        if n >= h * blocks * ns {
            return None;
        }
        next[k] += 1;
        Some((x(n), n / (ns * blocks), samples.start + n % ns))
    };
    loop {
        if cancelled(opts) {
            break;
        }
        // Refill: every free lane takes the next pixel sample.
        let mut active = 0u8;
        for k in 0..PACKET {
            while lanes[k].is_none() {
                let Some((x, y, s)) = take(k) else { break };
                let (px, py) = (x0 + x, y0 + y);
                let sampler = &mut samplers[k];
                sampler.start_pixel_sample(px, py, s);
                let j = sampler.get_pixel_2d();
                let wl = SampledWavelengths::sample(opts.settings.wavelengths, sampler.get_1d());
                let u = || sampler.get_2d();
                match cam.ray(px as f32 + j.x, py as f32 + j.y, u, wl.lambda[0]) {
                    Some(c) => {
                        lanes[k] = Some(Lane {
                            pixel: (x, y, s),
                            state: (fns.start)(&c),
                            ray: c.ray,
                            wl,
                            camera: true,
                        })
                    }
                    // Stopped by the lens: the sample adds 0, and the lane takes the
                    // next one.
                    None => sums.add::<N, VARIANCE, SampledSpectrum<N>>(
                        (x, y, s),
                        &SampledSpectrum::zero(),
                        &wl,
                    ),
                }
            }
            if let Some(lane) = &lanes[k] {
                queries[k] = lane.ray.query();
                active |= 1 << k;
            }
        }
        if active == 0 {
            break;
        }
        counters.rays += active.count_ones() as u64;
        let hits = closest_hits(ctx, &mut lanes, &queries, active);
        let mut going = 0u8;
        let mut rounds = 0;
        for k in 0..PACKET {
            let Some(lane) = &mut lanes[k] else { continue };
            shadows[k].clear();
            let mut t = Tracer {
                ctx,
                wl: &lane.wl,
                sampler: &mut samplers[k],
                counters: &mut counters,
                shadows: &mut shadows[k],
                carry: &mut (),
            };
            if (fns.step)(&mut t, &mut lane.state, &mut lane.ray, hits[k]) {
                going |= 1 << k;
            }
            rounds = rounds.max(shadows[k].tests.len());
        }
        trace_shadows(ctx, &mut shadows, &mut queries, rounds, &mut counters);
        walk_shadows(ctx, &mut shadows, &lanes, &mut queries, &mut counters);
        for k in 0..PACKET {
            let Some(lane) = &mut lanes[k] else { continue };
            shadows[k].resolve(&mut lane.state.l);
            if going & (1 << k) == 0 {
                let l = lane.state.radiance();
                sums.add::<N, VARIANCE, SampledSpectrum<N>>(lane.pixel, &l, &lane.wl);
                lanes[k] = None;
                shadows[k].clear();
            }
        }
    }
    sums.result(
        Splats::default(),
        Vec::new(),
        (counters.rays, counters.shadow_rays),
    )
}

/// The closest hits of the live lanes' rays. Camera rays go as one coherent packet,
/// later rays as one incoherent packet: each ray's hint follows from the ray alone. (A
/// hint chosen by what a packet holds would make a ray's traversal, and so the last bits
/// of its hit, depend on its partners, which differ between a whole render and its
/// shards.) Under `whitted` most paths end at their first hit, so most rounds are all
/// camera rays.
#[inline(always)]
fn closest_hits<const N: usize>(
    ctx: &Context,
    lanes: &mut [Option<Lane<N>>; PACKET],
    queries: &[RayQuery; PACKET],
    active: u8,
) -> [Option<embree::Hit>; PACKET] {
    let mut fresh = 0u8;
    for (k, lane) in lanes.iter_mut().enumerate() {
        if let Some(lane) = lane {
            fresh |= (lane.camera as u8) << k;
            lane.camera = false;
        }
    }
    let mut hits = [None; PACKET];
    for (mask, hint) in [
        (fresh, RayCoherence::Coherent),
        (active & !fresh, RayCoherence::Incoherent),
    ] {
        if mask != 0 {
            let h = ctx.accel.intersect8_with(queries, mask, hint);
            for (k, h) in h.into_iter().enumerate() {
                if mask & (1 << k) != 0 {
                    hits[k] = h;
                }
            }
        }
    }
    hits
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
fn walk_shadows<const N: usize>(
    ctx: &Context,
    shadows: &mut [Deferred<N>; PACKET],
    lanes: &[Option<Lane<N>>; PACKET],
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
