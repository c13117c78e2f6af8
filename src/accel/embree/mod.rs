//! Intel Embree 3 (Debian's `libembree-dev`) through heron's own FFI layer.
//!
//! This module is the only place in heron where `unsafe` is allowed. Its public API is
//! safe: RAII wrappers for device, scene and geometry, a scene that is immutable once
//! committed (so it can be shared by all worker threads), and query functions for single
//! rays, packets of 4, 8 and 16 (closest hit and occlusion) and Embree 3's streams.
//!
//! * `sys.rs` (private): the `extern "C"` declarations and `#[repr(C)]` structs, with the
//!   Embree 3/4 difference behind `cfg(heron_embree4)` (set by build.rs).
//! * [`Device`] (device.rs): `rtcNewDevice`, the error callback, error checks.
//! * [`SceneBuilder`], [`Scene`] (scene.rs): geometry, commit, queries (their records
//!   built with SSE, so that heron's queries cost what Embree's own C API costs:
//!   `heron bench traversal --raw`).
//! * [`record`]: the ray log, every query a scene sends while recording
//!   ([`Scene::record`]), for `heron bench record`/`replay`/`limit`.
//!
//! References are to the Embree 3 API man pages shipped in `libembree-dev`
//! (`man rtcIntersect1`), the same text as the "Embree API" chapter of the Embree 3
//! documentation.
//!
//! Usage: one [`Device`] per process; build a scene with [`Device::scene_builder`], add
//! shapes (their geometry IDs are 0, 1, 2, … in insertion order), [`SceneBuilder::commit`],
//! then share the [`Scene`] (e.g. in an `Arc`) with the worker threads, each of which
//! calls [`set_flush_denormals`] once.
#![allow(unsafe_code)]

mod builder;
mod device;
pub mod record;
mod scene;
mod sys;

pub use device::Device;

/// The Embree major version heron's bindings were compiled for (build.rs sets
/// `cfg(heron_embree4)` for 4); the library's own version must agree.
pub const BINDINGS_MAJOR: u32 = if cfg!(heron_embree4) { 4 } else { 3 };
pub use builder::SceneBuilder;
pub use record::{QueryTally, RayLog};
pub use scene::{Scene, StreamScratch};

use glam::Vec3;

pub use crate::error::EmbreeError;

/// One ray for a query. `tnear` is the lecture's epsilon offset, `tfar` the cutoff.
///
/// `dir` need not be normalised; `t` is measured in units of `dir`. Embree needs a finite
/// origin and direction, a non-zero direction and `0 <= tnear <= tfar` (`tfar` may be
/// infinite); queries answer other rays with "no hit" / "not occluded" without tracing.
///
/// Laid out as the first 32 bytes of Embree's `RTCRay` (origin, tnear, direction, and
/// `tfar` where `RTCRay` has `time`), so a query copies it into Embree's record with two
/// 16-byte moves.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayQuery {
    pub origin: Vec3,
    pub tnear: f32,
    pub dir: Vec3,
    pub tfar: f32,
}

const _: () = {
    use std::mem::{align_of, offset_of, size_of};
    assert!(size_of::<RayQuery>() == 32 && align_of::<RayQuery>() == 4);
    assert!(offset_of!(RayQuery, tnear) == 12);
    assert!(offset_of!(RayQuery, dir) == 16);
    assert!(offset_of!(RayQuery, tfar) == 28);
};

/// A closest hit. `ng` is Embree's unnormalised geometric normal; `u`, `v` are the
/// barycentric coordinates for triangles.
///
/// Triangles: `ng = (p1 - p0) × (p2 - p0)` (counter-clockwise front face), hit point
/// `(1-u-v) p0 + u p1 + v p2`. Spheres: `ng` points outwards (from the centre through the
/// hit point, length ≈ radius), also for a ray that starts inside; `u = v = 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub t: f32,
    pub geom_id: u32,
    pub prim_id: u32,
    pub ng: Vec3,
    pub u: f32,
    pub v: f32,
}

/// Hint for Embree's traversal (`RTC_INTERSECT_CONTEXT_FLAG_COHERENT/INCOHERENT`,
/// `rtcInitIntersectContext(3)`): coherent rays (camera rays of one tile, shadow rays to
/// one light) may traverse faster with `Coherent`. Results are the same either way.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum RayCoherence {
    #[default]
    Incoherent,
    Coherent,
}

/// MXCSR bit 15: flush-to-zero (denormal results become 0).
#[cfg(target_arch = "x86_64")]
const MXCSR_FTZ: u32 = 1 << 15;
/// MXCSR bit 6: denormals-are-zero (denormal inputs are read as 0).
#[cfg(target_arch = "x86_64")]
const MXCSR_DAZ: u32 = 1 << 6;

/// A rayon pool of `threads` workers (0: one per core) whose threads set flush-to-zero
/// and denormals-are-zero when they start, as Embree asks of every thread that traces
/// rays ("Embree API", "Performance Recommendations: MXCSR control and status
/// register"), so that denormal numbers do not slow traversal down.
///
/// This is the only way heron changes MXCSR. Rust's documentation of `_mm_setcsr` calls
/// changing the floating-point environment undefined behaviour, because compiled code
/// may assume the default one. heron accepts that risk because Embree asks for it, and
/// keeps it small: the bits are set once, first thing on threads heron creates for
/// tracing, and the only effect is that subnormal inputs and results become zero.
pub fn worker_pool(threads: usize) -> Result<rayon::ThreadPool, EmbreeError> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .start_handler(|_| set_flush_denormals())
        .build()
        .map_err(|e| EmbreeError::Other(format!("cannot start worker threads: {e}")))
}

/// Sets FTZ and DAZ on the calling thread; see [`worker_pool`]. No-op on targets other
/// than x86_64.
pub fn set_flush_denormals() {
    #[cfg(target_arch = "x86_64")]
    {
        #[allow(deprecated)]
        use std::arch::x86_64::{_mm_getcsr, _mm_setcsr};
        // SAFETY: reads MXCSR; SSE is part of the x86_64 baseline.
        #[allow(deprecated)]
        let csr = unsafe { _mm_getcsr() };
        // SAFETY: SSE is part of the x86_64 baseline. Only the FTZ and DAZ bits change;
        // rounding mode and exception masks are kept, so no floating-point exception is
        // unmasked. This runs first thing on a fresh worker thread (see `worker_pool`
        // for why heron accepts the floating-point-environment caveat).
        #[allow(deprecated)]
        unsafe {
            _mm_setcsr(csr | MXCSR_FTZ | MXCSR_DAZ)
        };
    }
}

/// Whether both flush-to-zero and denormals-are-zero are set on the calling thread (always
/// false on targets other than x86_64). For debug assertions in render workers.
pub fn flush_denormals_enabled() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        #[allow(deprecated)]
        use std::arch::x86_64::_mm_getcsr;
        // SAFETY: reads MXCSR; SSE is part of the x86_64 baseline.
        #[allow(deprecated)]
        let csr = unsafe { _mm_getcsr() };
        csr & (MXCSR_FTZ | MXCSR_DAZ) == MXCSR_FTZ | MXCSR_DAZ
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}
