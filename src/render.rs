//! Rendering: tiles on rayon, camera rays traced as Embree 8-wide packets, the chosen
//! integrator per pixel sample, splats from anywhere in the image, and deterministic
//! seeding.
//!
//! Determinism: every (pixel, sample) has its own random numbers (the sampler depends
//! only on seed, pixel and sample index), each pixel's samples are summed in sample
//! order by the one worker that owns its tile, and tiles are gathered in tile order.
//! Splats (contributions an integrator makes to other pixels than its own) are kept in
//! a list per tile, in the order they were made, and added to the film tile by tile in
//! tile order, pass by pass. So the image is bit-identical whatever the thread count.
use crate::accel::embree::{self, RayCoherence, RayQuery};
use crate::camera::CameraRay;
use crate::checkpoint::{Checkpoint, FilmKey, Shard};
use crate::film::planes::Layout;
use crate::film::state::FilmState;
use crate::film::tile::{SampleValue, TileResult, TileSums};
use crate::film::{add_splat_squares, Film, SpectralBins, Splats};
use crate::geometry::{Ray, ShapeKind};
use crate::integrator::sppm::SppmPixels;
use crate::integrator::{self, Context, Deferred, PathState, TraceCounters, WALKS};
use crate::sampler::Sampler;
use crate::scene::{Features, Scene};
use crate::settings::{IntegratorKind, KernelFlags, Packets, RenderSettings};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::{HeronError, Result};
use rayon::prelude::*;
use std::time::{Duration, Instant};

/// Square tile edge in pixels; a multiple of the packet width.
const TILE: u32 = 16;
const PACKET: usize = 8;

/// A render: its settings (everything that decides the pixels) and how it runs.
#[derive(Clone)]
pub struct RenderOptions {
    /// The scene's settings with the flags or keyword arguments applied.
    pub settings: RenderSettings,
    /// Worker threads; 0 means one per core.
    pub threads: usize,
    /// Write the film's state to this file after a pass when this long has passed since
    /// the last write (zero: after every pass).
    pub checkpoint: Option<(std::path::PathBuf, Duration)>,
    /// Continue from this checkpoint (made with the same settings).
    pub resume: Option<std::sync::Arc<Checkpoint>>,
    /// Render only this shard's share of the sample indices (`Shard::samples`).
    pub shard: Option<Shard>,
    /// Stop at the first pass boundary after this long.
    pub time_limit: Option<Duration>,
    /// Stop at the next pass boundary once this is set (SIGINT).
    pub stop: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
    /// Abandon the render within a row of a tile once this is set (Ctrl-C in Python):
    /// the render returns [`HeronError::Cancelled`] and no image.
    pub cancel: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
    /// Called after each finished tile with (tiles done, tiles in all).
    pub progress: Option<std::sync::Arc<dyn Fn(u64, u64) + Send + Sync>>,
    /// Also sum the squares of each pixel's contributions, for the variance of each
    /// pixel's value (`heron render --variance`); off, the render does no extra work.
    pub variance: bool,
    /// The progress image: called with the film's state so far after a pass (not the
    /// last) once this long has passed since the render started or since the last call
    /// (zero: after every pass). It only reads the state, so the image is unchanged.
    pub preview: Option<(Duration, PreviewFn)>,
}

/// What [`RenderOptions::preview`] calls (`--preview-every` rewrites the PNG with it).
pub type PreviewFn = std::sync::Arc<dyn Fn(&Checkpoint) + Send + Sync>;

impl RenderOptions {
    /// A render of `scene` with its own settings, on every core, with no checkpoints.
    pub fn from_scene(scene: &Scene) -> Self {
        RenderOptions {
            settings: scene.settings.clone(),
            threads: 0,
            checkpoint: None,
            resume: None,
            shard: None,
            time_limit: None,
            stop: None,
            cancel: None,
            progress: None,
            variance: false,
            preview: None,
        }
    }
}

#[derive(Clone, Debug, Default)]
pub struct RenderStats {
    pub wall: Duration,
    pub counters: TraceCounters,
    /// Samples whose radiance was NaN or infinite; they are left out of the image and
    /// counted here.
    pub nonfinite: u64,
    /// Where this process met its first non-finite sample, in render order (pass, tile,
    /// row, packet, sample, lane): (x, y, sample index).
    pub first_nonfinite: Option<(u32, u32, u32)>,
    pub samples: u64,
    /// The kernel that ran ([`crate::scene::features::flag_names`] names it).
    pub kernel: KernelFlags,
    /// Samples per pixel in the image: the requested spp, or fewer when the render was
    /// stopped (time limit, SIGINT) at a pass boundary.
    pub spp: u32,
    /// Whether the render stopped before all its samples.
    pub stopped: bool,
    /// The samples per pixel a resumed render started from.
    pub resumed_from: Option<u32>,
}

impl RenderStats {
    pub fn total_rays(&self) -> u64 {
        self.counters.rays + self.counters.shadow_rays
    }
    pub fn mrays_per_s(&self) -> f64 {
        self.total_rays() as f64 / self.wall.as_secs_f64().max(1e-9) / 1e6
    }
}

/// Builds the Embree scene: shape i becomes geometry i.
pub fn build_accel(scene: &Scene, device: &embree::Device) -> Result<embree::Scene> {
    // Embree drops primitives with coordinates beyond about 1.8e18; say so in the
    // scene's own terms rather than let the build fail deep inside Embree.
    const LIMIT: f32 = 1e18;
    for (i, shape) in scene.shapes.iter().enumerate() {
        let too_far = match &shape.kind {
            ShapeKind::Sphere { center, radius } => center.abs().max_element() + radius > LIMIT,
            ShapeKind::Mesh(m) => m.positions.iter().any(|p| p.abs().max_element() > LIMIT),
        };
        if too_far {
            return Err(HeronError::Scene {
                file: scene.source.clone(),
                message: format!(
                    "shape {i} ({}): expected coordinates within ±1e18 (Embree's limit)",
                    scene.material_names[shape.material as usize]
                ),
            });
        }
    }
    let mut b = device.scene_builder();
    for (i, shape) in scene.shapes.iter().enumerate() {
        let id = match &shape.kind {
            ShapeKind::Sphere { center, radius } => b.add_sphere(*center, *radius)?,
            ShapeKind::Mesh(m) => b.add_triangle_mesh(&m.positions, &m.indices)?,
        };
        if id as usize != i {
            return Err(HeronError::Invalid(format!(
                "embree assigned geometry id {id} to shape {i}"
            )));
        }
    }
    Ok(b.commit()?)
}

/// A scene ready to trace: the Embree device and committed scene, built once and
/// reused across renders (benchmarks, progressive runs).
pub struct Renderer<'s> {
    scene: &'s Scene,
    accel: embree::Scene,
    /// The worker pool of the last render and its thread count, reused while the count
    /// stays the same.
    pool: std::sync::Mutex<Option<(usize, std::sync::Arc<rayon::ThreadPool>)>>,
    // Kept alive for as long as the committed scene.
    _device: embree::Device,
}

impl<'s> Renderer<'s> {
    /// Builds the Embree scene with Embree's own threads (one per core).
    pub fn new(scene: &'s Scene) -> Result<Self> {
        Self::with_threads(scene, 0)
    }

    /// Builds the Embree scene; `threads` > 0 limits Embree's build threads too.
    pub fn with_threads(scene: &'s Scene, threads: usize) -> Result<Self> {
        let config = if threads > 0 {
            format!("threads={threads}")
        } else {
            String::new()
        };
        let device = embree::Device::new(&config)?;
        let accel = build_accel(scene, &device)?;
        Ok(Renderer {
            scene,
            accel,
            pool: std::sync::Mutex::new(None),
            _device: device,
        })
    }

    pub fn accel(&self) -> &embree::Scene {
        &self.accel
    }

    /// Renders the image; returns the film and statistics.
    pub fn render(&self, opts: &RenderOptions) -> Result<(Film, RenderStats)> {
        let (state, stats) = self.render_state(opts)?;
        Ok((state.film.image(), stats))
    }

    /// Renders and returns the film's unnormalised state (sums and counts), which a
    /// shard writes to its film file.
    pub fn render_state(&self, opts: &RenderOptions) -> Result<(Checkpoint, RenderStats)> {
        let pool = {
            let mut cached = self.pool.lock().unwrap_or_else(|e| e.into_inner());
            match &*cached {
                Some((t, p)) if *t == opts.threads => p.clone(),
                _ => {
                    let p = std::sync::Arc::new(embree::worker_pool(opts.threads)?);
                    *cached = Some((opts.threads, p.clone()));
                    p
                }
            }
        };
        render_with(self.scene, &self.accel, &pool, opts)
    }
}

/// Renders `scene`; returns the film and statistics.
pub fn render(scene: &Scene, opts: &RenderOptions) -> Result<(Film, RenderStats)> {
    Renderer::with_threads(scene, opts.threads)?.render(opts)
}

/// Renders `scene`; returns the film's unnormalised state and statistics.
pub fn render_state(scene: &Scene, opts: &RenderOptions) -> Result<(Checkpoint, RenderStats)> {
    Renderer::with_threads(scene, opts.threads)?.render_state(opts)
}

fn render_with(
    scene: &Scene,
    accel: &embree::Scene,
    pool: &rayon::ThreadPool,
    opts: &RenderOptions,
) -> Result<(Checkpoint, RenderStats)> {
    let kind = opts.settings.integrator;
    if scene.camera.lens.is_some()
        && matches!(kind, IntegratorKind::LightTrace | IntegratorKind::Bdpt)
    {
        return Err(HeronError::Invalid(format!(
            "integrator {}: the lens camera (camera.type = \"lens\") has no importance function We and no connection to the film yet, which light tracing and BDPT need to reach the camera from the lights; use integrator = \"path\" or \"whitted\"",
            kind.name()
        )));
    }
    if !opts.settings.polarization {
        let which = if opts.settings.polarizer.is_some() {
            Some("--polarizer")
        } else if scene.camera.polarizer.is_some() {
            Some("camera.polarizer")
        } else {
            None
        };
        if let Some(w) = which {
            return Err(HeronError::Invalid(format!(
                "{w}: an analyser needs polarised transport; set [render] polarization = true or pass --polarization"
            )));
        }
    }
    if opts.settings.polarization {
        integrator::stokes_kernel::<1>(kind, 0).map_err(HeronError::Invalid)?;
        // The sky's polarisation is tabulated here, before the workers start.
        if let Some(sky) = &scene.sky {
            sky.linear_table();
        }
    }
    let ctx = Context {
        scene,
        accel,
        settings: &opts.settings,
        offset: opts.settings.ray_offset(kind),
    };
    // The kernel is decided here, once per render, from what the scene uses.
    let k = Features::of(scene)
        .choose(kind, opts.settings.kernel)
        .map_err(HeronError::Invalid)?;
    // Polarised transport has two kernels: with media and without.
    let k = if opts.settings.polarization {
        integrator::stokes_flags(kind, k)
    } else {
        k
    };
    if kind == IntegratorKind::Sppm {
        // Rays one at a time: the camera pass follows specular chains and the photons
        // scatter from wherever the lights put them, so neither has packets.
        let mut opts = opts.clone();
        opts.settings.packets = Packets::Off;
        let (state, mut stats) = match opts.settings.lanes {
            1 => render_sppm::<1>(&ctx, pool, &opts),
            4 => render_sppm::<4>(&ctx, pool, &opts),
            8 => render_sppm::<8>(&ctx, pool, &opts),
            n => Err(HeronError::Invalid(format!(
                "lanes: expected 1, 4 or 8, got {n}"
            ))),
        }?;
        stats.kernel = k;
        return Ok((state, stats));
    }
    let mut opts = opts.clone();
    // `auto` resolved: the provenance records what ran (light tracing has no camera
    // rays, so no camera packets).
    opts.settings.packets = match (kind, opts.settings.packets) {
        (IntegratorKind::Whitted, Packets::Auto) => Packets::Paths,
        (IntegratorKind::LightTrace, Packets::Paths) => Packets::Paths,
        (IntegratorKind::LightTrace, _) => Packets::Off,
        (_, Packets::Auto) => Packets::Camera,
        (_, p) => p,
    };
    // Light tracing and BDPT have no steps: with `paths`, each pixel sample sends its
    // connections' shadow rays 8 at a time (toolkit `Connections`).
    if opts.settings.polarization
        && opts.settings.packets == Packets::Paths
        && integrator::path_fns::<1>(kind, 0).is_some()
    {
        // The packet engine's steps carry scalar throughputs: camera packets only (light
        // tracing's and BDPT's connections carry Stokes vectors in their packets).
        opts.settings.packets = Packets::Camera;
    }
    let paths =
        opts.settings.packets == Packets::Paths && integrator::path_fns::<1>(kind, 0).is_some();
    let polarized = opts.settings.polarization;
    let integrate = move |n: Lanes| -> SampleFn {
        if polarized {
            // Checked above: the integrator has a polarised kernel.
            const WHY: &str = "a polarised kernel";
            return match n {
                Lanes::One => {
                    SampleFn::StokesOne(integrator::stokes_kernel::<1>(kind, k).expect(WHY))
                }
                Lanes::Four => {
                    SampleFn::StokesFour(integrator::stokes_kernel::<4>(kind, k).expect(WHY))
                }
                Lanes::Eight => {
                    SampleFn::StokesEight(integrator::stokes_kernel::<8>(kind, k).expect(WHY))
                }
            };
        }
        let p = |f1, f4, f8| match n {
            Lanes::One => f1,
            Lanes::Four => f4,
            Lanes::Eight => f8,
        };
        match (paths, n) {
            (true, _) => p(
                integrator::path_fns::<1>(kind, k).map(SampleFn::PathsOne),
                integrator::path_fns::<4>(kind, k).map(SampleFn::PathsFour),
                integrator::path_fns::<8>(kind, k).map(SampleFn::PathsEight),
            )
            .expect("an integrator with a step"),
            (false, Lanes::One) => SampleFn::One(integrator::kernel::<1>(kind, k)),
            (false, Lanes::Four) => SampleFn::Four(integrator::kernel::<4>(kind, k)),
            (false, Lanes::Eight) => SampleFn::Eight(integrator::kernel::<8>(kind, k)),
        }
    };
    // Every render can stop, checkpoint or resume at a pass boundary. A splatting
    // integrator keeps its splats per tile for one pass: passes of about 2²⁰ pixel
    // samples bound that memory (tens of MB), and since splats are summed pass by pass,
    // their pass size is fixed by the image size alone. Other integrators' pixels
    // accumulate in sample order across passes, so their pass size does not change the
    // image; it is 2²² pixel samples, because each pass starts new samplers (whose cached
    // Sobol' digits then serve fewer samples) and waits for its slowest tile: at 2²⁰ a
    // 512² Whitted render was 3-5% slower than in one pass.
    let npix = (scene.camera.width * scene.camera.height).max(1);
    let pass = if kind.splats() {
        ((1u32 << 20) / npix).max(1)
    } else {
        ((1u32 << 22) / npix).max(1)
    };
    let (state, mut stats) = render_passes(&ctx, pool, &opts, pass, &integrate)?;
    stats.kernel = k;
    Ok((state, stats))
}

/// The settings that determine a render's image, which a checkpoint must match to be
/// resumed: the provenance (scene and input hashes, integrator, sampler, spp, seed,
/// lanes, wavelengths, depth, packets, bins), the image size and the pass size.
fn settings_key(scene: &Scene, opts: &RenderOptions, pass_spp: u32) -> FilmKey {
    let spp = opts.settings.spp;
    FilmKey::new(
        &crate::provenance::Provenance::of_render(scene, &opts.settings, spp),
        spp,
        (scene.camera.width, scene.camera.height),
        pass_spp,
        opts.variance,
    )
}

/// The planes of a render's film.
fn layout(scene: &Scene, opts: &RenderOptions) -> Layout {
    Layout {
        width: scene.camera.width,
        height: scene.camera.height,
        bins: opts.settings.spectral_bins,
        splats: kind_splats(opts),
        variance: opts.variance,
        stokes: opts.settings.polarization,
    }
}

/// Whether the render's integrator splats (so that splat buffers are needed).
fn kind_splats(opts: &RenderOptions) -> bool {
    opts.settings.integrator.splats()
}

/// The lane counts a render can use, chosen once per render.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Lanes {
    One,
    Four,
    Eight,
}

/// The per-sample function of a render, one per lane count (see
/// [`integrator::kernel`]): one indirect call per pixel sample.
pub(crate) type SampleFnN<const N: usize> = integrator::RadianceFn<N>;

pub(crate) enum SampleFn {
    One(SampleFnN<1>),
    Four(SampleFnN<4>),
    Eight(SampleFnN<8>),
    /// The packet engine's (`Packets::Paths`).
    PathsOne(integrator::PathFns<1>),
    PathsFour(integrator::PathFns<4>),
    PathsEight(integrator::PathFns<8>),
    /// Polarised transport's (`integrator::polarized`).
    StokesOne(integrator::StokesFn<1>),
    StokesFour(integrator::StokesFn<4>),
    StokesEight(integrator::StokesFn<8>),
}

/// Renders `spp` samples per pixel (or the shard's share of them) in passes of
/// `pass_spp` samples; returns the film's unnormalised state. Pass boundaries are where
/// a render may checkpoint or stop, and they bound the splat lists kept per tile; the
/// sums are exact (`film/fixed.rs`), so passes, shards and threads do not change them.
pub(crate) fn render_passes(
    ctx: &Context,
    pool: &rayon::ThreadPool,
    opts: &RenderOptions,
    pass_spp: u32,
    integrate: &(dyn Fn(Lanes) -> SampleFn + Sync),
) -> Result<(Checkpoint, RenderStats)> {
    if opts.settings.spp == 0 {
        return Err(HeronError::Invalid("spp must be at least 1".into()));
    }
    let lanes = match opts.settings.lanes {
        1 => Lanes::One,
        4 => Lanes::Four,
        8 => Lanes::Eight,
        n => {
            return Err(HeronError::Invalid(format!(
                "lanes: expected 1, 4 or 8, got {n}"
            )))
        }
    };
    let sample = integrate(lanes);
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
    let mut state = initial_state(ctx.scene, opts, key, passes.len())?;
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
                    // Two instances of the tile loop, so that a render without the
                    // variance runs the loop it ran before the variance existed.
                    let r = match (&sample, opts.variance) {
                        (SampleFn::One(f), false) => {
                            render_tile::<1, false, _>(ctx, opts, x0, y0, s0..s1, f)
                        }
                        (SampleFn::Four(f), false) => {
                            render_tile::<4, false, _>(ctx, opts, x0, y0, s0..s1, f)
                        }
                        (SampleFn::Eight(f), false) => {
                            render_tile::<8, false, _>(ctx, opts, x0, y0, s0..s1, f)
                        }
                        (SampleFn::One(f), true) => {
                            render_tile::<1, true, _>(ctx, opts, x0, y0, s0..s1, f)
                        }
                        (SampleFn::Four(f), true) => {
                            render_tile::<4, true, _>(ctx, opts, x0, y0, s0..s1, f)
                        }
                        (SampleFn::Eight(f), true) => {
                            render_tile::<8, true, _>(ctx, opts, x0, y0, s0..s1, f)
                        }
                        (SampleFn::PathsOne(f), false) => {
                            render_tile_paths::<1, false>(ctx, opts, x0, y0, s0..s1, f)
                        }
                        (SampleFn::PathsFour(f), false) => {
                            render_tile_paths::<4, false>(ctx, opts, x0, y0, s0..s1, f)
                        }
                        (SampleFn::PathsEight(f), false) => {
                            render_tile_paths::<8, false>(ctx, opts, x0, y0, s0..s1, f)
                        }
                        (SampleFn::PathsOne(f), true) => {
                            render_tile_paths::<1, true>(ctx, opts, x0, y0, s0..s1, f)
                        }
                        (SampleFn::PathsFour(f), true) => {
                            render_tile_paths::<4, true>(ctx, opts, x0, y0, s0..s1, f)
                        }
                        (SampleFn::PathsEight(f), true) => {
                            render_tile_paths::<8, true>(ctx, opts, x0, y0, s0..s1, f)
                        }
                        (SampleFn::StokesOne(f), false) => {
                            render_tile::<1, false, _>(ctx, opts, x0, y0, s0..s1, f)
                        }
                        (SampleFn::StokesFour(f), false) => {
                            render_tile::<4, false, _>(ctx, opts, x0, y0, s0..s1, f)
                        }
                        (SampleFn::StokesEight(f), false) => {
                            render_tile::<8, false, _>(ctx, opts, x0, y0, s0..s1, f)
                        }
                        (SampleFn::StokesOne(f), true) => {
                            render_tile::<1, true, _>(ctx, opts, x0, y0, s0..s1, f)
                        }
                        (SampleFn::StokesFour(f), true) => {
                            render_tile::<4, true, _>(ctx, opts, x0, y0, s0..s1, f)
                        }
                        (SampleFn::StokesEight(f), true) => {
                            render_tile::<8, true, _>(ctx, opts, x0, y0, s0..s1, f)
                        }
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
    fn finish(&mut self, state: &FilmState, start: Instant, before: (u64, u64)) {
        self.wall = start.elapsed();
        self.spp = state.spp_done;
        self.samples = state.layout.pixels() as u64 * state.spp_done as u64;
        // This process's rays (a resumed render's earlier ones are in the checkpoint).
        self.counters.rays = state.rays - before.0;
        self.counters.shadow_rays = state.shadow_rays - before.1;
        self.nonfinite = state.nonfinite;
    }
}

/// A photon-mapping render (`integrator = "sppm"`): `spp` iterations of
/// [`integrator::sppm::iteration`], each a pass. An iteration's camera paths are the
/// film's samples (their light, the direct light, goes into its sums as any sample's
/// does); its photons' sums Σ Φ/(πR²) are added to the film's splats, which the film
/// divides by the iterations done, so the image is the direct light's mean plus
/// Hachisuka & Jensen's estimate of the rest. Checkpoints add the pixels' photon counts
/// and radii, from which `--resume` continues.
///
/// Shards: the estimator is progressive, each iteration's radii depending on the ones
/// before, so an iteration cannot be split across processes. Shard K/N instead runs
/// iterations ⌊K·I/N⌋ to ⌊(K+1)·I/N⌋ − 1 as a chain of its own, from the initial radii,
/// and `heron merge` adds the sums and iteration counts: the merged image is the
/// iteration-weighted mean of N independent SPPM estimates. It has the variance of one
/// render of I iterations but the bias of a render of I/N (the radii shrink only as far
/// as each shard's iterations take them), so it is not that render's bytes.
fn render_sppm<const N: usize>(
    ctx: &Context,
    pool: &rayon::ThreadPool,
    opts: &RenderOptions,
) -> Result<(Checkpoint, RenderStats)> {
    if opts.variance {
        return Err(HeronError::Invalid(
            "--variance: photon mapping's pixels are not means of independent samples (each iteration's radii depend on the ones before), so it has no per-pixel variance; use integrator path or bdpt for --variance".into(),
        ));
    }
    let scene = ctx.scene;
    let cam = &scene.camera;
    let npix = (cam.width * cam.height) as usize;
    let range = opts
        .shard
        .map_or(0..opts.settings.spp, |s| s.samples(opts.settings.spp));
    let key = settings_key(scene, opts, 1);
    let mut state = initial_state(scene, opts, key, range.len())?;
    let mut stats = RenderStats {
        resumed_from: opts.resume.as_ref().map(|c| c.film.spp_done),
        ..Default::default()
    };
    let before = (state.film.rays, state.film.shadow_rays);
    let mut clock = PassClock::new();
    let start = clock.start;
    let first = range.start + state.film.passes_done;
    let cancel = || cancelled(opts);
    for k in first..range.end {
        let mut pixels = state
            .film
            .integrator
            .take()
            .map_or_else(|| SppmPixels::new(npix), SppmPixels::from_plane);
        let it = pool.install(|| integrator::sppm::iteration::<N>(ctx, &mut pixels, k, &cancel));
        if cancelled(opts) {
            return Err(HeronError::Cancelled);
        }
        state.film.integrator = Some(pixels.into_plane());
        // The camera paths' light, as one tile of the whole image.
        let layout = state.film.layout;
        let mut sums = TileSums::new(&layout, (0, 0, cam.width, cam.height), PACKET as u32);
        for y in 0..cam.height {
            for x in 0..cam.width {
                let l = &it.l[(y * cam.width + x) as usize];
                sums.add::<N, false, SampledSpectrum<N>>((x, y, k), l, &it.wl);
            }
        }
        let tile = sums.result(
            Splats::new(0),
            Vec::new(),
            (it.counters.rays, it.counters.shadow_rays),
        );
        let first = state.film.add_tile(tile);
        stats.first_nonfinite = stats.first_nonfinite.or(first);
        // The photons' sums, already exact integers.
        let planes = &mut state.film.planes;
        for (a, b) in planes.splat.iter_mut().zip(it.photons.xyz.iter().flatten()) {
            *a = a.wrapping_add(b.load());
        }
        for (a, b) in planes.splat_bins.iter_mut().zip(&it.photons.bins) {
            *a = a.wrapping_add(b.load());
        }
        state.film.nonfinite += it
            .photons
            .nonfinite
            .load(std::sync::atomic::Ordering::Relaxed);
        state.film.passes_done += 1;
        state.film.spp_done = k + 1 - range.start;
        if let Some(p) = &opts.progress {
            p(state.film.spp_done as u64, range.len() as u64);
        }
        if clock.end_pass(opts, &state, k + 1 == range.end)? {
            stats.stopped = true;
            break;
        }
    }
    stats.finish(&state.film, start, before);
    Ok((state, stats))
}

/// The film's state a render starts from: the checkpoint `opts` resumes, checked against
/// this render (its settings `key`, its film's planes and at most `passes` passes), or
/// an empty film.
fn initial_state(
    scene: &Scene,
    opts: &RenderOptions,
    key: FilmKey,
    passes: usize,
) -> Result<Checkpoint> {
    let layout = layout(scene, opts);
    let sppm = opts.settings.integrator == IntegratorKind::Sppm;
    match &opts.resume {
        // Photon mapping keeps N and R² per pixel.
        Some(c) => c.resume(
            &key,
            opts.shard,
            &layout,
            passes,
            sppm.then_some((SppmPixels::PLANE, 2)),
        ),
        None => {
            let mut film = FilmState::new(layout);
            film.integrator = sppm.then(|| SppmPixels::new(layout.pixels()).into_plane());
            Ok(Checkpoint {
                key,
                shard: opts.shard,
                xyz_channels: false,
                film,
            })
        }
    }
}

/// When a render last wrote a checkpoint and a preview, for the decisions at the end
/// of each pass.
struct PassClock {
    start: Instant,
    last_checkpoint: Instant,
    last_preview: Instant,
}

impl PassClock {
    fn new() -> PassClock {
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
    fn end_pass(&mut self, opts: &RenderOptions, state: &Checkpoint, last: bool) -> Result<bool> {
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

/// Whether the render was abandoned (`RenderOptions::cancel`).
#[inline]
fn cancelled(opts: &RenderOptions) -> bool {
    opts.cancel
        .as_ref()
        .is_some_and(|c| c.load(std::sync::atomic::Ordering::Relaxed))
}

/// One tile's samples of one pass, one path at a time (camera rays in packets with
/// `Packets::Camera`); `VARIANCE` also sums the squares (`--variance`).
fn render_tile<const N: usize, const VARIANCE: bool, O: SampleValue<N>>(
    ctx: &Context,
    opts: &RenderOptions,
    x0: u32,
    y0: u32,
    samples: std::ops::Range<u32>,
    sample_fn: &integrator::KernelFn<N, O>,
) -> TileResult {
    let cam = &ctx.scene.camera;
    let w = TILE.min(cam.width - x0);
    let h = TILE.min(cam.height - y0);
    let mut sums = TileSums::new(&layout(ctx.scene, opts), (x0, y0, w, h), PACKET as u32);
    let mut splat_sq = Vec::new();
    let mut scratch = Vec::new();
    let mut counters = TraceCounters::default();
    let mut splats = Splats::with_bins(
        cam.width * cam.height,
        (opts.settings.spectral_bins > 0).then_some(SpectralBins {
            count: opts.settings.spectral_bins,
        }),
    );
    let base = Sampler::new(
        opts.settings.sampler,
        opts.settings.seed,
        cam.width,
        cam.height,
        opts.settings.spp,
    );
    let mut samplers: [Sampler; PACKET] = std::array::from_fn(|_| base.clone());
    let mut rays = [RayQuery {
        origin: cam.eye,
        dir: glam::Vec3::Z,
        tnear: 0.0,
        tfar: f32::INFINITY,
    }; PACKET];
    let mut wls = [SampledWavelengths::<N>::sample_uniform(0.0); PACKET];
    let mut cams: [Option<CameraRay>; PACKET] = [None; PACKET];
    for y in 0..h {
        if cancelled(opts) {
            break;
        }
        for xs in (0..w).step_by(PACKET) {
            let lanes = (w - xs).min(PACKET as u32) as usize;
            let active: u8 = if lanes == PACKET {
                0xff
            } else {
                (1u8 << lanes) - 1
            };
            for s in samples.clone() {
                for k in 0..lanes {
                    let (px, py) = (x0 + xs + k as u32, y0 + y);
                    let sampler = &mut samplers[k];
                    sampler.start_pixel_sample(px, py, s);
                    let j = sampler.get_pixel_2d();
                    wls[k] =
                        SampledWavelengths::sample(opts.settings.wavelengths, sampler.get_1d());
                    cams[k] = cam.ray(
                        px as f32 + j.x,
                        py as f32 + j.y,
                        || sampler.get_2d(),
                        wls[k].lambda[0],
                    );
                    if let Some(c) = &cams[k] {
                        rays[k].origin = c.ray.origin;
                        rays[k].dir = c.ray.dir;
                    }
                }
                // A ray the lens stopped is traced by no one.
                let traced =
                    (0..lanes).fold(
                        active,
                        |m, k| {
                            if cams[k].is_none() {
                                m & !(1 << k)
                            } else {
                                m
                            }
                        },
                    );
                let hits = if opts.settings.packets.camera()
                    && opts.settings.integrator.uses_camera_rays()
                {
                    counters.rays += traced.count_ones() as u64;
                    Some(ctx.accel.intersect8(&rays, traced))
                } else {
                    None
                };
                for k in 0..lanes {
                    let splats_before = if VARIANCE { splats.list.len() } else { 0 };
                    let l = match cams[k] {
                        Some(ray) => sample_fn(
                            ctx,
                            ray,
                            hits.map(|h| h[k]),
                            &wls[k],
                            &mut samplers[k],
                            &mut counters,
                            &mut splats,
                        ),
                        // Stopped by the lens: the sample adds 0.
                        None => O::zero(),
                    };
                    if VARIANCE && splats.list.len() > splats_before {
                        add_splat_squares(
                            &splats.list[splats_before..],
                            &mut scratch,
                            &mut splat_sq,
                        );
                    }
                    sums.add::<N, VARIANCE, O>((xs + k as u32, y, s), &l, &wls[k]);
                }
            }
        }
    }
    sums.result(splats, splat_sq, (counters.rays, counters.shadow_rays))
}

/// A path of the packet engine: its pixel sample (tile coordinates and sample index),
/// its state, the ray it traces next and its wavelengths.
struct Lane<const N: usize> {
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
fn render_tile_paths<const N: usize, const VARIANCE: bool>(
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
        // Camera rays go as one coherent packet, later rays as one incoherent packet:
        // each ray's hint follows from the ray alone. (A hint chosen by what a packet
        // holds would make a ray's traversal, and so the last bits of its hit, depend on
        // its partners, which differ between a whole render and its shards.) Under
        // `whitted` most paths end at their first hit, so most rounds are all camera
        // rays.
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
                let h = ctx.accel.intersect8_with(&queries, mask, hint);
                for (k, h) in h.into_iter().enumerate() {
                    if mask & (1 << k) != 0 {
                        hits[k] = h;
                    }
                }
            }
        }
        let mut going = 0u8;
        let mut rounds = 0;
        for k in 0..PACKET {
            let Some(lane) = &mut lanes[k] else { continue };
            shadows[k].clear();
            if (fns.step)(
                ctx,
                &mut lane.state,
                &mut lane.ray,
                hits[k],
                &lane.wl,
                &mut samplers[k],
                &mut counters,
                &mut shadows[k],
            ) {
                going |= 1 << k;
            }
            rounds = rounds.max(shadows[k].tests.len());
        }
        // The shadow rays, the r-th of every lane's in the r-th packet.
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
                .occluded8_with(&queries, mask, RayCoherence::Incoherent);
            for (k, sh) in shadows.iter_mut().enumerate() {
                if mask & (1 << k) != 0 {
                    sh.tests[r].blocked = blocked & (1 << k) != 0;
                }
            }
        }
        // Shadow rays through media walk boundary by boundary: one closest-hit packet
        // per crossing, until every lane's walk has ended; a lane's first walk before
        // its second, so contributions add in the order they were made.
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
                    .intersect8_with(&queries, mask, RayCoherence::Incoherent);
                for (k, sh) in shadows.iter_mut().enumerate() {
                    if mask & (1 << k) != 0 {
                        let wl = &lanes[k].as_ref().expect("a walking lane is live").wl;
                        sh.advance_walk(ctx, slot, hits[k], wl);
                    }
                }
            }
        }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::load::load_scene_from_str;
    use std::path::Path;

    /// A splatting integrator (standing in for light tracing): each sample splats the
    /// constant spectrum 1 into a pixel chosen by its own random numbers and returns
    /// nothing for its own pixel. Every pixel is then expected to receive 1 per sample on
    /// average, i.e. Y ≈ 1 after the film divides by spp, and the image must be the same
    /// bytes for any thread count, since splats are merged tile by tile in order.
    #[test]
    fn splats_are_deterministic_and_normalised_by_spp() {
        let scene = load_scene_from_str(
            "[camera]\neye = [0.0, 0.0, 1.0]\nlook_at = [0.0, 0.0, 0.0]\nresolution = [40, 24]\n",
            Path::new("splat.toml"),
        )
        .unwrap();
        let device = embree::Device::new("").unwrap();
        let accel = build_accel(&scene, &device).unwrap();
        let ctx = Context {
            scene: &scene,
            accel: &accel,
            settings: &scene.settings,
            offset: scene.settings.ray_offset(IntegratorKind::Whitted),
        };
        fn splat_one(
            _: &Context,
            _: CameraRay,
            _: Option<Option<crate::accel::embree::Hit>>,
            wl: &SampledWavelengths<4>,
            s: &mut Sampler,
            _: &mut TraceCounters,
            splats: &mut Splats,
        ) -> crate::spectrum::SampledSpectrum<4> {
            let p = (s.get_1d() * (40 * 24) as f32) as u32;
            // Radiance 1 at every lane: the film's Y of one splat is the sample's
            // estimate of ∫ȳ / ∫ȳ = 1 (up to the lanes' λ noise).
            splats.add(p, &crate::spectrum::SampledSpectrum::splat(1.0), wl);
            crate::spectrum::SampledSpectrum::zero()
        }
        let integrate = |n: Lanes| -> SampleFn {
            assert_eq!(n, Lanes::Four);
            SampleFn::Four(splat_one)
        };
        let run = |threads: usize, pass: u32| {
            let pool = embree::worker_pool(threads).unwrap();
            let mut o = RenderOptions::from_scene(&scene);
            o.settings.spp = 64;
            o.settings.lanes = 4;
            o.threads = threads;
            render_passes(&ctx, &pool, &o, pass, &integrate)
                .unwrap()
                .0
                .film
                .image()
        };
        let a = run(1, 16);
        assert!(
            a == run(2, 16) && a == run(3, 16),
            "splats depend on the thread count"
        );
        let mean = a.xyz.iter().map(|c| c[1] as f64).sum::<f64>() / a.xyz.len() as f64;
        assert!((mean - 1.0).abs() < 0.02, "mean splatted Y {mean}");
        // Passes only regroup the same splats, and the sums are exact: the same bytes.
        assert!(a == run(2, 64), "splats depend on the pass size");
    }

    /// The variance estimate (`--variance`) against the spread it estimates. Two fake
    /// integrators whose every pixel is an independent estimate of the same value, so
    /// the variance of the pixel values across the image is what each pixel's estimate
    /// should be on average: one returns radiance 2u for a uniform u (the pixel's own
    /// samples: sums S₁, S₂), one splats radiance 1 into a uniformly chosen pixel (the
    /// splats' sums T₁, T₂; each pixel's count of splats is binomial). 1 200 pixels: the
    /// spread's own relative standard error is about √(2/1199) ≈ 4%, so 15% is more
    /// than 3 of them; the estimate's mean over the pixels is far steadier.
    #[test]
    fn the_variance_estimate_matches_the_spread_of_independent_pixels() {
        let scene = load_scene_from_str(
            "[camera]\neye = [0.0, 0.0, 1.0]\nlook_at = [0.0, 0.0, 0.0]\nresolution = [40, 30]\n",
            Path::new("variance.toml"),
        )
        .unwrap();
        let device = embree::Device::new("").unwrap();
        let accel = build_accel(&scene, &device).unwrap();
        let ctx = Context {
            scene: &scene,
            accel: &accel,
            settings: &scene.settings,
            offset: scene.settings.ray_offset(IntegratorKind::Whitted),
        };
        fn own(
            _: &Context,
            _: CameraRay,
            _: Option<Option<crate::accel::embree::Hit>>,
            _: &SampledWavelengths<4>,
            s: &mut Sampler,
            _: &mut TraceCounters,
            _: &mut Splats,
        ) -> crate::spectrum::SampledSpectrum<4> {
            crate::spectrum::SampledSpectrum::splat(2.0 * s.get_1d())
        }
        fn splat(
            _: &Context,
            _: CameraRay,
            _: Option<Option<crate::accel::embree::Hit>>,
            wl: &SampledWavelengths<4>,
            s: &mut Sampler,
            _: &mut TraceCounters,
            splats: &mut Splats,
        ) -> crate::spectrum::SampledSpectrum<4> {
            let p = (s.get_1d() * (40 * 30) as f32) as u32;
            splats.add(p, &crate::spectrum::SampledSpectrum::splat(1.0), wl);
            crate::spectrum::SampledSpectrum::zero()
        }
        let pool = embree::worker_pool(2).unwrap();
        for (name, f) in [("own", own as SampleFnN<4>), ("splat", splat)] {
            let integrate = move |_: Lanes| SampleFn::Four(f);
            let mut o = RenderOptions::from_scene(&scene);
            o.settings.spp = 64;
            o.settings.lanes = 4;
            o.settings.sampler = crate::settings::SamplerKind::Independent;
            o.variance = true;
            let film = render_passes(&ctx, &pool, &o, 16, &integrate)
                .unwrap()
                .0
                .film
                .image();
            let rgb = film.linear_srgb();
            let var = film.variance.as_ref().unwrap();
            let n = rgb.len() as f64;
            for c in 0..3 {
                let mean = rgb.iter().map(|v| v[c] as f64).sum::<f64>() / n;
                let spread = rgb
                    .iter()
                    .map(|v| (v[c] as f64 - mean).powi(2))
                    .sum::<f64>()
                    / (n - 1.0);
                let estimate = var.iter().map(|v| v[c] as f64).sum::<f64>() / n;
                eprintln!("{name} channel {c}: estimate {estimate:.5e}, spread {spread:.5e}");
                assert!(
                    (estimate / spread - 1.0).abs() < 0.15,
                    "{name} channel {c}: estimated variance {estimate:.4e}, spread {spread:.4e}"
                );
            }
        }
    }
}
