//! Rendering: tiles on rayon, camera rays traced as Embree 8-wide packets, the
//! integrator per lane, and deterministic seeding.
//!
//! Determinism: every (pixel, sample) has its own random stream (math::rng), each pixel's
//! samples are summed in sample order by the one worker that owns its tile, and tiles are
//! gathered in tile order, so the image is bit-identical whatever the thread count.
use crate::accel::embree::{self, RayQuery};
use crate::film::{add_to_bins, xyz_of_sample, Film, SpectralBins};
use crate::geometry::{Ray, ShapeKind};
use crate::integrator::{whitted, Context, TraceCounters};
use crate::math::Rng;
use crate::scene::Scene;
use crate::spectrum::{SampledWavelengths, WavelengthSampler};
use crate::{HeronError, Result};
use rayon::prelude::*;
use std::time::{Duration, Instant};

/// Square tile edge in pixels; a multiple of the packet width.
const TILE: u32 = 16;
const PACKET: usize = 8;

#[derive(Clone)]
pub struct RenderOptions {
    pub spp: u32,
    pub seed: u64,
    /// Worker threads; 0 means one per core.
    pub threads: usize,
    /// Wavelength lanes per path: 1, 4 or 8.
    pub lanes: usize,
    /// Trace camera rays as 8-wide packets (otherwise one by one).
    pub packets: bool,
    /// How hero wavelengths are drawn.
    pub wavelengths: WavelengthSampler,
    /// Accumulate the mean spectral radiance in this many equal bins over 360–830 nm
    /// (0: none).
    pub spectral_bins: usize,
    /// Called after each finished tile with (tiles done, tiles in all).
    pub progress: Option<std::sync::Arc<dyn Fn(u64, u64) + Send + Sync>>,
}

impl RenderOptions {
    pub fn from_scene(scene: &Scene) -> Self {
        RenderOptions {
            spp: scene.settings.spp,
            seed: scene.settings.seed,
            threads: 0,
            lanes: 4,
            packets: true,
            wavelengths: WavelengthSampler::Uniform,
            spectral_bins: 0,
            progress: None,
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
    pub samples: u64,
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

struct TileResult {
    x0: u32,
    y0: u32,
    w: u32,
    h: u32,
    xyz: Vec<[f32; 3]>,
    /// Per pixel, `bins` values (empty without spectral output).
    spectral: Vec<f32>,
    counters: TraceCounters,
    nonfinite: u64,
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

fn render_with(
    scene: &Scene,
    accel: &embree::Scene,
    pool: &rayon::ThreadPool,
    opts: &RenderOptions,
) -> Result<(Film, RenderStats)> {
    if opts.spp == 0 {
        return Err(HeronError::Invalid("spp must be at least 1".into()));
    }
    if ![1, 4, 8].contains(&opts.lanes) {
        return Err(HeronError::Invalid(format!(
            "lanes: expected 1, 4 or 8, got {}",
            opts.lanes
        )));
    }
    let ctx = Context { scene, accel };
    let cam = &scene.camera;
    let (tw, th) = (cam.width.div_ceil(TILE), cam.height.div_ceil(TILE));
    let tiles: Vec<(u32, u32)> = (0..th)
        .flat_map(|ty| (0..tw).map(move |tx| (tx * TILE, ty * TILE)))
        .collect();
    let n_tiles = tiles.len() as u64;
    let done = std::sync::atomic::AtomicU64::new(0);
    let start = Instant::now();
    let results: Vec<TileResult> = pool.install(|| {
        tiles
            .par_iter()
            .map(|&(x0, y0)| {
                let r = match opts.lanes {
                    1 => render_tile::<1>(&ctx, opts, x0, y0),
                    4 => render_tile::<4>(&ctx, opts, x0, y0),
                    _ => render_tile::<8>(&ctx, opts, x0, y0),
                };
                let k = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                if let Some(p) = &opts.progress {
                    p(k, n_tiles);
                }
                r
            })
            .collect()
    });
    let wall = start.elapsed();
    let bins = (opts.spectral_bins > 0).then_some(SpectralBins {
        count: opts.spectral_bins,
    });
    let npix = (cam.width * cam.height) as usize;
    let mut film = Film {
        width: cam.width,
        height: cam.height,
        xyz: vec![[0.0; 3]; npix],
        spectral: bins.map(|b| (b, vec![0.0; npix * b.count])),
    };
    let mut stats = RenderStats {
        wall,
        samples: cam.width as u64 * cam.height as u64 * opts.spp as u64,
        ..Default::default()
    };
    for t in results {
        for y in 0..t.h {
            for x in 0..t.w {
                let (dst, src) = (
                    ((t.y0 + y) * cam.width + t.x0 + x) as usize,
                    (y * t.w + x) as usize,
                );
                film.xyz[dst] = t.xyz[src];
                if let Some((b, data)) = &mut film.spectral {
                    data[dst * b.count..(dst + 1) * b.count]
                        .copy_from_slice(&t.spectral[src * b.count..(src + 1) * b.count]);
                }
            }
        }
        stats.counters.rays += t.counters.rays;
        stats.counters.shadow_rays += t.counters.shadow_rays;
        stats.nonfinite += t.nonfinite;
    }
    Ok((film, stats))
}

fn render_tile<const N: usize>(
    ctx: &Context,
    opts: &RenderOptions,
    x0: u32,
    y0: u32,
) -> TileResult {
    let cam = &ctx.scene.camera;
    let w = TILE.min(cam.width - x0);
    let h = TILE.min(cam.height - y0);
    let mut xyz = vec![[0.0f64; 3]; (w * h) as usize];
    let bins = SpectralBins {
        count: opts.spectral_bins,
    };
    let mut spectral = vec![0.0f64; (w * h) as usize * opts.spectral_bins];
    let mut counters = TraceCounters::default();
    let mut nonfinite = 0u64;
    let mut good = vec![0u32; (w * h) as usize];
    let mut rngs: [Rng; PACKET] = std::array::from_fn(|_| Rng::new(0, 0));
    let mut rays = [RayQuery {
        origin: cam.eye,
        dir: glam::Vec3::Z,
        tnear: 0.0,
        tfar: f32::INFINITY,
    }; PACKET];
    let mut wls = [SampledWavelengths::<N>::sample_uniform(0.0); PACKET];
    for y in 0..h {
        for xs in (0..w).step_by(PACKET) {
            let lanes = (w - xs).min(PACKET as u32) as usize;
            let active: u8 = if lanes == PACKET {
                0xff
            } else {
                (1u8 << lanes) - 1
            };
            for s in 0..opts.spp {
                for k in 0..lanes {
                    let (px, py) = (x0 + xs + k as u32, y0 + y);
                    let pixel = py as u64 * cam.width as u64 + px as u64;
                    let mut rng = Rng::for_sample(opts.seed, pixel, s as u64);
                    let (jx, jy) = (rng.uniform(), rng.uniform());
                    wls[k] = SampledWavelengths::sample(opts.wavelengths, rng.uniform());
                    rays[k].dir = cam.direction(px as f32 + jx, py as f32 + jy);
                    rngs[k] = rng;
                }
                let hits = if opts.packets {
                    counters.rays += lanes as u64;
                    Some(ctx.accel.intersect8(&rays, active))
                } else {
                    None
                };
                for k in 0..lanes {
                    let ray = Ray::new(cam.eye, rays[k].dir, 0.0, f32::INFINITY);
                    let l = whitted::radiance(
                        ctx,
                        ray,
                        hits.map(|h| h[k]),
                        &wls[k],
                        &mut rngs[k],
                        &mut counters,
                    );
                    let i = (y * w + xs + k as u32) as usize;
                    if !l.is_finite() {
                        nonfinite += 1;
                        continue;
                    }
                    let c = xyz_of_sample(&l, &wls[k]);
                    for j in 0..3 {
                        xyz[i][j] += c[j] as f64;
                    }
                    if bins.count > 0 {
                        let b = bins.count;
                        add_to_bins(&bins, &mut spectral[i * b..(i + 1) * b], &l, &wls[k]);
                    }
                    good[i] += 1;
                }
            }
        }
    }
    // Non-finite samples are left out and counted: the mean is over the finite ones.
    let inv = |n: u32| if n > 0 { 1.0 / n as f64 } else { 0.0 };
    let xyz = xyz
        .iter()
        .zip(&good)
        .map(|(c, &n)| {
            let k = inv(n);
            [(c[0] * k) as f32, (c[1] * k) as f32, (c[2] * k) as f32]
        })
        .collect();
    let spectral = spectral
        .iter()
        .enumerate()
        .map(|(j, &v)| (v * inv(good[j / opts.spectral_bins.max(1)])) as f32)
        .collect();
    TileResult {
        x0,
        y0,
        w,
        h,
        xyz,
        spectral,
        counters,
        nonfinite,
    }
}
