//! The hexagonal ice prism: its eight faces, its projected area toward a direction, a
//! point of entry drawn uniformly over that projected area, and the face a ray inside
//! leaves through.
//!
//! Frame of the crystal: the c-axis (the prism's axis, normal to the two basal faces) is
//! +z; the a-axes (centre to vertex of the hexagon) are at 0°, 60°, …, 300° from +x, so
//! the six prism faces have outward normals at 30°, 90°, …, 330° (Tape 1994,
//! "Atmospheric Halos", fig. 1.1; Greenler 1980, "Rainbows, Halos and Glories", ch. 2).
//! Faces 0–5 are the prism faces in that order, 6 the top basal face (+z), 7 the
//! bottom one. Alternate prism faces (k and k + 2) make the 60° prism of the 22° halo; a
//! basal face and a prism face the 90° prism of the 46° halo.
//!
//! Size: the hexagon's semi-diameter a (centre to vertex, which is also its side) is 1;
//! the prism's half-length along the c-axis is c. The shape is the aspect ratio c/a:
//! plates below 1, columns above.
use glam::DVec3;

/// Index of the top basal face (+z); the bottom one is `TOP + 1`.
pub const TOP: usize = 6;
/// Number of faces.
pub const FACES: usize = 8;

const SQRT3: f64 = 1.732_050_807_568_877_2;

/// A hexagonal prism of semi-diameter 1 and half-length `c` (c/a = c).
#[derive(Clone, Debug)]
pub struct HexPrism {
    /// Half-length along the c-axis, in units of the semi-diameter: the aspect ratio c/a.
    pub aspect: f64,
    normals: [DVec3; FACES],
    /// Distance of each face's plane from the centre.
    offsets: [f64; FACES],
    areas: [f64; FACES],
}

impl HexPrism {
    /// The prism of aspect ratio c/a = `aspect` (> 0).
    pub fn new(aspect: f64) -> HexPrism {
        let mut normals = [DVec3::ZERO; FACES];
        let mut offsets = [0.0; FACES];
        let mut areas = [0.0; FACES];
        for (k, n) in normals.iter_mut().enumerate().take(6) {
            let phi = (30.0 + 60.0 * k as f64).to_radians();
            *n = DVec3::new(phi.cos(), phi.sin(), 0.0);
            offsets[k] = SQRT3 / 2.0;
            // A side of the hexagon (length 1) times the prism's length 2c.
            areas[k] = 2.0 * aspect;
        }
        normals[TOP] = DVec3::Z;
        normals[TOP + 1] = -DVec3::Z;
        offsets[TOP] = aspect;
        offsets[TOP + 1] = aspect;
        // The regular hexagon of side 1.
        areas[TOP] = 1.5 * SQRT3;
        areas[TOP + 1] = 1.5 * SQRT3;
        HexPrism {
            aspect,
            normals,
            offsets,
            areas,
        }
    }

    /// The outward unit normal of face `k`.
    #[inline]
    pub fn normal(&self, k: usize) -> DVec3 {
        self.normals[k]
    }

    /// The area of face `k`.
    #[inline]
    pub fn area(&self, k: usize) -> f64 {
        self.areas[k]
    }

    /// The total surface area S (a convex body's mean projected area over random
    /// orientations is S/4, Cauchy's theorem).
    pub fn surface_area(&self) -> f64 {
        self.areas.iter().sum()
    }

    /// The area the crystal presents to light travelling along the unit `dir`:
    /// Σ_k A_k max(0, −dir·n_k), the lit faces' areas projected (a convex body).
    pub fn projected_area(&self, dir: DVec3) -> f64 {
        (0..FACES)
            .map(|k| self.areas[k] * (-dir.dot(self.normals[k])).max(0.0))
            .sum()
    }

    /// An upper bound of [`Self::projected_area`] over all directions: half the surface
    /// area (the lit half of a convex body can never exceed it).
    pub fn max_projected_area(&self) -> f64 {
        0.5 * self.surface_area()
    }

    /// A point where light travelling along `dir` enters, uniform over the projected
    /// area, and the face it is on. `u` gives uniform numbers in [0, 1).
    pub fn sample_entry(&self, dir: DVec3, u: &mut impl FnMut() -> f64) -> (DVec3, usize) {
        let weights: [f64; FACES] =
            std::array::from_fn(|k| self.areas[k] * (-dir.dot(self.normals[k])).max(0.0));
        let total: f64 = weights.iter().sum();
        let mut x = u() * total;
        let mut face = FACES - 1;
        for (k, &w) in weights.iter().enumerate() {
            if w > 0.0 {
                face = k;
                if x < w {
                    break;
                }
                x -= w;
            }
        }
        (self.point_on(face, u), face)
    }

    /// A point uniform on face `k`.
    fn point_on(&self, k: usize, u: &mut impl FnMut() -> f64) -> DVec3 {
        if k < TOP {
            let n = self.normals[k];
            let t = DVec3::new(-n.y, n.x, 0.0);
            n * (SQRT3 / 2.0) + t * (u() - 0.5) + DVec3::Z * (self.aspect * (2.0 * u() - 1.0))
        } else {
            // One of the six equilateral triangles (centre, vertex j, vertex j + 1), then a
            // point uniform in it (folding the unit square's upper triangle).
            let j = ((u() * 6.0) as usize).min(5);
            let (a, b) = (
                (60.0 * j as f64).to_radians(),
                (60.0 * (j + 1) as f64).to_radians(),
            );
            let (va, vb) = (
                DVec3::new(a.cos(), a.sin(), 0.0),
                DVec3::new(b.cos(), b.sin(), 0.0),
            );
            let (mut s, mut t) = (u(), u());
            if s + t > 1.0 {
                (s, t) = (1.0 - s, 1.0 - t);
            }
            let z = if k == TOP { self.aspect } else { -self.aspect };
            va * s + vb * t + DVec3::new(0.0, 0.0, z)
        }
    }

    /// The face a ray from `p` (inside, or on face `from`) along the unit `dir` leaves
    /// through, and the distance to it: the nearest plane ahead among the faces it moves
    /// toward.
    pub fn exit(&self, p: DVec3, dir: DVec3, from: usize) -> (usize, f64) {
        let mut best = (from, f64::INFINITY);
        for k in 0..FACES {
            let dn = dir.dot(self.normals[k]);
            if k == from || dn <= 0.0 {
                continue;
            }
            let t = ((self.offsets[k] - p.dot(self.normals[k])) / dn).max(0.0);
            if t < best.1 {
                best = (k, t);
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn uniforms(seed: u64) -> impl FnMut() -> f64 {
        let mut rng = crate::math::rng::Rng::new(seed, 0);
        move || rng.uniform_f64()
    }

    #[test]
    fn mean_projected_area_is_a_quarter_of_the_surface() {
        // Cauchy's theorem for convex bodies, over directions uniform on the sphere.
        let p = HexPrism::new(0.7);
        let mut u = uniforms(1);
        let n = 200_000;
        let mut sum = 0.0;
        for _ in 0..n {
            let z = 2.0 * u() - 1.0;
            let phi = 2.0 * std::f64::consts::PI * u();
            let r = (1.0 - z * z).sqrt();
            sum += p.projected_area(DVec3::new(r * phi.cos(), r * phi.sin(), z));
        }
        let mean = sum / n as f64;
        assert!(
            (mean / (p.surface_area() / 4.0) - 1.0).abs() < 0.005,
            "{mean}"
        );
    }

    #[test]
    fn entry_points_lie_on_lit_faces_and_exits_on_the_surface() {
        let p = HexPrism::new(2.5);
        let mut u = uniforms(7);
        let dir = DVec3::new(0.3, -0.5, -0.81).normalize();
        for _ in 0..10_000 {
            let (x, face) = p.sample_entry(dir, &mut u);
            assert!(dir.dot(p.normal(face)) < 0.0);
            assert!((x.dot(p.normal(face)) - p.offsets[face]).abs() < 1e-12);
            // Inside every other plane.
            for k in 0..FACES {
                assert!(x.dot(p.normal(k)) <= p.offsets[k] + 1e-12, "face {k}");
            }
            let (out, t) = p.exit(x, -p.normal(face), face);
            let y = x - p.normal(face) * t;
            assert!((y.dot(p.normal(out)) - p.offsets[out]).abs() < 1e-9);
        }
    }
}
