//! Geometry as heron stores it: shapes indexed by Embree's geomID, the ray, and the
//! surface interaction record (the lecture's HitInfo).
pub mod interaction;
pub mod ray;
pub mod spawn;

pub use interaction::Interaction;
pub use ray::Ray;
pub use spawn::{RayOffset, SpawnPoint};

use glam::Vec3;

/// A triangle mesh in world space. Planes, quads and single triangles from scene files
/// become meshes too, so Embree sees one triangle type.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    pub positions: Vec<Vec3>,
    pub indices: Vec<[u32; 3]>,
}

impl Mesh {
    /// The vertices of triangle `prim` (Embree's primID).
    #[inline]
    pub fn triangle(&self, prim: u32) -> [Vec3; 3] {
        let [a, b, c] = self.indices[prim as usize];
        [
            self.positions[a as usize],
            self.positions[b as usize],
            self.positions[c as usize],
        ]
    }
}

#[derive(Clone, Debug)]
pub enum ShapeKind {
    Sphere { center: Vec3, radius: f32 },
    Mesh(Mesh),
}

/// One shape of the scene; its index in `Scene::shapes` is its Embree geomID.
#[derive(Clone, Debug)]
pub struct Shape {
    pub kind: ShapeKind,
    /// Index into `Scene::materials`.
    pub material: u32,
}
