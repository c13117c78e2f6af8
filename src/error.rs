//! heron's library error type. Messages for bad input name the file, the key or line,
//! and what was expected.
use std::path::PathBuf;

#[derive(Debug, thiserror::Error)]
pub enum HeronError {
    /// A scene file (or a file it refers to) is unreadable or invalid.
    #[error("{file}: {message}")]
    Scene { file: PathBuf, message: String },
    #[error(transparent)]
    Embree(#[from] EmbreeError),
    #[error("{path}: {message}")]
    Io { path: PathBuf, message: String },
    #[error("{0}")]
    Invalid(String),
    /// The render was abandoned through `RenderOptions::cancel`.
    #[error("the render was cancelled")]
    Cancelled,
}

/// Errors reported by Embree, through the device error callback or return codes
/// (defined here, at the bottom of the layers, and re-exported by `accel::embree`).
#[derive(Debug, thiserror::Error)]
pub enum EmbreeError {
    #[error("embree: {code}: {message}")]
    Device { code: String, message: String },
    #[error("embree: {0}")]
    Other(String),
}

pub type Result<T> = std::result::Result<T, HeronError>;
