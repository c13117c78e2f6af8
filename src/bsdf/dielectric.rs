//! Smooth dielectric interface: refraction after the seed ("Refraction and total internal
//! reflection"), with Fresnel-weighted choice between reflection and refraction.

#[derive(Clone, Debug)]
pub struct Dielectric {
    /// Index of refraction of the inside relative to the outside (air/vacuum = 1).
    pub ior: f32,
    /// Weight reflection and refraction by the Fresnel equations (default). When false,
    /// the lecture's pure refraction: always refract, reflect only on total internal
    /// reflection.
    pub fresnel: bool,
}
