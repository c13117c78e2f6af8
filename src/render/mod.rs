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
use crate::film::fixed::SquareSum;
use crate::film::planes::Layout;
use crate::film::state::FilmState;
use crate::film::state::IntegratorPlane;
use crate::film::tile::{SampleValue, TileResult, TileSums};
use crate::film::{add_splat_squares, Film, SpectralBins, Splats};
use crate::geometry::{Ray, ShapeKind};
use crate::integrator::sppm::PhotonMapping;
use crate::integrator::PassIntegrator;
use crate::integrator::{self, Context, Deferred, PathState, TraceCounters, Tracer, WALKS};
use crate::sampler::Sampler;
use crate::scene::{Features, Scene};
use crate::settings::{IntegratorKind, KernelFlags, Lanes, Packets, RenderSettings};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use crate::{HeronError, Result};
use rayon::prelude::*;
use std::time::{Duration, Instant};

mod passes;
mod programs;
mod progressive;
mod tile;

use passes::render_passes;
use progressive::render_progressive;

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
    let caps = integrator::capabilities(kind);
    integrator::capabilities::check_camera(scene, &opts.settings).map_err(HeronError::Invalid)?;
    if opts.settings.polarization {
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
    let k = integrator::choose_kernel(kind, &Features::of(scene), opts.settings.kernel)
        .map_err(HeronError::Invalid)?;
    integrator::capabilities::check_variance(kind, opts.variance).map_err(HeronError::Invalid)?;
    // Polarised transport has two kernels: with media and without.
    let k = if opts.settings.polarization {
        integrator::stokes_flags(kind, k)
    } else {
        k
    };
    let mut opts = opts.clone();
    // `auto` resolved: the provenance records what ran.
    opts.settings.packets =
        integrator::capabilities::packets(kind, opts.settings.packets, opts.settings.polarization);
    if kind == IntegratorKind::Sppm {
        let (state, mut stats) = match opts.settings.lanes {
            Lanes::One => render_progressive::<PhotonMapping, 1>(&ctx, pool, &opts),
            Lanes::Four => render_progressive::<PhotonMapping, 4>(&ctx, pool, &opts),
            Lanes::Eight => render_progressive::<PhotonMapping, 8>(&ctx, pool, &opts),
        }?;
        stats.kernel = k;
        return Ok((state, stats));
    }
    let paths = opts.settings.packets == Packets::Paths && caps.steps;
    let polarized = opts.settings.polarization;
    let integrate = move |n: Lanes| match n {
        Lanes::One => SampleFn::One(tile_fn(kind, k, polarized, paths)),
        Lanes::Four => SampleFn::Four(tile_fn(kind, k, polarized, paths)),
        Lanes::Eight => SampleFn::Eight(tile_fn(kind, k, polarized, paths)),
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
    let pass = if caps.splats {
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
    integrator::capabilities(opts.settings.integrator).splats
}

/// The per-sample function of a render, one per lane count (see
/// [`integrator::kernel`]): one indirect call per pixel sample.
pub(crate) type SampleFnN<const N: usize> = integrator::RadianceFn<N>;

/// What a render's tiles run at `N` lanes: one of the integrator's monomorphised
/// functions, chosen once per render.
pub(crate) enum TileFn<const N: usize> {
    /// Whole pixel samples of radiance (`integrator::kernel`).
    Radiance(SampleFnN<N>),
    /// Whole pixel samples of Stokes radiance, for polarised transport
    /// (`integrator::stokes_kernel`).
    Stokes(integrator::StokesFn<N>),
    /// The steps of packets of paths (`integrator::path_fns`, `--packets paths`).
    Steps(integrator::PathFns<N>),
}

/// The render's [`TileFn`] at its lane count.
pub(crate) enum SampleFn {
    One(TileFn<1>),
    Four(TileFn<4>),
    Eight(TileFn<8>),
}

/// The tile function of `kind` at `N` lanes for the kernel flags `k`: polarised
/// transport's (checked by `check_camera`: the integrator has one), else the steps of
/// packets of paths when `paths` (the integrator has steps: `packets`), else whole
/// samples.
fn tile_fn<const N: usize>(
    kind: IntegratorKind,
    k: KernelFlags,
    polarized: bool,
    paths: bool,
) -> TileFn<N> {
    if polarized {
        TileFn::Stokes(integrator::stokes_kernel::<N>(kind, k).expect("a polarised kernel"))
    } else if paths {
        TileFn::Steps(integrator::path_fns::<N>(kind, k).expect("an integrator with a step"))
    } else {
        TileFn::Radiance(integrator::kernel::<N>(kind, k))
    }
}

/// Whether the render was abandoned (`RenderOptions::cancel`).
#[inline]
fn cancelled(opts: &RenderOptions) -> bool {
    opts.cancel
        .as_ref()
        .is_some_and(|c| c.load(std::sync::atomic::Ordering::Relaxed))
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
            SampleFn::Four(TileFn::Radiance(splat_one))
        };
        let run = |threads: usize, pass: u32| {
            let pool = embree::worker_pool(threads).unwrap();
            let mut o = RenderOptions::from_scene(&scene);
            o.settings.spp = 64;
            o.settings.lanes = Lanes::Four;
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
            let integrate = move |_: Lanes| SampleFn::Four(TileFn::Radiance(f));
            let mut o = RenderOptions::from_scene(&scene);
            o.settings.spp = 64;
            o.settings.lanes = Lanes::Four;
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
