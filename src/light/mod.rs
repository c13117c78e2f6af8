//! Light sources; a closed enum dispatched by `match`.
pub mod directional;
pub mod point;
pub mod sun;

pub use directional::DirectionalLight;
pub use point::PointLight;
pub use sun::SunLight;

#[derive(Clone, Debug)]
pub enum Light {
    Point(PointLight),
    Directional(DirectionalLight),
    Sun(SunLight),
}
