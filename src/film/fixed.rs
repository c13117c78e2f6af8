//! Exact sums of film contributions, independent of the order they are added in.
//!
//! A pixel's value is a sum of many f32 contributions. Floating-point addition is not
//! associative, so a sum carried in sample order gives different bits from the same
//! samples summed in two halves and added. Sharded renders (`--shard K/N`, `heron
//! merge`) must give the bytes of one render whatever N and the order of the parts, so
//! every contribution is rounded once, on its own, to a fixed-point integer with 62
//! fractional bits, and the integers are added with wrapping arithmetic, which is
//! associative and commutative exactly. The sum is the same whichever way the samples
//! are grouped; it is converted to f64 once, when the image is made.
//!
//! Range: a contribution must have |v| < 2⁴⁰ (≈ 1.1·10¹²; radiance of the sun's disk is
//! ~2·10⁴ W m⁻² sr⁻¹ nm⁻¹) to be added; larger ones are counted with the non-finite
//! samples and left out. A total of up to 2²³ such contributions to one pixel stays
//! below 2⁶⁵, the range of the i128 sum, so wrapping can only occur past 8 million
//! samples of the largest values in one pixel. Resolution: 2⁻⁶² ≈ 2.2·10⁻¹⁹ (values
//! are truncated toward zero, so a contribution of 10⁻⁹ keeps 32 bits; the f32 it came
//! from has 24).
//!
//! The idea is that of exact accumulators for reproducible summation (Kulisch's long
//! accumulator; Demmel & Nguyen 2015, "Parallel reproducible summation", IEEE Trans.
//! Computers 64(7)), with a window wide enough for rendering instead of the full f32
//! range.

/// Fractional bits of a fixed-point sum.
pub const FRAC_BITS: i32 = 62;

/// Contributions must be smaller than this in magnitude (2⁴⁰).
pub const LIMIT: f32 = (1u64 << 40) as f32;

/// `v` in fixed point, truncated toward zero to a multiple of 2⁻⁶²; None when `v` is not
/// finite or |v| ≥ 2⁴⁰.
///
/// Branch-free but for the range check: the integer part and the fraction of `v` (both
/// exact in f64, since v has 24 significant bits and |v| < 2⁴⁰) become two i64s by
/// truncating conversions, the fraction scaled by 2⁶² first (exact, a power of two).
/// A bit-level shift of the significand by the exponent cost three times as many
/// instructions (callgrind).
#[inline]
pub fn to_fixed(v: f32) -> Option<i128> {
    // False for NaN too.
    if !(v.abs() < LIMIT) {
        return None;
    }
    let x = v as f64;
    let int = x as i64;
    let frac = x - int as f64;
    let lo = (frac * (FRAC_BITS as f64).exp2()) as i64;
    Some(((int as i128) << FRAC_BITS) + lo as i128)
}

/// All of `values` in fixed point, or None if any is out of range.
#[inline]
pub fn to_fixed3(v: [f32; 3]) -> Option<[i128; 3]> {
    Some([to_fixed(v[0])?, to_fixed(v[1])?, to_fixed(v[2])?])
}

/// A fixed-point sum as f64 (rounded to nearest once).
#[inline]
pub fn to_f64(s: i128) -> f64 {
    // Scaling by a power of two is exact.
    s as f64 * (-FRAC_BITS as f64).exp2()
}

/// A sum of squares, exact in any grouping: each square (a non-negative f64) is
/// truncated once to a multiple of 2⁻⁶⁴ and added to a 192-bit integer (three 64-bit
/// limbs, least significant first, wrapping like the i128 sums above).
///
/// Why not an i128 like the sums: a square of a contribution near the 2⁴⁰ limit is near
/// 2⁸⁰, and the squares of dim pixels (values near 10⁻⁶, squares near 10⁻¹²) need a
/// fine resolution to keep their digits; 128 bits cannot hold both (2⁸⁰ · 2⁶⁴ = 2¹⁴⁴).
/// 192 bits hold a sum of 2⁴⁸ squares of the largest contributions at a resolution of
/// 2⁻⁶⁴ ≈ 5.4·10⁻²⁰. Three limbs rather than a u128 and a u64 keep the array 8-byte
/// aligned, 24 bytes per value.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SquareSum(pub [u64; 3]);

impl SquareSum {
    /// `s` ≥ 0 in fixed point (2⁻⁶⁴ resolution, truncated); None when `s` is not finite,
    /// negative or ≥ 2¹²⁸.
    #[inline]
    pub fn of(s: f64) -> Option<SquareSum> {
        if !(s >= 0.0 && s < 2f64.powi(128)) {
            return None;
        }
        // Both parts are exact: s's integer part is representable, s − int is exact
        // (Sterbenz), and scaling by 2⁶⁴ is a power of two.
        let int = s as u128;
        let frac = ((s - int as f64) * 2f64.powi(64)) as u64;
        Some(SquareSum([frac, int as u64, (int >> 64) as u64]))
    }

    /// Adds `o` (wrapping at 2¹⁹² like an integer: associative and commutative).
    #[inline]
    pub fn add(&mut self, o: SquareSum) {
        let (l0, c0) = self.0[0].overflowing_add(o.0[0]);
        let (l1, c1a) = self.0[1].overflowing_add(o.0[1]);
        let (l1, c1b) = l1.overflowing_add(c0 as u64);
        let l2 = self.0[2]
            .wrapping_add(o.0[2])
            .wrapping_add((c1a || c1b) as u64);
        self.0 = [l0, l1, l2];
    }

    /// The sum as f64.
    #[inline]
    pub fn to_f64(self) -> f64 {
        let [l0, l1, l2] = self.0;
        l2 as f64 * 2f64.powi(64) + l1 as f64 + l0 as f64 * 2f64.powi(-64)
    }

    /// The limbs as 24 little-endian bytes (checkpoint files).
    pub fn to_le_bytes(self) -> [u8; 24] {
        let mut b = [0u8; 24];
        for (k, l) in self.0.iter().enumerate() {
            b[8 * k..8 * k + 8].copy_from_slice(&l.to_le_bytes());
        }
        b
    }

    pub fn from_le_bytes(b: [u8; 24]) -> SquareSum {
        SquareSum(std::array::from_fn(|k| {
            u64::from_le_bytes(b[8 * k..8 * k + 8].try_into().unwrap())
        }))
    }
}

/// A fixed-point sum (as [`to_fixed`] makes them) that threads add to at once, with the
/// same bits whatever the order: the i128 is kept as two 64-bit limbs, and an add puts
/// its low limb in with one atomic add and its high limb, plus the carry that add
/// produced, with another. Each add's carry is decided by its own low-limb add, so the
/// limbs end as the exact sum modulo 2¹²⁸ once every add has finished, as the plain
/// wrapping sums do. Photon mapping's deposits (`integrator::sppm`) land in visible
/// points from every thread; a lock-free exact sum keeps its image thread-independent.
#[derive(Debug, Default)]
pub struct AtomicFixed {
    lo: std::sync::atomic::AtomicU64,
    hi: std::sync::atomic::AtomicU64,
}

impl AtomicFixed {
    #[inline]
    pub fn add(&self, v: i128) {
        use std::sync::atomic::Ordering::Relaxed;
        let (lo, hi) = (v as u64, (v >> 64) as u64);
        let old = self.lo.fetch_add(lo, Relaxed);
        let carry = old.overflowing_add(lo).1 as u64;
        // A small positive value (below 4) with no carry leaves the high limb as it is:
        // most deposits, whose second locked add is then saved.
        let h = hi.wrapping_add(carry);
        if h != 0 {
            self.hi.fetch_add(h, Relaxed);
        }
    }

    /// The sum; exact once no thread adds any more.
    #[inline]
    pub fn load(&self) -> i128 {
        use std::sync::atomic::Ordering::Relaxed;
        let (lo, hi) = (self.lo.load(Relaxed), self.hi.load(Relaxed));
        (((hi as u128) << 64) | lo as u128) as i128
    }

    /// The sum, and zero left in its place.
    #[inline]
    pub fn take(&self) -> i128 {
        use std::sync::atomic::Ordering::Relaxed;
        let (lo, hi) = (self.lo.swap(0, Relaxed), self.hi.swap(0, Relaxed));
        (((hi as u128) << 64) | lo as u128) as i128
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::rng::Rng;

    #[test]
    fn atomic_sums_from_threads_equal_the_wrapping_sum() {
        // Values of both signs and magnitudes whose low limbs carry and borrow.
        let mut rng = Rng::new(7, 1);
        let values: Vec<i128> = (0..40_000)
            .map(|i| {
                let v = (rng.uniform() as f64 - 0.5) * 10f64.powi(i % 13 - 6);
                to_fixed(v as f32).unwrap()
            })
            .collect();
        let plain = values.iter().fold(0i128, |a, &b| a.wrapping_add(b));
        let sum = AtomicFixed::default();
        std::thread::scope(|s| {
            for part in values.chunks(10_000) {
                let sum = &sum;
                s.spawn(move || part.iter().for_each(|&v| sum.add(v)));
            }
        });
        assert_eq!(sum.load(), plain);
        assert_eq!(sum.take(), plain);
        assert_eq!(sum.load(), 0);
    }

    #[test]
    fn converts_exactly_where_the_float_fits() {
        for v in [
            0.0f32,
            1.0,
            -1.0,
            0.5,
            3.0e-5,
            1234.5678,
            -7.25e9,
            1.0e12 - 65536.0,
        ] {
            let f = to_fixed(v).unwrap();
            assert_eq!(to_f64(f), v as f64, "{v}");
        }
        // Truncated toward zero below the resolution, symmetrically.
        let r = 2f32.powi(-FRAC_BITS);
        assert_eq!(to_fixed(1.5 * r), Some(1));
        assert_eq!(to_fixed(-1.5 * r), Some(-1));
        assert_eq!(to_fixed(0.49 * r), Some(0));
        assert_eq!(to_fixed(1e-30), Some(0));
        assert_eq!(to_fixed(f32::MIN_POSITIVE / 4.0), Some(0));
        // Integer and fraction parts meet exactly.
        assert_eq!(to_fixed(-2.75), Some(-(11i128 << (FRAC_BITS - 2))));
        assert_eq!(
            to_fixed(3.0e9 + 256.0),
            Some(3_000_000_256i128 << FRAC_BITS)
        );
    }

    #[test]
    fn refuses_non_finite_and_too_large_values() {
        for v in [f32::NAN, f32::INFINITY, -f32::INFINITY, LIMIT, -LIMIT, 3e38] {
            assert_eq!(to_fixed(v), None, "{v}");
        }
        assert!(to_fixed(LIMIT * (1.0 - f32::EPSILON)).is_some());
    }

    /// The point of the module: any grouping and order of the same contributions gives
    /// the same bits, which f64 sums do not.
    #[test]
    fn sums_do_not_depend_on_order_or_grouping() {
        let mut rng = Rng::new(7, 11);
        let values: Vec<f32> = (0..10_000)
            .map(|i| {
                let e = (rng.uniform() * 60.0 - 30.0).exp2();
                let s = if i % 3 == 0 { -1.0 } else { 1.0 };
                s * e * rng.uniform()
            })
            .collect();
        let fixed = |v: &[f32]| {
            v.iter()
                .fold(0i128, |a, &x| a.wrapping_add(to_fixed(x).unwrap()))
        };
        let whole = fixed(&values);
        let mut rev = values.clone();
        rev.reverse();
        assert_eq!(whole, fixed(&rev));
        for parts in [2, 3, 7, 64] {
            let chunk = values.len().div_ceil(parts);
            let s = values
                .chunks(chunk)
                .map(fixed)
                .fold(0i128, i128::wrapping_add);
            assert_eq!(s, whole, "{parts} parts");
        }
        // f64 in sample order and in reverse differ for the same data (so the test
        // above is not trivially true of any sum).
        let f = |v: &[f32]| v.iter().fold(0f64, |a, &x| a + x as f64);
        assert_ne!(f(&values), f(&rev));
        // And the fixed sum is as accurate as an f64 sum here.
        let exact: f64 = values.iter().map(|&x| x as f64).sum();
        assert!((to_f64(whole) - exact).abs() <= 1e-9 * exact.abs().max(1.0));
    }

    #[test]
    fn square_sums_are_exact_in_any_grouping_and_wide_enough() {
        // Carries across both limb boundaries.
        let mut a = SquareSum([u64::MAX, u64::MAX, 0]);
        a.add(SquareSum([1, 0, 0]));
        assert_eq!(a, SquareSum([0, 0, 1]));
        assert_eq!(SquareSum::of(1.5), Some(SquareSum([1 << 63, 1, 0])));
        assert_eq!(
            SquareSum::of(2f64.powi(80)).unwrap().to_f64(),
            2f64.powi(80)
        );
        for bad in [-1e-30, f64::NAN, f64::INFINITY, 2f64.powi(128)] {
            assert_eq!(SquareSum::of(bad), None, "{bad}");
        }
        let mut rng = Rng::new(3, 5);
        let values: Vec<f64> = (0..5000)
            .map(|_| {
                let v = (rng.uniform() as f64 * 100.0 - 50.0).exp2() * rng.uniform() as f64;
                v * v
            })
            .collect();
        let sum = |v: &[f64]| {
            v.iter().fold(SquareSum::default(), |mut a, &x| {
                a.add(SquareSum::of(x).unwrap());
                a
            })
        };
        let whole = sum(&values);
        for parts in [2, 3, 64] {
            let chunk = values.len().div_ceil(parts);
            let s = values
                .chunks(chunk)
                .map(sum)
                .fold(SquareSum::default(), |mut a, b| {
                    a.add(b);
                    a
                });
            assert_eq!(s, whole, "{parts} parts");
        }
        let exact: f64 = values.iter().sum();
        assert!((whole.to_f64() - exact).abs() <= 1e-12 * exact);
        // Squares of dim values keep their digits: (10⁻⁶)² = 10⁻¹² to 10⁻⁶ relative.
        let tiny = SquareSum::of(1e-12).unwrap().to_f64();
        assert!((tiny / 1e-12 - 1.0).abs() < 1e-6, "{tiny}");
        assert_eq!(SquareSum::from_le_bytes(whole.to_le_bytes()), whole);
    }
}
