//! The pass loop: every tile of the image on rayon, pass by pass, each tile by the tile
//! engine (`tile.rs`) running the render's program (`programs.rs`: whole pixel samples,
//! or the steps of packets of paths); the film's state a render starts from and when it
//! checkpoints, previews or stops.
use super::programs::{Steps, Whole};
use super::tile::render_tile;
use super::*;

/// One tile's samples of one pass by the tile engine, with the program `f` names. Two
/// instances of the engine per program, so that a render without the variance runs the
/// loop it ran before the variance existed.
fn run_tile<const N: usize>(
    ctx: &Context,
    opts: &RenderOptions,
    xy: (u32, u32),
    samples: std::ops::Range<u32>,
    f: &TileFn<N>,
) -> TileResult {
    match (f, opts.variance) {
        (TileFn::Radiance(f), false) => {
            render_tile::<N, false, _>(ctx, opts, xy, samples, Whole::new(ctx, opts, f))
        }
        (TileFn::Radiance(f), true) => {
            render_tile::<N, true, _>(ctx, opts, xy, samples, Whole::new(ctx, opts, f))
        }
        (TileFn::Stokes(f), false) => {
            render_tile::<N, false, _>(ctx, opts, xy, samples, Whole::new(ctx, opts, f))
        }
        (TileFn::Stokes(f), true) => {
            render_tile::<N, true, _>(ctx, opts, xy, samples, Whole::new(ctx, opts, f))
        }
        (TileFn::Steps(f), false) => {
            render_tile::<N, false, _>(ctx, opts, xy, samples, Steps::new(f))
        }
        (TileFn::Steps(f), true) => {
            render_tile::<N, true, _>(ctx, opts, xy, samples, Steps::new(f))
        }
    }
}

/// Renders `spp` samples per pixel (or the shard's share of them) in passes of
/// `pass_spp` samples; returns the film's unnormalised state. Pass boundaries are where
/// a render may checkpoint or stop, and they bound the splat lists kept per tile; the
/// sums are exact (`film/fixed.rs`), so passes, shards and threads do not change them.
// Never inlined: scripts/callgrind_loop.sh counts the instructions inside it by name.
#[inline(never)]
pub(super) fn render_passes(
    ctx: &Context,
    pool: &rayon::ThreadPool,
    opts: &RenderOptions,
    pass_spp: u32,
    integrate: &(dyn Fn(Lanes) -> SampleFn + Sync),
) -> Result<(Checkpoint, RenderStats)> {
    if opts.settings.spp == 0 {
        return Err(HeronError::Invalid("spp must be at least 1".into()));
    }
    let sample = integrate(opts.settings.lanes);
    let scene = ctx.scene;
    let cam = &scene.camera;
    let (tw, th) = (cam.width.div_ceil(TILE), cam.height.div_ceil(TILE));
    let tiles: Vec<(u32, u32)> = (0..th)
        .flat_map(|ty| (0..tw).map(move |tx| (tx * TILE, ty * TILE)))
        .collect();
    let pass_spp = pass_spp.clamp(1, opts.settings.spp);
    let range = opts
        .shard
        .map_or(0..opts.settings.spp, |s| s.samples(opts.settings.spp));
    let passes: Vec<(u32, u32)> = range
        .clone()
        .step_by(pass_spp as usize)
        .map(|s0| (s0, (s0 + pass_spp).min(range.end)))
        .collect();
    let n_work = tiles.len() as u64 * passes.len() as u64;
    let done = std::sync::atomic::AtomicU64::new(0);
    // Unnormalised sums over the whole render: XYZ and bins per pixel, finite samples per
    // pixel, and splatted XYZ.
    let key = settings_key(ctx.scene, opts, pass_spp);
    let mut state = initial_state(ctx.scene, opts, key, passes.len(), None)?;
    let mut stats = RenderStats {
        resumed_from: opts.resume.as_ref().map(|c| c.film.spp_done),
        ..Default::default()
    };
    let first_pass = state.film.passes_done as usize;
    let (rays0, shadow0) = (state.film.rays, state.film.shadow_rays);
    done.store(
        first_pass as u64 * tiles.len() as u64,
        std::sync::atomic::Ordering::Relaxed,
    );
    let mut clock = PassClock::new();
    let start = clock.start;
    for &(s0, s1) in &passes[first_pass..] {
        let results: Vec<TileResult> = pool.install(|| {
            tiles
                .par_iter()
                .map(|&(x0, y0)| {
                    let r = match &sample {
                        SampleFn::One(f) => run_tile(ctx, opts, (x0, y0), s0..s1, f),
                        SampleFn::Four(f) => run_tile(ctx, opts, (x0, y0), s0..s1, f),
                        SampleFn::Eight(f) => run_tile(ctx, opts, (x0, y0), s0..s1, f),
                    };
                    let k = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                    if let Some(p) = &opts.progress {
                        p(k, n_work);
                    }
                    r
                })
                .collect()
        });
        if opts
            .cancel
            .as_ref()
            .is_some_and(|c| c.load(std::sync::atomic::Ordering::Relaxed))
        {
            return Err(HeronError::Cancelled);
        }
        for t in results {
            let first = state.film.add_tile(t);
            stats.first_nonfinite = stats.first_nonfinite.or(first);
        }
        state.film.passes_done += 1;
        state.film.spp_done = s1 - range.start;
        if clock.end_pass(opts, &state, s1 == range.end)? {
            stats.stopped = true;
            break;
        }
    }
    stats.finish(&state.film, start, (rays0, shadow0));
    Ok((state, stats))
}

impl RenderStats {
    /// The statistics of a render that ended with `state`, started at `start` from a
    /// state that had traced `before` (camera and shadow rays).
    pub(super) fn finish(&mut self, state: &FilmState, start: Instant, before: (u64, u64)) {
        self.wall = start.elapsed();
        self.spp = state.spp_done;
        self.samples = state.layout.pixels() as u64 * state.spp_done as u64;
        // This process's rays (a resumed render's earlier ones are in the checkpoint).
        self.counters.rays = state.rays - before.0;
        self.counters.shadow_rays = state.shadow_rays - before.1;
        self.nonfinite = state.nonfinite;
    }
}

/// The film's state a render starts from: the checkpoint `opts` resumes, checked against
/// this render (its settings `key`, its film's planes, at most `passes` passes and the
/// integrator's own plane: its name and values per pixel, and its initial state), or an
/// empty film.
pub(super) fn initial_state(
    scene: &Scene,
    opts: &RenderOptions,
    key: FilmKey,
    passes: usize,
    plane: Option<OwnPlane>,
) -> Result<Checkpoint> {
    let layout = layout(scene, opts);
    match &opts.resume {
        Some(c) => c.resume(
            &key,
            opts.shard,
            &layout,
            passes,
            plane.map(|p| (p.name, p.per_pixel)),
        ),
        None => {
            let mut film = FilmState::new(layout);
            film.integrator = plane.map(|p| (p.initial)(layout.pixels()));
            Ok(Checkpoint {
                key,
                shard: opts.shard,
                xyz_channels: false,
                film,
            })
        }
    }
}

/// A progressive integrator's own plane of the film (`PassIntegrator::PLANE`): its name,
/// its values per pixel and its state before the first pass.
#[derive(Clone, Copy)]
pub(super) struct OwnPlane {
    pub name: &'static str,
    pub per_pixel: usize,
    pub initial: fn(usize) -> IntegratorPlane,
}

/// When a render last wrote a checkpoint and a preview, for the decisions at the end
/// of each pass.
pub(super) struct PassClock {
    pub(super) start: Instant,
    last_checkpoint: Instant,
    last_preview: Instant,
}

impl PassClock {
    pub(super) fn new() -> PassClock {
        let now = Instant::now();
        PassClock {
            start: now,
            last_checkpoint: now,
            last_preview: now,
        }
    }

    /// At the end of a pass (`last`: the render's last): writes the checkpoint when one
    /// is due or the render stops here, calls the preview when due; returns true when the
    /// render stops before its last pass (a time limit, SIGINT).
    pub(super) fn end_pass(
        &mut self,
        opts: &RenderOptions,
        state: &Checkpoint,
        last: bool,
    ) -> Result<bool> {
        let stop = opts
            .stop
            .as_ref()
            .is_some_and(|f| f.load(std::sync::atomic::Ordering::Relaxed))
            || opts.time_limit.is_some_and(|t| self.start.elapsed() >= t);
        if let Some((path, every)) = &opts.checkpoint {
            if !last && (stop || self.last_checkpoint.elapsed() >= *every) {
                state.write(path)?;
                self.last_checkpoint = Instant::now();
            }
        }
        if stop && !last {
            return Ok(true);
        }
        if let Some((every, preview)) = &opts.preview {
            if !last && self.last_preview.elapsed() >= *every {
                preview(state);
                self.last_preview = Instant::now();
            }
        }
        Ok(false)
    }
}
