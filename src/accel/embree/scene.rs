//! Scene building (`rtcNewScene(3)`, `rtcNewGeometry(3)`, `rtcAttachGeometry(3)`,
//! `rtcCommitScene(3)`) and ray queries on committed scenes (`rtcIntersect1(3)`,
//! `rtcOccluded1(3)`, `rtcIntersect8(3)`, `rtcOccluded8(3)`).
use std::sync::Arc;

use glam::Vec3;

use super::device::DeviceInner;
use super::sys;
use super::{Device, EmbreeError, Hit, RayCoherence, RayQuery};

/// `rtcCommitScene(3)`: "Embree silently ignores primitives … containing NaNs, INFs, or
/// values greater than 1.844E18f". heron rejects such input instead of losing it.
const EMBREE_MAX_COORD: f32 = 1.844e18;

/// A scene being built. Geometry IDs are assigned in insertion order starting at 0, so
/// they index heron's own per-shape Vecs.
///
/// Dropping a builder without committing releases the scene (`rtcReleaseScene(3)`).
pub struct SceneBuilder<'d> {
    device: &'d Device,
    /// Null after `commit` or if `rtcNewScene` failed.
    raw: sys::RTCScene,
    /// The ID Embree must give the next attached geometry.
    next_id: u32,
    /// Set when Embree failed in a way that leaves the scene unusable or its IDs out of
    /// step with ours; every later call returns this error.
    broken: Option<EmbreeError>,
}

/// A committed scene: immutable, `Send + Sync`, queried concurrently by all workers.
///
/// Owns its `RTCScene` (released on drop) and a reference to the device, so it does not
/// borrow the [`Device`] and can be stored anywhere.
pub struct Scene {
    raw: sys::RTCScene,
    device: Arc<DeviceInner>,
    geometry_count: u32,
    bounds: Option<(Vec3, Vec3)>,
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

/// Releases a geometry handle when dropped (`rtcReleaseGeometry(3)`); a geometry attached
/// to a scene is kept alive by the scene.
/// Declared after the `Locked` guard in `add_geometry`, so it drops first, while the
/// device lock is still held.
struct GeometryGuard {
    raw: sys::RTCGeometry,
}

impl Drop for GeometryGuard {
    fn drop(&mut self) {
        // SAFETY: `raw` came from rtcNewGeometry and is released exactly once, with the
        // device lock held (see the struct doc).
        unsafe { sys::rtcReleaseGeometry(self.raw) }
    }
}

fn other(message: String) -> EmbreeError {
    EmbreeError::Other(message)
}

fn clone_error(e: &EmbreeError) -> EmbreeError {
    match e {
        EmbreeError::Device { code, message } => EmbreeError::Device {
            code: code.clone(),
            message: message.clone(),
        },
        EmbreeError::Other(m) => EmbreeError::Other(m.clone()),
    }
}

fn check_point(what: &str, p: Vec3) -> Result<(), EmbreeError> {
    if !p.is_finite() {
        return Err(other(format!("{what} is not finite: {p}")));
    }
    if p.abs().max_element() > EMBREE_MAX_COORD {
        return Err(other(format!(
            "{what} = {p} is beyond Embree's coordinate limit {EMBREE_MAX_COORD:e}"
        )));
    }
    Ok(())
}

impl<'d> SceneBuilder<'d> {
    /// `rtcNewScene(3)` with `RTC_SCENE_FLAG_ROBUST` and `RTC_BUILD_QUALITY_HIGH`.
    ///
    /// ROBUST: "avoids optimizations that reduce arithmetic accuracy … avoiding artifacts
    /// caused by rays shooting through edges of neighboring primitives"
    /// (`rtcSetSceneFlags(3)`). heron traces refraction through closed meshes (lenses,
    /// prisms); a ray leaking through a shared edge changes the physics, not just a pixel.
    ///
    /// HIGH: "higher quality data structures for final-frame rendering … spatial split
    /// BVH" (`rtcSetSceneBuildQuality(3)`). heron scenes are static and built once, then
    /// traced by millions of rays per render, so a slower commit pays for itself.
    pub(crate) fn new(device: &'d Device) -> SceneBuilder<'d> {
        let locked = device.inner.lock();
        // SAFETY: live device, lock held.
        let raw = unsafe { sys::rtcNewScene(locked.raw()) };
        let mut builder = SceneBuilder {
            device,
            raw,
            next_id: 0,
            broken: None,
        };
        if raw.is_null() {
            builder.broken = Some(
                locked
                    .check("rtcNewScene")
                    .err()
                    .unwrap_or_else(|| other("rtcNewScene returned NULL".into())),
            );
            return builder;
        }
        // SAFETY: `raw` is a live scene not yet shared; lock held.
        unsafe { sys::rtcSetSceneFlags(raw, sys::RTC_SCENE_FLAG_ROBUST) };
        // SAFETY: as above.
        unsafe { sys::rtcSetSceneBuildQuality(raw, sys::RTC_BUILD_QUALITY_HIGH) };
        if let Err(e) = locked.check("rtcSetSceneFlags/rtcSetSceneBuildQuality") {
            builder.broken = Some(e);
        }
        drop(locked);
        builder
    }

    fn usable(&self) -> Result<(), EmbreeError> {
        match &self.broken {
            Some(e) => Err(clone_error(e)),
            None => Ok(()),
        }
    }

    /// Adds a triangle mesh (`RTC_GEOMETRY_TYPE_TRIANGLE(3)`); returns its geometry ID.
    ///
    /// `positions` become an `RTC_FORMAT_FLOAT3` vertex buffer and `indices` an
    /// `RTC_FORMAT_UINT3` index buffer; `prim_id` in a [`Hit`] is the index into
    /// `indices`. Counter-clockwise triangles have `Ng = (p1 - p0) × (p2 - p0)`, and
    /// `u`, `v` weight `p1`, `p2`: `p = (1-u-v) p0 + u p1 + v p2`.
    ///
    /// Errors (nothing is added): no triangles, a non-finite or too large position, an
    /// index out of range, more than `u32::MAX` vertices or triangles.
    pub fn add_triangle_mesh(
        &mut self,
        positions: &[Vec3],
        indices: &[[u32; 3]],
    ) -> Result<u32, EmbreeError> {
        self.usable()?;
        if indices.is_empty() {
            return Err(other("triangle mesh has no triangles".into()));
        }
        if positions.len() > u32::MAX as usize || indices.len() > u32::MAX as usize {
            return Err(other(format!(
                "triangle mesh too large: {} vertices, {} triangles (Embree's IDs are 32-bit)",
                positions.len(),
                indices.len()
            )));
        }
        for (i, p) in positions.iter().enumerate() {
            check_point(&format!("triangle mesh vertex {i}"), *p)?;
        }
        let n = positions.len();
        for (t, tri) in indices.iter().enumerate() {
            if let Some(bad) = tri.iter().find(|&&i| i as usize >= n) {
                return Err(other(format!(
                    "triangle {t} refers to vertex {bad}, but the mesh has {n} vertices"
                )));
            }
        }

        self.add_geometry(sys::RTC_GEOMETRY_TYPE_TRIANGLE, "triangle mesh", |geom| {
            // SAFETY: live geometry, lock held by add_geometry. 12-byte stride, n items.
            let vptr = unsafe {
                sys::rtcSetNewGeometryBuffer(
                    geom,
                    sys::RTC_BUFFER_TYPE_VERTEX,
                    0,
                    sys::RTC_FORMAT_FLOAT3,
                    12,
                    n,
                )
            } as *mut f32;
            // SAFETY: as above; 12-byte stride, indices.len() items.
            let iptr = unsafe {
                sys::rtcSetNewGeometryBuffer(
                    geom,
                    sys::RTC_BUFFER_TYPE_INDEX,
                    0,
                    sys::RTC_FORMAT_UINT3,
                    12,
                    indices.len(),
                )
            } as *mut u32;
            if vptr.is_null() || iptr.is_null() {
                return Err(other("rtcSetNewGeometryBuffer returned NULL".into()));
            }
            debug_assert!(vptr.is_aligned() && iptr.is_aligned());
            // SAFETY: Embree allocated `n` FLOAT3 items (3n f32, plus its own padding so
            // the last vertex can be read with a 16-byte load), aligned (Embree's
            // allocator aligns to at least 16 bytes), fresh and aliased by nothing else.
            let v = unsafe { std::slice::from_raw_parts_mut(vptr, 3 * n) };
            for (dst, p) in v.chunks_exact_mut(3).zip(positions) {
                dst.copy_from_slice(&[p.x, p.y, p.z]);
            }
            // SAFETY: likewise, `indices.len()` UINT3 items.
            let idx = unsafe { std::slice::from_raw_parts_mut(iptr, 3 * indices.len()) };
            for (dst, tri) in idx.chunks_exact_mut(3).zip(indices) {
                dst.copy_from_slice(tri);
            }
            Ok(())
        })
    }

    /// Adds one sphere (`RTC_GEOMETRY_TYPE_SPHERE_POINT`, see `RTC_GEOMETRY_TYPE_POINT(3)`)
    /// as an `RTC_FORMAT_FLOAT4` vertex (x, y, z, r); returns its geometry ID.
    ///
    /// Hits report `Ng` pointing outwards (hit point minus centre, length about the
    /// radius) and `u = v = 0`. A ray starting inside gets the far hit.
    ///
    /// Errors (nothing is added): non-finite or too large centre, radius not finite and > 0.
    pub fn add_sphere(&mut self, center: Vec3, radius: f32) -> Result<u32, EmbreeError> {
        self.usable()?;
        check_point("sphere centre", center)?;
        if !(radius.is_finite() && radius > 0.0 && radius <= EMBREE_MAX_COORD) {
            return Err(other(format!(
                "sphere radius must be positive and finite, got {radius}"
            )));
        }
        self.add_geometry(sys::RTC_GEOMETRY_TYPE_SPHERE_POINT, "sphere", |geom| {
            // SAFETY: live geometry, lock held by add_geometry. One 16-byte item.
            let ptr = unsafe {
                sys::rtcSetNewGeometryBuffer(
                    geom,
                    sys::RTC_BUFFER_TYPE_VERTEX,
                    0,
                    sys::RTC_FORMAT_FLOAT4,
                    16,
                    1,
                )
            } as *mut [f32; 4];
            if ptr.is_null() {
                return Err(other("rtcSetNewGeometryBuffer returned NULL".into()));
            }
            debug_assert!(ptr.is_aligned());
            // SAFETY: Embree allocated one aligned FLOAT4 item that nothing else aliases.
            unsafe { ptr.write([center.x, center.y, center.z, radius]) };
            Ok(())
        })
    }

    /// rtcNewGeometry → `fill` (buffers) → rtcCommitGeometry → rtcAttachGeometry →
    /// rtcReleaseGeometry, checking Embree's error state after each step.
    fn add_geometry(
        &mut self,
        kind: sys::RTCGeometryType,
        what: &str,
        fill: impl FnOnce(sys::RTCGeometry) -> Result<(), EmbreeError>,
    ) -> Result<u32, EmbreeError> {
        let locked = self.device.inner.lock();
        // SAFETY: live device, lock held.
        let raw = unsafe { sys::rtcNewGeometry(locked.raw(), kind) };
        let geom = (!raw.is_null()).then_some(GeometryGuard { raw });
        locked.check(&format!("{what}: rtcNewGeometry"))?;
        let Some(geom) = geom else {
            return Err(other(format!("{what}: rtcNewGeometry returned NULL")));
        };
        fill(geom.raw)?;
        locked.check(&format!("{what}: rtcSetNewGeometryBuffer"))?;
        // SAFETY: live geometry with its buffers set; lock held.
        unsafe { sys::rtcCommitGeometry(geom.raw) };
        locked.check(&format!("{what}: rtcCommitGeometry"))?;

        let expected = self.next_id;
        // SAFETY: live scene (usable() checked) and geometry of the same device.
        let id = unsafe { sys::rtcAttachGeometry(self.raw, geom.raw) };
        let attached = locked.check(&format!("{what}: rtcAttachGeometry"));
        drop(geom);
        let result = match attached {
            Err(e) => Err(e),
            Ok(()) if id != expected => Err(other(format!(
                "{what}: Embree assigned geometry ID {id}, expected {expected} (insertion order)"
            ))),
            Ok(()) => Ok(id),
        };
        match &result {
            Ok(_) => self.next_id += 1,
            // The scene may now hold a geometry under an ID heron does not know about.
            Err(e) => self.broken = Some(clone_error(e)),
        }
        result
    }

    /// Number of geometries added so far (the next geometry ID).
    pub fn geometry_count(&self) -> u32 {
        self.next_id
    }

    /// Commits (builds the BVH, `rtcCommitScene(3)`). After this the scene cannot be
    /// modified.
    pub fn commit(mut self) -> Result<Scene, EmbreeError> {
        self.usable()?;
        let raw = std::mem::replace(&mut self.raw, std::ptr::null_mut());
        let device = Arc::clone(&self.device.inner);
        let locked = device.lock();
        // SAFETY: `raw` is a live scene now owned by this function; lock held.
        unsafe { sys::rtcCommitScene(raw) };
        let committed = locked.check("rtcCommitScene");
        let mut b = sys::RTCBounds::default();
        if committed.is_ok() {
            // SAFETY: committed scene; `b` is align(16) as required.
            unsafe { sys::rtcGetSceneBounds(raw, &mut b) };
        }
        let bounded = locked.check("rtcGetSceneBounds");
        if let Err(e) = committed.and(bounded) {
            // SAFETY: the scene is ours and never escaped; released once, lock held.
            unsafe { sys::rtcReleaseScene(raw) };
            return Err(e);
        }
        drop(locked);
        let lower = Vec3::new(b.lower_x, b.lower_y, b.lower_z);
        let upper = Vec3::new(b.upper_x, b.upper_y, b.upper_z);
        // An empty scene has lower > upper (Embree reports an empty box).
        let bounds = (self.next_id > 0 && lower.cmple(upper).all()).then_some((lower, upper));
        Ok(Scene {
            raw,
            device,
            geometry_count: self.next_id,
            bounds,
        })
    }
}

impl Drop for SceneBuilder<'_> {
    fn drop(&mut self) {
        if !self.raw.is_null() {
            let _locked = self.device.inner.lock();
            // SAFETY: live, uncommitted scene owned by this builder; released once.
            unsafe { sys::rtcReleaseScene(self.raw) }
        }
    }
}

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
/// can make Embree traverse the whole tree; Debian does not build it with
/// `EMBREE_IGNORE_INVALID_RAYS`).
#[inline]
fn valid_ray(r: &RayQuery) -> bool {
    r.origin.is_finite()
        && r.dir.is_finite()
        && r.dir != Vec3::ZERO
        && r.tnear >= 0.0
        && r.tnear.is_finite()
        && r.tfar >= r.tnear
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

/// The record buffer of [`Scene::intersect_stream`], reused between calls.
#[derive(Default)]
pub struct StreamScratch(Vec<sys::RTCRayHit>);

/// Generates, for one packet width, the SoA packet builder and the closest-hit query
/// `rtcIntersectW(3)`: lanes whose bit in `active` is 0 (or whose ray is invalid) are
/// inactive and get None.
macro_rules! packet_query {
    ($(#[$doc:meta])* $name:ident, $each:ident, $build:ident, $w:literal, $mask:ty,
     $valid:ident, $ray:ident, $hit:ident, $rayhit:ident, $sysfn:ident) => {
        /// Fills the SoA packet `p` and the valid mask in place (a packet is up to 768
        /// bytes; returning it by value cost a memcpy per query); false if no lane is
        /// active. Every lane is copied and only the mask depends on the lane's validity,
        /// so the copy has no branches (Embree reads no field of an inactive lane).
        #[inline]
        fn $build(
            rays: &[RayQuery; $w],
            active: $mask,
            valid: &mut sys::$valid,
            p: &mut sys::$ray,
        ) -> bool {
            let mut any = false;
            for (i, r) in rays.iter().enumerate() {
                let on = active & (1 << i) != 0 && valid_ray(r);
                any |= on;
                valid.0[i] = -(on as i32);
                p.org_x[i] = r.origin.x;
                p.org_y[i] = r.origin.y;
                p.org_z[i] = r.origin.z;
                p.tnear[i] = r.tnear;
                p.dir_x[i] = r.dir.x;
                p.dir_y[i] = r.dir.y;
                p.dir_z[i] = r.dir.z;
                p.tfar[i] = r.tfar;
                p.mask[i] = u32::MAX;
            }
            any
        }

        /// Calls `f(lane, hit)` for every active lane that hits, in lane order; the
        /// cheapest form of the packet query, since no `Option` is built for a miss.
        #[inline]
        pub fn $each(
            &self,
            rays: &[RayQuery; $w],
            active: $mask,
            coherence: RayCoherence,
            mut f: impl FnMut(usize, Hit),
        ) {
            let mut valid = sys::$valid::default();
            let mut rh = sys::$rayhit {
                ray: sys::$ray::default(),
                hit: sys::$hit::invalid(),
            };
            if !Self::$build(rays, active, &mut valid, &mut rh.ray) {
                return;
            }
            // SAFETY: committed, unmodified scene; `valid` and `rh` are aligned to the
            // packet width, valid and exclusive for the call.
            unsafe {
                sys::$sysfn(&valid, self.raw, &mut rh, coherence == RayCoherence::Coherent)
            };
            for i in 0..$w {
                if valid.0[i] != 0 && rh.hit.geomID[i] != sys::RTC_INVALID_GEOMETRY_ID {
                    f(
                        i,
                        Hit {
                            t: rh.ray.tfar[i],
                            geom_id: rh.hit.geomID[i],
                            prim_id: rh.hit.primID[i],
                            ng: Vec3::new(rh.hit.Ng_x[i], rh.hit.Ng_y[i], rh.hit.Ng_z[i]),
                            u: rh.hit.u[i],
                            v: rh.hit.v[i],
                        },
                    );
                }
            }
        }

        $(#[$doc])*
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
    pub fn intersect1_with(&self, ray: &RayQuery, coherence: RayCoherence) -> Option<Hit> {
        if !valid_ray(ray) {
            return None;
        }
        let mut rh = sys::RTCRayHit {
            ray: to_rtc_ray(ray),
            hit: sys::RTCHit::invalid(),
        };
        // SAFETY: `self.raw` is a committed scene that nothing modifies (see the Send/Sync
        // impls); `rh` is a valid, aligned, exclusive ray/hit record.
        unsafe { sys::intersect1(self.raw, &mut rh, coherence == RayCoherence::Coherent) };
        hit_of(&rh)
    }

    /// Whether anything lies along `ray` within `[tnear, tfar]` (`rtcOccluded1(3)`,
    /// incoherent context; Embree sets `tfar = -inf` when occluded). Invalid rays give
    /// false.
    #[inline]
    pub fn occluded1(&self, ray: &RayQuery) -> bool {
        self.occluded1_with(ray, RayCoherence::Incoherent)
    }

    /// [`Scene::occluded1`] with an explicit coherence hint.
    pub fn occluded1_with(&self, ray: &RayQuery, coherence: RayCoherence) -> bool {
        if !valid_ray(ray) {
            return false;
        }
        let mut r = to_rtc_ray(ray);
        // SAFETY: as in intersect1_with.
        unsafe { sys::occluded1(self.raw, &mut r, coherence == RayCoherence::Coherent) };
        r.tfar == f32::NEG_INFINITY
    }

    /// Coherent 8-wide packet; lanes whose bit in `active` is 0 are ignored and get None.
    ///
    /// `rtcIntersect8(3)` with the valid mask (-1 active, 0 inactive) and a COHERENT
    /// context. Lane `i` is bit `1 << i`; invalid rays are treated as inactive.
    pub fn intersect8(&self, rays: &[RayQuery; 8], active: u8) -> [Option<Hit>; 8] {
        self.intersect8_with(rays, active, RayCoherence::Coherent)
    }

    packet_query!(
        /// [`Scene::intersect8`] with an explicit coherence hint.
        intersect8_with, intersect8_each, packet8, 8, u8, ValidMask8, RTCRay8, RTCHit8, RTCRayHit8, intersect8
    );
    packet_query!(
        /// 4-wide packet (`rtcIntersect4(3)`), as [`Scene::intersect8_with`].
        intersect4_with, intersect4_each, packet4, 4, u8, ValidMask4, RTCRay4, RTCHit4, RTCRayHit4, intersect4
    );
    packet_query!(
        /// 16-wide packet (`rtcIntersect16(3)`), as [`Scene::intersect8_with`].
        intersect16_with, intersect16_each, packet16, 16, u16, ValidMask16, RTCRay16, RTCHit16, RTCRayHit16, intersect16
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
        let records = &mut scratch.0;
        records.clear();
        records.extend(rays.iter().map(|r| {
            let mut ray = to_rtc_ray(r);
            if !valid_ray(r) {
                // An empty segment: Embree reports no hit for it.
                ray.tnear = 0.0;
                ray.tfar = -1.0;
            }
            sys::RTCRayHit {
                ray,
                hit: sys::RTCHit::invalid(),
            }
        }));
        // SAFETY: committed, unmodified scene; the records are valid, aligned and
        // exclusive for the call.
        if !unsafe { sys::intersect1m(self.raw, records, coherence == RayCoherence::Coherent) } {
            return false;
        }
        for (h, rh) in hits.iter_mut().zip(records.iter()) {
            *h = hit_of(rh);
        }
        true
    }

    /// Returns a bit mask of the active lanes that are occluded.
    ///
    /// `rtcOccluded8(3)` with a COHERENT context; occluded lanes come back with
    /// `tfar = -inf`.
    pub fn occluded8(&self, rays: &[RayQuery; 8], active: u8) -> u8 {
        let mut valid = sys::ValidMask8::default();
        let mut ray = sys::RTCRay8::default();
        if !Self::packet8(rays, active, &mut valid, &mut ray) {
            return 0;
        }
        // SAFETY: as in intersect8.
        unsafe { sys::occluded8(&valid, self.raw, &mut ray, true) };
        (0..8)
            .filter(|&i| valid.0[i] != 0 && ray.tfar[i] == f32::NEG_INFINITY)
            .fold(0u8, |m, i| m | (1 << i))
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
