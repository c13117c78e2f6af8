//! The surface interaction (the seed's HitInfo).
pub struct Interaction;
