//! Directional light: a source infinitely far away, so its shadow rays have no distance
//! cutoff (seed, "Shadow rays"). `radiance` is the lecture's L_i, the incident radiance
//! times the light's solid angle (irradiance at normal incidence).
use crate::spectrum::DenseSpectrum;
use glam::Vec3;

#[derive(Clone, Debug)]
pub struct DirectionalLight {
    /// Unit vector in the direction the light travels (from the light into the scene).
    pub direction: Vec3,
    pub radiance: DenseSpectrum,
}
