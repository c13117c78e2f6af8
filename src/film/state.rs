//! The film's unnormalised state after some passes: its planes of exact sums
//! (`planes.rs`), the passes and samples they hold, the rays traced, the samples left
//! out, and an integrator's own per-pixel state. Tiles add into it in tile order, shards
//! add into each other in any order (the sums are integers), and [`FilmState::image`]
//! normalises it into a [`Film`].
//!
//! Variance (`--variance`): a pixel's value is the mean of its n finite samples, so its
//! variance is estimated from their sums S₁ = Σ c and S₂ = Σ c² as
//! (S₂ − S₁²/n) / (n (n − 1)), the unbiased sample variance divided by n. Splats add the
//! image's splatted part, (1/spp) Σⱼ sⱼ over all N = pixels × spp samples of the image,
//! sⱼ the sum of sample j's splats into the pixel; the samples are independent and
//! identically distributed (a light path does not depend on the pixel that started
//! it), so its variance is estimated as (T₂ − T₁²/N) N / ((N − 1) spp²) from T₁ = Σ sⱼ
//! and T₂ = Σ sⱼ². Left out: the covariance of a sample's own value with its splats into
//! its own pixel (BDPT), of the order of 1/pixels of the terms kept. The sums are exact
//! integers, so the variance, like the image, does not depend on threads, passes,
//! checkpoints or shards.
use super::fixed::{to_f64, to_fixed, to_fixed3, SquareSum};
use super::planes::{Layout, Planes};
use super::tile::TileResult;
use super::{linear_srgb_f64, Film, SpectralBins, Splats};

/// An integrator's own per-pixel state, which a resumed render continues from (photon
/// mapping's photon counts and radii): the film keeps and writes it, but neither adds
/// nor normalises it, and a merge of shards drops it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct IntegratorPlane {
    /// Whose state it is (`"sppm"`).
    pub name: String,
    pub values: Vec<f32>,
}

/// The film's state.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FilmState {
    pub layout: Layout,
    pub passes_done: u32,
    /// Samples per pixel held (of a shard's range).
    pub spp_done: u32,
    pub rays: u64,
    pub shadow_rays: u64,
    /// Samples and splats left out because they were not finite or out of range.
    pub nonfinite: u64,
    pub planes: Planes,
    pub integrator: Option<IntegratorPlane>,
}

impl FilmState {
    /// An empty film of `layout`.
    pub fn new(layout: Layout) -> FilmState {
        FilmState {
            layout,
            planes: Planes::new(&layout),
            ..Default::default()
        }
    }

    /// Adds one tile's sums of a pass and its splats; returns the first sample it left
    /// out, if any.
    pub fn add_tile(&mut self, t: TileResult) -> Option<(u32, u32, u32)> {
        self.planes.add_tile(self.layout.width, t.rect, &t.planes);
        self.add_splats(&t.splats, &t.splat_sq);
        self.rays += t.rays;
        self.shadow_rays += t.shadow_rays;
        self.nonfinite += t.nonfinite + t.splats.nonfinite;
        t.first_nonfinite
    }

    /// Adds splats, in their order; with `--variance`, `splat_sq` holds the squares of
    /// each sample's splats summed per pixel (`add_splat_squares`).
    fn add_splats(&mut self, splats: &Splats, splat_sq: &[(u32, [SquareSum; 3])]) {
        if !splats.list.is_empty() && !self.layout.splats {
            // Splats from an integrator not known to splat: now they count.
            self.layout.splats = true;
            self.planes.widen(&self.layout);
        }
        let nb = self.layout.bins;
        let p = &mut self.planes;
        let stokes_splats = !splats.stokes.is_empty();
        // A render splats through `Splats::add` or through `add_stokes`, never both.
        debug_assert!(!stokes_splats || splats.stokes.len() == splats.list.len());
        for (j, &(px, c)) in splats.list.iter().enumerate() {
            let px = px as usize;
            // A polarised splat's four components count together.
            let st = if stokes_splats {
                let s = &splats.stokes[j];
                match (to_fixed3(s[0]), to_fixed3(s[1]), to_fixed3(s[2])) {
                    (Some(a), Some(b), Some(c)) => Some([a, b, c]),
                    _ => None,
                }
            } else {
                Some([[0; 3]; 3])
            };
            match (to_fixed3(c), st) {
                (Some(f), Some(st)) => {
                    for (a, b) in p.splat[3 * px..3 * px + 3].iter_mut().zip(f) {
                        *a = a.wrapping_add(b);
                    }
                    if stokes_splats {
                        for (a, b) in p.splat_stokes[9 * px..9 * px + 9]
                            .iter_mut()
                            .zip(st.iter().flatten())
                        {
                            *a = a.wrapping_add(*b);
                        }
                    }
                }
                _ => self.nonfinite += 1,
            }
        }
        for (px, sq) in splat_sq {
            let px = *px as usize;
            for (a, b) in p.splat_sq[3 * px..3 * px + 3].iter_mut().zip(sq) {
                a.add(*b);
            }
        }
        for (j, &(px, k, v)) in splats.spectral.iter().enumerate() {
            // A splat too large for the film was counted with its XYZ above.
            let Some(f) = to_fixed(v) else { continue };
            if stokes_splats {
                let s = splats.stokes_spectral[j].map(to_fixed);
                let [Some(s1), Some(s2), Some(s3)] = s else {
                    continue;
                };
                for (c, v) in [s1, s2, s3].into_iter().enumerate() {
                    let a = &mut p.splat_stokes_bins[(3 * px as usize + c) * nb + k as usize];
                    *a = a.wrapping_add(v);
                }
            }
            let a = &mut p.splat_bins[px as usize * nb + k as usize];
            *a = a.wrapping_add(f);
        }
    }

    /// Adds another part's sums and counts (of the same layout) to this one's. Integer
    /// sums, so the result does not depend on the order of the parts.
    pub fn add(&mut self, o: &FilmState) {
        self.planes.add(&o.planes);
        self.passes_done += o.passes_done;
        self.spp_done += o.spp_done;
        self.rays += o.rays;
        self.shadow_rays += o.shadow_rays;
        self.nonfinite += o.nonfinite;
    }

    /// Per value of `sums` (`per` values a pixel): the pixel's mean over its finite
    /// samples, plus the value's splats (if the film has them) divided by the samples
    /// per pixel (a splat estimates the whole image per pixel sample).
    fn means(&self, sums: &[i128], splats: &[i128], per: usize) -> Vec<f32> {
        let inv_spp = 1.0 / self.spp_done.max(1) as f64;
        sums.iter()
            .enumerate()
            .map(|(j, &s)| {
                let n = self.planes.good[j / per];
                let v = to_f64(s) * if n > 0 { 1.0 / n as f64 } else { 0.0 };
                match splats.get(j) {
                    Some(&t) => (v + to_f64(t) * inv_spp) as f32,
                    None => v as f32,
                }
            })
            .collect()
    }

    /// The image: every channel's means (see [`FilmState::means`]).
    pub fn image(&self) -> Film {
        let (p, nb) = (&self.planes, self.layout.bins);
        let xyz = self.means(&p.xyz, &p.splat, 3);
        let spectral = (nb > 0).then(|| {
            (
                SpectralBins { count: nb },
                self.means(&p.bins, &p.splat_bins, nb),
            )
        });
        let stokes = self.layout.stokes.then(|| {
            self.means(&p.stokes, &p.splat_stokes, 9)
                .chunks_exact(9)
                .map(|c| std::array::from_fn(|k| std::array::from_fn(|j| c[3 * k + j])))
                .collect()
        });
        let stokes_spectral = (self.layout.stokes && nb > 0)
            .then(|| self.means(&p.stokes_bins, &p.splat_stokes_bins, 3 * nb));
        Film {
            width: self.layout.width,
            height: self.layout.height,
            xyz: xyz.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
            spectral,
            variance: self.layout.variance.then(|| self.variance_image()),
            stokes,
            stokes_spectral,
        }
    }

    /// The variance of each pixel's linear sRGB value, from the sums of squares (see the
    /// module's documentation); infinite where a pixel has fewer than two samples.
    fn variance_image(&self) -> Vec<[f32; 3]> {
        let p = &self.planes;
        let npix = self.layout.pixels();
        let spp = self.spp_done as f64;
        let n_all = npix as f64 * spp;
        let rgb = |s: &[i128]| linear_srgb_f64([to_f64(s[0]), to_f64(s[1]), to_f64(s[2])]);
        let splat = !p.splat_sq.is_empty() && n_all > 1.0;
        (0..npix)
            .map(|i| {
                let n = p.good[i] as f64;
                if p.good[i] < 2 {
                    return [f32::INFINITY; 3];
                }
                let s1 = rgb(&p.xyz[3 * i..3 * i + 3]);
                let t1 = if splat {
                    rgb(&p.splat[3 * i..3 * i + 3])
                } else {
                    [0.0; 3]
                };
                std::array::from_fn(|c| {
                    let s2 = p.sq[3 * i + c].to_f64();
                    let mut v = (s2 - s1[c] * s1[c] / n).max(0.0) / (n * (n - 1.0));
                    if splat {
                        let t2 = p.splat_sq[3 * i + c].to_f64();
                        v += (t2 - t1[c] * t1[c] / n_all).max(0.0) * n_all
                            / ((n_all - 1.0) * spp * spp);
                    }
                    v as f32
                })
            })
            .collect()
    }
}
