//! Intel Embree 3 (Debian's `libembree-dev`) through heron's own FFI layer.
//!
//! This module is the only place in heron where `unsafe` is allowed. Its public API is
//! safe: RAII wrappers for device, scene and geometry, a scene that is immutable once
//! committed (so it can be shared by all worker threads), and query functions for single
//! rays and 8-wide packets.
//!
//! API CONTRACT (filled in by the Embree work; signatures are fixed):
#![allow(unsafe_code)]

mod sys;

use glam::Vec3;

/// Errors reported by Embree, through the device error callback or return codes.
#[derive(Debug, thiserror::Error)]
pub enum EmbreeError {
    #[error("embree: {code}: {message}")]
    Device { code: String, message: String },
    #[error("embree: {0}")]
    Other(String),
}

/// One ray for a query. `tnear` is the lecture's epsilon offset, `tfar` the cutoff.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayQuery {
    pub origin: Vec3,
    pub dir: Vec3,
    pub tnear: f32,
    pub tfar: f32,
}

/// A closest hit. `ng` is Embree's unnormalised geometric normal; `u`, `v` are the
/// barycentric coordinates for triangles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub t: f32,
    pub geom_id: u32,
    pub prim_id: u32,
    pub ng: Vec3,
    pub u: f32,
    pub v: f32,
}

/// An Embree device (`rtcNewDevice`), released on drop.
pub struct Device {/* private */}

/// A scene being built. Geometry IDs are assigned in insertion order starting at 0, so
/// they index heron's own per-shape Vecs.
pub struct SceneBuilder<'d> {
    _device: &'d Device,
}

/// A committed scene: immutable, `Send + Sync`, queried concurrently by all workers.
pub struct Scene {/* private */}

impl Device {
    /// Creates a device; `config` is Embree's configuration string (may be empty).
    pub fn new(config: &str) -> Result<Device, EmbreeError> {
        let _ = config;
        unimplemented!()
    }
    pub fn scene_builder(&self) -> SceneBuilder<'_> {
        unimplemented!()
    }
}

impl<'d> SceneBuilder<'d> {
    /// Adds a triangle mesh; returns its geometry ID.
    pub fn add_triangle_mesh(
        &mut self,
        positions: &[Vec3],
        indices: &[[u32; 3]],
    ) -> Result<u32, EmbreeError> {
        let _ = (positions, indices);
        unimplemented!()
    }
    /// Adds one sphere; returns its geometry ID.
    pub fn add_sphere(&mut self, center: Vec3, radius: f32) -> Result<u32, EmbreeError> {
        let _ = (center, radius);
        unimplemented!()
    }
    /// Commits (builds the BVH). After this the scene cannot be modified.
    pub fn commit(self) -> Result<Scene, EmbreeError> {
        unimplemented!()
    }
}

impl Scene {
    pub fn intersect1(&self, ray: &RayQuery) -> Option<Hit> {
        let _ = ray;
        unimplemented!()
    }
    pub fn occluded1(&self, ray: &RayQuery) -> bool {
        let _ = ray;
        unimplemented!()
    }
    /// Coherent 8-wide packet; lanes whose bit in `active` is 0 are ignored and get None.
    pub fn intersect8(&self, rays: &[RayQuery; 8], active: u8) -> [Option<Hit>; 8] {
        let _ = (rays, active);
        unimplemented!()
    }
    /// Returns a bit mask of the active lanes that are occluded.
    pub fn occluded8(&self, rays: &[RayQuery; 8], active: u8) -> u8 {
        let _ = (rays, active);
        unimplemented!()
    }
}

/// Sets the flush-to-zero and denormals-are-zero bits of the calling thread's MXCSR, as
/// Embree asks of every thread that traces rays. Call once per worker thread.
pub fn set_flush_denormals() {}
