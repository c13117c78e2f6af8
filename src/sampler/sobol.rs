//! Owen-scrambled Sobol' points with pixels decorrelated along a Morton curve (pbrt-v4's
//! `ZSobolSampler`, after Ahmed & Wonka 2020, "Screen-Space Blue-Noise Diffusion of
//! Monte Carlo Sampling Error via Hierarchical Ordering of Pixels").
//!
//! - Every dimension is drawn from the first two dimensions of Sobol's sequence (the
//!   van der Corput sequence and its companion, Sobol 1967), which form a (0, 2)-sequence
//!   in base 2: any 2^m consecutive, aligned points are a (0, m, 2)-net. A 1D decision
//!   reads dimension 0, a 2D decision both.
//! - Each decision's points are scrambled by its own nested uniform (Owen) scramble,
//!   computed by hashing (Burley 2020, "Practical Hash-based Owen Scrambling", JCGT 9(4),
//!   with the improved hash pbrt-v4 uses), which keeps the net property and makes the
//!   decisions independent of each other.
//! - The sample index is the pixel's Morton code followed by the sample number, its
//!   base-4 digits shuffled by a hash of the decision (pbrt-v4 §8.7.7): neighbouring
//!   pixels take disjoint, well-spread parts of one global sequence, and each pixel's
//!   own samples are an aligned block of it, so they stratify its pixel area, its
//!   wavelengths and each bounce's decisions.
//!
//! Everything depends only on (seed, pixel, sample number, decision), never on the
//! thread: renders stay deterministic.
use glam::Vec2;

/// One minus the smallest f32 step below 1: samples stay in [0, 1).
const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// The generator matrix of Sobol's second dimension (x + 1 as primitive polynomial, all
/// direction numbers 1): column i is v_i, v_0 = 2³¹, v_i = v_{i−1} ⊕ (v_{i−1} >> 1).
const fn second_dimension() -> [u32; 32] {
    let mut v = [0u32; 32];
    v[0] = 1 << 31;
    let mut i = 1;
    while i < 32 {
        v[i] = v[i - 1] ^ (v[i - 1] >> 1);
        i += 1;
    }
    v
}

const SOBOL_1: [u32; 32] = second_dimension();

/// The second dimension's matrix applied to each byte of an index, 4 × 256 entries, so
/// that a point costs four lookups instead of a loop over 32 bits.
const fn byte_tables() -> [[u32; 256]; 4] {
    let mut t = [[0u32; 256]; 4];
    let mut byte = 0;
    while byte < 4 {
        let mut v = 0;
        while v < 256 {
            let mut y = 0u32;
            let mut bit = 0;
            while bit < 8 {
                if v & (1 << bit) != 0 {
                    y ^= SOBOL_1[8 * byte + bit];
                }
                bit += 1;
            }
            t[byte][v] = y;
            v += 1;
        }
        byte += 1;
    }
    t
}

static SOBOL_1_BYTES: [[u32; 256]; 4] = byte_tables();

/// The first two Sobol' dimensions of point `index`, as 32-bit fractions.
#[inline]
pub fn sobol_bits(index: u32) -> (u32, u32) {
    let t = &SOBOL_1_BYTES;
    let y = t[0][(index & 0xff) as usize]
        ^ t[1][((index >> 8) & 0xff) as usize]
        ^ t[2][((index >> 16) & 0xff) as usize]
        ^ t[3][(index >> 24) as usize];
    (index.reverse_bits(), y)
}

/// A nested uniform scramble of the 32-bit fraction `v` by `seed` (Burley 2020, with the
/// hash of pbrt-v4's `FastOwenScrambler`): every bit is flipped or not depending only on
/// the bits above it, so intervals of every size are permuted, never split.
#[inline]
pub fn owen_scramble(v: u32, seed: u32) -> u32 {
    let mut v = v.reverse_bits();
    v ^= v.wrapping_mul(0x3d20_adea);
    v = v.wrapping_add(seed);
    v = v.wrapping_mul((seed >> 16) | 1);
    v ^= v.wrapping_mul(0x0552_6c56);
    v ^= v.wrapping_mul(0x53a2_2864);
    v.reverse_bits()
}

#[inline]
fn to_unit(v: u32) -> f32 {
    (v as f32 * (1.0 / 4_294_967_296.0)).min(ONE_MINUS_EPSILON)
}

/// A 64-bit mixing function (pbrt-v4 `MixBits`, after Stafford's Mix13).
#[inline]
fn mix_bits(mut v: u64) -> u64 {
    v ^= v >> 31;
    v = v.wrapping_mul(0x7fb5_d329_728e_a185);
    v ^= v >> 27;
    v = v.wrapping_mul(0x81da_def4_bc2d_d44d);
    v ^= v >> 33;
    v
}

/// Morton code of (x, y): their bits interleaved, x in the even positions.
#[inline]
fn morton2(x: u32, y: u32) -> u64 {
    fn spread(v: u32) -> u64 {
        let mut v = v as u64 & 0xffff_ffff;
        v = (v | (v << 16)) & 0x0000_ffff_0000_ffff;
        v = (v | (v << 8)) & 0x00ff_00ff_00ff_00ff;
        v = (v | (v << 4)) & 0x0f0f_0f0f_0f0f_0f0f;
        v = (v | (v << 2)) & 0x3333_3333_3333_3333;
        v = (v | (v << 1)) & 0x5555_5555_5555_5555;
        v
    }
    spread(x) | (spread(y) << 1)
}

/// The 24 permutations of four base-4 digits.
const PERMUTATIONS: [[u8; 4]; 24] = [
    [0, 1, 2, 3],
    [0, 1, 3, 2],
    [0, 2, 1, 3],
    [0, 2, 3, 1],
    [0, 3, 2, 1],
    [0, 3, 1, 2],
    [1, 0, 2, 3],
    [1, 0, 3, 2],
    [1, 2, 0, 3],
    [1, 2, 3, 0],
    [1, 3, 2, 0],
    [1, 3, 0, 2],
    [2, 1, 0, 3],
    [2, 1, 3, 0],
    [2, 0, 1, 3],
    [2, 0, 3, 1],
    [2, 3, 0, 1],
    [2, 3, 1, 0],
    [3, 1, 2, 0],
    [3, 1, 0, 2],
    [3, 2, 1, 0],
    [3, 2, 0, 1],
    [3, 0, 2, 1],
    [3, 0, 1, 2],
];

/// The permuted base-4 digits `lo..hi` of a Morton index for decision `dim`: digit i
/// (at bit 2i, or 2i − 1 when log₂ spp is odd and the lowest digit is a single bit) is
/// replaced by one of the 24 permutations of {0, 1, 2, 3}, chosen by a hash of the digits
/// above it and of the decision (pbrt-v4 `ZSobolSampler::GetSampleIndex`).
#[inline]
fn permuted_digits(morton: u64, dim: u64, odd: bool, lo: u32, hi: u32) -> u64 {
    let mut index = 0u64;
    for i in lo..hi {
        let shift = 2 * i - odd as u32;
        let digit = (morton >> shift) & 3;
        let p = digit_permutation(morton, shift, dim);
        index |= (PERMUTATIONS[p as usize][digit as usize] as u64) << shift;
    }
    index
}

/// Which of the 24 permutations the digit at bit `shift` takes: a hash of the digits
/// above it and of the decision.
#[inline]
fn digit_permutation(morton: u64, shift: u32, dim: u64) -> u8 {
    let salt = 0x5555_5555u64.wrapping_mul(dim);
    ((mix_bits((morton >> (shift + 2)) ^ salt) >> 24) % 24) as u8
}

/// The lowest bit of the index when log₂ spp is odd, flipped by a hash of the bits above.
#[inline]
fn permuted_last_bit(morton: u64, dim: u64) -> u64 {
    let flip = mix_bits((morton >> 1) ^ 0x5555_5555u64.wrapping_mul(dim)) & 1;
    (morton & 1) ^ flip
}

/// Decisions whose pixel part of the index is cached (a Whitted or path sample up to a
/// depth of about 10 uses fewer; later ones are computed in full).
const CACHED: usize = 64;

#[derive(Clone, Debug)]
pub struct SobolSampler {
    /// mix_bits of the seed, the scrambles' salt.
    seed_hash: u64,
    /// log₂ of the samples per pixel, rounded up.
    log2_spp: u32,
    /// Base-4 digits of the Morton index that carry information.
    base4_digits: u32,
    /// The Morton code of the current pixel.
    pixel: u64,
    morton_index: u64,
    dimension: u32,
    /// Per decision, the permuted digits that hold only pixel bits, which every sample of
    /// the pixel shares: a sampler renders one pixel's samples in a row (the render loop
    /// keeps one sampler per packet lane), so only the few digits holding the sample
    /// number are permuted per point. Bit d of `cached` says entry d is the current
    /// pixel's.
    high: [u64; CACHED],
    cached: u64,
    /// Per decision, the digits below `split` except the lowest, permuted, and the lowest
    /// digit's permutation (its flip when log₂ spp is odd), for the samples whose index
    /// agrees above the lowest digit (`low_key`): consecutive samples of a pixel share
    /// them in runs of 4 (2 when log₂ spp is odd), so the hashes run once per run.
    low_key: [u64; CACHED],
    low_upper: [u64; CACHED],
    low_perm: [u8; CACHED],
    /// Per decision, the scrambles' hash ([`Self::hash`]), which depends only on the seed
    /// and the decision.
    scramble: [u64; CACHED],
}

impl SobolSampler {
    /// For a film of `width` × `height` pixels and `spp` samples per pixel (rounded up to
    /// a power of two for the index arithmetic; a render of fewer samples uses the first
    /// `spp` of each pixel's block).
    pub fn new(seed: u64, width: u32, height: u32, spp: u32) -> Self {
        let log2_spp = spp.max(1).next_power_of_two().trailing_zeros();
        let res = width.max(height).max(1).next_power_of_two();
        let log4_res = res.trailing_zeros();
        let seed_hash = mix_bits(seed.wrapping_add(0x9e37_79b9_7f4a_7c15));
        SobolSampler {
            seed_hash,
            log2_spp,
            base4_digits: log4_res + log2_spp.div_ceil(2),
            pixel: u64::MAX,
            morton_index: 0,
            dimension: 0,
            high: [0; CACHED],
            cached: 0,
            low_key: [u64::MAX; CACHED],
            low_upper: [0; CACHED],
            low_perm: [0; CACHED],
            scramble: std::array::from_fn(|d| mix_bits(d as u64 ^ seed_hash)),
        }
    }

    #[inline]
    pub fn start_pixel_sample(&mut self, x: u32, y: u32, index: u32) {
        let pixel = morton2(x, y);
        if pixel != self.pixel {
            self.pixel = pixel;
            self.cached = 0;
        }
        self.morton_index = (pixel << self.log2_spp) | index as u64;
        self.dimension = 0;
    }

    /// The sample's index in the global sequence for the current decision: the Morton
    /// index with its base-4 digits permuted.
    #[inline]
    fn sample_index(&mut self) -> u64 {
        let odd = self.log2_spp & 1 == 1;
        // Digits from `split` up hold pixel bits only.
        let split = self.log2_spp.div_ceil(2);
        let dim = self.dimension as u64;
        let m = self.morton_index;
        let d = self.dimension as usize;
        if d >= CACHED {
            let mut index = permuted_digits(m, dim, odd, odd as u32, self.base4_digits);
            if odd {
                index |= permuted_last_bit(m, dim);
            }
            return index;
        }
        if self.cached & (1 << d) == 0 {
            self.high[d] = permuted_digits(m, dim, odd, split, self.base4_digits);
            self.cached |= 1 << d;
        }
        if self.log2_spp == 0 {
            return self.high[d];
        }
        // The lowest digit's permutation and every digit above it depend only on the
        // index without that digit (`permuted_digits`).
        let key = if odd { m >> 1 } else { m >> 2 };
        if self.low_key[d] != key {
            self.low_key[d] = key;
            self.low_upper[d] = permuted_digits(m, dim, odd, 1, split);
            self.low_perm[d] = if odd {
                permuted_last_bit(m, dim) as u8 ^ (m & 1) as u8
            } else {
                digit_permutation(m, 0, dim)
            };
        }
        let lowest = if odd {
            (m & 1) ^ self.low_perm[d] as u64
        } else {
            PERMUTATIONS[self.low_perm[d] as usize][(m & 3) as usize] as u64
        };
        self.high[d] | self.low_upper[d] | lowest
    }

    /// Hash of (decision, seed) for the scrambles.
    #[inline]
    fn hash(&self) -> u64 {
        match self.scramble.get(self.dimension as usize) {
            Some(&h) => h,
            None => mix_bits((self.dimension as u64) ^ self.seed_hash),
        }
    }

    /// (pixel and sample, decision, seed) hashed, drawing no number.
    #[inline]
    pub fn stream_key(&self) -> u64 {
        mix_bits(self.morton_index ^ mix_bits((self.dimension as u64) ^ self.seed_hash))
    }

    /// (index in the sequence, scramble hash) for the current decision.
    #[inline]
    fn point(&mut self) -> (u32, u64) {
        (self.sample_index() as u32, self.hash())
    }

    #[inline]
    pub fn get_1d(&mut self) -> f32 {
        let (index, h) = self.point();
        self.dimension += 1;
        to_unit(owen_scramble(sobol_bits(index).0, h as u32))
    }

    #[inline]
    pub fn get_2d(&mut self) -> Vec2 {
        let (index, h) = self.point();
        self.dimension += 2;
        let (x, y) = sobol_bits(index);
        Vec2::new(
            to_unit(owen_scramble(x, h as u32)),
            to_unit(owen_scramble(y, (h >> 32) as u32)),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every elementary interval [a/2^k, (a+1)/2^k) × [b/2^(m−k), (b+1)/2^(m−k)) holds
    /// exactly one of 2^m points.
    fn is_net(points: &[(f64, f64)], m: u32) -> bool {
        for k in 0..=m {
            let (nx, ny) = (1usize << k, 1usize << (m - k));
            let mut seen = vec![false; nx * ny];
            for &(x, y) in points {
                let cell = ((x * nx as f64) as usize).min(nx - 1) * ny
                    + ((y * ny as f64) as usize).min(ny - 1);
                if seen[cell] {
                    return false;
                }
                seen[cell] = true;
            }
        }
        true
    }

    #[test]
    fn scrambled_sobol_blocks_are_nets() {
        for m in [4u32, 7, 10] {
            for seed in [0u32, 7, 0xdead_beef] {
                for start in [0u32, 1 << m, 5 << m] {
                    let pts: Vec<(f64, f64)> = (start..start + (1 << m))
                        .map(|i| {
                            let (x, y) = sobol_bits(i);
                            (
                                to_unit(owen_scramble(x, seed)) as f64,
                                to_unit(owen_scramble(y, seed ^ 0x1234_5678)) as f64,
                            )
                        })
                        .collect();
                    assert!(is_net(&pts, m), "m = {m}, seed = {seed}, start = {start}");
                }
            }
        }
    }

    #[test]
    fn each_pixels_samples_are_a_net_in_every_2d_decision() {
        for spp in [16u32, 64, 256] {
            let m = spp.trailing_zeros();
            let mut s = SobolSampler::new(3, 37, 23, spp);
            for &(px, py) in &[(0u32, 0u32), (5, 9), (36, 22)] {
                // The pixel position and the next 2D decision.
                for decision in 0..2 {
                    let pts: Vec<(f64, f64)> = (0..spp)
                        .map(|i| {
                            s.start_pixel_sample(px, py, i);
                            let mut p = s.get_2d();
                            if decision == 1 {
                                s.get_1d();
                                p = s.get_2d();
                            }
                            (p.x as f64, p.y as f64)
                        })
                        .collect();
                    assert!(
                        is_net(&pts, m),
                        "spp {spp}, pixel ({px}, {py}), decision {decision}"
                    );
                }
            }
        }
    }

    #[test]
    fn byte_tables_equal_the_matrix_product() {
        let slow = |mut a: u32| {
            let mut y = 0u32;
            let mut i = 0;
            while a != 0 {
                if a & 1 != 0 {
                    y ^= SOBOL_1[i];
                }
                a >>= 1;
                i += 1;
            }
            y
        };
        let mut x = 0x1234_5678u32;
        for i in 0..100_000u32 {
            x = x.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
            assert_eq!(sobol_bits(i).1, slow(i));
            assert_eq!(sobol_bits(x).1, slow(x));
        }
        // The second dimension's first points: 0, 1/2, 3/4, 1/4, 5/8, 1/8, 3/8, 7/8.
        let want = [0.0, 0.5, 0.75, 0.25, 0.625, 0.125, 0.375, 0.875];
        for (i, w) in want.iter().enumerate() {
            assert_eq!(sobol_bits(i as u32).1 as f64 / 4_294_967_296.0, *w);
        }
    }

    /// The index with every digit permuted afresh, as the cache must reproduce it.
    fn full_index(s: &SobolSampler) -> u64 {
        let odd = s.log2_spp & 1 == 1;
        let dim = s.dimension as u64;
        let mut index = permuted_digits(s.morton_index, dim, odd, odd as u32, s.base4_digits);
        if odd {
            index |= permuted_last_bit(s.morton_index, dim);
        }
        index
    }

    #[test]
    fn cached_digits_give_the_full_index() {
        for spp in [1u32, 2, 8, 32, 64] {
            let mut s = SobolSampler::new(9, 300, 200, spp);
            // Revisit pixels in an order that invalidates the cache, and run past it.
            // Samples in a row (as the render loop asks for them), backwards, and
            // jumping by an odd stride, so that runs sharing the low digits' cache are
            // cut at every place.
            let orders: [Vec<u32>; 3] = [
                (0..spp).collect(),
                (0..spp).rev().collect(),
                (0..spp).map(|i| (i * 7 + 3) % spp).collect(),
            ];
            let pixels = [(0u32, 0u32), (299, 199), (0, 0), (17, 4), (17, 4), (5, 150)];
            for (&(x, y), order) in pixels.iter().zip(orders.iter().cycle()) {
                for &i in order {
                    s.start_pixel_sample(x, y, i);
                    for _ in 0..CACHED + 5 {
                        let want = full_index(&s);
                        assert_eq!(s.sample_index(), want, "spp {spp}, pixel ({x}, {y}), {i}");
                        s.dimension += 1;
                    }
                }
            }
        }
    }

    #[test]
    fn morton_interleaves_bits() {
        assert_eq!(morton2(0b11, 0b00), 0b0101);
        assert_eq!(morton2(0b00, 0b11), 0b1010);
        assert_eq!(morton2(5, 3), 0b011011);
    }
}
