//! Math: glam re-exports, per-sample random numbers, frames and warps.
pub use glam::{Vec2, Vec3, Vec3A};
