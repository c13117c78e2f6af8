//! One tile's sums of one pass, as its samples arrive: the film's planes over the tile
//! (`Layout::tile`), which [`FilmState::add_tile`](super::state::FilmState::add_tile)
//! adds into the image's in tile order.
use super::fixed::{to_fixed3, SquareSum};
use super::planes::{Layout, Planes};
use super::{add_stokes_to_bins, add_to_bins, rgb_squares, xyz_of_sample, SpectralBins, Splats};
use crate::spectrum::stokes::StokesSpectrum;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

/// What one pixel sample or one connection gives the film: radiance, or Stokes radiance
/// in a polarised render (whose S0 is the radiance and whose S1–S3 go to planes of
/// their own). The tile sums and splats are generic over it, so an unpolarised render
/// runs code with no Stokes in it (`STOKES` false); the integrators' transport
/// (`integrator::transport::Transport::Value`) is one of the two.
pub trait SampleValue<const N: usize>: Copy {
    const STOKES: bool;
    fn zero() -> Self;
    /// Adds `self` to `own` when it is finite (a connection to its pixel sample's value).
    fn add_to(&self, own: &mut Self);
    /// Splats `self` into `pixel`.
    fn splat(&self, splats: &mut Splats, pixel: u32, wl: &SampledWavelengths<N>);
    /// The radiance (S0).
    fn s0(&self) -> SampledSpectrum<N>;
    /// S1, S2, S3 as XYZ, in fixed point; None when any is out of the film's range.
    fn stokes_fixed(&self, wl: &SampledWavelengths<N>) -> Option<[i128; 9]>;
    /// S1, S2, S3 (zero for radiance).
    fn stokes_components(&self) -> [SampledSpectrum<N>; 3];
    /// `self` times `w` (a reconstruction filter's sample weight).
    fn scaled(&self, w: f32) -> Self;
}

impl<const N: usize> SampleValue<N> for SampledSpectrum<N> {
    const STOKES: bool = false;
    #[inline(always)]
    fn zero() -> Self {
        SampledSpectrum::zero()
    }
    #[inline]
    fn add_to(&self, own: &mut Self) {
        if self.is_finite() {
            *own += *self;
        }
    }
    #[inline]
    fn splat(&self, splats: &mut Splats, pixel: u32, wl: &SampledWavelengths<N>) {
        splats.add(pixel, self, wl);
    }
    #[inline(always)]
    fn s0(&self) -> SampledSpectrum<N> {
        *self
    }
    #[inline(always)]
    fn stokes_fixed(&self, _: &SampledWavelengths<N>) -> Option<[i128; 9]> {
        Some([0; 9])
    }
    #[inline(always)]
    fn stokes_components(&self) -> [SampledSpectrum<N>; 3] {
        [SampledSpectrum::zero(); 3]
    }
    #[inline]
    fn scaled(&self, w: f32) -> Self {
        *self * w
    }
}

impl<const N: usize> SampleValue<N> for StokesSpectrum<N> {
    const STOKES: bool = true;
    #[inline]
    fn zero() -> Self {
        StokesSpectrum::zero()
    }
    #[inline]
    fn add_to(&self, own: &mut Self) {
        if self.is_finite() {
            *own += *self;
        }
    }
    #[inline]
    fn splat(&self, splats: &mut Splats, pixel: u32, wl: &SampledWavelengths<N>) {
        splats.add_stokes(pixel, self, wl);
    }
    #[inline]
    fn s0(&self) -> SampledSpectrum<N> {
        self.component(0)
    }
    #[inline]
    fn stokes_fixed(&self, wl: &SampledWavelengths<N>) -> Option<[i128; 9]> {
        let mut out = [0i128; 9];
        for k in 1..4 {
            let c = self.component(k);
            if !c.is_finite() {
                return None;
            }
            let f = to_fixed3(xyz_of_sample(&c, wl))?;
            out[3 * (k - 1)..3 * k].copy_from_slice(&f);
        }
        Some(out)
    }
    #[inline]
    fn stokes_components(&self) -> [SampledSpectrum<N>; 3] {
        std::array::from_fn(|k| self.component(k + 1))
    }
    #[inline]
    fn scaled(&self, w: f32) -> Self {
        StokesSpectrum(self.0.map(|v| v * w))
    }
}

/// One tile's sums of one pass, as its samples arrive.
pub struct TileSums {
    /// The tile's origin and size in the image.
    rect: (u32, u32, u32, u32),
    bins: SpectralBins,
    planes: Planes,
    /// The render's camera packet width: the one-path-at-a-time engine's order, in which
    /// the first non-finite sample is reported.
    packet: u32,
    nonfinite: u64,
    /// The first sample left out, in the one-path-at-a-time engine's order (its key:
    /// row, packet, sample, lane), whichever order the samples finished in.
    first_nonfinite: Option<([u32; 4], (u32, u32, u32))>,
}

/// A finished tile of one pass, for [`FilmState::add_tile`](super::state::FilmState::add_tile).
pub struct TileResult {
    /// The tile's origin and size in the image.
    pub rect: (u32, u32, u32, u32),
    /// Its planes (`Layout::tile`).
    pub planes: Planes,
    /// The splats its samples made anywhere in the image, and with `--variance` per
    /// sample that splatted the squares of its splats summed per pixel.
    pub splats: Splats,
    pub splat_sq: Vec<(u32, [SquareSum; 3])>,
    /// Camera and shadow rays traced.
    pub rays: u64,
    pub shadow_rays: u64,
    pub nonfinite: u64,
    pub first_nonfinite: Option<(u32, u32, u32)>,
}

impl TileSums {
    /// Empty sums of the tile `rect` (origin and size) of a film of `layout`, whose
    /// samples come in packets of `packet` pixels of a row.
    pub fn new(layout: &Layout, rect: (u32, u32, u32, u32), packet: u32) -> Self {
        TileSums {
            rect,
            bins: SpectralBins { count: layout.bins },
            planes: Planes::new(&layout.tile(rect.2, rect.3)),
            packet,
            nonfinite: 0,
            first_nonfinite: None,
        }
    }

    /// Adds the value of sample `s` at wavelengths `wl` to the tile's pixel (`x`, `y`)
    /// (tile coordinates); `VARIANCE` also adds its squares. The sums are exact integers,
    /// so the order in which samples arrive does not change them.
    #[inline]
    pub fn add<const N: usize, const VARIANCE: bool, O: SampleValue<N>>(
        &mut self,
        (x, y, s): (u32, u32, u32),
        value: &O,
        wl: &SampledWavelengths<N>,
    ) {
        let l = &value.s0();
        let (nb, i) = (self.bins.count, (y * self.rect.2 + x) as usize);
        // A sample whose radiance is not finite, or too large for the film's fixed-point
        // sums (film/fixed.rs), is left out and counted.
        let v = if l.is_finite() {
            Some(xyz_of_sample(l, wl))
        } else {
            None
        };
        let c = v.and_then(to_fixed3);
        // S1–S3 (polarised renders) count only with S0, and S0 only with them.
        let st = if O::STOKES {
            value.stokes_fixed(wl)
        } else {
            Some([0; 9])
        };
        let p = &mut self.planes;
        // The bins are added only when the XYZ is in range, and the XYZ only when the
        // bins were. A polarised sample's four components go into their bins together.
        let ok = c.is_some()
            && st.is_some()
            && (nb == 0
                || if O::STOKES {
                    let [s1, s2, s3] = value.stokes_components();
                    add_stokes_to_bins(
                        &self.bins,
                        &mut p.bins[i * nb..(i + 1) * nb],
                        &mut p.stokes_bins[3 * i * nb..3 * (i + 1) * nb],
                        [*l, s1, s2, s3],
                        wl,
                    )
                } else {
                    add_to_bins(&self.bins, &mut p.bins[i * nb..(i + 1) * nb], l, wl)
                });
        let (Some(c), true) = (c, ok) else {
            self.nonfinite += 1;
            let key = [y, x / self.packet, s, x % self.packet];
            if self.first_nonfinite.map_or(true, |(k, _)| key < k) {
                self.first_nonfinite = Some((key, (self.rect.0 + x, self.rect.1 + y, s)));
            }
            return;
        };
        for (a, b) in p.xyz[3 * i..3 * i + 3].iter_mut().zip(c) {
            *a = a.wrapping_add(b);
        }
        if O::STOKES {
            if let Some(st) = st {
                for (a, b) in p.stokes[9 * i..9 * i + 9].iter_mut().zip(st) {
                    *a = a.wrapping_add(b);
                }
            }
        }
        p.good[i] += 1;
        if VARIANCE {
            // In range: v passed to_fixed3.
            if let Some(q) = v.and_then(rgb_squares) {
                for (a, b) in p.sq[3 * i..3 * i + 3].iter_mut().zip(q) {
                    a.add(b);
                }
            }
        }
    }

    /// The finished tile, with the splats its samples made and its ray counts.
    pub fn result(
        self,
        splats: Splats,
        splat_sq: Vec<(u32, [SquareSum; 3])>,
        (rays, shadow_rays): (u64, u64),
    ) -> TileResult {
        TileResult {
            rect: self.rect,
            planes: self.planes,
            splats,
            splat_sq,
            rays,
            shadow_rays,
            nonfinite: self.nonfinite,
            first_nonfinite: self.first_nonfinite.map(|(_, p)| p),
        }
    }
}
