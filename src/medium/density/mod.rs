//! Heterogeneous media: a density field ρ(x) ≥ 0 that scales a medium's coefficients,
//! σ_a(x, λ) = ρ(x) σ_a(λ) and σ_s(x, λ) = ρ(x) σ_s(λ) (for water drops: their number
//! density scales by ρ, the drops stay the same), so the phase function and the
//! spectral shape of σ_t are the same everywhere and only the amount of medium varies.
//!
//! One file per field: `height_fog` (exponential in height), `rain_shaft` (a cylinder or
//! cone under a cloud base), `noise` (seeded value noise for clouds, baked into a grid)
//! and `grid` (values on a grid of cells, trilinear; Mitsuba's `.vol` files). Each
//! answers `eval` and an upper bound over a box, `max_in`, from which [`Majorants`]
//! builds the coarse grid of majorants the trackers (`medium::tracking`) step through.
pub mod grid;
pub mod height_fog;
pub mod noise;
pub mod rain_shaft;

pub use grid::Grid;
pub use height_fog::HeightFog;
pub use noise::Noise;
pub use rain_shaft::RainShaft;

use glam::Vec3;

/// A density field.
#[derive(Clone, Debug, PartialEq)]
pub enum Field {
    /// ρ = 1: a medium that varies only in its drops (`Medium::aloft`).
    Uniform,
    HeightFog(HeightFog),
    RainShaft(RainShaft),
    Grid(Grid),
}

impl Field {
    /// ρ at `p`.
    #[inline]
    pub fn eval(&self, p: Vec3) -> f32 {
        match self {
            Field::Uniform => 1.0,
            Field::HeightFog(f) => f.eval(p),
            Field::RainShaft(f) => f.eval(p),
            Field::Grid(f) => f.eval(p),
        }
    }

    /// An upper bound of ρ over the box [lo, hi].
    pub fn max_in(&self, lo: Vec3, hi: Vec3) -> f32 {
        match self {
            Field::Uniform => 1.0,
            Field::HeightFog(f) => f.max_in(lo, hi),
            Field::RainShaft(f) => f.max_in(lo, hi),
            Field::Grid(f) => f.max_in(lo, hi),
        }
    }
}

/// Cells of the majorant grid along each axis. Finer cells bound the density more
/// tightly (fewer null collisions) but cost more steps through empty space.
pub const MAJORANT_CELLS: usize = 16;

/// The majorant grid: the box of the medium's shapes divided into cells, each with an
/// upper bound of ρ inside it (pbrt-v4's `MajorantGrid`, §11.4.3, 16³ as there).
#[derive(Clone, Debug)]
pub struct Majorants {
    lo: Vec3,
    hi: Vec3,
    cell: Vec3,
    max: Vec<f32>,
}

impl Majorants {
    /// The majorants of `field` over the box [lo, hi].
    pub fn new(field: &Field, lo: Vec3, hi: Vec3) -> Majorants {
        let n = MAJORANT_CELLS;
        let cell = (hi - lo) / n as f32;
        let mut max = Vec::with_capacity(n * n * n);
        for z in 0..n {
            for y in 0..n {
                for x in 0..n {
                    let a = lo + cell * Vec3::new(x as f32, y as f32, z as f32);
                    max.push(field.max_in(a, a + cell));
                }
            }
        }
        Majorants { lo, hi, cell, max }
    }

    /// The box the majorants cover.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        (self.lo, self.hi)
    }

    /// The largest majorant.
    pub fn peak(&self) -> f32 {
        self.max.iter().copied().fold(0.0, f32::max)
    }

    /// Calls `f(t0, t1, ρ̄)` for each stretch of the ray o + t d (d unit), t ∈ [0, len],
    /// inside one cell, in order, until `f` returns false (Amanatides & Woo 1987's grid
    /// walk). Parts of the ray outside the box have ρ̄ = 0 and are skipped: the medium is
    /// inside its shapes, and its shapes inside the box.
    #[inline]
    pub fn walk(&self, o: Vec3, d: Vec3, len: f32, mut f: impl FnMut(f32, f32, f32) -> bool) {
        let inv = d.recip();
        let (ta, tb) = ((self.lo - o) * inv, (self.hi - o) * inv);
        let (near, far) = (ta.min(tb), ta.max(tb));
        // NaN (a zero direction component on a slab's plane) is ignored by max/min.
        let t0 = near.max_element().max(0.0);
        let t1 = far.min_element().min(len);
        if !(t0 < t1) {
            return;
        }
        let n = MAJORANT_CELLS as i32;
        let p = (o + d * t0 - self.lo) / self.cell;
        let mut c = [0i32; 3];
        let mut step = [0i32; 3];
        let mut next = [f32::INFINITY; 3];
        let mut delta = [f32::INFINITY; 3];
        for a in 0..3 {
            c[a] = (p[a].floor() as i32).clamp(0, n - 1);
            if d[a] > 0.0 {
                step[a] = 1;
                delta[a] = self.cell[a] / d[a];
                next[a] = t0 + ((c[a] + 1) as f32 - p[a]) * delta[a];
            } else if d[a] < 0.0 {
                step[a] = -1;
                delta[a] = -self.cell[a] / d[a];
                next[a] = t0 + (p[a] - c[a] as f32) * delta[a];
            }
        }
        let mut t = t0;
        loop {
            let a = if next[0] <= next[1] && next[0] <= next[2] {
                0
            } else if next[1] <= next[2] {
                1
            } else {
                2
            };
            let end = next[a].min(t1);
            let m = self.max[((c[2] * n + c[1]) * n + c[0]) as usize];
            if end > t && !f(t, end, m) {
                return;
            }
            if end >= t1 {
                return;
            }
            t = end;
            c[a] += step[a];
            if !(0..n).contains(&c[a]) {
                return;
            }
            next[a] += delta[a];
        }
    }
}

/// A medium's density: its field and the field's majorants over the medium's box.
#[derive(Clone, Debug)]
pub struct Density {
    pub field: Field,
    pub majorants: Majorants,
}

impl Density {
    /// The density of `field` in a medium whose shapes fill the box [lo, hi].
    pub fn new(field: Field, lo: Vec3, hi: Vec3) -> Density {
        // A box of no thickness (a flat mesh is not closed, but rounding may make one)
        // keeps a cell size > 0.
        let hi = hi.max(lo + Vec3::splat(1e-6 * (hi - lo).max_element().max(1e-6)));
        let majorants = Majorants::new(&field, lo, hi);
        Density { field, majorants }
    }

    #[inline]
    pub fn eval(&self, p: Vec3) -> f32 {
        self.field.eval(p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_walk_covers_the_ray_inside_the_box_in_order() {
        let f = Field::HeightFog(HeightFog {
            up: Vec3::Y,
            base: 0.0,
            scale_height: 1.0,
        });
        let m = Majorants::new(&f, Vec3::splat(-1.0), Vec3::splat(1.0));
        let o = Vec3::new(-3.0, -0.3, 0.2);
        let d = Vec3::new(1.0, 0.4, -0.2).normalize();
        let mut last: Option<f32> = None;
        let mut total = 0.0;
        m.walk(o, d, 100.0, |a, b, maj| {
            if let Some(l) = last {
                assert!((a - l).abs() < 1e-5, "gap {l} .. {a}");
            }
            // Every point of the stretch is under its majorant.
            for k in 0..=8 {
                let p = o + d * (a + (b - a) * k as f32 / 8.0);
                assert!(f.eval(p) <= maj * 1.0001, "{} > {maj}", f.eval(p));
            }
            last = Some(b);
            total += b - a;
            true
        });
        // The chord through the box, from the slab test.
        let inv = d.recip();
        let (ta, tb) = ((Vec3::splat(-1.0) - o) * inv, (Vec3::splat(1.0) - o) * inv);
        let chord = ta.max(tb).min_element() - ta.min(tb).max_element();
        assert!((total - chord).abs() < 1e-4, "{total} vs {chord}");
    }
}
