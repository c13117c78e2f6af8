//! Embree traversal throughput, for `heron bench traversal` and the criterion bench:
//! primary (coherent) camera rays and incoherent secondary rays (one random direction
//! in the hemisphere of each primary hit), as single rays or 8-wide packets.
//!
//! The camera follows Embree's tutorial viewer (`viewer --benchmark`): eye, look-at,
//! up and a vertical field of view, one ray through each pixel centre, so its
//! frames/s × W × H can be held against heron's primary-ray throughput on the same OBJ.
use crate::accel::embree::{self, Hit, RayQuery};
use crate::geometry::Mesh;
use crate::math::Rng;
use crate::{HeronError, Result};
use glam::Vec3;
use rayon::prelude::*;
use std::path::Path;
use std::time::{Duration, Instant};

#[derive(Clone, Debug)]
pub struct TraversalOptions {
    pub eye: Vec3,
    pub look_at: Vec3,
    pub up: Vec3,
    /// Vertical field of view in degrees.
    pub fov_deg: f32,
    pub width: u32,
    pub height: u32,
    /// 1 (rtcIntersect1) or 8 (rtcIntersect8).
    pub packet: usize,
    pub frames: u32,
    /// Worker threads; 0 means one per core.
    pub threads: usize,
}

#[derive(Clone, Debug, Default)]
pub struct TraversalReport {
    pub triangles: usize,
    pub build: Duration,
    pub primary_rays: u64,
    pub primary_time: Duration,
    pub primary_hits: u64,
    pub secondary_rays: u64,
    pub secondary_time: Duration,
    pub secondary_hits: u64,
}

impl TraversalReport {
    pub fn primary_mrays(&self) -> f64 {
        self.primary_rays as f64 / self.primary_time.as_secs_f64().max(1e-12) / 1e6
    }
    pub fn secondary_mrays(&self) -> f64 {
        self.secondary_rays as f64 / self.secondary_time.as_secs_f64().max(1e-12) / 1e6
    }
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
    crate::film::write_atomically(path, |tmp| {
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

/// Traces one warm-up frame and `frames` timed frames of primary rays, then one incoherent secondary ray per
/// primary hit of the last frame (repeated `frames` times), on `mesh`.
pub fn run_traversal(mesh: &Mesh, o: &TraversalOptions) -> Result<TraversalReport> {
    if o.width == 0 || o.height == 0 || o.frames == 0 {
        return Err(HeronError::Invalid(
            "--size and --frames must be positive".into(),
        ));
    }
    if o.packet != 1 && o.packet != 8 {
        return Err(HeronError::Invalid(format!(
            "--packet: expected 1 or 8, got {}",
            o.packet
        )));
    }
    let cam = ViewCamera::new(o)?;
    let pool = embree::worker_pool(o.threads)?;
    let device = embree::Device::new("")?;
    let t0 = Instant::now();
    let mut b = device.scene_builder();
    b.add_triangle_mesh(&mesh.positions, &mesh.indices)?;
    let scene = b.commit()?;
    let mut report = TraversalReport {
        triangles: mesh.indices.len(),
        build: t0.elapsed(),
        ..Default::default()
    };

    // Primary rays: rows of 4×2 pixel blocks, so a packet covers a compact patch.
    let rows: Vec<u32> = (0..o.height.div_ceil(2)).collect();
    let mut secondary: Vec<RayQuery> = Vec::new();
    // One untimed warm-up frame: first touches of the BVH and thread start-up.
    pool.install(|| {
        rows.par_iter()
            .for_each(|&by| drop(trace_primary_row(&scene, &cam, by, o.packet, false)))
    });
    for frame in 0..o.frames {
        let last = frame + 1 == o.frames;
        let t = Instant::now();
        let per_row: Vec<(u64, Vec<RayQuery>)> = pool.install(|| {
            rows.par_iter()
                .map(|&by| trace_primary_row(&scene, &cam, by, o.packet, last))
                .collect()
        });
        report.primary_time += t.elapsed();
        report.primary_rays += o.width as u64 * o.height as u64;
        for (hits, rays) in per_row {
            report.primary_hits += hits;
            if last {
                secondary.extend(rays);
            }
        }
    }

    let chunks: Vec<&[RayQuery]> = secondary.chunks(1024).collect();
    for _ in 0..o.frames {
        let t = Instant::now();
        let hits: u64 = pool.install(|| {
            chunks
                .par_iter()
                .map(|c| trace_batch(&scene, c, o.packet))
                .sum()
        });
        report.secondary_time += t.elapsed();
        report.secondary_rays += secondary.len() as u64;
        report.secondary_hits += hits;
    }
    Ok(report)
}

fn trace_primary_row(
    scene: &embree::Scene,
    cam: &ViewCamera,
    by: u32,
    packet: usize,
    spawn: bool,
) -> (u64, Vec<RayQuery>) {
    let mut hits = 0u64;
    let mut next = Vec::new();
    let mut rng = Rng::new(by as u64, 17);
    let mut emit = |r: &RayQuery, h: &Option<Hit>, rng: &mut Rng| {
        if let Some(h) = h {
            hits += 1;
            if spawn {
                let mut n = h.ng.normalize();
                if n.dot(r.dir) > 0.0 {
                    n = -n;
                }
                next.push(RayQuery {
                    origin: r.origin + h.t * r.dir,
                    dir: hemisphere(n, rng),
                    tnear: 1e-4,
                    tfar: f32::INFINITY,
                });
            }
        }
    };
    for bx in 0..cam.width.div_ceil(4) {
        let mut rays = [RayQuery {
            origin: cam.eye,
            dir: Vec3::Z,
            tnear: 0.0,
            tfar: 0.0,
        }; 8];
        let mut active = 0u8;
        for k in 0..8u32 {
            let (x, y) = (bx * 4 + k % 4, by * 2 + k / 4);
            if x < cam.width && y < cam.height {
                rays[k as usize] = cam.ray(x, y);
                active |= 1 << k;
            }
        }
        if packet == 8 {
            let h = scene.intersect8(&rays, active);
            for k in 0..8 {
                if active & (1 << k) != 0 {
                    emit(&rays[k], &h[k], &mut rng);
                }
            }
        } else {
            for (k, r) in rays.iter().enumerate() {
                if active & (1 << k) != 0 {
                    let h = scene.intersect1(r);
                    emit(r, &h, &mut rng);
                }
            }
        }
    }
    (hits, next)
}

fn trace_batch(scene: &embree::Scene, rays: &[RayQuery], packet: usize) -> u64 {
    let mut hits = 0;
    if packet == 8 {
        for c in rays.chunks(8) {
            let mut p = [c[0]; 8];
            p[..c.len()].copy_from_slice(c);
            let active = if c.len() == 8 {
                0xff
            } else {
                (1u8 << c.len()) - 1
            };
            hits += scene
                .intersect8(&p, active)
                .iter()
                .take(c.len())
                .filter(|h| h.is_some())
                .count() as u64;
        }
    } else {
        hits = rays
            .iter()
            .filter(|r| scene.intersect1(r).is_some())
            .count() as u64;
    }
    hits
}
