//! Scene building (`rtcNewScene(3)`, `rtcNewGeometry(3)`, `rtcAttachGeometry(3)`,
//! `rtcCommitScene(3)`): triangle meshes and spheres, checked before Embree sees them.
use std::sync::{Arc, OnceLock};

use glam::Vec3;

use super::scene::Scene;
use super::sys;
use super::{Device, EmbreeError};

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
            recorder: OnceLock::new(),
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
