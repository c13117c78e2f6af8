//! Materials, one file per model; a closed enum dispatched by `match` in the integrator.
//!
//! Direction convention: as in the seed and pbrt, ωo and ωi point away from the surface.
pub mod dielectric;
pub mod fresnel;
pub mod lambertian;
pub mod mirror;
pub mod phong;

pub use dielectric::Dielectric;
pub use lambertian::Lambertian;
pub use mirror::Mirror;
pub use phong::Glossy;

#[derive(Clone, Debug)]
pub enum Material {
    Lambertian(Lambertian),
    Mirror(Mirror),
    Dielectric(Dielectric),
    /// The seed's modified Phong model, optionally over a refractive base.
    Glossy(Glossy),
}
