//! Geometry as heron stores it: shapes indexed by Embree's geomID, the ray, and the
//! surface interaction record (the lecture's HitInfo).
pub mod interaction;
pub mod ray;
pub mod spawn;

pub use interaction::Interaction;
pub use ray::Ray;
pub use spawn::{RayOffset, SpawnPoint, MIN_RELATIVE_RADIUS};

use glam::Vec3;
use std::collections::HashMap;

/// A triangle mesh in world space. Planes, quads and single triangles from scene files
/// become meshes too, so Embree sees one triangle type.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    pub positions: Vec<Vec3>,
    pub indices: Vec<[u32; 3]>,
    /// Texture coordinates of each triangle's three corners (image textures), or empty:
    /// a triangle then has the barycentric coordinates (b1, b2) as its uv, as Mitsuba 3
    /// gives a mesh without them. Per corner, so that a seam needs no split vertices.
    pub uvs: Vec<[glam::Vec2; 3]>,
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

    /// The texture coordinates at barycentrics (b1, b2) of triangle `prim`.
    #[inline]
    pub fn uv(&self, prim: u32, b1: f32, b2: f32) -> glam::Vec2 {
        triangle_uv(&self.uvs, prim, b1, b2)
    }
}

/// The texture coordinates at barycentrics (b1, b2) of triangle `prim` of a mesh whose
/// per-corner coordinates are `uvs` (empty: (b1, b2) themselves); [`Mesh::uv`], and an
/// emitting mesh's sampled points (`light::area`).
#[inline]
pub fn triangle_uv(uvs: &[[glam::Vec2; 3]], prim: u32, b1: f32, b2: f32) -> glam::Vec2 {
    if uvs.is_empty() {
        return glam::Vec2::new(b1, b2);
    }
    let [ta, tb, tc] = uvs[prim as usize];
    ta * (1.0 - b1 - b2) + tb * b1 + tc * b2
}

/// A sphere's texture coordinates in the direction `d` from its centre: Mitsuba 3's
/// (φ/2π, θ/π) about +z, φ = atan2(y, x) in [0, 2π), θ from +z
/// (`src/shapes/sphere.cpp`). [`Shape::uv`], and an emitting sphere's sampled points.
#[inline]
pub fn sphere_uv(d: Vec3) -> glam::Vec2 {
    let d = d.normalize_or_zero();
    let mut phi = d.y.atan2(d.x);
    if phi < 0.0 {
        phi += 2.0 * std::f32::consts::PI;
    }
    let theta = d.x.hypot(d.y).atan2(d.z);
    glam::Vec2::new(
        phi * (0.5 * std::f32::consts::FRAC_1_PI),
        theta * std::f32::consts::FRAC_1_PI,
    )
}

#[derive(Clone, Debug)]
pub enum ShapeKind {
    Sphere { center: Vec3, radius: f32 },
    Mesh(Mesh),
}

/// [`Shape::light`] of a shape that does not emit.
pub const NO_LIGHT: u32 = u32::MAX;

/// [`Shape::medium`] of a shape that encloses no medium.
pub const NO_MEDIUM: u32 = u32::MAX;

/// One shape of the scene; its index in `Scene::shapes` is its Embree geomID. It carries
/// what the transport asks of it at a hit: its material, its light and its medium.
#[derive(Clone, Debug)]
pub struct Shape {
    pub kind: ShapeKind,
    /// Index into `Scene::materials`.
    pub material: u32,
    /// Its area light in `Scene::lights`, or [`NO_LIGHT`].
    pub light: u32,
    /// The medium it encloses in `Scene::media`, or [`NO_MEDIUM`].
    pub medium: u32,
    /// Whether it is only a medium's boundary (a medium and no material): index-matched,
    /// rays pass it without refraction or reflection.
    pub interface: bool,
    /// Whether its area light's emission is a texture, so that a hit needs its uv
    /// (`Scene::interaction`) even when its material is not textured.
    pub textured_emission: bool,
}

impl Shape {
    /// A shape of `material` that neither emits nor encloses a medium.
    pub fn new(kind: ShapeKind, material: u32) -> Shape {
        Shape {
            kind,
            material,
            light: NO_LIGHT,
            medium: NO_MEDIUM,
            interface: false,
            textured_emission: false,
        }
    }

    /// The texture coordinates at point `p` of the shape (on it), barycentrics (b1, b2)
    /// of triangle `prim` for a mesh: a mesh's own uvs ([`Mesh::uv`]); for a sphere
    /// Mitsuba 3's (φ/2π, θ/π) about +z, φ = atan2(y, x) in [0, 2π), θ from +z
    /// (`src/shapes/sphere.cpp`).
    #[inline]
    pub fn uv(&self, p: Vec3, prim: u32, b1: f32, b2: f32) -> glam::Vec2 {
        match &self.kind {
            ShapeKind::Sphere { center, .. } => sphere_uv(p - *center),
            ShapeKind::Mesh(m) => m.uv(prim, b1, b2),
        }
    }

    /// Whether the shape encloses a volume: a sphere, or a mesh whose every edge is
    /// shared by exactly two triangles. A medium needs one around it, and `heron stress`
    /// counts a ray that escapes after leaving into one as a leak.
    pub fn is_closed(&self) -> bool {
        match &self.kind {
            ShapeKind::Sphere { .. } => true,
            ShapeKind::Mesh(m) => {
                let mut edges: HashMap<(u32, u32), u32> = HashMap::new();
                for t in &m.indices {
                    for k in 0..3 {
                        let (a, b) = (t[k], t[(k + 1) % 3]);
                        *edges.entry((a.min(b), a.max(b))).or_default() += 1;
                    }
                }
                !edges.is_empty() && edges.values().all(|&c| c == 2)
            }
        }
    }
}
