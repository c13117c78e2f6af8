//! The tile engine: PACKET lanes take a tile's pixel samples, their rays go to Embree as
//! 8-wide packets, and each lane runs a [`Program`]: whole pixel samples of any pixel
//! integrator (`programs::Whole`), or the steps of a step integrator with its shadow
//! rays in packets too (`programs::Steps`, `--packets paths`).
use super::*;
use crate::camera::filter::Filter;

/// A lane's pixel sample: where it is (tile coordinates and sample index), its
/// wavelengths, the ray it traces next and what the program keeps of it.
pub(super) struct Lane<const N: usize, S> {
    pub pixel: (u32, u32, u32),
    pub wl: SampledWavelengths<N>,
    pub ray: Ray,
    /// Whether `ray` is the camera ray (not yet traced).
    pub camera: bool,
    /// The reconstruction filter's weight of the camera sample (1 for a box).
    pub weight: f32,
    pub state: S,
}

/// What the lanes of the tile engine run.
pub(super) trait Program<const N: usize> {
    /// What a pixel sample gives the film.
    type Value: SampleValue<N>;
    /// What a lane keeps of its pixel sample between rounds.
    type State;
    /// Whether the lanes take their pixel samples together, each round the same sample of
    /// a row of PACKET neighbouring pixels (whole samples, whose only packet is the camera
    /// rays), or each lane its next one as soon as it is free (paths of different
    /// lengths).
    const LOCKSTEP: bool;

    /// Whether each round's rays go to Embree as one packet before the lanes advance
    /// (otherwise a program traces its own rays).
    fn packets(&self) -> bool;

    /// A lane's state at its camera ray.
    fn begin(&self, cam: &CameraRay) -> Self::State;

    /// Lane `k` advances from its ray's closest hit (`None` when the round traced no
    /// packet); returns whether its path goes on. `VARIANCE` also keeps what the
    /// sample's squares need (`--variance`).
    fn advance<const VARIANCE: bool>(
        &mut self,
        ctx: &Context,
        k: usize,
        lane: &mut Lane<N, Self::State>,
        sampler: &mut Sampler,
        counters: &mut TraceCounters,
        hit: Option<Option<embree::Hit>>,
    ) -> bool;

    /// The round's deferred work, once every lane has advanced (the shadow rays'
    /// packets).
    fn settle(
        &mut self,
        ctx: &Context,
        lanes: &[Option<Lane<N, Self::State>>; PACKET],
        queries: &mut [RayQuery; PACKET],
        counters: &mut TraceCounters,
    );

    /// Lane `k`'s sample value, once its path has ended (`going` false).
    fn finish(
        &mut self,
        k: usize,
        lane: &mut Lane<N, Self::State>,
        going: bool,
    ) -> Option<Self::Value>;

    /// What the tile splatted, and its squares with `--variance`.
    fn into_splats(self) -> (Splats, Vec<(u32, [SquareSum; 3])>);
}

/// The order in which the lanes take a tile's pixel samples: lane k the samples of the
/// pixels in columns k, k + PACKET, … by rows, a pixel's samples one after the other on
/// one sampler, whose per-pixel caches (sampler/sobol.rs) then serve them all. Round n
/// is row n / (ns·blocks), block n / ns mod blocks, sample n mod ns.
struct Order {
    w: u32,
    blocks: u32,
    ns: u32,
    s0: u32,
    rounds: u32,
    next: [u32; PACKET],
}

impl Order {
    fn new(w: u32, h: u32, samples: std::ops::Range<u32>) -> Self {
        let ns = samples.len() as u32;
        let blocks = w.div_ceil(PACKET as u32);
        Order {
            w,
            blocks,
            ns,
            s0: samples.start,
            rounds: h * blocks * ns,
            next: [0; PACKET],
        }
    }

    /// Lane k's pixel sample in round n; `None` past the tile's right edge.
    #[inline(always)]
    fn at(&self, n: u32, k: usize) -> Option<(u32, u32, u32)> {
        let x = (n / self.ns % self.blocks) * PACKET as u32 + k as u32;
        (x < self.w).then_some((x, n / (self.ns * self.blocks), self.s0 + n % self.ns))
    }

    /// Lane k's next pixel sample; `None` once it has had all of its own.
    #[inline(always)]
    fn take(&mut self, k: usize) -> Option<(u32, u32, u32)> {
        while self.next[k] < self.rounds {
            let n = self.next[k];
            self.next[k] += 1;
            if let Some(p) = self.at(n, k) {
                return Some(p);
            }
        }
        None
    }
}

/// One tile's samples of one pass. Each round every free lane takes its next pixel
/// sample (its random numbers drawn by `start_pixel_sample`, so a sample's value does
/// not depend on its lane's neighbours), the live lanes' rays go to Embree as a packet,
/// every lane advances, the program settles what it deferred, and a lane whose path has
/// ended gives its pixel its sample. The film's sums are exact, so the order in which
/// samples end does not change them.
// Never inlined: scripts/callgrind_loop.sh counts the instructions inside it by name on
// the worker threads.
#[inline(never)]
pub(super) fn render_tile<const N: usize, const VARIANCE: bool, P: Program<N>>(
    ctx: &Context,
    opts: &RenderOptions,
    (x0, y0): (u32, u32),
    samples: std::ops::Range<u32>,
    mut program: P,
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
    let filter = Filter::new(&opts.settings.filter);
    let mut lanes: [Option<Lane<N, P::State>>; PACKET] = std::array::from_fn(|_| None);
    let mut queries = [RayQuery {
        origin: cam.eye,
        dir: glam::Vec3::Z,
        tnear: 0.0,
        tfar: f32::INFINITY,
    }; PACKET];
    let mut order = Order::new(w, h, samples);
    let mut round = 0;
    loop {
        if cancelled(opts) || (P::LOCKSTEP && round == order.rounds) {
            break;
        }
        let mut active = 0u8;
        for k in 0..PACKET {
            while lanes[k].is_none() {
                let next = if P::LOCKSTEP {
                    order.at(round, k)
                } else {
                    order.take(k)
                };
                let Some((x, y, s)) = next else { break };
                let (px, py) = (x0 + x, y0 + y);
                let sampler = &mut samplers[k];
                sampler.start_pixel_sample(px, py, s);
                let j = sampler.get_pixel_2d();
                let (fx, fy, weight) = filter.film_point(px, py, j);
                let wl = SampledWavelengths::sample(opts.settings.wavelengths, sampler.get_1d());
                let u = || sampler.get_2d();
                match cam.ray(fx, fy, u, wl.lambda[0]) {
                    Some(c) => {
                        lanes[k] = Some(Lane {
                            pixel: (x, y, s),
                            wl,
                            ray: c.ray,
                            camera: true,
                            weight,
                            state: program.begin(&c),
                        })
                    }
                    // Stopped by the lens: the sample adds 0, and the lane takes the
                    // next one (in lockstep, in the next round).
                    None => sums.add::<N, VARIANCE, P::Value>((x, y, s), &P::Value::zero(), &wl),
                }
                if P::LOCKSTEP {
                    break;
                }
            }
            if let Some(lane) = &lanes[k] {
                queries[k] = lane.ray.query();
                active |= 1 << k;
            }
        }
        round += 1;
        if active == 0 {
            if P::LOCKSTEP {
                continue;
            }
            break;
        }
        let hits = program.packets().then(|| {
            counters.rays += active.count_ones() as u64;
            closest_hits(ctx, &mut lanes, &queries, active)
        });
        let mut going = 0u8;
        for (k, lane) in lanes.iter_mut().enumerate() {
            let Some(lane) = lane else { continue };
            let hit = hits.as_ref().map(|h| h[k]);
            let sampler = &mut samplers[k];
            if program.advance::<VARIANCE>(ctx, k, lane, sampler, &mut counters, hit) {
                going |= 1 << k;
            }
        }
        program.settle(ctx, &lanes, &mut queries, &mut counters);
        for (k, slot) in lanes.iter_mut().enumerate() {
            let Some(lane) = slot else { continue };
            if let Some(mut l) = program.finish(k, lane, going & (1 << k) != 0) {
                // The filter's weight f/(p ∫f) (filter importance sampling); a box's is 1.
                if lane.weight != 1.0 {
                    l = l.scaled(lane.weight);
                }
                sums.add::<N, VARIANCE, P::Value>(lane.pixel, &l, &lane.wl);
                *slot = None;
            }
        }
    }
    let (splats, splat_sq) = program.into_splats();
    sums.result(splats, splat_sq, (counters.rays, counters.shadow_rays))
}

/// The closest hits of the live lanes' rays. Camera rays go as one coherent packet,
/// later rays as one incoherent packet: each ray's hint follows from the ray alone. (A
/// hint chosen by what a packet holds would make a ray's traversal, and so the last bits
/// of its hit, depend on its partners, which differ between a whole render and its
/// shards.) Under `whitted` most paths end at their first hit, so most rounds are all
/// camera rays.
#[inline(always)]
fn closest_hits<const N: usize, S>(
    ctx: &Context,
    lanes: &mut [Option<Lane<N, S>>; PACKET],
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
