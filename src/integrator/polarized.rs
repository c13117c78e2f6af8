//! Polarised spectral path tracing (`[render] polarization`, `--polarization`): the path
//! tracer of `path.rs` itself (next-event estimation, MIS by the power heuristic,
//! Russian roulette, participating media with their hero-wavelength MIS, forced
//! next-event estimation and the sun guide, the same random numbers in the same order)
//! carrying per lane a 4 × 4 Mueller product besides its scalar throughput, so that the
//! camera receives a Stokes vector per wavelength (Wilkie & Weidlich 2012, "Polarised
//! light in computer graphics", SIGGRAPH Asia course, §§ 4–5; Mitsuba 3's polarised
//! variants, Jakob et al. 2022, do the same). It is `path::step_carrying` with the
//! [`Carrier`] of this file.
//!
//! **The Mueller product.** Every event's Mueller matrix is its scalar weight (what the
//! unpolarised path tracer multiplies its throughput by: f |cos θ| / pdf at a surface,
//! σ_s p / (σ_t pdf) in a medium) times its matrix divided by its [0][0] element (the
//! event's "shape": `bsdf::polarization` for materials, `Medium::phase_matrix` for
//! Lorenz–Mie media). So the path's full Mueller throughput is β (the scalar one) times
//! the product T of the shapes, and every contribution the path tracer computes as a
//! scalar c per lane becomes T · R · M · S_e · c, where M is the last event's shape and
//! S_e the light's normalised Stokes vector. Following the path from the camera, T maps
//! the Stokes vector of the light travelling along the current segment toward the
//! camera, written in the segment's frame x̂_cur, to what the camera receives in its own
//! frame (`Camera::stokes_x`: x̂ horizontal in the image); at the camera T is the
//! analyser (`[camera] polarizer`) or the identity. At an event that takes light
//! arriving along ωi (frame x̂_in) to ωo (frame x̂_out), T becomes T · R(x̂_out → x̂_cur)
//! · M and x̂_cur becomes x̂_in; R is the rotation of the Stokes frame about the
//! direction of travel (`spectrum::stokes::rotate_basis`). Lights are unpolarised
//! (S_e = (1, 0, 0, 0), which needs no frame: the first column of T carries it) but for
//! the physical rainbow skies, whose light is linearly polarised perpendicular or
//! parallel to the scattering plane (`Light::le_linear`, `SceneSky::linear_table`), and
//! delta lights given a `polarization` (`light::polarization`); the sun itself is
//! unpolarised.
//!
//! **What stays scalar.** Sampling, MIS, roulette and transmittance (spheres of water
//! attenuate both polarisations alike) are the unpolarised path tracer's, so a scene
//! whose materials all depolarise renders the unpolarised image's S0
//! (`tests/polarization.rs` holds it to that).
//!
//! **What is not here yet.** Polarised area lights, light tracing, BDPT, the Whitted
//! tracer and the packet engine of paths.
use super::toolkit::{next_hit, Carrier, Immediate, PathState, Vertex};
use super::{path, whitted};
use super::{Context, TraceCounters};
use crate::accel::embree::Hit;
use crate::bsdf::{LobeFlags, Polarizing};
use crate::camera::CameraRay;
use crate::optics::mueller::Mueller;
use crate::sampler::Sampler;
use crate::scene::Scene;
use crate::settings::KernelFlags;
use crate::spectrum::stokes::{any_perpendicular, mueller_from_rows, rotate_basis, StokesSpectrum};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use glam::{Mat4, Vec3, Vec4};

/// What a polarised path carries: per lane the product T of its events' normalised
/// Mueller matrices (module docs), the frame of its current segment, and the Stokes
/// radiance found so far.
struct Polarized<'a, const N: usize> {
    scene: &'a Scene,
    t: [Mat4; N],
    x: Vec3,
    out: StokesSpectrum<N>,
}

impl<const N: usize> Polarized<'_, N> {
    /// The normalised Stokes vector per lane (S0 = 1) of light `light` arriving from
    /// direction `dir` (toward the light), and its frame; None when it is unpolarised.
    #[inline]
    fn light_state(
        &self,
        light: usize,
        dir: Vec3,
        wl: &SampledWavelengths<N>,
    ) -> Option<([Vec4; N], Vec3)> {
        if let Some(p) = self.scene.light_polarization(light) {
            let (s, x) = p.stokes(-dir);
            return Some(([s; N], x));
        }
        let l = &self.scene.lights[light];
        let (s1, x) = l.le_linear(dir, wl)?;
        let le = l.le(dir, wl);
        Some((
            std::array::from_fn(|i| {
                let p = if le.0[i] > 0.0 {
                    s1.0[i] / le.0[i]
                } else {
                    0.0
                };
                Vec4::new(1.0, p, 0.0, 0.0)
            }),
            x,
        ))
    }

    /// The shape of the event at `v` taking light arriving along −`wi` to the path's
    /// previous vertex, by a lobe of `flags`: per lane T · R(x̂_out → x̂_cur) · M, and the
    /// frame x̂_in of the arriving light (None: the event depolarises).
    #[inline]
    fn through(
        &self,
        v: &Vertex,
        wi: Vec3,
        wi_local: Vec3,
        flags: LobeFlags,
        wl: &SampledWavelengths<N>,
    ) -> ([Mat4; N], Option<Vec3>) {
        let depolarized = || {
            std::array::from_fn(|i| {
                Mat4::from_cols(self.t[i].col(0), Vec4::ZERO, Vec4::ZERO, Vec4::ZERO)
            })
        };
        match *v {
            Vertex::Surface {
                material,
                frame,
                wo_local,
            } => match material.mueller(wo_local, wi_local, flags, wl, frame) {
                Polarizing::Depolarizing => (depolarized(), None),
                Polarizing::Mueller { m, x_in, x_out } => {
                    let wo = frame.to_world(wo_local);
                    let r = rotate_basis(wo, frame.to_world(x_out), self.x);
                    (
                        std::array::from_fn(|i| self.t[i] * r * m[i]),
                        Some(frame.to_world(x_in)),
                    )
                }
            },
            Vertex::Medium { medium, d_in } => match medium.phase_matrix(d_in, wi, wl) {
                None => (depolarized(), None),
                Some((m, x)) => {
                    let r = rotate_basis(-d_in, x, self.x);
                    (std::array::from_fn(|i| self.t[i] * r * m[i]), Some(x))
                }
            },
        }
    }
}

impl<const N: usize> Carrier<N> for Polarized<'_, N> {
    const POLARIZED: bool = true;

    #[inline]
    fn found(
        &mut self,
        _: &mut SampledSpectrum<N>,
        c: SampledSpectrum<N>,
        light: usize,
        dir: Vec3,
        wl: &SampledWavelengths<N>,
    ) {
        let add: StokesSpectrum<N> = match self.light_state(light, dir, wl) {
            None => StokesSpectrum(std::array::from_fn(|i| self.t[i].col(0) * c.0[i])),
            Some((s, x)) => {
                let r = rotate_basis(-dir, x, self.x);
                StokesSpectrum(std::array::from_fn(|i| self.t[i] * (r * s[i]) * c.0[i]))
            }
        };
        self.out += add;
    }

    #[inline]
    fn lit(
        &mut self,
        _: &mut SampledSpectrum<N>,
        c: SampledSpectrum<N>,
        v: &Vertex,
        wi: Vec3,
        wi_local: Vec3,
        light: usize,
        wl: &SampledWavelengths<N>,
    ) {
        // Light samples reach the non-delta lobes only.
        let flags = match v {
            Vertex::Surface { material, .. } => {
                LobeFlags::from_bits(material.flags().bits() & !LobeFlags::SPECULAR.bits())
            }
            Vertex::Medium { .. } => LobeFlags::NONE,
        };
        let (t, x_in) = self.through(v, wi, wi_local, flags, wl);
        let add = match (self.light_state(light, wi, wl), x_in) {
            // Polarised light onto a polarising event: into the event's frame.
            (Some((s, x)), Some(x_in)) => {
                let r = rotate_basis(-wi, x, x_in);
                StokesSpectrum(std::array::from_fn(|i| t[i] * (r * s[i]) * c.0[i]))
            }
            // Unpolarised light, or a depolarising event: only S0 counts.
            _ => StokesSpectrum(std::array::from_fn(|i| t[i].col(0) * c.0[i])),
        };
        self.out += add;
    }

    #[inline]
    fn scattered(
        &mut self,
        v: &Vertex,
        wi: Vec3,
        wi_local: Vec3,
        flags: LobeFlags,
        wl: &SampledWavelengths<N>,
    ) {
        let (t, x_in) = self.through(v, wi, wi_local, flags, wl);
        self.t = t;
        self.x = x_in.unwrap_or_else(|| any_perpendicular(wi));
    }
}

impl<'a, const N: usize> Polarized<'a, N> {
    /// The carrier of a camera ray: T is the camera's analyser (`[camera] polarizer`,
    /// `--polarizer`) or the identity, in the camera's frame.
    fn at_camera(ctx: &Context<'a>, cam: &CameraRay) -> Self {
        let scene = ctx.scene;
        let analyser = match ctx.settings.polarizer.or(scene.camera.polarizer) {
            Some(a) => {
                let m = Mueller::linear_polarizer(a as f64);
                mueller_from_rows(m.0.map(|r| r.map(|v| v as f32)))
            }
            None => Mat4::IDENTITY,
        };
        Polarized {
            scene,
            t: [analyser; N],
            x: scene.camera.stokes_x(cam.ray.dir),
            out: StokesSpectrum::zero(),
        }
    }
}

/// The Stokes radiance arriving along the camera ray `cam` at the wavelengths `wl`, in
/// the camera's frame, from the path tracer with the kernel flags `K`
/// (`path::radiance`'s).
pub fn radiance<const N: usize, const K: KernelFlags>(
    ctx: &Context,
    cam: CameraRay,
    first_hit: Option<Option<Hit>>,
    wl: &SampledWavelengths<N>,
    sampler: &mut Sampler,
    counters: &mut TraceCounters,
) -> StokesSpectrum<N> {
    let s = PathState::<N>::at_camera(&cam);
    follow(
        ctx,
        cam,
        s,
        first_hit,
        sampler,
        counters,
        |s, ray, hit, sampler, c, carry| {
            path::step_carrying::<N, K, _, _>(
                ctx,
                s,
                ray,
                hit,
                wl,
                sampler,
                c,
                &mut Immediate,
                carry,
            )
        },
    )
}

/// The same from the seed's Whitted tracer (`whitted::step_carrying`): its direct
/// lighting light by light through the surface's non-delta lobes, and its delta
/// continuations, each with its Mueller matrix.
pub fn whitted_radiance<const N: usize, const K: KernelFlags>(
    ctx: &Context,
    cam: CameraRay,
    first_hit: Option<Option<Hit>>,
    wl: &SampledWavelengths<N>,
    sampler: &mut Sampler,
    counters: &mut TraceCounters,
) -> StokesSpectrum<N> {
    let s = whitted::start::<N>(&cam);
    follow(
        ctx,
        cam,
        s,
        first_hit,
        sampler,
        counters,
        |s, ray, hit, sampler, c, carry| {
            whitted::step_carrying::<N, K, _, _>(
                ctx,
                s,
                ray,
                hit,
                wl,
                sampler,
                c,
                &mut Immediate,
                carry,
            )
        },
    )
}

/// The one-path-at-a-time loop over an integrator's `step` from the camera ray `cam`
/// and the path state `s` at it, with the polarised carrier; its Stokes radiance.
#[inline(always)]
fn follow<const N: usize>(
    ctx: &Context,
    cam: CameraRay,
    mut s: PathState<N>,
    first_hit: Option<Option<Hit>>,
    sampler: &mut Sampler,
    counters: &mut TraceCounters,
    mut step: impl FnMut(
        &mut PathState<N>,
        &mut crate::geometry::Ray,
        Option<Hit>,
        &mut Sampler,
        &mut TraceCounters,
        &mut Polarized<'_, N>,
    ) -> bool,
) -> StokesSpectrum<N> {
    let mut carry = Polarized::at_camera(ctx, &cam);
    let mut ray = cam.ray;
    let mut pending = first_hit;
    loop {
        let hit = next_hit(ctx, &ray, &mut pending, counters);
        if !step(&mut s, &mut ray, hit, sampler, counters, &mut carry) {
            break;
        }
    }
    carry.out
}
