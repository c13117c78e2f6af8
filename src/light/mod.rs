//! Light sources; a closed enum dispatched by `match`.
pub mod directional;
pub mod point;

pub use directional::DirectionalLight;
pub use point::PointLight;

#[derive(Clone, Debug)]
pub enum Light {
    Point(PointLight),
    Directional(DirectionalLight),
}
