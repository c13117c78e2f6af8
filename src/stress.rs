//! `heron stress SCENE`: random rays at the numerical edge cases of a scene's materials
//! and shapes, counting every non-finite value, every direction that is not of unit
//! length, every self-intersection and every light leak.
//!
//! Two kinds of case:
//!
//! * **Materials.** For each material, outgoing directions ωo at grazing incidence
//!   (cos θ log-uniform in [10⁻⁷, 1], either side), at the edge of total internal
//!   reflection (sin²θ = (1 − δ)/η², so cos²θt = δ with |δ| ≤ 10⁻⁷; materials with an
//!   interface only) and uniform over the sphere. Each draws a BSDF sample and evaluates
//!   f and the pdf at the sampled direction and at a grazing one, with 8 wavelength lanes,
//!   alternating radiance and importance transport. Every direction must be finite and
//!   unit length to 10⁻⁵; f, the pdf and the throughput weight finite and non-negative.
//! * **Shapes.** For each shape, rays aimed at random points of it (spheres uniformly,
//!   meshes by triangle, so that slivers are hit as often as large triangles) from
//!   grazing (as above) or cosine-distributed directions; at each hit the interaction
//!   must be finite, and three rays leave it with the render's [`RayOffset`]: the
//!   material's own sample, a grazing one back to the side the ray came from and one to
//!   the other side. Each is traced and classified:
//!   - a **self-hit** when it meets what it left: the same triangle, a coincident copy,
//!     a surface in the same plane within a few error bounds (away from edges), the same
//!     sphere after leaving it outward, a sphere it entered met from outside, a closed
//!     mesh it left outward met from inside;
//!   - a **leak** when it left into a closed shape (a sphere, or a mesh whose every edge
//!     has two triangles) and escaped the scene, or left a sphere inward and met
//!     something outside it.
//!
//! * **Media.** For each heterogeneous medium, rays through its majorant box (uniform,
//!   along its faces and parallel to its axes, where the grid walk divides by zero
//!   direction components), each tracked with 8 lanes of its σ_t by delta tracking
//!   (the free flight) and ratio tracking (a shadow ray): every weight, rescaled
//!   probability and transmittance must be finite and non-negative.
//!
//! Counts are deterministic for a seed: the rays are drawn in chunks of [`CHUNK`] from
//! per-chunk random streams, whatever the thread count.
use crate::accel::embree::{self, Hit};
use crate::bsdf::{BsdfContext, Material, TransportMode};
use crate::geometry::interaction::unit_normal;
use crate::geometry::{Interaction, Ray, RayOffset, Shape, ShapeKind};
use crate::math::warp::{cosine_hemisphere, uniform_sphere, uniform_triangle};
use crate::math::{Frame, Rng};
use crate::scene::Scene;
use crate::settings::WavelengthSampler;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use glam::{Vec2, Vec3};
use rayon::prelude::*;

/// Wavelength lanes of the material cases (heron's default).
const LANES: usize = 8;
/// How far from 1 a direction's length may be.
pub const UNIT_TOLERANCE: f32 = 1e-5;
/// The most grazing cosine drawn.
pub const MIN_COS: f32 = 1e-7;
/// The half-width of the band around the critical angle (in cos²θt).
pub const TIR_BAND: f32 = 1e-7;
/// Rays per random stream.
pub const CHUNK: u64 = 1 << 14;

/// What one case found.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct CaseReport {
    pub name: String,
    /// Directions drawn (material cases) or rays traced (shape cases).
    pub rays: u64,
    pub non_finite: u64,
    pub not_unit: u64,
    pub self_hits: u64,
    pub leaks: u64,
    /// The first failure in draw order, described.
    pub first: Option<String>,
}

impl CaseReport {
    pub fn failures(&self) -> u64 {
        self.non_finite + self.not_unit + self.self_hits + self.leaks
    }

    fn absorb(&mut self, o: CaseReport) {
        self.rays += o.rays;
        self.non_finite += o.non_finite;
        self.not_unit += o.not_unit;
        self.self_hits += o.self_hits;
        self.leaks += o.leaks;
        if self.first.is_none() {
            self.first = o.first;
        }
    }

    fn fail(&mut self, kind: Failure, what: impl FnOnce() -> String) {
        match kind {
            Failure::NonFinite => self.non_finite += 1,
            Failure::NotUnit => self.not_unit += 1,
            Failure::SelfHit => self.self_hits += 1,
            Failure::Leak => self.leaks += 1,
        }
        if self.first.is_none() {
            self.first = Some(what());
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Failure {
    NonFinite,
    NotUnit,
    SelfHit,
    Leak,
}

/// The incidence regimes of the material cases.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Incidence {
    Grazing,
    TirEdge,
    Uniform,
}

impl Incidence {
    pub const ALL: [Incidence; 3] = [Incidence::Grazing, Incidence::TirEdge, Incidence::Uniform];

    pub fn name(self) -> &'static str {
        match self {
            Incidence::Grazing => "grazing",
            Incidence::TirEdge => "TIR edge",
            Incidence::Uniform => "uniform",
        }
    }
}

/// Draws `rays` in chunks from independent streams, in parallel, and merges the chunks'
/// reports in order (so `first` is the first failure in draw order).
fn chunked(
    name: String,
    rays: u64,
    seed: u64,
    stream: u64,
    run: impl Fn(&mut Rng, u64, &mut CaseReport) + Sync,
) -> CaseReport {
    let chunks = rays.div_ceil(CHUNK);
    let parts: Vec<CaseReport> = (0..chunks)
        .into_par_iter()
        .map(|c| {
            // The renderer's float mode (flush-to-zero), whichever worker runs the chunk.
            embree::set_flush_denormals();
            let mut rng = Rng::new(seed ^ stream.wrapping_mul(0x9e37_79b9_7f4a_7c15), c);
            let n = CHUNK.min(rays - c * CHUNK);
            let mut r = CaseReport::default();
            run(&mut rng, n, &mut r);
            r
        })
        .collect();
    let mut report = CaseReport {
        name,
        ..CaseReport::default()
    };
    for p in parts {
        report.absorb(p);
    }
    report
}

fn u2(rng: &mut Rng) -> Vec2 {
    Vec2::new(rng.uniform(), rng.uniform())
}

/// A local direction with cos θ log-uniform in [MIN_COS, 1] on the side `sign`.
fn grazing_local(rng: &mut Rng, sign: f32) -> Vec3 {
    let cos = 10f32.powf(MIN_COS.log10() * rng.uniform());
    let sin = ((1.0 - cos) * (1.0 + cos)).sqrt();
    let phi = std::f32::consts::TAU * rng.uniform();
    Vec3::new(sin * phi.cos(), sin * phi.sin(), sign * cos)
}

fn finite(s: &SampledSpectrum<LANES>) -> bool {
    s.0.iter().all(|x| x.is_finite() && *x >= 0.0)
}

fn unit(v: Vec3) -> bool {
    (v.length() - 1.0).abs() <= UNIT_TOLERANCE
}

/// The outgoing direction of one material sample, or None when the regime does not
/// apply (no interface, or no side with total internal reflection).
fn material_wo(m: &Material, inc: Incidence, lambda: f32, rng: &mut Rng) -> Option<Vec3> {
    let side = if rng.uniform() < 0.5 { 1.0 } else { -1.0 };
    match inc {
        Incidence::Grazing => Some(grazing_local(rng, side)),
        Incidence::Uniform => Some(uniform_sphere(u2(rng))),
        Incidence::TirEdge => {
            // n_i/n_t for light arriving from outside (front) and from inside.
            let front = m.ior1_over_ior2(lambda, true);
            let back = m.ior1_over_ior2(lambda, false);
            let (r, sign) = if back > 1.0 && (side < 0.0 || front <= 1.0) {
                (back, -1.0)
            } else if front > 1.0 {
                (front, 1.0)
            } else {
                return None;
            };
            let delta = TIR_BAND * (2.0 * rng.uniform() - 1.0);
            let sin2 = (1.0 - delta) / (r * r);
            let cos = (1.0 - sin2).max(0.0).sqrt();
            let phi = std::f32::consts::TAU * rng.uniform();
            let sin = sin2.sqrt();
            Some(Vec3::new(sin * phi.cos(), sin * phi.sin(), sign * cos))
        }
    }
}

/// Whether the material has a side with total internal reflection (at 550 nm).
pub fn has_tir(m: &Material) -> bool {
    m.ior1_over_ior2(550.0, true) > 1.0 || m.ior1_over_ior2(550.0, false) > 1.0
}

/// One material case: `rays` outgoing directions in regime `inc`.
pub fn material_case(
    name: &str,
    m: &Material,
    inc: Incidence,
    rays: u64,
    seed: u64,
    stream: u64,
) -> CaseReport {
    chunked(
        format!("material {name}: {}", inc.name()),
        rays,
        seed,
        stream,
        |rng, n, r| {
            for i in 0..n {
                let wl =
                    SampledWavelengths::<LANES>::sample(WavelengthSampler::Visible, rng.uniform());
                let mode = if i % 2 == 0 {
                    TransportMode::Radiance
                } else {
                    TransportMode::Importance
                };
                let ctx = BsdfContext::radiance::<LANES>().with_mode(mode);
                let Some(wo) = material_wo(m, inc, wl.lambda[0], rng) else {
                    continue;
                };
                r.rays += 1;
                let (uc, u) = (rng.uniform(), u2(rng));
                let at = || format!("{name}: wo {wo:?}, λ {} nm, {mode:?}", wl.lambda[0]);
                if let Some(bs) = m.sample(wo, uc, u, &wl, &ctx) {
                    if !(bs.wi.is_finite() && finite(&bs.f) && bs.pdf >= 0.0 && bs.pdf.is_finite())
                    {
                        r.fail(Failure::NonFinite, || {
                            format!(
                                "{}: sample wi {:?} f {:?} pdf {}",
                                at(),
                                bs.wi,
                                bs.f.0,
                                bs.pdf
                            )
                        });
                        continue;
                    }
                    if !unit(bs.wi) {
                        r.fail(Failure::NotUnit, || {
                            format!("{}: sample wi {:?} |wi| {}", at(), bs.wi, bs.wi.length())
                        });
                    }
                    if !finite(&bs.weight()) || !bs.eta.is_finite() {
                        r.fail(Failure::NonFinite, || {
                            format!("{}: weight {:?} eta {}", at(), bs.weight().0, bs.eta)
                        });
                    }
                    check_eval(m, wo, bs.wi, &wl, &ctx, r, &at);
                }
                let side = if rng.uniform() < 0.5 { 1.0 } else { -1.0 };
                let wi = grazing_local(rng, side);
                check_eval(m, wo, wi, &wl, &ctx, r, &at);
            }
        },
    )
}

fn check_eval(
    m: &Material,
    wo: Vec3,
    wi: Vec3,
    wl: &SampledWavelengths<LANES>,
    ctx: &BsdfContext,
    r: &mut CaseReport,
    at: &dyn Fn() -> String,
) {
    let f = m.eval(wo, wi, wl, ctx).f;
    let pdf = m.pdf(wo, wi, wl, ctx);
    if !(finite(&f) && pdf >= 0.0 && pdf.is_finite()) {
        r.fail(Failure::NonFinite, || {
            format!("{}: eval at wi {wi:?}: f {:?} pdf {pdf}", at(), f.0)
        });
    }
}

/// A point of the shape (spheres uniformly, meshes by triangle then uniformly within
/// it), its outward unit normal, and a length of the order of the shape's size.
fn shape_point(shape: &Shape, rng: &mut Rng) -> (Vec3, Vec3, f32) {
    match &shape.kind {
        ShapeKind::Sphere { center, radius } => {
            let n = uniform_sphere(u2(rng));
            (*center + *radius * n, n, *radius)
        }
        ShapeKind::Mesh(m) => {
            let i = ((rng.uniform() * m.indices.len() as f32) as usize).min(m.indices.len() - 1);
            let [a, b, c] = m.triangle(i as u32);
            let bc = uniform_triangle(u2(rng));
            let p = bc[0] * a + bc[1] * b + bc[2] * c;
            let size = (b - a).length().max((c - a).length()).max((c - b).length());
            (p, unit_normal((b - a).cross(c - a), Vec3::Z), size)
        }
    }
}

/// Whether each shape of the scene is closed ([`Shape::is_closed`]), computed once per
/// scene.
pub fn closed_shapes(scene: &Scene) -> Vec<bool> {
    scene.shapes.iter().map(Shape::is_closed).collect()
}

/// One shape case: `rays` rays traced at and from shape `index` of `scene`; `closed` is
/// [`closed_shapes`] of the scene.
pub fn shape_case(
    scene: &Scene,
    accel: &embree::Scene,
    offset: RayOffset,
    closed: &[bool],
    index: usize,
    rays: u64,
    seed: u64,
) -> CaseReport {
    let shape = &scene.shapes[index];
    let is_closed = closed[index];
    let kind = match &shape.kind {
        ShapeKind::Sphere { radius, .. } => format!("sphere r = {radius:e}"),
        ShapeKind::Mesh(m) => format!(
            "{} mesh of {} triangles",
            if is_closed { "closed" } else { "open" },
            m.indices.len()
        ),
    };
    let name = format!(
        "shape {index} ({kind}, {})",
        scene.material_names[shape.material as usize]
    );
    let label = name.clone();
    let target = ShapeTarget {
        scene,
        accel,
        offset,
        index,
        closed,
        label: &label,
    };
    chunked(name, rays, seed, 1 << 32 | index as u64, |rng, n, r| {
        let budget = r.rays + n;
        while r.rays < budget {
            shape_sample(&target, rng, r);
        }
    })
}

/// The shape a case aims at: shape `index` of `scene`, traced in `accel` with rays
/// leaving surfaces by `offset`; `closed` is [`closed_shapes`] of the scene and `label`
/// names the case in failures.
#[derive(Clone, Copy)]
struct ShapeTarget<'a> {
    scene: &'a Scene,
    accel: &'a embree::Scene,
    offset: RayOffset,
    index: usize,
    closed: &'a [bool],
    label: &'a str,
}

/// One ray at the shape and its three continuations.
fn shape_sample(target: &ShapeTarget, rng: &mut Rng, r: &mut CaseReport) {
    let ShapeTarget {
        scene,
        accel,
        offset,
        index,
        closed,
        label,
    } = *target;
    let (p, n, size) = shape_point(&scene.shapes[index], rng);
    // From outside for closed shapes; from either side for open ones.
    let side = if closed[index] || rng.uniform() < 0.5 {
        1.0
    } else {
        -1.0
    };
    let local = if rng.uniform() < 0.5 {
        grazing_local(rng, side)
    } else {
        let c = cosine_hemisphere(u2(rng));
        Vec3::new(c.x, c.y, side * c.z)
    };
    let dir = -Frame::from_z(n).to_world(local).normalize();
    let origin = p - 2.0 * size * dir;
    let ray = Ray::new(origin, dir, 0.0, f32::INFINITY);
    r.rays += 1;
    let Some(hit) = accel.intersect1(&ray.query()) else {
        return;
    };
    let wl = SampledWavelengths::<LANES>::sample(WavelengthSampler::Visible, rng.uniform());
    let (it, material) = scene.interaction(&ray, &hit, offset.is_robust());
    // The classification's tolerances come from the hit point's error bound whichever
    // offsets the rays use (with ε offsets the render leaves it zero).
    let err = if offset.is_robust() {
        it.p_err
    } else {
        scene.interaction(&ray, &hit, true).0.p_err
    };
    let at = |what: &str| {
        format!(
            "{label}: ray {origin:?} → {dir:?} hit shape {} prim {} at {:?}: {what}",
            hit.geom_id, hit.prim_id, it.position
        )
    };
    if !it.position.is_finite() || !err.is_finite() || !it.n_outward.is_finite() {
        r.fail(Failure::NonFinite, || at("non-finite interaction"));
        return;
    }
    if !unit(it.n_outward) {
        r.fail(Failure::NotUnit, || {
            at(&format!("normal {:?} not unit", it.n_outward))
        });
    }
    let left = Left {
        scene,
        hit: &hit,
        it: &it,
        err,
        closed: closed[hit.geom_id as usize],
    };
    let frame = it.frame();
    let wo = frame.to_local(-ray.dir);
    let ctx = BsdfContext::radiance::<LANES>();
    let sampled = material
        .sample(wo, rng.uniform(), u2(rng), &wl, &ctx)
        .map(|bs| frame.to_world(bs.wi));
    let back = Frame::from_z(it.normal).to_world(grazing_local(rng, 1.0));
    let through = Frame::from_z(it.normal).to_world(grazing_local(rng, -1.0));
    for (what, w) in [
        ("sampled", sampled),
        ("grazing back", Some(back)),
        ("grazing through", Some(through)),
    ] {
        let Some(w) = w else { continue };
        if !w.is_finite() {
            r.fail(Failure::NonFinite, || {
                at(&format!("{what} direction {w:?}"))
            });
            continue;
        }
        if !unit(w) {
            r.fail(Failure::NotUnit, || {
                at(&format!("{what} direction {w:?}, |w| = {}", w.length()))
            });
        }
        let out = offset.spawn(&it.spawn_point(), w);
        if !out.origin.is_finite() {
            r.fail(Failure::NonFinite, || {
                at(&format!("{what} origin {:?}", out.origin))
            });
            continue;
        }
        r.rays += 1;
        let next = accel.intersect1(&out.query());
        if let Some(kind) = left.classify(&out, next.as_ref()) {
            r.fail(kind, || {
                let met = next.map_or("nothing".to_string(), |h2| {
                    format!("shape {} prim {} at t = {:e}", h2.geom_id, h2.prim_id, h2.t)
                });
                at(&format!("{what} ray {w:?} from {:?} met {met}", out.origin))
            });
        }
    }
}

/// A surface point rays left, for classifying where they went.
struct Left<'a> {
    scene: &'a Scene,
    hit: &'a Hit,
    it: &'a Interaction,
    /// The hit point's error bound.
    err: Vec3,
    /// Whether the shape left encloses a volume.
    closed: bool,
}

impl Left<'_> {
    /// The failure, if any, of the ray `out` that left this point and met `next`:
    ///
    /// - **self-hit**: it met the surface it left: the same triangle, a coincident copy
    ///   (the same three vertices, in any shape), a triangle facing the same way in the
    ///   same plane within a few error bounds of the origin (acne; away from the edges
    ///   of the triangle left, where a neighbour in the plane, coplanar only to rounding,
    ///   may be as close), the same sphere after leaving it outward, or the same closed
    ///   shape from the side it should not be on (entering a sphere it left inward;
    ///   meeting a closed mesh from inside after leaving it outward: the origin was
    ///   inside);
    /// - **leak**: it left into a closed shape and got out without meeting the shape
    ///   from inside: it escaped the scene, or (for a sphere) met something outside it.
    ///   Hits within the error bound of an edge are exempt: there a ray may pass on
    ///   either side of the neighbouring face.
    ///
    /// Not counted: a surface crossing the one left (a box standing on or sunk into a
    /// floor) met at the crease, a nearly coplanar neighbour met further away (a quad's
    /// two halves, two walls in one plane given to six digits, meet at cos θ = 10⁻⁷
    /// legitimately), and, for a closed mesh left inward, another shape met first (it may
    /// be inside the mesh: heron cannot tell without a point-in-mesh test).
    fn classify(&self, out: &Ray, next: Option<&Hit>) -> Option<Failure> {
        let (scene, h1, it) = (self.scene, self.hit, self.it);
        let s1 = &scene.shapes[h1.geom_id as usize];
        let into = out.dir.dot(it.n_outward) < 0.0;
        let t1 = match &s1.kind {
            ShapeKind::Mesh(m) => Some(m.triangle(h1.prim_id)),
            ShapeKind::Sphere { .. } => None,
        };
        let edge = t1.is_some_and(|t| near_edge(it, t, 4.0 * self.err.max_element()));
        let Some(h2) = next else {
            return (into && self.closed && !edge).then_some(Failure::Leak);
        };
        let same = h1.geom_id == h2.geom_id;
        // Leaving outward, through the shape's outside; inward, from its inside.
        let from_inside = out.dir.dot(h2.ng) > 0.0;
        if let ShapeKind::Sphere { center, radius } = &s1.kind {
            return if same {
                (!into || !from_inside).then_some(Failure::SelfHit)
            } else if into {
                // Something met first must be inside the sphere.
                let x = out.at(h2.t);
                let inside = (x - *center).length() <= *radius + 4.0 * self.err.max_element();
                (!inside).then_some(Failure::Leak)
            } else {
                None
            };
        }
        let t1 = t1?;
        if same && self.closed && !into && from_inside && !edge {
            return Some(Failure::SelfHit);
        }
        let ShapeKind::Mesh(m2) = &scene.shapes[h2.geom_id as usize].kind else {
            return None;
        };
        if same && h1.prim_id == h2.prim_id {
            return Some(Failure::SelfHit);
        }
        let t2 = m2.triangle(h2.prim_id);
        if t2.iter().all(|v| t1.contains(v)) {
            return Some(Failure::SelfHit);
        }
        let n2 = unit_normal((t2[1] - t2[0]).cross(t2[2] - t2[0]), Vec3::ZERO);
        let reach = 16.0 * self.err.max_element();
        let acne = n2.dot(it.n_outward) > 1.0 - 1e-4
            && n2.dot(t2[0] - it.position).abs() <= reach
            && (out.at(h2.t) - it.position).length() <= reach
            && !near_edge(it, t1, reach);
        acne.then_some(Failure::SelfHit)
    }
}

/// Whether the hit lies within `tol` of an edge of its triangle, where a ray may pass
/// on either side of the neighbouring face (so leaving "into" a closed mesh there does
/// not prove that it must hit it again).
fn near_edge(it: &Interaction, t: [Vec3; 3], tol: f32) -> bool {
    (0..3).any(|k| {
        let (a, b) = (t[(k + 1) % 3], t[(k + 2) % 3]);
        let e = b - a;
        let d = (it.position - a).cross(e).length() / e.length();
        !(d > tol)
    })
}

/// Every case of a scene: each material in each regime that applies, then each shape.
pub fn run(
    scene: &Scene,
    accel: &embree::Scene,
    offset: RayOffset,
    rays: u64,
    seed: u64,
) -> Vec<CaseReport> {
    let mut out = Vec::new();
    for (i, m) in scene.materials.iter().enumerate() {
        for inc in Incidence::ALL {
            if inc == Incidence::TirEdge && !has_tir(m) {
                continue;
            }
            out.push(material_case(
                &scene.material_names[i],
                m,
                inc,
                rays,
                seed,
                (i as u64) << 8 | inc as u64,
            ));
        }
    }
    let closed = closed_shapes(scene);
    for i in 0..scene.shapes.len() {
        out.push(shape_case(scene, accel, offset, &closed, i, rays, seed));
    }
    for (i, m) in scene.media.iter().enumerate() {
        if m.density.is_some() {
            out.push(medium_case(i, m, rays, seed));
        }
    }
    out
}

/// One medium case: `rays` rays through a heterogeneous medium's box (module docs).
pub fn medium_case(index: usize, m: &crate::medium::Medium, rays: u64, seed: u64) -> CaseReport {
    use crate::medium::tracking::{delta_tracking, ratio_tracking, Flight, Weights};
    let density = m.density.as_ref().expect("a heterogeneous medium");
    let (lo, hi) = density.majorants.bounds();
    chunked(
        format!("medium {index}: tracking"),
        rays,
        seed,
        0xDE45_0000 | index as u64,
        |rng, n, r| {
            for i in 0..n {
                let wl =
                    SampledWavelengths::<LANES>::sample(WavelengthSampler::Visible, rng.uniform());
                let k = m.majorant_sigma_t(&wl);
                let at = |p| m.extinction_at(p, &wl);
                let inside =
                    lo + (hi - lo) * Vec3::new(rng.uniform(), rng.uniform(), rng.uniform());
                let (o, d) = match i % 3 {
                    // Uniform: from outside the box through a point inside it.
                    0 => {
                        let d = uniform_sphere(u2(rng));
                        (inside - d * (hi - lo).length(), d)
                    }
                    // In a face's plane.
                    1 => {
                        let a = (rng.uniform() * 3.0) as usize % 3;
                        let mut o = inside;
                        o[a] = if rng.uniform() < 0.5 { lo[a] } else { hi[a] };
                        let mut d = uniform_sphere(u2(rng));
                        d[a] = 0.0;
                        (o, d.try_normalize().unwrap_or(Vec3::X))
                    }
                    // Along an axis.
                    _ => {
                        let a = (rng.uniform() * 3.0) as usize % 3;
                        let mut d = Vec3::ZERO;
                        d[a] = if rng.uniform() < 0.5 { 1.0 } else { -1.0 };
                        let mut o = inside;
                        o[a] = if d[a] > 0.0 { lo[a] } else { hi[a] };
                        (o, d)
                    }
                };
                let len = 2.0 * (hi - lo).length();
                r.rays += 1;
                let ok =
                    |s: &SampledSpectrum<LANES>| s.0.iter().all(|v| v.is_finite() && *v >= 0.0);
                let one = SampledSpectrum::splat(1.0);
                let mut w = Weights {
                    beta: one,
                    r_u: one,
                    r_l: one,
                };
                let u0 = rng.uniform();
                let flight = delta_tracking(density, (o, d, len), k, at, u0, rng, &mut w);
                let (tr, t) = match flight {
                    Flight::Collided { t, tr, .. } => (tr, t),
                    Flight::Escaped { tr } => (tr, 0.0),
                };
                if !(ok(&w.beta) && ok(&w.r_u) && ok(&w.r_l) && ok(&tr) && t.is_finite()) {
                    r.fail(Failure::NonFinite, || {
                        format!(
                            "delta tracking from {o:?} along {d:?}, λ {} nm: beta {:?} r_u {:?} r_l {:?} T̄ {:?} t {t}",
                            wl.lambda[0], w.beta.0, w.r_u.0, w.r_l.0, tr.0
                        )
                    });
                    continue;
                }
                let (tr, a) = ratio_tracking(density, (o, d, len), k, at, rng);
                if !(ok(&tr) && ok(&a)) {
                    r.fail(Failure::NonFinite, || {
                        format!(
                            "ratio tracking from {o:?} along {d:?}, λ {} nm: T {:?} a {:?}",
                            wl.lambda[0], tr.0, a.0
                        )
                    });
                }
            }
        },
    )
}

/// The report as a table, one case per line, then the first failure of each case that
/// failed.
pub fn format_table(reports: &[CaseReport]) -> String {
    use std::fmt::Write as _;
    let w = reports
        .iter()
        .map(|r| r.name.chars().count())
        .max()
        .unwrap_or(4)
        .max(4);
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{:<w$}  {:>11}  {:>10}  {:>8}  {:>9}  {:>5}",
        "case", "rays", "non-finite", "not-unit", "self-hits", "leaks"
    );
    for r in reports {
        let _ = writeln!(
            s,
            "{:<w$}  {:>11}  {:>10}  {:>8}  {:>9}  {:>5}",
            r.name, r.rays, r.non_finite, r.not_unit, r.self_hits, r.leaks
        );
    }
    for r in reports.iter().filter(|r| r.first.is_some()) {
        let _ = writeln!(
            s,
            "first failure in {}: {}",
            r.name,
            r.first.as_ref().unwrap()
        );
    }
    s
}
