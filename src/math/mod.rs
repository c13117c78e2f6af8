//! Math: glam re-exports, shading frames, warps with their densities, piecewise-constant
//! distributions and per-sample random numbers.
pub mod distribution;
pub mod fastmath;
pub mod frame;
pub mod rng;
pub mod warp;

pub use distribution::Distribution1D;
pub use frame::Frame;
pub use glam::{Vec2, Vec3, Vec3A};
pub use rng::Rng;
