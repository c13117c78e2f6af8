//! Polarised spectral path tracing (`[render] polarization`, `--polarization`): the path
//! tracer of `path.rs` (next-event estimation, MIS by the power heuristic, Russian
//! roulette, the same random numbers per bounce in the same order) carrying per lane a
//! 4 × 4 Mueller throughput instead of a scalar one, so that the camera receives a
//! Stokes vector per wavelength (Wilkie & Weidlich 2012, "Polarised light in computer
//! graphics", SIGGRAPH Asia course, §§ 4–5; Mitsuba 3's polarised variants, Jakob et al.
//! 2022, do the same).
//!
//! **The throughput.** Following the path from the camera, T maps the Stokes vector of
//! the light travelling along the current segment toward the camera, written in the
//! segment's frame x̂_cur, to the Stokes vector the camera receives in its own frame
//! (`Camera::stokes_x`: x̂ horizontal in the image). At the camera T is the analyser
//! (`[camera] polarizer`) or the identity, times the camera ray's weight. At a vertex
//! whose material scatters light arriving along ωi into ωo with the normalised Mueller
//! matrix M (frames x̂_in ⊥ ωi, x̂_out ⊥ ωo: `bsdf::polarization`) and the scalar
//! weight w = f |cos θi| / pdf, T becomes T · R(x̂_out → x̂_cur) · w M, and x̂_cur
//! becomes x̂_in; R is the rotation of the Stokes frame about the direction of travel
//! (`spectrum::stokes::rotate_basis`). Light found at a vertex (an emitter hit, a light
//! sample, light at infinity) adds T · R · S_e. Lights are unpolarised (S_e = (L, 0,
//! 0, 0), which needs no frame: the first column of T carries it) but for the physical
//! rainbow skies, whose light is linearly polarised perpendicular or parallel to the
//! scattering plane (`Light::le_linear`, `SceneSky::linear_table`); the sun itself is
//! unpolarised.
//!
//! **What stays scalar.** Sampling, MIS and roulette use the unpolarised scalar
//! throughput and densities exactly as `path.rs` does, so a scene whose materials all
//! depolarise renders the unpolarised image's S0 (`tests/polarization.rs` holds it to
//! that), and the roulette's 1/q reweights T as it does β.
//!
//! **What is not here yet.** Participating media (the render refuses them with
//! polarisation), polarised lights of the scene's own, light tracing,
//! BDPT, the Whitted tracer and the packet engine.
use super::toolkit::Immediate;
use super::toolkit::{light_pdf, next_hit, roulette, sample_light, PathState, ShadowSink};
use super::{Context, TraceCounters};
use crate::accel::embree::Hit;
use crate::bsdf::{LobeFlags, Polarizing};
use crate::camera::CameraRay;
use crate::light::SurfacePoint;
use crate::math::warp::power_heuristic;
use crate::math::Frame;
use crate::optics::mueller::Mueller;
use crate::sampler::Sampler;
use crate::scene::NO_LIGHT;
use crate::spectrum::stokes::{mueller_from_rows, rotate_basis, StokesSpectrum};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use glam::{Mat4, Vec3, Vec4};

/// The Mueller throughput of a path: per lane T, and the frame of the current segment.
struct Throughput<const N: usize> {
    t: [Mat4; N],
    x: Vec3,
}

impl<const N: usize> Throughput<N> {
    /// The light `l` per lane, unpolarised, arriving along the current segment, as the
    /// camera sees it, times `w`.
    #[inline]
    fn unpolarized(&self, l: SampledSpectrum<N>, w: f32) -> StokesSpectrum<N> {
        StokesSpectrum(std::array::from_fn(|i| self.t[i].col(0) * (l.0[i] * w)))
    }

    /// Light of S0 `l` and S1 `s1` per lane (S2 = S3 = 0) in the frame `x` (⊥ `k`, its
    /// direction of travel) arriving along the current segment, as the camera sees it,
    /// times `w`.
    #[inline]
    fn linear(
        &self,
        l: SampledSpectrum<N>,
        s1: SampledSpectrum<N>,
        x: Vec3,
        k: Vec3,
        w: f32,
    ) -> StokesSpectrum<N> {
        let r = rotate_basis(k, x, self.x);
        StokesSpectrum(std::array::from_fn(|i| {
            self.t[i] * (r * Vec4::new(l.0[i] * w, s1.0[i] * w, 0.0, 0.0))
        }))
    }

    /// T · R(x̂_out → x̂_cur) · M per lane for an event whose light leaves along `k_out`
    /// (world), without the scalar weights; and the frame the event's light arrives in.
    #[inline]
    fn through(&self, p: &Polarizing<N>, frame: &Frame, k_out: Vec3) -> ([Mat4; N], Option<Vec3>) {
        match p {
            // diag(1, 0, 0, 0): only T's first column survives, in any frame.
            Polarizing::Depolarizing => (
                std::array::from_fn(|i| {
                    Mat4::from_cols(self.t[i].col(0), Vec4::ZERO, Vec4::ZERO, Vec4::ZERO)
                }),
                None,
            ),
            Polarizing::Mueller { m, x_in, x_out } => {
                let r = rotate_basis(k_out, frame.to_world(*x_out), self.x);
                (
                    std::array::from_fn(|i| self.t[i] * r * m[i]),
                    Some(frame.to_world(*x_in)),
                )
            }
        }
    }
}

/// The Stokes radiance arriving along the camera ray `cam` at the wavelengths `wl`.
pub fn radiance<const N: usize>(
    ctx: &Context,
    cam: CameraRay,
    first_hit: Option<Option<Hit>>,
    wl: &SampledWavelengths<N>,
    sampler: &mut Sampler,
    counters: &mut TraceCounters,
) -> StokesSpectrum<N> {
    let scene = ctx.scene;
    let mut s = PathState::<N>::at_camera(&cam);
    let analyser = match ctx.settings.polarizer.or(scene.camera.polarizer) {
        Some(a) => {
            let m = Mueller::linear_polarizer(a as f64);
            mueller_from_rows(m.0.map(|r| r.map(|v| v as f32)))
        }
        None => Mat4::IDENTITY,
    };
    let mut tp = Throughput {
        t: std::array::from_fn(|i| analyser * s.beta.0[i]),
        x: scene.camera.stokes_x(cam.ray.dir),
    };
    let mut out = StokesSpectrum::<N>::zero();
    let mut ray = cam.ray;
    let mut pending = first_hit;
    loop {
        let hit = next_hit(ctx, &ray, &mut pending, counters);
        // The MIS weight of light the path reached by BSDF sampling, against light
        // sampling's density `p_light` (1 after a delta lobe).
        let found = |s: &PathState<N>, p_light: &dyn Fn() -> f32| {
            if s.specular_bounce {
                1.0
            } else {
                power_heuristic(s.prev_pdf, p_light())
            }
        };
        let Some(hit) = hit else {
            for &i in &scene.infinite_lights {
                let light = &scene.lights[i as usize];
                let le = light.le(ray.dir, wl);
                if !le.is_zero() {
                    let w = found(&s, &|| light_pdf(ctx, i as usize, s.prev_p, ray.dir, None));
                    out += match light.le_linear(ray.dir, wl) {
                        None => tp.unpolarized(le, w),
                        Some((s1, x)) => tp.linear(le, s1, x, -ray.dir, w),
                    };
                }
            }
            break;
        };
        let (it, material) = scene.interaction(&ray, &hit, ctx.offset.is_robust());
        s.bsdf_ctx.uv = it.uv;
        let wo = -ray.dir;
        let emitter = scene.shapes[hit.geom_id as usize].light;
        if emitter != NO_LIGHT {
            let le = scene.lights[emitter as usize].l(it.n_outward, wo, wl);
            if !le.is_zero() {
                let sp = SurfacePoint {
                    p: it.position,
                    n: it.n_outward,
                };
                let w = found(&s, &|| {
                    light_pdf(ctx, emitter as usize, s.prev_p, ray.dir, Some(&sp))
                });
                out += tp.unpolarized(le, w);
            }
        }
        if s.depth == ctx.settings.max_depth {
            break;
        }
        s.depth += 1;
        let u_light = sampler.get_1d();
        let u_light_point = sampler.get_2d();
        let u_lobe = sampler.get_1d();
        let u_dir = sampler.get_2d();
        let u_rr = sampler.get_1d();

        let frame = it.frame();
        let wo_local = frame.to_local(wo);
        let flags = material.flags();
        if flags.has_non_specular() {
            // Next-event estimation, as path.rs's `surface_direct_light`.
            if let Some(cl) = sample_light(ctx, it.position, u_light, u_light_point, wl) {
                let ls = &cl.sample;
                let wi_local = frame.to_local(ls.wi);
                let f = material.eval(wo_local, wi_local, wl, &s.bsdf_ctx).f * wi_local.z.abs();
                if !f.is_zero() {
                    let weight = if ls.delta {
                        1.0
                    } else {
                        power_heuristic(cl.pdf, material.pdf(wo_local, wi_local, wl, &s.bsdf_ctx))
                    };
                    let q = ctx
                        .offset
                        .shadow(&it.spawn_point(), ls.wi, ls.dist, &ls.target());
                    let scale = weight / cl.pdf;
                    if let Some(c) = Immediate.test(ctx, q, counters, || f * ls.l * scale) {
                        let lobe = LobeFlags::from_bits(flags.bits() & !LobeFlags::SPECULAR.bits());
                        let p = material.mueller(wo_local, wi_local, lobe, wl, &frame);
                        let (t, x_in) = tp.through(&p, &frame, wo);
                        let linear = scene.lights[cl.index].le_linear(ls.wi, wl);
                        out += match (linear, x_in) {
                            // Polarised light onto a polarising event: into its frame.
                            (Some((s1, x)), Some(x_in)) => {
                                let r = rotate_basis(-ls.wi, x, x_in);
                                let c1 = f * s1 * scale;
                                StokesSpectrum(std::array::from_fn(|i| {
                                    t[i] * (r * Vec4::new(c.0[i], c1.0[i], 0.0, 0.0))
                                }))
                            }
                            // Unpolarised light, or a depolarising event: only S0 counts.
                            _ => StokesSpectrum(std::array::from_fn(|i| t[i].col(0) * c.0[i])),
                        };
                    }
                }
            }
        }

        let Some(bs) = material.sample(wo_local, u_lobe, u_dir, wl, &s.bsdf_ctx) else {
            break;
        };
        let w = bs.weight();
        let p = material.mueller(wo_local, bs.wi, bs.flags, wl, &frame);
        let (t, x_in) = tp.through(&p, &frame, wo);
        let wi = frame.to_world(bs.wi);
        tp.t = std::array::from_fn(|i| t[i] * w.0[i]);
        tp.x = x_in.unwrap_or_else(|| crate::spectrum::stokes::any_perpendicular(wi));
        s.beta *= w;
        s.specular_bounce = bs.is_specular();
        s.prev_pdf = bs.pdf;
        s.prev_p = it.position;
        if bs.ended_companions {
            s.bsdf_ctx.companions_alive = false;
        }
        if bs.is_transmission() {
            s.eta_scale *= bs.eta * bs.eta;
        }
        ray = ctx.offset.spawn(&it.spawn_point(), wi);
        if s.beta.is_zero() {
            break;
        }
        let before = s.beta.0;
        let rr = s.beta.max_value() * s.eta_scale;
        if !roulette(&mut s.beta, rr, s.depth, ctx.settings.rr_depth, u_rr) {
            break;
        }
        if before != s.beta.0 {
            // Survived the roulette: T is reweighted as β was (the same 1/q per lane).
            let k = (0..N)
                .find(|&i| before[i] != 0.0)
                .map_or(1.0, |i| s.beta.0[i] / before[i]);
            for t in tp.t.iter_mut() {
                *t *= k;
            }
        }
    }
    out
}
