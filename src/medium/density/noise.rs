//! Seeded value noise for clouds: fractal Brownian motion of value noise (Perlin 1985's
//! lattice noise with random values at the lattice points instead of gradients, summed
//! over octaves: Ebert et al., "Texturing and Modeling", ch. 2), thresholded so that
//! part of the volume is clear air, and baked into a [`Grid`] over the medium's box so
//! that its lookup is trilinear and its majorants exact.
//!
//! n(x) = Σ_{o<O} g^o v(2^o x/s) / Σ_{o<O} g^o with v the lattice values (a hash of the
//! seed and the lattice point, in [0, 1)) interpolated with the quintic fade
//! 6t⁵ − 15t⁴ + 10t³, s the feature size and g = 1/2; then ρ = max(0, n − c)/(1 − c) with
//! c the threshold. With `taper`, n is first multiplied by 1 − r², r the distance from
//! the box's centre in units of the ellipsoid the box circumscribes (0 at and beyond
//! it), so a cloud fades out inside its box instead of being cut by the box's walls.
use super::grid::Grid;
use glam::Vec3;

/// Cloud noise's parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct Noise {
    pub seed: u32,
    /// The largest features' size, in scene units.
    pub scale: f32,
    pub octaves: u32,
    /// The fraction of the noise's range that is clear air, in [0, 1).
    pub threshold: f32,
    /// Cells of the baked grid along the box's longest side.
    pub resolution: u32,
    /// Whether the noise fades to 0 at the ellipsoid inscribed in the box.
    pub taper: bool,
}

/// The lattice value at (i, j, k) in [0, 1).
#[inline]
fn lattice(seed: u32, i: i32, j: i32, k: i32) -> f32 {
    let mut h = (seed as u64) ^ 0x9E37_79B9_7F4A_7C15;
    for v in [i, j, k] {
        h ^= v as u32 as u64;
        h = h.wrapping_mul(0xBF58_476D_1CE4_E5B9);
        h ^= h >> 29;
        h = h.wrapping_mul(0x94D0_49BB_1331_11EB);
        h ^= h >> 32;
    }
    (h >> 40) as f32 * (1.0 / 16_777_216.0)
}

#[inline]
fn fade(t: f32) -> f32 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

impl Noise {
    /// Value noise at `p` (in lattice units).
    fn value(&self, p: Vec3, octave: u32) -> f32 {
        let seed = self.seed.wrapping_add(octave.wrapping_mul(0x68E3_1DA4));
        let f = p.floor();
        let t = p - f;
        let (i, j, k) = (f.x as i32, f.y as i32, f.z as i32);
        let (u, v, w) = (fade(t.x), fade(t.y), fade(t.z));
        let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
        let row = |j: i32, k: i32| lerp(lattice(seed, i, j, k), lattice(seed, i + 1, j, k), u);
        let plane = |k: i32| lerp(row(j, k), row(j + 1, k), v);
        lerp(plane(k), plane(k + 1), w)
    }

    /// The thresholded fractal noise at `p`, times `weight` before the threshold.
    pub fn eval(&self, p: Vec3, weight: f32) -> f32 {
        let (mut sum, mut norm, mut amp, mut freq) = (0.0, 0.0, 1.0, 1.0 / self.scale);
        for o in 0..self.octaves {
            sum += amp * self.value(p * freq, o);
            norm += amp;
            amp *= 0.5;
            freq *= 2.0;
        }
        ((weight * sum / norm - self.threshold) / (1.0 - self.threshold)).max(0.0)
    }

    /// The noise baked at the centres of a grid over [lo, hi], `resolution` cells along
    /// its longest side and as many of the same size (at least 2) along the others.
    pub fn bake(&self, lo: Vec3, hi: Vec3) -> Grid {
        let size = hi - lo;
        let cell = size.max_element() / self.resolution as f32;
        let n = |s: f32| ((s / cell).ceil() as usize).max(2);
        let res = [n(size.x), n(size.y), n(size.z)];
        let mut values = Vec::with_capacity(res[0] * res[1] * res[2]);
        for z in 0..res[2] {
            for y in 0..res[1] {
                for x in 0..res[0] {
                    let t = Vec3::new(
                        (x as f32 + 0.5) / res[0] as f32,
                        (y as f32 + 0.5) / res[1] as f32,
                        (z as f32 + 0.5) / res[2] as f32,
                    );
                    let weight = if self.taper {
                        (1.0 - (2.0 * t - Vec3::ONE).length_squared()).max(0.0)
                    } else {
                        1.0
                    };
                    values.push(self.eval(lo + size * t, weight));
                }
            }
        }
        Grid {
            res,
            lo,
            hi,
            values,
            edge: super::grid::Edge::Clamp,
        }
    }
}
