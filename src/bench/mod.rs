//! Embree traversal throughput, for `heron bench traversal` and the criterion bench:
//! primary (coherent) camera rays and incoherent secondary rays (one random direction
//! in the hemisphere of each primary hit), as single rays, packets of 4, 8 or 16, or
//! Embree 3's ray streams, each timed beside a raw-Embree C program tracing the very
//! same rays ([`raw`]), so the table shows heron's own overhead as a ratio; and a real
//! render's rays recorded and replayed through the same C program ([`limit`]), so that a
//! render's time can be put beside raw Embree's time for its rays.
//!
//! The camera follows Embree's tutorial viewer (`viewer --benchmark`): eye, look-at,
//! up and a vertical field of view, one ray through each pixel centre.
use crate::accel::embree::{self, Hit, RayCoherence, RayQuery};
use crate::geometry::Mesh;
use crate::math::Rng;
use crate::{HeronError, Result};
use glam::Vec3;
use std::path::Path;
use std::time::{Duration, Instant};

pub mod limit;
pub mod raw;

use raw::{RawEmbree, Tally};

/// How rays are handed to Embree.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Width {
    /// `rtcIntersect1`, one ray per call.
    One,
    /// `rtcIntersect4`/`8`/`16` packets of consecutive rays.
    Four,
    Eight,
    Sixteen,
    /// Embree 3's stream API, `rtcIntersect1M` on [`STREAM_CHUNK`] rays per call.
    Stream,
}

/// Rays per `rtcIntersect1M` call (the C program uses the same).
pub const STREAM_CHUNK: usize = 256;

impl Width {
    pub const ALL: [Width; 5] = [
        Width::One,
        Width::Four,
        Width::Eight,
        Width::Sixteen,
        Width::Stream,
    ];

    pub fn parse(s: &str) -> std::result::Result<Width, String> {
        match s {
            "1" => Ok(Width::One),
            "4" => Ok(Width::Four),
            "8" => Ok(Width::Eight),
            "16" => Ok(Width::Sixteen),
            "stream" => Ok(Width::Stream),
            other => Err(format!("expected 1, 4, 8, 16 or stream, got {other:?}")),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Width::One => "1",
            Width::Four => "4",
            Width::Eight => "8",
            Width::Sixteen => "16",
            Width::Stream => "stream",
        }
    }

    /// The C program's code for this width (0 is the stream).
    fn code(self) -> u32 {
        match self {
            Width::One => 1,
            Width::Four => 4,
            Width::Eight => 8,
            Width::Sixteen => 16,
            Width::Stream => 0,
        }
    }
}

#[derive(Clone, Debug)]
pub struct TraversalOptions {
    pub eye: Vec3,
    pub look_at: Vec3,
    pub up: Vec3,
    /// Vertical field of view in degrees.
    pub fov_deg: f32,
    pub width: u32,
    pub height: u32,
    pub widths: Vec<Width>,
    /// Timed passes per (ray set, width), after one untimed warm-up pass.
    pub rounds: u32,
    /// Also time the raw-Embree C program on the same rays, interleaved.
    pub raw: bool,
}

/// The two ray sets: camera rays through pixel centres in 4×4 pixel tiles (so that
/// consecutive rays, and so packets of 4, 8 and 16, cover compact patches; coherent
/// context), and one uniformly random hemisphere ray from each camera hit (incoherent
/// context).
pub const SETS: [&str; 2] = ["coherent", "incoherent"];

/// One (ray set, width) row of the table.
#[derive(Clone, Debug)]
pub struct Row {
    pub set: usize,
    pub width: Width,
    pub rays: u64,
    pub hits: u64,
    /// Per round, heron's pass time in ns; empty when the library lacks this query.
    pub heron_ns: Vec<u64>,
    /// Per round, the raw program's pass time in ns (with `raw`).
    pub raw_ns: Vec<u64>,
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n == 0 {
        f64::NAN
    } else if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

impl Row {
    pub fn heron_mrays(&self) -> f64 {
        let mut v: Vec<f64> = self
            .heron_ns
            .iter()
            .map(|&t| self.rays as f64 / t as f64 * 1e3)
            .collect();
        median(&mut v)
    }
    pub fn raw_mrays(&self) -> f64 {
        let mut v: Vec<f64> = self
            .raw_ns
            .iter()
            .map(|&t| self.rays as f64 / t as f64 * 1e3)
            .collect();
        median(&mut v)
    }
    /// heron's throughput over the raw program's: the median over rounds of the ratio of
    /// the two passes timed back to back (1 means no overhead).
    pub fn ratio(&self) -> f64 {
        let mut v: Vec<f64> = self
            .heron_ns
            .iter()
            .zip(&self.raw_ns)
            .map(|(&h, &r)| r as f64 / h as f64)
            .collect();
        median(&mut v)
    }
}

#[derive(Clone, Debug, Default)]
pub struct TraversalReport {
    pub triangles: usize,
    pub build: Duration,
    pub embree_version: (u32, u32, u32),
    pub rows: Vec<Row>,
}

/// Loads every object of an OBJ file as one triangle mesh, with the scene loader's OBJ
/// reader (errors name the line).
pub fn load_obj_mesh(path: &Path) -> Result<Mesh> {
    let err = |message: String| HeronError::Io {
        path: path.to_path_buf(),
        message,
    };
    let text = std::fs::read_to_string(path).map_err(|e| err(format!("cannot read: {e}")))?;
    let groups = crate::scene::load::obj::parse_obj(&text).map_err(err)?;
    let mut mesh = Mesh::default();
    for g in groups {
        let base = mesh.positions.len() as u32;
        mesh.positions.extend(g.positions);
        mesh.indices.extend(
            g.indices
                .iter()
                .map(|t| [base + t[0], base + t[1], base + t[2]]),
        );
    }
    if mesh.indices.is_empty() {
        return Err(err("no triangles".into()));
    }
    Ok(mesh)
}

/// A deterministic closed mesh of about `2 n²` triangles: a sphere of radius 1 with a
/// smooth bumpy displacement, so rays hit at many depths and angles.
pub fn procedural_mesh(n: u32) -> Mesh {
    let n = n.max(4);
    let mut mesh = Mesh::default();
    for i in 0..=n {
        let theta = std::f32::consts::PI * i as f32 / n as f32;
        for j in 0..=n {
            let phi = 2.0 * std::f32::consts::PI * j as f32 / n as f32;
            let r = 1.0 + 0.05 * (7.0 * theta).sin() * (9.0 * phi).cos();
            mesh.positions.push(
                r * Vec3::new(
                    theta.sin() * phi.cos(),
                    theta.cos(),
                    theta.sin() * phi.sin(),
                ),
            );
        }
    }
    let row = n + 1;
    for i in 0..n {
        for j in 0..n {
            let a = i * row + j;
            let (b, c, d) = (a + 1, a + row, a + row + 1);
            mesh.indices.push([a, c, b]);
            mesh.indices.push([b, c, d]);
        }
    }
    mesh
}

/// Writes a mesh as OBJ (positions and faces), through a temporary file.
pub fn write_obj(mesh: &Mesh, path: &Path) -> Result<()> {
    use std::io::Write;
    crate::files::write_atomically(path, |tmp| {
        let f = std::fs::File::create(tmp).map_err(|e| e.to_string())?;
        let mut w = std::io::BufWriter::new(f);
        let mut go = || -> std::io::Result<()> {
            writeln!(
                w,
                "# heron procedural mesh: {} triangles",
                mesh.indices.len()
            )?;
            for p in &mesh.positions {
                writeln!(w, "v {} {} {}", p.x, p.y, p.z)?;
            }
            for t in &mesh.indices {
                writeln!(w, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1)?;
            }
            w.flush()
        };
        go().map_err(|e| e.to_string())
    })
}

/// Camera rays of Embree's viewer camera for pixel (x, y) centres.
struct ViewCamera {
    eye: Vec3,
    right: Vec3,
    up: Vec3,
    fwd: Vec3,
    width: u32,
    height: u32,
}

impl ViewCamera {
    fn new(o: &TraversalOptions) -> Result<Self> {
        let fwd = (o.look_at - o.eye).normalize();
        let right = fwd.cross(o.up);
        if !fwd.is_finite() || right.length_squared() < 1e-12 {
            return Err(HeronError::Invalid(
                "--eye, --look-at and up must give a view direction not parallel to up".into(),
            ));
        }
        if !(o.fov_deg > 0.0 && o.fov_deg < 180.0) {
            return Err(HeronError::Invalid(format!(
                "--fov: expected degrees in (0, 180), got {}",
                o.fov_deg
            )));
        }
        let right = right.normalize();
        let up = right.cross(fwd);
        // Image plane at distance 1 with half-height tan(fov/2).
        let h = (0.5 * o.fov_deg.to_radians()).tan();
        Ok(ViewCamera {
            eye: o.eye,
            right: right * h,
            up: up * h,
            fwd,
            width: o.width,
            height: o.height,
        })
    }

    #[inline]
    fn ray(&self, x: u32, y: u32) -> RayQuery {
        let aspect = self.width as f32 / self.height as f32;
        let u = ((x as f32 + 0.5) / self.width as f32 * 2.0 - 1.0) * aspect;
        let v = 1.0 - (y as f32 + 0.5) / self.height as f32 * 2.0;
        RayQuery {
            origin: self.eye,
            dir: (self.fwd + u * self.right + v * self.up).normalize(),
            tnear: 0.0,
            tfar: f32::INFINITY,
        }
    }
}

/// A uniformly distributed direction in the hemisphere around `n`.
#[inline]
fn hemisphere(n: Vec3, rng: &mut Rng) -> Vec3 {
    let z = rng.uniform();
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * std::f32::consts::PI * rng.uniform();
    let (t, b) = n.any_orthonormal_pair();
    (r * phi.cos()) * t + (r * phi.sin()) * b + z * n
}

/// The two ray sets of [`SETS`] for the view in `o`.
pub fn ray_sets(scene: &embree::Scene, o: &TraversalOptions) -> Result<[Vec<RayQuery>; 2]> {
    let cam = ViewCamera::new(o)?;
    let mut primary = Vec::with_capacity(o.width as usize * o.height as usize);
    for ty in 0..o.height.div_ceil(4) {
        for tx in 0..o.width.div_ceil(4) {
            for k in 0..16u32 {
                let (x, y) = (tx * 4 + k % 4, ty * 4 + k / 4);
                if x < o.width && y < o.height {
                    primary.push(cam.ray(x, y));
                }
            }
        }
    }
    let secondary = primary
        .iter()
        .enumerate()
        .filter_map(|(i, r)| {
            let h = scene.intersect1(r)?;
            let mut n = h.ng.normalize();
            if n.dot(r.dir) > 0.0 {
                n = -n;
            }
            let mut rng = Rng::new(i as u64, 17);
            Some(RayQuery {
                origin: r.origin + h.t * r.dir,
                dir: hemisphere(n, &mut rng),
                tnear: 1e-4,
                tfar: f32::INFINITY,
            })
        })
        .collect();
    Ok([primary, secondary])
}

/// A reusable pass of heron's own queries over `rays`.
struct HeronTracer {
    scratch: embree::StreamScratch,
}

impl HeronTracer {
    /// One pass; None where the library lacks the query (the stream API on Embree 4).
    /// Never inlined, so that `scripts/callgrind_traversal.sh` can count its instructions
    /// per pass (as the C program's `trace1` … `trace_stream`).
    #[inline(never)]
    fn trace(
        &mut self,
        scene: &embree::Scene,
        rays: &[RayQuery],
        width: Width,
        coherence: RayCoherence,
    ) -> Option<Tally> {
        let mut t = Tally::default();
        // By value, as a renderer reads its hits (the C program reads Embree's record).
        let mut add = |h: Hit| {
            t.hits += 1;
            t.prim_sum += h.prim_id as u64;
            t.t_sum += h.t as f64;
        };
        macro_rules! packets {
            ($w:literal, $mask:ty, $query:ident) => {
                for c in rays.chunks($w) {
                    // Full chunks are borrowed in place, as the C program reads its rays.
                    let active = <$mask>::MAX >> ($w - c.len());
                    match <&[RayQuery; $w]>::try_from(c) {
                        Ok(p) => scene.$query(p, active, coherence, |_, h| add(h)),
                        Err(_) => {
                            let mut p = [c[0]; $w];
                            p[..c.len()].copy_from_slice(c);
                            scene.$query(&p, active, coherence, |_, h| add(h))
                        }
                    }
                }
            };
        }
        match width {
            Width::One => {
                for r in rays {
                    if let Some(h) = scene.intersect1_with(r, coherence) {
                        add(h);
                    }
                }
            }
            Width::Four => packets!(4, u8, intersect4_each),
            Width::Eight => packets!(8, u8, intersect8_each),
            Width::Sixteen => packets!(16, u16, intersect16_each),
            Width::Stream => {
                for c in rays.chunks(STREAM_CHUNK) {
                    let traced =
                        scene.intersect_stream_each(c, coherence, &mut self.scratch, |_, h| add(h));
                    if !traced {
                        return None;
                    }
                }
            }
        }
        Some(t)
    }
}

/// Builds the BVH, makes the ray sets and times every (set, width) pass `rounds` times
/// on the calling thread, heron and (with `raw`) the raw-Embree program back to back,
/// alternating which goes first. Every pass of both must find the same hits.
pub fn run_traversal(mesh: &Mesh, o: &TraversalOptions) -> Result<TraversalReport> {
    if o.width == 0 || o.height == 0 || o.rounds == 0 {
        return Err(HeronError::Invalid(
            "--size and --rounds must be positive".into(),
        ));
    }
    if o.widths.is_empty() {
        return Err(HeronError::Invalid(
            "--widths: expected at least one".into(),
        ));
    }
    // The same device configuration as the C program (Embree's default threads for the
    // build); queries run on this thread, with the FTZ/DAZ bits heron's workers use.
    embree::set_flush_denormals();
    let device = embree::Device::new("")?;
    let t0 = Instant::now();
    let mut b = device.scene_builder();
    b.add_triangle_mesh(&mesh.positions, &mesh.indices)?;
    let scene = b.commit()?;
    let build = t0.elapsed();
    let sets = ray_sets(&scene, o)?;
    let mut raw = if o.raw {
        Some(RawEmbree::start(mesh, &sets[0], &sets[1])?)
    } else {
        None
    };
    let mut tracer = HeronTracer {
        scratch: embree::StreamScratch::default(),
    };
    let coherence = [RayCoherence::Coherent, RayCoherence::Incoherent];
    let mut rows = Vec::new();
    for (set, rays) in sets.iter().enumerate() {
        for &width in &o.widths {
            let mut row = Row {
                set,
                width,
                rays: rays.len() as u64,
                hits: 0,
                heron_ns: Vec::new(),
                raw_ns: Vec::new(),
            };
            // Round 0 is the untimed warm-up (first touches of the BVH and the rays).
            for round in 0..=o.rounds {
                let mut heron_pass = || {
                    let t = Instant::now();
                    let tally = tracer.trace(&scene, rays, width, coherence[set]);
                    (t.elapsed().as_nanos() as u64, tally)
                };
                let mut raw_pass = || raw.as_mut().map(|r| r.trace(width, set)).transpose();
                let ((h_ns, h), r) = if round % 2 == 0 {
                    let h = heron_pass();
                    (h, raw_pass()?)
                } else {
                    let r = raw_pass()?;
                    (heron_pass(), r)
                };
                let Some(h) = h else {
                    break; // no such query in this Embree: the row stays empty
                };
                row.hits = h.hits;
                if let Some(r) = r.flatten() {
                    let same = r.tally.hits == h.hits
                        && r.tally.prim_sum == h.prim_sum
                        && (r.tally.t_sum - h.t_sum).abs() <= 1e-9 * h.t_sum.abs();
                    if !same {
                        return Err(HeronError::Invalid(format!(
                            "heron and raw Embree disagree on the {} rays at width {}: {h:?} vs {:?}",
                            SETS[set],
                            width.name(),
                            r.tally
                        )));
                    }
                    if round > 0 {
                        row.raw_ns.push(r.ns);
                    }
                }
                if round > 0 {
                    row.heron_ns.push(h_ns);
                }
            }
            rows.push(row);
        }
    }
    Ok(TraversalReport {
        triangles: mesh.indices.len(),
        build,
        embree_version: device.version(),
        rows,
    })
}
