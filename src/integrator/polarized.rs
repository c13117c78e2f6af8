//! Polarised spectral path tracing (`[render] polarization`, `--polarization`): the path
//! tracer of `path.rs` itself (next-event estimation, MIS by the power heuristic,
//! Russian roulette, participating media with their hero-wavelength MIS, forced
//! next-event estimation and the sun guide, the same random numbers in the same order)
//! carrying per lane a 4 × 4 Mueller product besides its scalar throughput, so that the
//! camera receives a Stokes vector per wavelength (Wilkie & Weidlich 2012, "Polarised
//! light in computer graphics", SIGGRAPH Asia course, §§ 4–5; Mitsuba 3's polarised
//! variants, Jakob et al. 2022, do the same). It is `path::step` (or `whitted::step`,
//! light tracing, BDPT) with the transport [`Polarized`] of this file.
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
//! **Light paths.** Light tracing and BDPT's light subpaths carry the transpose of that
//! bookkeeping: a [`Beam`], per lane the light's normalised Stokes vector through the
//! normalised matrices of the events so far (S0 is no longer 1 once a polariser has
//! acted), in the frame of the segment it travels. A connection is a [`Chain`] (the
//! camera side: the analyser alone for a splat, a camera subpath's product in BDPT)
//! through the one or two vertices the connection joins, by their non-delta lobes,
//! applied to the beam: the same Mueller matrices, evaluated for light travelling the
//! physical way, so the three integrators estimate one Stokes image.
//!
//! **What is not here yet.** Polarised area lights, photon mapping and the packet
//! engine of paths.
use super::bdpt::{self, Bdpt, Subpaths};
use super::toolkit::Vertex;
use super::transport::{LightEvent, Scatter, Transport};
use super::Context;
use crate::bsdf::{LobeFlags, Material, Polarizing};
use crate::camera::CameraRay;
use crate::math::Frame;
use crate::optics::mueller::Mueller;
use crate::scene::Scene;
use crate::spectrum::stokes::{any_perpendicular, mueller_from_rows, rotate_basis, StokesSpectrum};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use glam::{Mat4, Vec3, Vec4};

/// The normalised Stokes vector per lane (S0 = 1) of light `light` arriving from
/// direction `dir` (toward the light), and its frame; None when it is unpolarised.
#[inline]
fn light_state<const N: usize>(
    scene: &Scene,
    light: usize,
    dir: Vec3,
    wl: &SampledWavelengths<N>,
) -> Option<([Vec4; N], Vec3)> {
    if let Some(p) = scene.light_polarization(light) {
        let (s, x) = p.stokes(-dir);
        return Some(([s; N], x));
    }
    let l = &scene.lights[light];
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

/// Light on a segment of a light path, travelling away from the light: per lane its
/// Stokes vector relative to the scalar throughput (the light's normalised Stokes
/// vector through the normalised Mueller matrices of the events so far, so S0 need not
/// stay 1), and its frame x̂ (None: unpolarised, (S0, 0, 0, 0) in any frame).
#[derive(Clone, Copy)]
pub(crate) struct Beam<const N: usize> {
    s: [Vec4; N],
    x: Option<Vec3>,
}

impl<const N: usize> Beam<N> {
    /// Unpolarised light of unit intensity.
    #[inline]
    pub(crate) fn unpolarized() -> Self {
        Beam {
            s: [Vec4::X; N],
            x: None,
        }
    }

    /// The light `light` emitting along `d`.
    #[inline]
    pub(crate) fn emitted(
        scene: &Scene,
        light: usize,
        d: Vec3,
        wl: &SampledWavelengths<N>,
    ) -> Self {
        match light_state(scene, light, -d, wl) {
            None => Beam::unpolarized(),
            Some((s, x)) => Beam { s, x: Some(x) },
        }
    }

    /// The beam after scattering at a surface (`Transport::light_scattered`).
    #[inline]
    pub(crate) fn scatter(
        &self,
        material: &Material,
        frame: &Frame,
        to_local: Vec3,
        from_local: Vec3,
        flags: LobeFlags,
        wl: &SampledWavelengths<N>,
    ) -> Self {
        match material.mueller(to_local, from_local, flags, wl, frame) {
            Polarizing::Depolarizing => Beam {
                s: self.s.map(|v| Vec4::new(v.x, 0.0, 0.0, 0.0)),
                x: None,
            },
            Polarizing::Mueller { m, x_in, x_out } => {
                let s = match self.x {
                    None => self.s,
                    Some(x) => {
                        let d = -frame.to_world(from_local);
                        let r = rotate_basis(d, x, frame.to_world(x_in));
                        self.s.map(|v| r * v)
                    }
                };
                Beam {
                    s: std::array::from_fn(|i| m[i] * s[i]),
                    x: Some(frame.to_world(x_out)),
                }
            }
        }
    }
}

/// The camera's side of a path: per lane the product T of its events' normalised
/// Mueller matrices from the camera (module docs), and the frame x̂ of its current
/// segment.
#[derive(Clone, Copy)]
pub(crate) struct Chain<const N: usize> {
    t: [Mat4; N],
    x: Vec3,
}

impl<const N: usize> Chain<N> {
    /// At the camera, for its ray along `dir`: T is the camera's analyser (`[camera]
    /// polarizer`, `--polarizer`) or the identity, in the camera's frame.
    pub(crate) fn at_camera(ctx: &Context, dir: Vec3) -> Self {
        let scene = ctx.scene;
        let analyser = match ctx.settings.polarizer.or(scene.camera.polarizer) {
            Some(a) => {
                let m = Mueller::linear_polarizer(a as f64);
                mueller_from_rows(m.0.map(|r| r.map(|v| v as f32)))
            }
            None => Mat4::IDENTITY,
        };
        Chain {
            t: [analyser; N],
            x: scene.camera.stokes_x(dir),
        }
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

    /// The chain past the event at `v` (see [`Chain::through`]).
    #[inline]
    pub(crate) fn past(
        &self,
        v: &Vertex,
        wi: Vec3,
        wi_local: Vec3,
        flags: LobeFlags,
        wl: &SampledWavelengths<N>,
    ) -> Self {
        let (t, x_in) = self.through(v, wi, wi_local, flags, wl);
        Chain {
            t,
            x: x_in.unwrap_or_else(|| any_perpendicular(wi)),
        }
    }

    /// The Stokes radiance the camera receives of `beam` on the chain's current
    /// segment, travelling along `d`, with the scalar contribution `c`.
    #[inline]
    pub(crate) fn receive(
        &self,
        beam: &Beam<N>,
        d: Vec3,
        c: SampledSpectrum<N>,
    ) -> StokesSpectrum<N> {
        match beam.x {
            None => StokesSpectrum(std::array::from_fn(|i| {
                self.t[i].col(0) * (beam.s[i].x * c.0[i])
            })),
            Some(x) => {
                let r = rotate_basis(d, x, self.x);
                StokesSpectrum(std::array::from_fn(|i| {
                    self.t[i] * (r * beam.s[i]) * c.0[i]
                }))
            }
        }
    }
}

/// What a polarised camera path carries: its [`Chain`] and the Stokes radiance found
/// so far.
pub(crate) struct CameraPath<const N: usize> {
    chain: Chain<N>,
    out: StokesSpectrum<N>,
}

/// Polarised transport: camera paths carry a [`Chain`], light paths a [`Beam`], BDPT
/// both per segment of its subpaths (`bdpt::carrier`).
pub(crate) struct Polarized;

impl<const N: usize> Transport<N> for Polarized {
    const POLARIZED: bool = true;
    type Value = StokesSpectrum<N>;
    type Camera = CameraPath<N>;
    type Light = Beam<N>;
    type Bdpt = bdpt::PolarizedSubpaths<N>;

    #[inline]
    fn at_camera(ctx: &Context, cam: &CameraRay) -> CameraPath<N> {
        CameraPath {
            chain: Chain::at_camera(ctx, cam.ray.dir),
            out: StokesSpectrum::zero(),
        }
    }

    #[inline]
    fn delivered(cam: CameraPath<N>, _: SampledSpectrum<N>) -> StokesSpectrum<N> {
        cam.out
    }

    #[inline]
    fn found(
        cam: &mut CameraPath<N>,
        ctx: &Context,
        _: &mut SampledSpectrum<N>,
        c: SampledSpectrum<N>,
        light: usize,
        dir: Vec3,
        wl: &SampledWavelengths<N>,
    ) {
        // `dir` points toward the light: its light travels along −dir.
        let beam = Beam::emitted(ctx.scene, light, -dir, wl);
        cam.out += cam.chain.receive(&beam, -dir, c);
    }

    #[inline]
    fn lit(
        cam: &mut CameraPath<N>,
        ctx: &Context,
        _: &mut SampledSpectrum<N>,
        c: SampledSpectrum<N>,
        at: Scatter,
        light: usize,
        wl: &SampledWavelengths<N>,
    ) {
        // Light samples reach the non-delta lobes only; the light travels along −wi.
        let chain = cam
            .chain
            .past(at.v, at.wi, at.wi_local, non_delta(at.v), wl);
        let beam = Beam::emitted(ctx.scene, light, -at.wi, wl);
        cam.out += chain.receive(&beam, -at.wi, c);
    }

    #[inline]
    fn scattered(
        cam: &mut CameraPath<N>,
        at: Scatter,
        flags: LobeFlags,
        wl: &SampledWavelengths<N>,
    ) {
        cam.chain = cam.chain.past(at.v, at.wi, at.wi_local, flags, wl);
    }

    #[inline]
    fn emitted(ctx: &Context, light: usize, d: Vec3, wl: &SampledWavelengths<N>) -> Beam<N> {
        Beam::emitted(ctx.scene, light, d, wl)
    }

    #[inline]
    fn light_scattered(
        b: &mut Beam<N>,
        e: &LightEvent,
        flags: LobeFlags,
        wl: &SampledWavelengths<N>,
    ) {
        *b = b.scatter(e.material, e.frame, e.to_local, e.from_local, flags, wl);
    }

    #[inline]
    fn seen(
        b: &Beam<N>,
        ctx: &Context,
        at: Option<&LightEvent>,
        d: Vec3,
        c: SampledSpectrum<N>,
        wl: &SampledWavelengths<N>,
    ) -> StokesSpectrum<N> {
        let chain = Chain::at_camera(ctx, -d);
        let chain = match at {
            None => chain,
            Some(e) => {
                let v = Vertex::Surface {
                    material: e.material,
                    frame: e.frame,
                    wo_local: e.to_local,
                };
                let from = e.frame.to_world(e.from_local);
                chain.past(&v, from, e.from_local, non_delta(&v), wl)
            }
        };
        let travel = match at {
            None => d,
            Some(e) => -e.frame.to_world(e.from_local),
        };
        chain.receive(b, travel, c)
    }

    #[inline]
    fn subpaths(b: &Bdpt<N>, paths: &Subpaths<N>, dir: Vec3) -> bdpt::PolarizedSubpaths<N> {
        bdpt::PolarizedSubpaths::new(b, paths, dir)
    }

    #[inline]
    fn strategy(
        x: &bdpt::PolarizedSubpaths<N>,
        b: &Bdpt<N>,
        paths: &Subpaths<N>,
        st: (usize, usize),
        sampled: Option<&bdpt::Vertex<N>>,
        c: SampledSpectrum<N>,
    ) -> StokesSpectrum<N> {
        x.value(b, paths, st, sampled, c)
    }
}

/// The lobes light samples and connections reach at `v`: a surface's non-delta ones.
#[inline]
pub(crate) fn non_delta(v: &Vertex) -> LobeFlags {
    match v {
        Vertex::Surface { material, .. } => {
            LobeFlags::from_bits(material.flags().bits() & !LobeFlags::SPECULAR.bits())
        }
        Vertex::Medium { .. } => LobeFlags::NONE,
    }
}
