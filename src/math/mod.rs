//! Math: glam re-exports, per-sample random numbers and ray offsetting.
pub mod rng;

pub use glam::{Vec2, Vec3, Vec3A};
pub use rng::Rng;
