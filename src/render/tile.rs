//! The one-path-at-a-time engine: a tile's pixel samples, camera rays in packets.
use super::*;

/// One tile's samples of one pass, one path at a time (camera rays in packets with
/// `Packets::Camera`); `VARIANCE` also sums the squares (`--variance`).
pub(super) fn render_tile<const N: usize, const VARIANCE: bool, O: SampleValue<N>>(
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
    let camera_packets = opts.settings.packets.camera()
        && integrator::capabilities(opts.settings.integrator).camera_rays;
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
                let hits = if camera_packets {
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
