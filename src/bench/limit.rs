//! How far a render is from Embree's own speed: `heron bench record` logs every query a
//! real render sends to Embree (closest-hit and shadow rays, in the order and grouping
//! heron sent them: one-ray calls, packets with their valid masks), `heron bench replay`
//! makes the same calls again through the raw C program (`embree_raw.c --replay`) and
//! through heron's own wrapper, and `heron bench limit` does both and times the render
//! against the raw replay, interleaved: the render's time as a multiple of raw Embree's
//! time for its rays is how far heron is from the traversal limit.
//!
//! **The ray log file** (little-endian):
//!
//! | bytes | field |
//! | --- | --- |
//! | 16 | `heron-rays 1\n` and three zero bytes |
//! | 4 | geometry count G; then G times: u32 kind (0 triangle mesh, 1 sphere); a mesh: u32 vertices V, u32 triangles T, 3·V f32 positions, 3·T u32 indices; a sphere: f32 x, y, z, radius |
//! | 8 | byte length L of the calls |
//! | L | the calls, as `accel::embree::record` lays them out |
//! | 48 | the tally of what the calls found in heron: u64 calls, rays, hits, primitive-ID sum, f64 distance sum, u64 occluded |
//!
//! Geometry i is the scene's shape i, as `render::build_accel` adds them, built with
//! heron's scene flags (robust, high quality) on both sides.
use std::path::{Path, PathBuf};
use std::time::Instant;

use glam::Vec3;

use super::raw::RawEmbree;
use crate::accel::embree::record::{CALL_HEADER, OP_OCCLUDED, OP_STREAM, RAY_BYTES};
use crate::accel::embree::{self, QueryTally, RayCoherence, RayLog, RayQuery};
use crate::geometry::ShapeKind;
use crate::render::{RenderOptions, Renderer};
use crate::scene::Scene;
use crate::{HeronError, Result};

const MAGIC: &[u8; 16] = b"heron-rays 1\n\0\0\0";

/// A shape as Embree got it.
#[derive(Clone, Debug, PartialEq)]
pub enum LogGeometry {
    Mesh {
        positions: Vec<Vec3>,
        indices: Vec<[u32; 3]>,
    },
    Sphere {
        center: Vec3,
        radius: f32,
    },
}

/// A ray log with the geometry it was traced on.
#[derive(Clone, Debug)]
pub struct RayLogFile {
    pub geometry: Vec<LogGeometry>,
    pub log: RayLog,
}

/// One call of a log, decoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Call {
    /// `accel::embree::record`'s op: the width (1, 4, 8, 16; 0 a stream) plus
    /// `OP_OCCLUDED` for occlusion queries.
    pub op: u8,
    pub coherent: bool,
    /// Active lanes of a packet, a bit each.
    pub valid: u16,
    /// The call's rays: `rays[first..first + n]`.
    pub first: usize,
    pub n: usize,
}

/// Calls of each kind in a log, in `op` order, with their names.
pub fn call_counts(calls: &[Call]) -> Vec<(String, u64)> {
    let mut counts = std::collections::BTreeMap::new();
    for c in calls {
        *counts.entry(c.op).or_insert(0u64) += 1;
    }
    counts.into_iter().map(|(op, n)| (op_name(op), n)).collect()
}

fn op_name(op: u8) -> String {
    let kind = if op & OP_OCCLUDED != 0 {
        "occluded"
    } else {
        "intersect"
    };
    match op & !OP_OCCLUDED {
        OP_STREAM => "intersect_stream".into(),
        w => format!("{kind}{w}"),
    }
}

impl RayLogFile {
    /// The log of a render of `scene` (geometry i = shape i).
    pub fn new(scene: &Scene, log: RayLog) -> Self {
        let geometry = scene
            .shapes
            .iter()
            .map(|s| match &s.kind {
                ShapeKind::Sphere { center, radius } => LogGeometry::Sphere {
                    center: *center,
                    radius: *radius,
                },
                ShapeKind::Mesh(m) => LogGeometry::Mesh {
                    positions: m.positions.clone(),
                    indices: m.indices.clone(),
                },
            })
            .collect();
        RayLogFile { geometry, log }
    }

    /// The file's bytes.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut b = Vec::with_capacity(self.log.calls.len() + 1024);
        b.extend(MAGIC);
        b.extend((self.geometry.len() as u32).to_le_bytes());
        for g in &self.geometry {
            match g {
                LogGeometry::Mesh { positions, indices } => {
                    b.extend(0u32.to_le_bytes());
                    b.extend((positions.len() as u32).to_le_bytes());
                    b.extend((indices.len() as u32).to_le_bytes());
                    for p in positions {
                        for v in p.to_array() {
                            b.extend(v.to_le_bytes());
                        }
                    }
                    for t in indices {
                        for v in t {
                            b.extend(v.to_le_bytes());
                        }
                    }
                }
                LogGeometry::Sphere { center, radius } => {
                    b.extend(1u32.to_le_bytes());
                    for v in [center.x, center.y, center.z, *radius] {
                        b.extend(v.to_le_bytes());
                    }
                }
            }
        }
        b.extend((self.log.calls.len() as u64).to_le_bytes());
        b.extend(&self.log.calls);
        let t = &self.log.tally;
        for v in [t.calls, t.rays, t.hits, t.prim_sum] {
            b.extend(v.to_le_bytes());
        }
        b.extend(t.t_sum.to_le_bytes());
        b.extend(t.occluded.to_le_bytes());
        b
    }

    /// Writes the file through a temporary file renamed into place.
    pub fn write(&self, path: &Path) -> Result<()> {
        let bytes = self.to_bytes();
        crate::files::write_atomically(path, |tmp| {
            std::fs::write(tmp, &bytes).map_err(|e| e.to_string())
        })
    }

    /// Reads and checks a ray log: every length, geometry that Embree can build, every
    /// call's op, width, lanes and active rays (valid, as heron sends them), and a tally
    /// that counts the calls and rays it follows. Errors name the file and what was
    /// expected.
    pub fn read(path: &Path) -> Result<(Self, Vec<Call>, Vec<RayQuery>)> {
        let err = |message: String| HeronError::Io {
            path: path.to_path_buf(),
            message,
        };
        let bytes = std::fs::read(path).map_err(|e| err(format!("cannot read: {e}")))?;
        Self::parse(&bytes).map_err(err)
    }

    /// [`RayLogFile::read`] on bytes; the error is the message without the path.
    pub fn parse(bytes: &[u8]) -> std::result::Result<(Self, Vec<Call>, Vec<RayQuery>), String> {
        let mut r = Reader { b: bytes, at: 0 };
        if r.take(16).ok() != Some(&MAGIC[..]) {
            return Err(
                "not a heron ray log (expected the header \"heron-rays 1\", as heron bench record writes)"
                    .into(),
            );
        }
        let ng = r.u32("the geometry count")?;
        let mut geometry = Vec::new();
        for g in 0..ng {
            let what = |s: &str| format!("geometry {g}: {s}");
            match r.u32(&what("its kind"))? {
                0 => {
                    let nv = r.u32(&what("the vertex count"))? as usize;
                    let nt = r.u32(&what("the triangle count"))? as usize;
                    if nv == 0 || nt == 0 {
                        return Err(what("expected a mesh with vertices and triangles"));
                    }
                    r.need(12 * (nv + nt), &what("the positions and indices"))?;
                    let positions: Vec<Vec3> = (0..nv)
                        .map(|_| Vec3::new(r.f32_(), r.f32_(), r.f32_()))
                        .collect();
                    let indices: Vec<[u32; 3]> =
                        (0..nt).map(|_| [r.u32_(), r.u32_(), r.u32_()]).collect();
                    if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
                        return Err(what(&format!("vertex {i} is not finite")));
                    }
                    if let Some(t) = indices
                        .iter()
                        .position(|t| t.iter().any(|&i| i as usize >= nv))
                    {
                        return Err(what(&format!(
                            "triangle {t} refers to a vertex beyond the {nv} vertices"
                        )));
                    }
                    geometry.push(LogGeometry::Mesh { positions, indices });
                }
                1 => {
                    r.need(16, &what("the sphere"))?;
                    let (center, radius) = (Vec3::new(r.f32_(), r.f32_(), r.f32_()), r.f32_());
                    if !(center.is_finite() && radius.is_finite() && radius > 0.0) {
                        return Err(what(
                            "expected a sphere with a finite centre and a positive radius",
                        ));
                    }
                    geometry.push(LogGeometry::Sphere { center, radius });
                }
                k => {
                    return Err(what(&format!(
                        "expected kind 0 (mesh) or 1 (sphere), got {k}"
                    )))
                }
            }
        }
        let len = r.u64("the length of the calls")?;
        let left = (bytes.len() - r.at) as u64;
        if len.checked_add(48) != Some(left) {
            return Err(format!(
                "expected {len} bytes of calls and a 48-byte tally after the geometry, found {left} bytes"
            ));
        }
        let calls_bytes = &bytes[r.at..r.at + len as usize];
        let (calls, rays) = decode_calls(calls_bytes)?;
        r.at += len as usize;
        let tally = QueryTally {
            calls: r.u64_(),
            rays: r.u64_(),
            hits: r.u64_(),
            prim_sum: r.u64_(),
            t_sum: f64::from_le_bytes(r.take(8).expect("length checked").try_into().unwrap()),
            occluded: r.u64_(),
        };
        let traced: u64 = calls
            .iter()
            .map(|c| {
                if c.op == OP_STREAM {
                    c.n as u64
                } else {
                    c.valid.count_ones() as u64
                }
            })
            .sum();
        if tally.calls != calls.len() as u64 || tally.rays != traced {
            return Err(format!(
                "the tally counts {} calls and {} rays, but the log holds {} calls of {traced} rays",
                tally.calls,
                tally.rays,
                calls.len()
            ));
        }
        let log = RayLog {
            calls: calls_bytes.to_vec(),
            tally,
        };
        Ok((RayLogFile { geometry, log }, calls, rays))
    }
}

/// The calls of a log and all their rays.
fn decode_calls(b: &[u8]) -> std::result::Result<(Vec<Call>, Vec<RayQuery>), String> {
    let mut calls = Vec::new();
    let mut rays = Vec::new();
    let mut at = 0;
    while at < b.len() {
        let k = calls.len();
        if b.len() - at < CALL_HEADER {
            return Err(format!(
                "call {k}: expected an 8-byte header, found {} bytes",
                b.len() - at
            ));
        }
        let op = b[at];
        let coherent = b[at + 1];
        let valid = u16::from_le_bytes([b[at + 2], b[at + 3]]);
        let n = u32::from_le_bytes(b[at + 4..at + 8].try_into().unwrap()) as usize;
        let width = op & !OP_OCCLUDED;
        let ok_op = matches!(width, 1 | 4 | 8 | 16) || op == OP_STREAM;
        if !ok_op {
            return Err(format!(
                "call {k}: expected an op of width 1, 4, 8 or 16 (plus 128 for occlusion) or 0 (a stream), got {op}"
            ));
        }
        if coherent > 1 {
            return Err(format!(
                "call {k}: expected a coherence flag 0 or 1, got {coherent}"
            ));
        }
        let (want_n, ok_valid) = match width {
            0 => (n.max(1), valid == 0),
            1 => (1, valid == 1),
            w => (w as usize, valid != 0 && (valid as u32) < (1u32 << w)),
        };
        if n != want_n {
            return Err(format!(
                "call {k}: {} expects {want_n} rays, got {n}",
                op_name(op)
            ));
        }
        if !ok_valid {
            return Err(format!(
                "call {k}: {} with an impossible valid mask {valid:#x}",
                op_name(op)
            ));
        }
        at += CALL_HEADER;
        if (b.len() - at) / RAY_BYTES < n {
            return Err(format!(
                "call {k}: expected {n} rays of 32 bytes, the calls end first"
            ));
        }
        let first = rays.len();
        for i in 0..n {
            let f = |j: usize| {
                let o = at + RAY_BYTES * i + 4 * j;
                f32::from_le_bytes(b[o..o + 4].try_into().unwrap())
            };
            let q = RayQuery {
                origin: Vec3::new(f(0), f(1), f(2)),
                tnear: f(3),
                dir: Vec3::new(f(4), f(5), f(6)),
                tfar: f(7),
            };
            // heron sends Embree only valid rays (a stream's invalid ones as the empty
            // segment tnear 0, tfar -1); Embree's behaviour on others is undefined.
            let active = width == 0 || valid >> i & 1 != 0;
            let empty = width == 0 && q.tnear == 0.0 && q.tfar == -1.0;
            if active && !q.is_valid() && !empty {
                return Err(format!(
                    "call {k}: ray {i} is not one Embree can trace: {q:?}"
                ));
            }
            rays.push(q);
        }
        at += RAY_BYTES * n;
        calls.push(Call {
            op,
            coherent: coherent == 1,
            valid,
            first,
            n,
        });
    }
    Ok((calls, rays))
}

struct Reader<'a> {
    b: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> std::result::Result<&'a [u8], String> {
        if self.b.len() - self.at < n {
            return Err(format!("the file ends at byte {}", self.b.len()));
        }
        let s = &self.b[self.at..self.at + n];
        self.at += n;
        Ok(s)
    }
    fn need(&self, n: usize, what: &str) -> std::result::Result<(), String> {
        if self.b.len() - self.at < n {
            return Err(format!(
                "expected {n} bytes of {what}, the file ends after {}",
                self.b.len() - self.at
            ));
        }
        Ok(())
    }
    fn u32(&mut self, what: &str) -> std::result::Result<u32, String> {
        self.need(4, what)?;
        Ok(self.u32_())
    }
    fn u64(&mut self, what: &str) -> std::result::Result<u64, String> {
        self.need(8, what)?;
        Ok(self.u64_())
    }
    /// After `need`.
    fn u32_(&mut self) -> u32 {
        u32::from_le_bytes(self.take(4).expect("length checked").try_into().unwrap())
    }
    fn u64_(&mut self) -> u64 {
        u64::from_le_bytes(self.take(8).expect("length checked").try_into().unwrap())
    }
    fn f32_(&mut self) -> f32 {
        f32::from_bits(self.u32_())
    }
}

/// Builds the log's geometry as an Embree scene with heron's own wrapper.
pub fn build_scene(device: &embree::Device, geometry: &[LogGeometry]) -> Result<embree::Scene> {
    let mut b = device.scene_builder();
    for g in geometry {
        match g {
            LogGeometry::Mesh { positions, indices } => b.add_triangle_mesh(positions, indices)?,
            LogGeometry::Sphere { center, radius } => b.add_sphere(*center, *radius)?,
        };
    }
    Ok(b.commit()?)
}

/// Makes every call of a log again through heron's wrapper, on one thread, and sums
/// what they found as the recorder did; None when the log has a stream call and the
/// library no stream API.
#[inline(never)]
pub fn replay_heron(
    scene: &embree::Scene,
    calls: &[Call],
    rays: &[RayQuery],
    scratch: &mut embree::StreamScratch,
) -> Option<QueryTally> {
    let mut t = QueryTally::default();
    let coherence = |c: &Call| {
        if c.coherent {
            RayCoherence::Coherent
        } else {
            RayCoherence::Incoherent
        }
    };
    macro_rules! packet {
        ($c:expr, $w:literal, $mask:ty, $each:ident, $occluded:ident) => {{
            let p: &[RayQuery; $w] = rays[$c.first..$c.first + $w].try_into().unwrap();
            if $c.op & OP_OCCLUDED != 0 {
                t.occluded += scene
                    .$occluded(p, $c.valid as $mask, coherence($c))
                    .count_ones() as u64;
            } else {
                scene.$each(p, $c.valid as $mask, coherence($c), |_, h| {
                    t.hits += 1;
                    t.prim_sum += h.prim_id as u64;
                    t.t_sum += h.t as f64;
                });
            }
        }};
    }
    for c in calls {
        t.calls += 1;
        t.rays += if c.op == OP_STREAM {
            c.n as u64
        } else {
            c.valid.count_ones() as u64
        };
        match c.op & !OP_OCCLUDED {
            1 => {
                let q = &rays[c.first];
                if c.op & OP_OCCLUDED != 0 {
                    t.occluded += scene.occluded1_with(q, coherence(c)) as u64;
                } else if let Some(h) = scene.intersect1_with(q, coherence(c)) {
                    t.hits += 1;
                    t.prim_sum += h.prim_id as u64;
                    t.t_sum += h.t as f64;
                }
            }
            4 => packet!(c, 4, u8, intersect4_each, occluded4_with),
            8 => packet!(c, 8, u8, intersect8_each, occluded8_with),
            16 => packet!(c, 16, u16, intersect16_each, occluded16_with),
            _ => {
                let traced = scene.intersect_stream_each(
                    &rays[c.first..c.first + c.n],
                    coherence(c),
                    scratch,
                    |_, h| {
                        t.hits += 1;
                        t.prim_sum += h.prim_id as u64;
                        t.t_sum += h.t as f64;
                    },
                );
                if !traced {
                    return None;
                }
            }
        }
    }
    Some(t)
}

/// Whether two tallies agree: counts exactly, the distance sums to 1e-9 (the same
/// additions in the same order give the same bits; the margin is for printing).
pub fn same_tally(a: &QueryTally, b: &QueryTally) -> bool {
    a.calls == b.calls
        && a.rays == b.rays
        && a.hits == b.hits
        && a.prim_sum == b.prim_sum
        && a.occluded == b.occluded
        && (a.t_sum - b.t_sum).abs() <= 1e-9 * a.t_sum.abs().max(1.0)
}

/// A render recorded on one thread: the log, and the rays the render counted
/// (`RenderStats::total_rays`).
pub fn record(scene: &Scene, opts: &RenderOptions) -> Result<(RayLogFile, u64)> {
    let renderer = Renderer::new(scene)?;
    renderer.accel().record();
    let mut opts = opts.clone();
    opts.threads = 1;
    let (_, stats) = renderer.render(&opts)?;
    let log = renderer.accel().take_recording().unwrap_or_default();
    Ok((RayLogFile::new(scene, log), stats.total_rays()))
}

/// Timed rounds of [`limit`]: per round, heron's render (one thread, a scene that never
/// recorded), the raw program's replay and heron's wrapper's replay, in ns.
#[derive(Clone, Debug, Default)]
pub struct LimitReport {
    pub tally: QueryTally,
    /// Rays the recorded render counted.
    pub counted_rays: u64,
    pub calls: Vec<(String, u64)>,
    pub log_bytes: u64,
    pub render_ns: Vec<u64>,
    pub raw_ns: Vec<u64>,
    pub wrapper_ns: Vec<u64>,
    /// Whether the raw program could replay (no stream call on Embree 4).
    pub replayed: bool,
}

/// Median, minimum and maximum.
pub fn spread(v: &[f64]) -> (f64, f64, f64) {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    if s.is_empty() {
        return (f64::NAN, f64::NAN, f64::NAN);
    }
    let n = s.len();
    let m = if n % 2 == 1 {
        s[n / 2]
    } else {
        0.5 * (s[n / 2 - 1] + s[n / 2])
    };
    (m, s[0], s[n - 1])
}

/// Replays `path` `rounds` times through the raw program and through heron's wrapper,
/// alternating which goes first; every pass must find the log's tally.
pub fn replay(path: &Path, rounds: u32) -> Result<LimitReport> {
    let (file, calls, rays) = RayLogFile::read(path)?;
    let mut report = LimitReport {
        tally: file.log.tally,
        calls: call_counts(&calls),
        log_bytes: std::fs::metadata(path).map_or(0, |m| m.len()),
        ..Default::default()
    };
    timed_rounds(path, &file, &calls, &rays, rounds, None, &mut report)?;
    Ok(report)
}

/// Records a render of `scene` to `log` (a temporary file if None), then times `rounds`
/// interleaved rounds of the render and the replays ([`LimitReport`]).
pub fn limit(
    scene: &Scene,
    opts: &RenderOptions,
    log: Option<&Path>,
    rounds: u32,
) -> Result<LimitReport> {
    let (file, counted) = record(scene, opts)?;
    let tmp;
    let path: PathBuf = match log {
        Some(p) => p.to_path_buf(),
        None => {
            tmp = TempFile(std::env::temp_dir().join(format!(
                "heron-rays-{}-{}.bin",
                std::process::id(),
                std::time::SystemTime::now()
                    .duration_since(std::time::UNIX_EPOCH)
                    .map_or(0, |d| d.as_nanos())
            )));
            tmp.0.clone()
        }
    };
    file.write(&path)?;
    drop(file);
    let (file, calls, rays) = RayLogFile::read(&path)?;
    let mut report = LimitReport {
        tally: file.log.tally,
        counted_rays: counted,
        calls: call_counts(&calls),
        log_bytes: std::fs::metadata(&path).map_or(0, |m| m.len()),
        ..Default::default()
    };
    let renderer = Renderer::new(scene)?;
    let mut opts = opts.clone();
    opts.threads = 1;
    let mut render = || -> Result<u64> {
        let (_, stats) = renderer.render(&opts)?;
        Ok(stats.wall.as_nanos() as u64)
    };
    timed_rounds(
        &path,
        &file,
        &calls,
        &rays,
        rounds,
        Some(&mut render),
        &mut report,
    )?;
    Ok(report)
}

/// Removes a file on drop.
struct TempFile(PathBuf);

impl Drop for TempFile {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

type RenderFn<'a> = &'a mut dyn FnMut() -> Result<u64>;

fn timed_rounds(
    path: &Path,
    file: &RayLogFile,
    calls: &[Call],
    rays: &[RayQuery],
    rounds: u32,
    mut render: Option<RenderFn>,
    report: &mut LimitReport,
) -> Result<()> {
    if rounds == 0 {
        return Err(HeronError::Invalid("--rounds: expected at least 1".into()));
    }
    // Both replays on this thread, with the FTZ/DAZ bits heron's workers and the C
    // program use.
    embree::set_flush_denormals();
    let device = embree::Device::new("")?;
    let scene = build_scene(&device, &file.geometry)?;
    let mut scratch = embree::StreamScratch::default();
    let mut raw = RawEmbree::start_replay(path)?;
    let want = file.log.tally;
    let check = |what: &str, got: &QueryTally| -> Result<()> {
        if same_tally(&want, got) {
            Ok(())
        } else {
            Err(HeronError::Invalid(format!(
                "{}: {what} found {got:?}, but the recorded render found {want:?} (a log \
                 replays exactly only with the Embree library and CPU that recorded it)",
                path.display()
            )))
        }
    };
    // Round 0 is an untimed warm-up.
    for round in 0..=rounds {
        let mut raw_pass = || raw.replay();
        let mut wrapper_pass = || {
            let t = Instant::now();
            let tally = replay_heron(&scene, calls, rays, &mut scratch);
            (t.elapsed().as_nanos() as u64, tally)
        };
        let (r, (w_ns, w), h_ns) = if round % 2 == 0 {
            let h = render.as_mut().map(|f| f()).transpose()?;
            let r = raw_pass()?;
            (r, wrapper_pass(), h)
        } else {
            let w = wrapper_pass();
            let r = raw_pass()?;
            let h = render.as_mut().map(|f| f()).transpose()?;
            (r, w, h)
        };
        let Some((r_ns, r)) = r else {
            // A stream call on Embree 4: nothing to replay.
            return Ok(());
        };
        check("the raw-Embree replay", &r)?;
        if let Some(w) = w {
            check("heron's replay", &w)?;
        }
        report.replayed = true;
        if round > 0 {
            report.raw_ns.push(r_ns);
            report.wrapper_ns.push(w_ns);
            report.render_ns.extend(h_ns);
        }
    }
    Ok(())
}

impl LimitReport {
    /// The report as printed: a comment line of what was replayed, then CSV rows
    /// `measure,median_s,min_s,max_s,over_raw` (heron's render, heron's wrapper replay
    /// and the raw replay; `over_raw` is the median over rounds of the measure's time
    /// over the same round's raw replay).
    pub fn text(&self) -> String {
        let t = &self.tally;
        let calls: Vec<String> = self.calls.iter().map(|(k, n)| format!("{k} {n}")).collect();
        let mut s = format!(
            "# calls: {}; rays {}, hits {}, occluded {}; log {:.1} MB\n",
            calls.join(", "),
            t.rays,
            t.hits,
            t.occluded,
            self.log_bytes as f64 / 1e6
        );
        if !self.replayed {
            s.push_str("# the log has stream calls, which this Embree lacks: nothing replayed\n");
            return s;
        }
        s.push_str("measure,median_s,min_s,max_s,over_raw\n");
        let mut row = |name: &str, ns: &[u64]| {
            if ns.is_empty() {
                return;
            }
            let secs: Vec<f64> = ns.iter().map(|&n| n as f64 * 1e-9).collect();
            let ratios: Vec<f64> = ns
                .iter()
                .zip(&self.raw_ns)
                .map(|(&a, &r)| a as f64 / r as f64)
                .collect();
            let (m, lo, hi) = spread(&secs);
            s.push_str(&format!(
                "{name},{m:.6},{lo:.6},{hi:.6},{:.3}\n",
                spread(&ratios).0
            ));
        };
        row("heron_render", &self.render_ns);
        row("heron_replay", &self.wrapper_ns);
        row("raw_replay", &self.raw_ns);
        s
    }
}
