//! heron: a physically faithful spectral ray tracer for optics research, on Intel Embree.
//!
//! See ARCHITECTURE.md for the map of the code and how one sample flows.
#![deny(unsafe_code)]
// `!(x > 0.0)` is how the sampling code rejects NaN along with non-positive values.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod accel;
pub mod bench;
pub mod bsdf;
pub mod camera;
pub mod checkpoint;
pub mod colorimetry;
pub mod compare;
pub mod converge;
pub mod drops;
pub mod error;
pub mod files;
pub mod film;
#[doc(hidden)]
pub mod fuzzing;
pub mod geometry;
pub mod integrator;
pub mod lensdesign;
pub mod light;
pub mod math;
pub mod medium;
pub mod optics;
pub mod plot;
pub mod provenance;
pub mod render;
pub mod sampler;
pub mod scene;
pub mod session;
pub mod settings;
pub mod sky;
pub mod spectrum;
pub mod stress;
pub mod texture;
pub mod trace;
pub mod view;

pub use error::{HeronError, Result};
