//! Math: glam re-exports, shading frames, warps with their densities, piecewise-constant
//! distributions, per-sample random numbers and a cache of recent tables.
pub mod distribution;
pub mod fastmath;
pub mod frame;
pub mod recent;
pub mod rng;
pub mod warp;

pub use distribution::Distribution1D;
pub use frame::Frame;
pub use glam::{Vec2, Vec3, Vec3A};
pub use rng::Rng;
