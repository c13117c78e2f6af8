//! Ray queries on committed scenes (`rtcIntersect1(3)`, `rtcOccluded1(3)`,
//! `rtcIntersect4/8/16(3)`, `rtcOccluded4/8/16(3)`, `rtcIntersect1M(3)`); `builder.rs`
//! builds them.
use std::sync::{Arc, OnceLock};

use glam::Vec3;

use super::device::DeviceInner;
use super::record::{RayLog, Recorder};
use super::sys;
use super::{Hit, RayCoherence, RayQuery};

/// A committed scene: immutable, `Send + Sync`, queried concurrently by all workers.
///
/// Owns its `RTCScene` (released on drop) and a reference to the device, so it does not
/// borrow the [`Device`] and can be stored anywhere.
pub struct Scene {
    pub(super) raw: sys::RTCScene,
    pub(super) device: Arc<DeviceInner>,
    pub(super) geometry_count: u32,
    pub(super) bounds: Option<(Vec3, Vec3)>,
    /// Set once by [`Scene::record`]; until then every query's only cost for it is one
    /// load and a branch never taken.
    pub(super) recorder: OnceLock<Recorder>,
}

// SAFETY: a committed Scene is never modified: no method takes `&mut self` or calls a
// scene-modifying Embree function, and the builder that could modify it was consumed by
// `commit`. Embree documents ray queries on a committed scene as thread-safe
// (Embree 3 API overview: "attaching geometries to the same scene and performing ray
// queries in a scene is thread-safe"). Release in `Drop` has exclusive access and takes
// the device lock. `DeviceInner` is itself Send + Sync.
unsafe impl Send for Scene {}
// SAFETY: see `Send`: shared access only ever performs thread-safe ray queries.
unsafe impl Sync for Scene {}

impl Drop for Scene {
    fn drop(&mut self) {
        let _locked = self.device.lock();
        // SAFETY: `raw` is the committed scene this Scene owns; dropping needs `&mut
        // self`, so no query is running. The device outlives this call (`self.device`).
        unsafe { sys::rtcReleaseScene(self.raw) }
    }
}

impl std::fmt::Debug for Scene {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Scene")
            .field("geometry_count", &self.geometry_count)
            .field("bounds", &self.bounds)
            .finish_non_exhaustive()
    }
}

// ---------------------------------------------------------------------------------------
// Queries

/// Rays Embree can take: finite origin and direction, non-zero direction,
/// `0 <= tnear <= tfar` (tfar may be +inf). `rtcIntersect1(3)`: "The ray segment has to
/// be in the range [0, ∞]". Others are answered "no hit" without calling Embree (NaN rays
/// can make Embree traverse the whole tree, and Debian's build asserts on a negative
/// tnear; it is not built with `EMBREE_IGNORE_INVALID_RAYS`).
///
/// This is the rule as written; the queries compute it with vector instructions
/// ([`write_ray`], [`fill_packet`]) and tests hold both to it.
#[inline(always)]
fn valid_ray(r: &RayQuery) -> bool {
    r.origin.is_finite()
        && r.dir.is_finite()
        && r.dir != Vec3::ZERO
        && r.tnear >= 0.0
        && r.tnear.is_finite()
        && r.tfar >= r.tnear
}

/// Writes Embree's record of one ray (all 48 bytes of an `RTCRay`: `time` 0, `mask` all
/// bits, `id` and `flags` 0) and returns whether Embree may trace it ([`valid_ray`]).
///
/// On x86_64 this is two 16-byte loads of the [`RayQuery`] (whose layout is the start of
/// `RTCRay`'s), the validity of all eight values tested in two vectors, and three 16-byte
/// stores: about twenty instructions, which every single-ray query of a render pays.
///
/// # Safety
/// `out` points to a writable `RTCRay` (16-byte aligned, as the type is).
#[inline(always)]
unsafe fn write_ray(r: &RayQuery, out: *mut sys::RTCRay) -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::*;
        // SAFETY: SSE and SSE2 are part of the x86_64 baseline. RayQuery is repr(C) and 32
        // bytes (asserted in mod.rs): the two unaligned loads read its [origin, tnear]
        // and [dir, tfar] and nothing beyond. RTCRay is repr(C, align(16)), 48 bytes, with
        // org_x..tnear at 0, dir_x..time at 16 and tfar, mask, id, flags at 32 (asserted
        // in sys.rs): the three aligned stores write exactly the record the caller gave.
        unsafe {
            let p = (r as *const RayQuery).cast::<f32>();
            let (a, b) = (_mm_loadu_ps(p), _mm_loadu_ps(p.add(4)));
            let xyz = _mm_castsi128_ps(_mm_setr_epi32(-1, -1, -1, 0));
            // [dir, 0]: lane 3 becomes RTCRay's `time` (0, no motion blur).
            let dir = _mm_and_ps(b, xyz);
            // [tfar, mask = all bits, id = 0, flags = 0].
            let tail = _mm_move_ss(
                _mm_castsi128_ps(_mm_setr_epi32(0, -1, 0, 0)),
                _mm_shuffle_ps(b, b, 0xff),
            );
            let q = out.cast::<f32>();
            _mm_store_ps(q, a);
            _mm_store_ps(q.add(4), dir);
            _mm_store_ps(q.add(8), tail);
            let zero = _mm_setzero_ps();
            // x - x is 0 for a finite x and NaN for ±inf and NaN, and a NaN survives the
            // sum (IEEE 754 §6.2): one compare tests origin, tnear and direction.
            let finite = _mm_cmpeq_ps(_mm_add_ps(_mm_sub_ps(a, a), _mm_sub_ps(dir, dir)), zero);
            // Lane 3: tnear >= 0 and tfar >= tnear; lanes 0-2 pass.
            let segment = _mm_or_ps(_mm_and_ps(_mm_cmpge_ps(a, zero), _mm_cmpge_ps(b, a)), xyz);
            (_mm_movemask_ps(_mm_and_ps(finite, segment)) == 0xf)
                & (_mm_movemask_ps(_mm_cmpneq_ps(dir, zero)) != 0)
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        // SAFETY: the caller guarantees `out`.
        unsafe { out.write(to_rtc_ray(r)) };
        valid_ray(r)
    }
}

impl RayQuery {
    /// Whether Embree may trace this ray (finite origin and direction, non-zero
    /// direction, `0 <= tnear <= tfar`); queries answer other rays without calling
    /// Embree.
    pub fn is_valid(&self) -> bool {
        valid_ray(self)
    }
}

/// The hit of a single-ray record after a query, or None if it missed.
#[inline]
fn hit_of(rh: &sys::RTCRayHit) -> Option<Hit> {
    (rh.hit.geomID != sys::RTC_INVALID_GEOMETRY_ID).then(|| Hit {
        t: rh.ray.tfar,
        geom_id: rh.hit.geomID,
        prim_id: rh.hit.primID,
        ng: Vec3::new(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z),
        u: rh.hit.u,
        v: rh.hit.v,
    })
}

#[cfg_attr(target_arch = "x86_64", allow(dead_code))]
#[inline]
fn to_rtc_ray(r: &RayQuery) -> sys::RTCRay {
    sys::RTCRay {
        org_x: r.origin.x,
        org_y: r.origin.y,
        org_z: r.origin.z,
        tnear: r.tnear,
        dir_x: r.dir.x,
        dir_y: r.dir.y,
        dir_z: r.dir.z,
        time: 0.0,
        tfar: r.tfar,
        // All bits: hits every geometry whether or not Embree was built with ray masks.
        mask: u32::MAX,
        id: 0,
        flags: 0,
    }
}

/// A stream's records as rays, for the recorder (before the call).
#[cold]
#[inline(never)]
fn sent_rays(records: &[sys::RTCRayHit]) -> Vec<RayQuery> {
    records
        .iter()
        .map(|r| RayQuery {
            origin: Vec3::new(r.ray.org_x, r.ray.org_y, r.ray.org_z),
            tnear: r.ray.tnear,
            dir: Vec3::new(r.ray.dir_x, r.ray.dir_y, r.ray.dir_z),
            tfar: r.ray.tfar,
        })
        .collect()
}

/// The record buffer of [`Scene::intersect_stream`], reused between calls.
#[derive(Default)]
pub struct StreamScratch(Vec<sys::RTCRayHit>);

/// `RTCRayW`'s fields in order (rtcore_ray.h), each an array of W lanes.
const RAY_FIELDS: usize = 12;
/// `RTCHitW`'s leading float fields (`Ng_x`, `Ng_y`, `Ng_z`, `u`, `v`); the ID fields
/// (`primID`, `geomID`, `instID`, and Embree 4's `instPrimID`) follow.
const HIT_FLOAT_FIELDS: usize = 5;

/// Writes every byte of the SoA ray packet `p` (an `RTCRayW`, [`RAY_FIELDS`] arrays of W
/// lanes) and of the valid mask (W `int`s, -1 active, 0 inactive) from `rays`, and
/// returns whether any lane is active. A lane is active when its bit in `active` is set
/// and its ray is valid ([`valid_ray`]); Embree reads no field of an inactive lane.
///
/// On x86_64 each group of four rays is two 4×4 transposes of 16-byte loads (a ray's
/// [origin, tnear] and [dir, tfar]) stored as whole vectors, with the four lanes'
/// validity computed on the transposed vectors: about four instructions per ray and
/// field group, no branch per lane. (The same transpose as `_MM_TRANSPOSE4_PS` in
/// Intel's `xmmintrin.h`.)
///
/// # Safety
/// `p` points to an `RTCRayW` and `valid` to W `i32`s, both aligned to 16 bytes and
/// writable; W is a multiple of 4.
#[inline(always)]
unsafe fn fill_packet<const W: usize>(
    rays: &[RayQuery; W],
    active: u32,
    p: *mut f32,
    valid: *mut i32,
) -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::*;
        // SAFETY: SSE and SSE2 are part of the x86_64 baseline. Loads read the W rays
        // (32 bytes each, repr(C), asserted in mod.rs) and nothing beyond; stores write
        // field f's lanes k..k+4 at `p + f·W + k`, inside the packet and 16-byte aligned
        // since W and k are multiples of 4 (the caller guarantees `p` and `valid`).
        unsafe {
            let q = rays.as_ptr().cast::<f32>();
            let zero = _mm_setzero_ps();
            let ones = _mm_castsi128_ps(_mm_set1_epi32(-1));
            let lane_bits = _mm_setr_epi32(1, 2, 4, 8);
            let mut any = _mm_setzero_ps();
            let mut k = 0;
            while k < W {
                let r = q.add(8 * k);
                let (a0, a1, a2, a3) = (
                    _mm_loadu_ps(r),
                    _mm_loadu_ps(r.add(8)),
                    _mm_loadu_ps(r.add(16)),
                    _mm_loadu_ps(r.add(24)),
                );
                let (b0, b1, b2, b3) = (
                    _mm_loadu_ps(r.add(4)),
                    _mm_loadu_ps(r.add(12)),
                    _mm_loadu_ps(r.add(20)),
                    _mm_loadu_ps(r.add(28)),
                );
                let transpose = |v0, v1, v2, v3| {
                    let (t0, t1) = (_mm_unpacklo_ps(v0, v1), _mm_unpacklo_ps(v2, v3));
                    let (t2, t3) = (_mm_unpackhi_ps(v0, v1), _mm_unpackhi_ps(v2, v3));
                    (
                        _mm_movelh_ps(t0, t1),
                        _mm_movehl_ps(t1, t0),
                        _mm_movelh_ps(t2, t3),
                        _mm_movehl_ps(t3, t2),
                    )
                };
                let (ox, oy, oz, tnear) = transpose(a0, a1, a2, a3);
                let (dx, dy, dz, tfar) = transpose(b0, b1, b2, b3);
                // valid_ray, four lanes at once: x - x is 0 for a finite x and NaN for
                // ±inf and NaN, and a NaN survives the sum (IEEE 754 §6.2).
                let d = |v| _mm_sub_ps(v, v);
                let sum = _mm_add_ps(
                    _mm_add_ps(_mm_add_ps(d(ox), d(oy)), _mm_add_ps(d(oz), d(tnear))),
                    _mm_add_ps(_mm_add_ps(d(dx), d(dy)), d(dz)),
                );
                let nonzero = _mm_or_ps(
                    _mm_or_ps(_mm_cmpneq_ps(dx, zero), _mm_cmpneq_ps(dy, zero)),
                    _mm_cmpneq_ps(dz, zero),
                );
                let ok = _mm_and_ps(
                    _mm_and_ps(_mm_cmpeq_ps(sum, zero), nonzero),
                    _mm_and_ps(_mm_cmpge_ps(tnear, zero), _mm_cmpge_ps(tfar, tnear)),
                );
                let bits = _mm_and_si128(_mm_set1_epi32((active >> k) as i32), lane_bits);
                let on = _mm_and_ps(ok, _mm_castsi128_ps(_mm_cmpeq_epi32(bits, lane_bits)));
                let mut fields = [ox, oy, oz, tnear, dx, dy, dz, zero, tfar, ones, zero, zero];
                if W == 16 {
                    // Embree 3 on a CPU without AVX-512 answers 16-wide queries by
                    // splitting them, and its Debian build asserts that every lane it
                    // then traces is a valid ray, whatever the mask says: inactive lanes
                    // get the ray from the origin along +z with tnear = tfar = 0, and the
                    // caller reads only active lanes' hits. (Compiled out at W = 4, 8.)
                    let safe = [
                        zero,
                        zero,
                        zero,
                        zero,
                        zero,
                        zero,
                        _mm_set1_ps(1.0),
                        zero,
                        zero,
                    ];
                    for (v, s) in fields.iter_mut().zip(safe) {
                        *v = _mm_or_ps(_mm_and_ps(on, *v), _mm_andnot_ps(on, s));
                    }
                }
                for (f, v) in fields.into_iter().enumerate() {
                    _mm_store_ps(p.add(f * W + k), v);
                }
                _mm_store_ps(valid.add(k).cast::<f32>(), on);
                any = _mm_or_ps(any, on);
                k += 4;
            }
            _mm_movemask_ps(any) != 0
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        let mut any = false;
        for (i, r) in rays.iter().enumerate() {
            let lane = [
                r.origin.x, r.origin.y, r.origin.z, r.tnear, r.dir.x, r.dir.y, r.dir.z, 0.0, r.tfar,
            ];
            for (f, v) in lane.into_iter().enumerate() {
                // SAFETY: field f, lane i of the packet the caller guarantees.
                unsafe { p.add(f * W + i).write(v) };
            }
            for (f, v) in [u32::MAX, 0, 0].into_iter().enumerate() {
                // SAFETY: as above (mask, id, flags).
                unsafe { p.add((9 + f) * W + i).cast::<u32>().write(v) };
            }
            let on = (active >> i) & 1 != 0 && valid_ray(r);
            // SAFETY: lane i of the mask the caller guarantees.
            unsafe { valid.add(i).write(-(on as i32)) };
            any |= on;
        }
        any
    }
}

/// Writes every byte of the SoA hit packet `h` (an `RTCHitW` of `bytes` bytes) as
/// `rtcIntersectW(3)` requires before the call: the float fields 0, the ID fields
/// (`primID`, `geomID`, instance IDs) `RTC_INVALID_GEOMETRY_ID`.
///
/// # Safety
/// `h` points to a writable `RTCHitW` of `bytes` bytes, aligned to 16; W is a multiple
/// of 4.
#[inline(always)]
unsafe fn clear_hits<const W: usize>(h: *mut u32, bytes: usize) {
    let fields = bytes / (4 * W);
    for f in 0..fields {
        let v = if f < HIT_FLOAT_FIELDS {
            0
        } else {
            sys::RTC_INVALID_GEOMETRY_ID
        };
        for i in 0..W {
            // SAFETY: field f, lane i, inside the `bytes` the caller guarantees.
            unsafe { h.add(f * W + i).write(v) };
        }
    }
}

/// A valid mask (-1 active, 0 inactive per lane) as a bit per lane.
fn lane_bits(valid: &[i32]) -> u16 {
    valid
        .iter()
        .enumerate()
        .fold(0, |m, (i, &v)| m | (((v != 0) as u16) << i))
}

/// Generates, for one packet width, the closest-hit query `rtcIntersectW(3)` and the
/// occlusion query `rtcOccludedW(3)`: lanes whose bit in `active` is 0 (or whose ray is
/// invalid) are inactive and get None / not occluded.
macro_rules! packet_query {
    ($(#[$doc:meta])* $name:ident, $each:ident, $occluded:ident, $w:literal, $mask:ty,
     $valid:ident, $ray:ident, $hit:ident, $rayhit:ident, $isect:ident, $occl:ident) => {
        /// Calls `f(lane, hit)` for every active lane that hits, in lane order; the
        /// cheapest form of the packet query, since no `Option` is built for a miss.
        ///
        /// The packet (up to 1.3 kB) is built in place, every byte written once: no
        /// zeroing, no copies, no allocation.
        #[inline]
        pub fn $each(
            &self,
            rays: &[RayQuery; $w],
            active: $mask,
            coherence: RayCoherence,
            mut f: impl FnMut(usize, Hit),
        ) {
            /// The query, and its log when recording; as `Scene::intersect1_query`,
            /// always inlined so that the log's code is compiled out where `rec` is None.
            #[inline(always)]
            fn query(
                scene: &Scene,
                rays: &[RayQuery; $w],
                active: $mask,
                coherent: bool,
                f: &mut impl FnMut(usize, Hit),
                rec: Option<&Recorder>,
            ) {
                let mut valid = std::mem::MaybeUninit::<sys::$valid>::uninit();
                let mut rh = std::mem::MaybeUninit::<sys::$rayhit>::uninit();
                let rp = rh.as_mut_ptr();
                // SAFETY: `rh` and `valid` are aligned to the packet width (≥ 16 bytes)
                // and W is 4, 8 or 16. `fill_packet` writes all of the ray packet and the
                // mask, `clear_hits` all of the hit packet (RTCRayHitW has no padding: the
                // ray is 48·W bytes, the hit 32·W or 36·W, and the alignment is 4·W), so
                // both are initialised afterwards.
                let (valid, mut rh) = unsafe {
                    let any = fill_packet::<$w>(
                        rays,
                        active as u32,
                        std::ptr::addr_of_mut!((*rp).ray).cast::<f32>(),
                        valid.as_mut_ptr().cast::<i32>(),
                    );
                    if !any {
                        return;
                    }
                    clear_hits::<$w>(
                        std::ptr::addr_of_mut!((*rp).hit).cast::<u32>(),
                        std::mem::size_of::<sys::$hit>(),
                    );
                    (valid.assume_init(), rh.assume_init())
                };
                const _: () = assert!(std::mem::size_of::<sys::$ray>() == RAY_FIELDS * 4 * $w);
                const _: () = assert!(
                    std::mem::size_of::<sys::$rayhit>()
                        == std::mem::size_of::<sys::$ray>() + std::mem::size_of::<sys::$hit>()
                );
                // SAFETY: committed, unmodified scene; `valid` and `rh` are aligned to the
                // packet width, valid and exclusive for the call.
                unsafe { sys::$isect(&valid, scene.raw, &mut rh, coherent) };
                let lane = |i: usize| Hit {
                    t: rh.ray.tfar[i],
                    geom_id: rh.hit.geomID[i],
                    prim_id: rh.hit.primID[i],
                    ng: Vec3::new(rh.hit.Ng_x[i], rh.hit.Ng_y[i], rh.hit.Ng_z[i]),
                    u: rh.hit.u[i],
                    v: rh.hit.v[i],
                };
                // Embree writes hit lanes only, so a lane that is inactive or missed still
                // holds the invalid geometry ID; the mask is tested too, for the inactive
                // lanes a split 16-wide query may trace (`fill_packet`).
                let hit = |i: usize| {
                    (valid.0[i] != 0) & (rh.hit.geomID[i] != sys::RTC_INVALID_GEOMETRY_ID)
                };
                if let Some(rec) = rec {
                    let hits: [Option<Hit>; $w] = std::array::from_fn(|i| hit(i).then(|| lane(i)));
                    rec.packet(false, rays, lane_bits(&valid.0), coherent, &hits, 0);
                }
                for i in 0..$w {
                    if hit(i) {
                        f(i, lane(i));
                    }
                }
            }

            #[cold]
            #[inline(never)]
            fn recorded(
                scene: &Scene,
                rays: &[RayQuery; $w],
                active: $mask,
                coherent: bool,
                f: &mut impl FnMut(usize, Hit),
                rec: &Recorder,
            ) {
                query(scene, rays, active, coherent, f, Some(rec))
            }

            let coherent = coherence == RayCoherence::Coherent;
            match self.recorder.get() {
                None => query(self, rays, active, coherent, &mut f, None),
                Some(rec) => recorded(self, rays, active, coherent, &mut f, rec),
            }
        }

        $(#[$doc])*
        #[inline]
        pub fn $name(
            &self,
            rays: &[RayQuery; $w],
            active: $mask,
            coherence: RayCoherence,
        ) -> [Option<Hit>; $w] {
            let mut out = [None; $w];
            self.$each(rays, active, coherence, |i, h| out[i] = Some(h));
            out
        }

        /// A bit mask of the active lanes that are occluded (`rtcOccludedW(3)`, which
        /// sets `tfar = -inf` on occluded lanes), with an explicit coherence hint.
        #[inline]
        pub fn $occluded(&self, rays: &[RayQuery; $w], active: $mask, coherence: RayCoherence) -> $mask {
            /// As in the closest-hit query.
            #[inline(always)]
            fn query(
                scene: &Scene,
                rays: &[RayQuery; $w],
                active: $mask,
                coherent: bool,
                rec: Option<&Recorder>,
            ) -> $mask {
                let mut valid = std::mem::MaybeUninit::<sys::$valid>::uninit();
                let mut ray = std::mem::MaybeUninit::<sys::$ray>::uninit();
                // SAFETY: as in the closest-hit query; `fill_packet` writes all of the
                // ray packet and the mask.
                let (valid, mut ray) = unsafe {
                    let any = fill_packet::<$w>(
                        rays,
                        active as u32,
                        ray.as_mut_ptr().cast::<f32>(),
                        valid.as_mut_ptr().cast::<i32>(),
                    );
                    if !any {
                        return 0;
                    }
                    (valid.assume_init(), ray.assume_init())
                };
                // SAFETY: committed, unmodified scene; `valid` and `ray` are aligned to
                // the packet width, valid and exclusive for the call.
                unsafe { sys::$occl(&valid, scene.raw, &mut ray, coherent) };
                let mut m: $mask = 0;
                for i in 0..$w {
                    m |= (((valid.0[i] != 0) & (ray.tfar[i] == f32::NEG_INFINITY)) as $mask) << i;
                }
                if let Some(rec) = rec {
                    rec.packet(true, rays, lane_bits(&valid.0), coherent, &[], m as u16);
                }
                m
            }

            #[cold]
            #[inline(never)]
            fn recorded(
                scene: &Scene,
                rays: &[RayQuery; $w],
                active: $mask,
                coherent: bool,
                rec: &Recorder,
            ) -> $mask {
                query(scene, rays, active, coherent, Some(rec))
            }

            let coherent = coherence == RayCoherence::Coherent;
            match self.recorder.get() {
                None => query(self, rays, active, coherent, None),
                Some(rec) => recorded(self, rays, active, coherent, rec),
            }
        }
    };
}

impl Scene {
    /// Closest hit along `ray` within `[tnear, tfar]` (`rtcIntersect1(3)`, incoherent
    /// context), or None. Invalid rays (see [`RayQuery`]) give None.
    ///
    /// Embree "makes no guarantees that primitives whose hit distance is exactly at (or
    /// very close to) tnear or tfar are hit or missed".
    #[inline]
    pub fn intersect1(&self, ray: &RayQuery) -> Option<Hit> {
        self.intersect1_with(ray, RayCoherence::Incoherent)
    }

    /// [`Scene::intersect1`] with an explicit coherence hint for the intersect context.
    ///
    /// `#[inline]`, as every query: heron is built in several codegen units, and only an
    /// inline function can be inlined into a caller in another unit (a call per ray is a
    /// fifth of what the wrapper adds to Embree's own work).
    #[inline]
    pub fn intersect1_with(&self, ray: &RayQuery, coherence: RayCoherence) -> Option<Hit> {
        let coherent = coherence == RayCoherence::Coherent;
        match self.recorder.get() {
            None => self.intersect1_query(ray, coherent, None),
            Some(rec) => self.intersect1_recorded(ray, coherent, rec),
        }
    }

    #[cold]
    #[inline(never)]
    fn intersect1_recorded(&self, ray: &RayQuery, coherent: bool, rec: &Recorder) -> Option<Hit> {
        self.intersect1_query(ray, coherent, Some(rec))
    }

    /// The query, and its log when recording. Always inlined, so that where `rec` is the
    /// constant None (every query while not recording) the log's code is compiled out:
    /// the recorder's whole cost is the `OnceLock::get` branch in front.
    #[inline(always)]
    fn intersect1_query(
        &self,
        ray: &RayQuery,
        coherent: bool,
        rec: Option<&Recorder>,
    ) -> Option<Hit> {
        let mut r = std::mem::MaybeUninit::<sys::RTCRay>::uninit();
        // SAFETY: `write_ray` writes the whole aligned record.
        let record = unsafe {
            if !write_ray(ray, r.as_mut_ptr()) {
                return None;
            }
            r.assume_init()
        };
        let mut rh = sys::RTCRayHit {
            ray: record,
            hit: sys::RTCHit::invalid(),
        };
        // SAFETY: `self.raw` is a committed scene that nothing modifies (see the Send/Sync
        // impls); `rh` is a valid, aligned, exclusive ray/hit record.
        unsafe { sys::intersect1(self.raw, &mut rh, coherent) };
        let hit = hit_of(&rh);
        if let Some(rec) = rec {
            rec.intersect1(ray, coherent, hit.as_ref());
        }
        hit
    }

    /// Whether anything lies along `ray` within `[tnear, tfar]` (`rtcOccluded1(3)`,
    /// incoherent context; Embree sets `tfar = -inf` when occluded). Invalid rays give
    /// false.
    #[inline]
    pub fn occluded1(&self, ray: &RayQuery) -> bool {
        self.occluded1_with(ray, RayCoherence::Incoherent)
    }

    /// [`Scene::occluded1`] with an explicit coherence hint.
    #[inline]
    pub fn occluded1_with(&self, ray: &RayQuery, coherence: RayCoherence) -> bool {
        let coherent = coherence == RayCoherence::Coherent;
        match self.recorder.get() {
            None => self.occluded1_query(ray, coherent, None),
            Some(rec) => self.occluded1_recorded(ray, coherent, rec),
        }
    }

    #[cold]
    #[inline(never)]
    fn occluded1_recorded(&self, ray: &RayQuery, coherent: bool, rec: &Recorder) -> bool {
        self.occluded1_query(ray, coherent, Some(rec))
    }

    /// As [`Scene::intersect1_query`].
    #[inline(always)]
    fn occluded1_query(&self, ray: &RayQuery, coherent: bool, rec: Option<&Recorder>) -> bool {
        let mut r = std::mem::MaybeUninit::<sys::RTCRay>::uninit();
        // SAFETY: `write_ray` writes the whole aligned record.
        let mut r = unsafe {
            if !write_ray(ray, r.as_mut_ptr()) {
                return false;
            }
            r.assume_init()
        };
        // SAFETY: as in intersect1_query.
        unsafe { sys::occluded1(self.raw, &mut r, coherent) };
        let occluded = r.tfar == f32::NEG_INFINITY;
        if let Some(rec) = rec {
            rec.occluded1(ray, coherent, occluded);
        }
        occluded
    }

    /// Coherent 8-wide packet; lanes whose bit in `active` is 0 are ignored and get None.
    ///
    /// `rtcIntersect8(3)` with the valid mask (-1 active, 0 inactive) and a COHERENT
    /// context. Lane `i` is bit `1 << i`; invalid rays are treated as inactive.
    #[inline]
    pub fn intersect8(&self, rays: &[RayQuery; 8], active: u8) -> [Option<Hit>; 8] {
        self.intersect8_with(rays, active, RayCoherence::Coherent)
    }

    packet_query!(
        /// [`Scene::intersect8`] with an explicit coherence hint.
        intersect8_with, intersect8_each, occluded8_with, 8, u8, ValidMask8, RTCRay8, RTCHit8,
        RTCRayHit8, intersect8, occluded8
    );
    packet_query!(
        /// 4-wide packet (`rtcIntersect4(3)`), as [`Scene::intersect8_with`].
        intersect4_with, intersect4_each, occluded4_with, 4, u8, ValidMask4, RTCRay4, RTCHit4,
        RTCRayHit4, intersect4, occluded4
    );
    packet_query!(
        /// 16-wide packet (`rtcIntersect16(3)`), as [`Scene::intersect8_with`].
        intersect16_with, intersect16_each, occluded16_with, 16, u16, ValidMask16, RTCRay16,
        RTCHit16, RTCRayHit16, intersect16, occluded16
    );

    /// Closest hits of a stream of single rays with Embree 3's stream API
    /// (`rtcIntersect1M(3)`), into `hits` (same length as `rays`). `scratch` holds the
    /// records between calls so that a caller tracing many streams allocates once.
    /// Returns false, touching nothing, on Embree 4, which has no stream API.
    pub fn intersect_stream(
        &self,
        rays: &[RayQuery],
        coherence: RayCoherence,
        scratch: &mut StreamScratch,
        hits: &mut [Option<Hit>],
    ) -> bool {
        assert_eq!(rays.len(), hits.len(), "one hit slot per ray");
        if !sys::STREAM_API {
            return false;
        }
        hits.fill(None);
        self.intersect_stream_each(rays, coherence, scratch, |i, h| hits[i] = Some(h))
    }

    /// [`Scene::intersect_stream`] calling `f(index, hit)` for every ray that hits, in
    /// order, straight from Embree's records (no `Option` per ray), as the packet
    /// queries' `intersectW_each`. Invalid rays get an empty segment (`tnear 0`,
    /// `tfar -1`), for which Embree reports no hit.
    pub fn intersect_stream_each(
        &self,
        rays: &[RayQuery],
        coherence: RayCoherence,
        scratch: &mut StreamScratch,
        mut f: impl FnMut(usize, Hit),
    ) -> bool {
        if !sys::STREAM_API {
            return false;
        }
        let records = &mut scratch.0;
        if records.len() < rays.len() {
            records.resize(
                rays.len(),
                sys::RTCRayHit {
                    ray: sys::RTCRay::default(),
                    hit: sys::RTCHit::invalid(),
                },
            );
        }
        let records = &mut records[..rays.len()];
        for (rec, r) in records.iter_mut().zip(rays) {
            // SAFETY: `rec.ray` is an aligned, exclusive RTCRay.
            if !unsafe { write_ray(r, &mut rec.ray) } {
                rec.ray.tnear = 0.0;
                rec.ray.tfar = -1.0;
            }
            rec.hit = sys::RTCHit::invalid();
        }
        let coherent = coherence == RayCoherence::Coherent;
        // The rays as Embree gets them (the call overwrites `tfar` of hits).
        let sent = self.recorder.get().map(|_| sent_rays(records));
        // SAFETY: committed, unmodified scene; the records are valid, aligned and
        // exclusive for the call.
        unsafe { sys::intersect1m(self.raw, records, coherent) };
        for (i, rec) in records.iter().enumerate() {
            if let Some(h) = hit_of(rec) {
                f(i, h);
            }
        }
        if let (Some(rec), Some(sent)) = (self.recorder.get(), sent) {
            let hits: Vec<Hit> = records.iter().filter_map(hit_of).collect();
            rec.stream(&sent, coherent, &hits);
        }
        true
    }

    /// Returns a bit mask of the active lanes that are occluded.
    ///
    /// `rtcOccluded8(3)` with a COHERENT context; occluded lanes come back with
    /// `tfar = -inf`.
    #[inline]
    pub fn occluded8(&self, rays: &[RayQuery; 8], active: u8) -> u8 {
        self.occluded8_with(rays, active, RayCoherence::Coherent)
    }

    /// Starts recording every query this scene sends to Embree (see [`RayLog`]); the
    /// calls accumulate until [`Scene::take_recording`]. Recording cannot be stopped, so
    /// a render to be timed uses a scene that never recorded. Calls from several threads
    /// interleave in no fixed order: record a render on one thread.
    pub fn record(&self) {
        self.recorder.get_or_init(Recorder::default);
    }

    /// The calls recorded since [`Scene::record`] or the last take (None if this scene
    /// never recorded); recording goes on into an empty log.
    pub fn take_recording(&self) -> Option<RayLog> {
        self.recorder.get().map(Recorder::take)
    }

    /// Number of geometries; IDs are `0..geometry_count()`.
    pub fn geometry_count(&self) -> u32 {
        self.geometry_count
    }

    /// Axis-aligned bounds of everything in the scene (`rtcGetSceneBounds(3)`), or None
    /// for an empty scene.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        self.bounds
    }
}
