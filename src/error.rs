//! heron's library error type. Messages for bad input name the file, the key or line,
//! and what was expected.
use std::path::PathBuf;

#[derive(Debug, thiserror::Error)]
pub enum HeronError {
    /// A scene file (or a file it refers to) is unreadable or invalid.
    #[error("{file}: {message}")]
    Scene { file: PathBuf, message: String },
    #[error(transparent)]
    Embree(#[from] crate::accel::embree::EmbreeError),
    #[error("{path}: {message}")]
    Io { path: PathBuf, message: String },
    #[error("{0}")]
    Invalid(String),
    /// The render was abandoned through `RenderOptions::cancel`.
    #[error("the render was cancelled")]
    Cancelled,
}

pub type Result<T> = std::result::Result<T, HeronError>;
