//! A progressive integrator's render (`PassIntegrator`: photon mapping): its passes.
use super::passes::{initial_state, OwnPlane, PassClock};
use super::*;

/// A render by the progressive integrator `P`: `spp` passes of [`PassIntegrator::pass`].
/// A pass's own samples are the film's (for photon mapping its camera paths' light,
/// the direct light, goes into the sums as any sample's does); its splat sums (photon
/// mapping's Σ Φ/(πR²)) are added to the film's splats, which the film divides by the
/// passes done, so the image is the direct light's mean plus Hachisuka & Jensen's
/// estimate of the rest. Checkpoints add the integrator's per-pixel plane (the photon
/// counts and radii), from which `--resume` continues.
///
/// Shards: the estimator is progressive, each iteration's radii depending on the ones
/// before, so an iteration cannot be split across processes. Shard K/N instead runs
/// iterations ⌊K·I/N⌋ to ⌊(K+1)·I/N⌋ − 1 as a chain of its own, from the initial radii,
/// and `heron merge` adds the sums and iteration counts: the merged image is the
/// iteration-weighted mean of N independent SPPM estimates. It has the variance of one
/// render of I iterations but the bias of a render of I/N (the radii shrink only as far
/// as each shard's iterations take them), so it is not that render's bytes.
pub(super) fn render_progressive<P: PassIntegrator, const N: usize>(
    ctx: &Context,
    pool: &rayon::ThreadPool,
    opts: &RenderOptions,
) -> Result<(Checkpoint, RenderStats)> {
    let scene = ctx.scene;
    let cam = &scene.camera;
    let npix = (cam.width * cam.height) as usize;
    let range = opts
        .shard
        .map_or(0..opts.settings.spp, |s| s.samples(opts.settings.spp));
    let key = settings_key(scene, opts, 1);
    let plane = Some(OwnPlane {
        name: P::PLANE.0,
        per_pixel: P::PLANE.1,
        initial: P::initial_plane,
    });
    let mut state = initial_state(scene, opts, key, range.len(), plane)?;
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
        let mut plane = state
            .film
            .integrator
            .take()
            .unwrap_or_else(|| P::initial_plane(npix));
        let it = pool.install(|| P::pass::<N>(ctx, &mut plane, k, &cancel));
        if cancelled(opts) {
            return Err(HeronError::Cancelled);
        }
        state.film.integrator = Some(plane);
        // The pass's own samples, as one tile of the whole image.
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
        // Its splat sums, already exact integers.
        let planes = &mut state.film.planes;
        for (a, b) in planes.splat.iter_mut().zip(&it.splat) {
            *a = a.wrapping_add(*b);
        }
        for (a, b) in planes.splat_bins.iter_mut().zip(&it.splat_bins) {
            *a = a.wrapping_add(*b);
        }
        state.film.nonfinite += it.nonfinite;
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
