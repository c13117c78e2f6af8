//! Integrators. `whitted` is the seed lecture's recursive tracer written as the
//! lecture's loop: the shader overwrites the ray and increments the depth.
pub mod whitted;

use crate::accel::embree;
use crate::scene::Scene;

/// What an integrator needs to trace: the scene and its committed Embree scene.
#[derive(Clone, Copy)]
pub struct Context<'a> {
    pub scene: &'a Scene,
    pub accel: &'a embree::Scene,
}

/// Counters one worker keeps while tracing (summed per tile, never shared).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TraceCounters {
    /// Closest-hit rays (camera rays included).
    pub rays: u64,
    /// Occlusion (shadow) rays.
    pub shadow_rays: u64,
}
