//! Deterministic per-sample random numbers. Every (seed, pixel, sample index) has its
//! own PCG32 stream, so the image does not depend on thread count or tile order.
//!
//! PCG32 (O'Neill 2014, "PCG: A Family of Simple Fast Space-Efficient Statistically
//! Good Algorithms for Random Number Generation"), XSH-RR output; stream selection by
//! SplitMix64 (Steele et al. 2014) hashing of the sample's coordinates.

#[derive(Clone, Debug)]
pub struct Rng {
    state: u64,
    inc: u64,
}

const MULT: u64 = 6364136223846793005;

#[inline]
fn splitmix64(mut x: u64) -> u64 {
    x = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    x ^ (x >> 31)
}

impl Rng {
    pub fn new(seed: u64, stream: u64) -> Self {
        let mut r = Rng {
            state: 0,
            inc: (stream << 1) | 1,
        };
        r.next_u32();
        r.state = r.state.wrapping_add(seed);
        r.next_u32();
        r
    }

    /// The stream for one sample of one pixel.
    #[inline]
    pub fn for_sample(seed: u64, pixel: u64, sample: u64) -> Self {
        let a = splitmix64(seed ^ splitmix64(pixel));
        let b = splitmix64(a ^ sample.wrapping_mul(0xD1B5_4A32_D192_ED03));
        Rng::new(a, b)
    }

    /// A stream keyed by `key` and `stream`: the null-collision trackers'
    /// (`medium::tracking`), which draw as many numbers as the ray meets tentative
    /// collisions, so they cannot take fixed dimensions of the sampler. Keyed by the
    /// pixel sample and decision (`Sampler::stream_key`) rather than by the ray's bits as
    /// pbrt-v4's `SampleT_maj` is: the same numbers whatever the thread, and whichever
    /// engine traced the ray.
    #[inline]
    pub fn keyed(key: u64, stream: u64) -> Self {
        let a = splitmix64(key ^ 0x2545_F491_4F6C_DD1D);
        Rng::new(
            a,
            splitmix64(a ^ stream.wrapping_mul(0xA076_1D64_78BD_642F)),
        )
    }

    /// The state, hashed, drawing no number.
    #[inline]
    pub fn key(&self) -> u64 {
        splitmix64(self.state ^ splitmix64(self.inc))
    }

    #[inline]
    pub fn next_u32(&mut self) -> u32 {
        let old = self.state;
        self.state = old.wrapping_mul(MULT).wrapping_add(self.inc);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        let rot = (old >> 59) as u32;
        xorshifted.rotate_right(rot)
    }

    /// Uniform in [0, 1): 24 random bits, so 1.0 is never returned.
    #[inline]
    pub fn uniform(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 * (1.0 / 16_777_216.0)
    }

    /// Uniform in [0, 1) with 53 random bits from two draws: for Monte Carlo in f64
    /// (the ice crystals' ray tracing), where 24 bits would quantise angles to 1e-7.
    #[inline]
    pub fn uniform_f64(&mut self) -> f64 {
        let hi = (self.next_u32() >> 5) as u64;
        let lo = (self.next_u32() >> 6) as u64;
        ((hi << 26) | lo) as f64 * (1.0 / 9_007_199_254_740_992.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_passes_a_chi_square_test() {
        let mut r = Rng::for_sample(7, 3, 1);
        let bins = 64;
        let n = 200_000;
        let mut h = vec![0u32; bins];
        for _ in 0..n {
            let u = r.uniform();
            assert!((0.0..1.0).contains(&u));
            h[(u * bins as f32) as usize] += 1;
        }
        let e = n as f64 / bins as f64;
        let chi2: f64 = h.iter().map(|&o| (o as f64 - e).powi(2) / e).sum();
        // 63 degrees of freedom: the 99.9th percentile is about 103.4.
        assert!(chi2 < 103.4, "chi2 = {chi2}");
    }

    #[test]
    fn streams_differ_and_repeat() {
        let a: Vec<u32> = {
            let mut r = Rng::for_sample(1, 2, 3);
            (0..8).map(|_| r.next_u32()).collect()
        };
        let b: Vec<u32> = {
            let mut r = Rng::for_sample(1, 2, 3);
            (0..8).map(|_| r.next_u32()).collect()
        };
        let c: Vec<u32> = {
            let mut r = Rng::for_sample(1, 2, 4);
            (0..8).map(|_| r.next_u32()).collect()
        };
        assert_eq!(a, b);
        assert_ne!(a, c);
    }
}
