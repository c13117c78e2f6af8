//! A constant sky: the same spectral radiance in every direction.
use crate::spectrum::DenseSpectrum;
use glam::Vec3;

#[derive(Clone, Debug)]
pub struct ConstantSky {
    /// Radiance in every direction (any unit; heron's film maps the constant 1 to Y = 1).
    pub radiance: DenseSpectrum,
}

impl ConstantSky {
    pub fn new(radiance: DenseSpectrum) -> Self {
        ConstantSky { radiance }
    }

    #[inline]
    pub fn radiance(&self, _view_dir: Vec3, lambda_nm: f32, _sun_dir: Vec3) -> f32 {
        self.radiance.eval(lambda_nm)
    }

    #[inline]
    pub fn profile(&self, _theta_rad: f64, lambda_nm: f32) -> f32 {
        self.radiance.eval(lambda_nm)
    }
}
