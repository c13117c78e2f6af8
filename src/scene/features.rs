//! Which parts of the transport a scene needs, so the renderer can pick a kernel that
//! skips the rest.

/// The parts of the transport a scene uses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Features {
    pub shadows: bool,
    pub specular: bool,
    pub glossy: bool,
}
