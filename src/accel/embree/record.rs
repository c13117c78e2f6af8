//! The ray log: every query a [`Scene`](super::Scene) sends to Embree while recording,
//! in the order and grouping it sent them (one-ray calls, packets with their valid
//! masks, streams), for `heron bench record`/`limit`, which replay the log through a raw
//! C program (src/bench/embree_raw.c) to measure how far a render is from Embree's own
//! speed on the very same rays.
//!
//! Recording is off unless [`Scene::record`](super::Scene::record) was called: each
//! query then pays one load and one never-taken branch (`OnceLock::get`), and the
//! recording itself lives in functions marked `#[cold]`, out of the query's code.
//!
//! **Calls.** Each call is an 8-byte header, then its rays (little-endian):
//!
//! | bytes | field |
//! | --- | --- |
//! | 1 | `op`: [`OP_OCCLUDED`] for `rtcOccluded*`, else 0, plus the width: 1, 4, 8, 16, or 0 for Embree 3's stream `rtcIntersect1M` |
//! | 1 | 1 for the coherent context flag, else 0 |
//! | 2 | the packet's valid mask as a bit per lane (lane `i` is bit `1 << i`); 1 for a single ray, 0 for a stream |
//! | 4 | `n`, the rays that follow: 1, the packet width (every lane, active or not), or the stream's length |
//! | 32·n | per ray: origin x, y, z, tnear, direction x, y, z, tfar (`f32`), as Embree got them |
//!
//! Rays heron answers without calling Embree (invalid rays, see `RayQuery`) are not
//! calls; a stream's invalid rays are logged as the empty segment Embree got.
use std::sync::Mutex;

use super::{Hit, RayQuery};

/// Added to a call's width in `op` for occlusion queries.
pub const OP_OCCLUDED: u8 = 0x80;
/// The width code of Embree 3's stream query (`rtcIntersect1M`).
pub const OP_STREAM: u8 = 0;
/// Bytes of a call's header.
pub const CALL_HEADER: usize = 8;
/// Bytes of a logged ray.
pub const RAY_BYTES: usize = 32;

/// What the logged calls found, summed in call and lane order, so a replay that makes
/// the same calls finds exactly the same numbers.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct QueryTally {
    /// Calls to Embree.
    pub calls: u64,
    /// Rays Embree traced: one per single-ray call, the active lanes of a packet, every
    /// ray of a stream.
    pub rays: u64,
    /// Closest-hit rays that hit something, and the sums of their primitive IDs and
    /// distances (`tfar`, in f64).
    pub hits: u64,
    pub prim_sum: u64,
    pub t_sum: f64,
    /// Occlusion rays that were occluded.
    pub occluded: u64,
}

impl QueryTally {
    fn hit(&mut self, h: &Hit) {
        self.hits += 1;
        self.prim_sum += h.prim_id as u64;
        self.t_sum += h.t as f64;
    }
}

/// The calls recorded so far ([`Scene::take_recording`](super::Scene::take_recording)).
#[derive(Clone, Debug, Default)]
pub struct RayLog {
    /// The calls, as the module documentation lays them out.
    pub calls: Vec<u8>,
    pub tally: QueryTally,
}

/// A scene's recorder: the log behind a lock (renders record on one thread, so that the
/// order of the calls is the render's own; more threads interleave them).
#[derive(Default)]
pub(super) struct Recorder(Mutex<RayLog>);

impl Recorder {
    pub(super) fn take(&self) -> RayLog {
        std::mem::take(&mut *self.0.lock().unwrap_or_else(|e| e.into_inner()))
    }

    fn with(&self, f: impl FnOnce(&mut RayLog)) {
        f(&mut self.0.lock().unwrap_or_else(|e| e.into_inner()))
    }

    /// A single-ray closest-hit call and its answer.
    #[cold]
    #[inline(never)]
    pub(super) fn intersect1(&self, ray: &RayQuery, coherent: bool, hit: Option<&Hit>) {
        self.with(|log| {
            push_call(log, 1, coherent, 1, std::slice::from_ref(ray));
            log.tally.rays += 1;
            if let Some(h) = hit {
                log.tally.hit(h);
            }
        })
    }

    /// A single-ray occlusion call and its answer.
    #[cold]
    #[inline(never)]
    pub(super) fn occluded1(&self, ray: &RayQuery, coherent: bool, occluded: bool) {
        self.with(|log| {
            push_call(log, OP_OCCLUDED | 1, coherent, 1, std::slice::from_ref(ray));
            log.tally.rays += 1;
            log.tally.occluded += occluded as u64;
        })
    }

    /// A packet call (`rays.len()` lanes, those of `valid` active) and its answers: the
    /// hits in lane order for a closest-hit query, the occluded lanes' bits for an
    /// occlusion query.
    #[cold]
    #[inline(never)]
    pub(super) fn packet(
        &self,
        occlusion: bool,
        rays: &[RayQuery],
        valid: u16,
        coherent: bool,
        hits: &[Option<Hit>],
        occluded: u16,
    ) {
        self.with(|log| {
            let op = rays.len() as u8 | if occlusion { OP_OCCLUDED } else { 0 };
            push_call(log, op, coherent, valid, rays);
            log.tally.rays += valid.count_ones() as u64;
            for h in hits.iter().flatten() {
                log.tally.hit(h);
            }
            log.tally.occluded += occluded.count_ones() as u64;
        })
    }

    /// A stream call (`rays` as Embree got them) and its hits in ray order.
    #[cold]
    #[inline(never)]
    pub(super) fn stream(&self, rays: &[RayQuery], coherent: bool, hits: &[Hit]) {
        self.with(|log| {
            push_call(log, OP_STREAM, coherent, 0, rays);
            log.tally.rays += rays.len() as u64;
            for h in hits {
                log.tally.hit(h);
            }
        })
    }
}

fn push_call(log: &mut RayLog, op: u8, coherent: bool, valid: u16, rays: &[RayQuery]) {
    let b = &mut log.calls;
    b.reserve(CALL_HEADER + RAY_BYTES * rays.len());
    b.push(op);
    b.push(coherent as u8);
    b.extend(valid.to_le_bytes());
    b.extend((rays.len() as u32).to_le_bytes());
    for r in rays {
        for v in [
            r.origin.x, r.origin.y, r.origin.z, r.tnear, r.dir.x, r.dir.y, r.dir.z, r.tfar,
        ] {
            b.extend(v.to_le_bytes());
        }
    }
    log.tally.calls += 1;
}
