//! A density grid: values at the centres of a box's cells, trilinear between them, and
//! outside the cells' centres either clamped to the edge cells (Mitsuba 3's
//! `gridvolume` with its default `filter_type = "trilinear"`, `wrap_mode = "clamp"`:
//! dr::Texture's cell-centred lookup) or blended with zeros and 0 outside the box
//! (pbrt-v4's `SampledGrid::Lookup`, src/pbrt/util/containers.h, whose `uniformgrid`
//! medium has no density outside its bounds); and Mitsuba's binary `.vol` format (`src/render/volumegrid.cpp`): "VOL",
//! version 3, encoding 1 (float32), x, y and z resolutions and the channel count as
//! little-endian int32, the box as six float32 (min then max), then the values, x fastest.
use glam::Vec3;

/// What a grid is outside its cells' centres.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Edge {
    /// The edge cells' values continue (Mitsuba 3).
    #[default]
    Clamp,
    /// Zeros beyond the edge cells, and 0 outside the box (pbrt-v4).
    Zero,
}

/// Values on a grid of cells over a box.
#[derive(Clone, Debug, PartialEq)]
pub struct Grid {
    /// Cells along x, y and z.
    pub res: [usize; 3],
    /// The box the cells divide.
    pub lo: Vec3,
    pub hi: Vec3,
    /// One value per cell, x fastest, then y, then z.
    pub values: Vec<f32>,
    pub edge: Edge,
}

/// The largest grid a `.vol` file may hold (values), so a corrupt header cannot ask for
/// more memory than a machine has: 1024³.
const MAX_VALUES: usize = 1 << 30;

impl Grid {
    /// The value at cell (x, y, z), clamped to the grid.
    #[inline]
    fn at(&self, x: isize, y: isize, z: isize) -> f32 {
        let inside = |v: isize, n: usize| (0..n as isize).contains(&v);
        if self.edge == Edge::Zero
            && !(inside(x, self.res[0]) && inside(y, self.res[1]) && inside(z, self.res[2]))
        {
            return 0.0;
        }
        let c = |v: isize, n: usize| v.clamp(0, n as isize - 1) as usize;
        let (x, y, z) = (c(x, self.res[0]), c(y, self.res[1]), c(z, self.res[2]));
        self.values[(z * self.res[1] + y) * self.res[0] + x]
    }

    /// Continuous cell coordinates of `p`: cell i's centre is at i + 0.5 … minus 0.5, so
    /// the lookup's lower corner is floor of it.
    #[inline]
    fn cell_coords(&self, p: Vec3) -> Vec3 {
        let r = Vec3::new(self.res[0] as f32, self.res[1] as f32, self.res[2] as f32);
        (p - self.lo) / (self.hi - self.lo) * r - Vec3::splat(0.5)
    }

    /// The trilinear value at `p`.
    #[inline]
    pub fn eval(&self, p: Vec3) -> f32 {
        if self.edge == Edge::Zero && !(p.cmpge(self.lo).all() && p.cmple(self.hi).all()) {
            return 0.0;
        }
        let c = self.cell_coords(p);
        let f = c.floor();
        let t = c - f;
        let (x, y, z) = (f.x as isize, f.y as isize, f.z as isize);
        let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
        let row = |y: isize, z: isize| lerp(self.at(x, y, z), self.at(x + 1, y, z), t.x);
        let plane = |z: isize| lerp(row(y, z), row(y + 1, z), t.y);
        lerp(plane(z), plane(z + 1), t.z)
    }

    /// The largest value the trilinear lookup takes in the box [lo, hi]: the largest of
    /// the cells it interpolates between there (a trilinear value lies between its eight
    /// corners').
    pub fn max_in(&self, lo: Vec3, hi: Vec3) -> f32 {
        let a = self.cell_coords(lo).floor();
        let b = self.cell_coords(hi).floor() + Vec3::ONE;
        let clamp = |v: f32, n: usize| (v.max(0.0) as usize).min(n - 1);
        let (x0, x1) = (clamp(a.x, self.res[0]), clamp(b.x, self.res[0]));
        let (y0, y1) = (clamp(a.y, self.res[1]), clamp(b.y, self.res[1]));
        let (z0, z1) = (clamp(a.z, self.res[2]), clamp(b.z, self.res[2]));
        let mut m = 0.0f32;
        for z in z0..=z1 {
            for y in y0..=y1 {
                let row = (z * self.res[1] + y) * self.res[0];
                for v in &self.values[row + x0..=row + x1] {
                    m = m.max(*v);
                }
            }
        }
        m
    }

    /// Checks the values: each finite and ≥ 0, naming the first bad one by its cell.
    pub fn check(&self) -> Result<(), String> {
        for (i, &v) in self.values.iter().enumerate() {
            if !(v.is_finite() && v >= 0.0) {
                let (x, rest) = (i % self.res[0], i / self.res[0]);
                let (y, z) = (rest % self.res[1], rest / self.res[1]);
                return Err(format!(
                    "expected densities finite and >= 0, got {v} at cell ({x}, {y}, {z})"
                ));
            }
        }
        Ok(())
    }

    /// A grid from a Mitsuba `.vol` file's bytes (one channel of float32).
    pub fn from_vol(bytes: &[u8]) -> Result<Grid, String> {
        if bytes.len() < 48 {
            return Err(format!(
                "expected a Mitsuba .vol grid (a 48-byte header, then the values), got {} bytes",
                bytes.len()
            ));
        }
        if &bytes[0..3] != b"VOL" {
            return Err("expected a Mitsuba .vol grid starting with \"VOL\"".into());
        }
        if bytes[3] != 3 {
            return Err(format!("expected .vol version 3, got version {}", bytes[3]));
        }
        let int = |k: usize| i32::from_le_bytes(bytes[4 + 4 * k..8 + 4 * k].try_into().unwrap());
        let float =
            |k: usize| f32::from_le_bytes(bytes[24 + 4 * k..28 + 4 * k].try_into().unwrap());
        let encoding = int(0);
        if encoding != 1 {
            return Err(format!(
                "expected .vol encoding 1 (float32), got encoding {encoding}"
            ));
        }
        let (nx, ny, nz, channels) = (int(1), int(2), int(3), int(4));
        if nx <= 0 || ny <= 0 || nz <= 0 {
            return Err(format!(
                "expected a .vol resolution of at least 1 in each axis, got {nx} x {ny} x {nz}"
            ));
        }
        if channels != 1 {
            return Err(format!(
                "expected a .vol grid of 1 channel (a density), got {channels} channels"
            ));
        }
        let res = [nx as usize, ny as usize, nz as usize];
        let count = res[0]
            .checked_mul(res[1])
            .and_then(|v| v.checked_mul(res[2]))
            .filter(|&v| v <= MAX_VALUES)
            .ok_or_else(|| {
                format!("expected a .vol grid of at most 1024^3 values, got {nx} x {ny} x {nz}")
            })?;
        let data = &bytes[48..];
        if data.len() != 4 * count {
            return Err(format!(
                "expected {count} float32 values ({} bytes) after the header for a {nx} x {ny} x {nz} grid, got {} bytes{}",
                4 * count,
                data.len(),
                if data.len() < 4 * count { " (truncated)" } else { "" }
            ));
        }
        let lo = Vec3::new(float(0), float(1), float(2));
        let hi = Vec3::new(float(3), float(4), float(5));
        if !(lo.is_finite() && hi.is_finite() && lo.cmplt(hi).all()) {
            return Err(format!(
                "expected a .vol bounding box with min < max in each axis, got min {lo} and max {hi}"
            ));
        }
        let values = data
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
            .collect();
        let g = Grid {
            res,
            lo,
            hi,
            values,
            edge: Edge::Clamp,
        };
        g.check()?;
        Ok(g)
    }

    /// The grid as a Mitsuba `.vol` file (for tests and the importers' round trips).
    pub fn to_vol(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(48 + 4 * self.values.len());
        out.extend_from_slice(b"VOL");
        out.push(3);
        for v in [
            1,
            self.res[0] as i32,
            self.res[1] as i32,
            self.res[2] as i32,
            1,
        ] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        for v in [
            self.lo.x, self.lo.y, self.lo.z, self.hi.x, self.hi.y, self.hi.z,
        ] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        for v in &self.values {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp() -> Grid {
        // Values x + 10 y + 100 z at cell centres: linear, so trilinear is exact inside.
        let res = [4, 3, 2];
        let mut values = Vec::new();
        for z in 0..2 {
            for y in 0..3 {
                for x in 0..4 {
                    values.push(x as f32 + 10.0 * y as f32 + 100.0 * z as f32);
                }
            }
        }
        Grid {
            res,
            lo: Vec3::ZERO,
            hi: Vec3::new(4.0, 3.0, 2.0),
            values,
            edge: Edge::Clamp,
        }
    }

    #[test]
    fn trilinear_is_exact_for_a_linear_field_and_clamps_outside() {
        let g = ramp();
        let v = g.eval(Vec3::new(1.75, 1.25, 1.0));
        assert!((v - (1.25 + 7.5 + 50.0)).abs() < 1e-4, "{v}");
        // Beyond the last centre the edge cell's value holds.
        assert_eq!(g.eval(Vec3::new(-5.0, 0.1, 0.2)), 0.0);
        assert_eq!(g.eval(Vec3::new(9.0, 9.0, 9.0)), 3.0 + 20.0 + 100.0);
        // pbrt's edge: half the edge value midway between the last centre and the wall,
        // nothing beyond the box.
        let z = Grid {
            edge: Edge::Zero,
            ..g
        };
        assert!((z.eval(Vec3::new(0.25, 0.5, 0.5)) - 0.0).abs() < 1e-6);
        let v = z.eval(Vec3::new(3.75, 0.5, 0.5));
        assert!((v - 0.75 * 3.0).abs() < 1e-5, "{v}");
        assert_eq!(z.eval(Vec3::new(4.01, 0.5, 0.5)), 0.0);
    }

    #[test]
    fn max_in_bounds_every_lookup_in_the_box() {
        let g = ramp();
        let (lo, hi) = (Vec3::new(0.6, 0.2, 0.1), Vec3::new(1.9, 1.4, 0.9));
        let m = g.max_in(lo, hi);
        let mut seen = 0.0f32;
        for i in 0..=20 {
            for j in 0..=20 {
                for k in 0..=20 {
                    let t = Vec3::new(i as f32, j as f32, k as f32) / 20.0;
                    seen = seen.max(g.eval(lo + (hi - lo) * t));
                }
            }
        }
        assert!(seen <= m, "{seen} > {m}");
        // And it is tight to the cells involved: cell (2, 1, 1) is the farthest corner.
        assert_eq!(m, 2.0 + 10.0 + 100.0);
    }

    #[test]
    fn vol_round_trips_and_bad_files_are_named() {
        let g = ramp();
        let bytes = g.to_vol();
        assert_eq!(Grid::from_vol(&bytes).unwrap(), g);
        let e = Grid::from_vol(&bytes[..bytes.len() - 3]).unwrap_err();
        assert!(e.contains("truncated"), "{e}");
        let mut nan = bytes.clone();
        nan[48 + 4 * 5..48 + 4 * 6].copy_from_slice(&f32::NAN.to_le_bytes());
        let e = Grid::from_vol(&nan).unwrap_err();
        assert!(e.contains("cell (1, 1, 0)"), "{e}");
        let mut neg = bytes.clone();
        neg[48..52].copy_from_slice(&(-1.0f32).to_le_bytes());
        assert!(Grid::from_vol(&neg).unwrap_err().contains(">= 0"));
        let mut wrong = bytes;
        wrong[8..12].copy_from_slice(&5i32.to_le_bytes());
        assert!(Grid::from_vol(&wrong).unwrap_err().contains("5 x 3 x 2"));
        assert!(Grid::from_vol(b"VOX").unwrap_err().contains("48-byte"));
    }
}
