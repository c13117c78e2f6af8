//! The film's state as a file: checkpoints of a render in progress (`heron render
//! --checkpoint FILE`, `--resume FILE`) and the parts of a sharded render (`heron render
//! --shard K/N -o part.heronfilm`, `heron merge`).
//!
//! A render runs in passes of samples (`render.rs`); after a pass the film's sums are
//! complete for the samples so far. The state holds those sums (fixed point, so that
//! they do not depend on how the samples were grouped: `film/fixed.rs`), the passes done
//! and the settings that determine the image. A render killed at any moment (even with
//! `kill -9`: the file is written to a temporary name and renamed) resumes where the
//! last checkpoint left it and finishes with the same bytes as a render never
//! interrupted; and the parts of a sharded render add up, in any order, to the sums of
//! one render with all the samples.
//!
//! File layout: the line `heron-film 1`; a line of JSON with `settings` (the settings
//! key), `shard` ([K, N] or null), `width`, `height`, `anySplat` and `xyzChannels`, and
//! `variance: true` when the film keeps squares (`--variance`; absent otherwise, so
//! films without it keep their bytes);
//! then little-endian binary: passes done, samples per pixel done (u32 each), camera and
//! shadow rays and non-finite samples (u64 each), the four array lengths (u64), then
//! XYZ sums (i128, 3 per pixel), splatted XYZ (i128, 3 per pixel), spectral bin sums
//! (i128), splatted bins (i128) and finite-sample counts (u32 per pixel); with
//! `variance`, then the two lengths (u64) of the arrays of squares and the arrays:
//! the sums of squares of the samples' linear sRGB (3 × 24 bytes per pixel, 192-bit
//! integers, `film::fixed::SquareSum`) and of the splats' (the same per pixel for a
//! splatting integrator, else empty); with `sppm: true` in the header (photon
//! mapping's checkpoints), then the pixel count (u64) and per pixel the photon count N,
//! then per pixel the squared radius R² (f32 each), from which a resumed render goes on;
//! with `stokes: true` (polarised renders), then per pixel the sums of S1, S2, S3 as XYZ
//! (9 × i128) and their spectral bins (3 × bins per pixel); with `stokesSplats: true`
//! (polarised light tracing and BDPT), then the same two arrays of the splats.
//!
//! Variance (`Checkpoint::film`): a pixel's value is the mean of its n finite samples,
//! so its variance is estimated from their sums S₁ = Σ c and S₂ = Σ c² as
//! (S₂ − S₁²/n) / (n (n − 1)), the unbiased sample variance divided by n. Splats add the
//! image's splatted part, (1/spp) Σⱼ sⱼ over all N = pixels × spp samples of the image,
//! sⱼ the sum of sample j's splats into the pixel; the samples are independent and
//! identically distributed (a light path does not depend on the pixel that started
//! it), so its variance is estimated as (T₂ − T₁²/N) N / ((N − 1) spp²) from T₁ = Σ sⱼ
//! and T₂ = Σ sⱼ². Left out: the covariance of a sample's own value with its splats into
//! its own pixel (BDPT), of the order of 1/pixels of the terms kept. The sums are exact
//! integers, so the variance, like the image, does not depend on threads, passes,
//! checkpoints or shards.
use crate::film::fixed::{to_f64, SquareSum};
use crate::film::{linear_srgb_f64, Film, SpectralBins};
use crate::integrator::sppm::SppmPixels;
use crate::{HeronError, Result};
use std::path::Path;

const MAGIC: &str = "heron-film 1\n";
const OLD_MAGIC: &str = "heron-checkpoint 1\n";

/// Shard `index` of `count`: its share of every pixel's sample indices.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    pub index: u32,
    pub count: u32,
}

impl Shard {
    /// Parses `K/N` (0 ≤ K < N).
    pub fn parse(s: &str) -> std::result::Result<Shard, String> {
        let bad = || format!("expected K/N with 0 <= K < N (e.g. 0/4), got {s:?}");
        let (k, n) = s.split_once('/').ok_or_else(bad)?;
        let index: u32 = k.trim().parse().map_err(|_| bad())?;
        let count: u32 = n.trim().parse().map_err(|_| bad())?;
        if count == 0 || index >= count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }

    /// The sample indices of this shard out of `spp`: the contiguous range
    /// [⌊K·spp/N⌋, ⌊(K+1)·spp/N⌋). Contiguous ranges keep the Sobol' points of a
    /// pixel in their order, and the shards together are exactly 0..spp.
    pub fn samples(&self, spp: u32) -> std::ops::Range<u32> {
        let at = |k: u32| (k as u64 * spp as u64 / self.count as u64) as u32;
        at(self.index)..at(self.index + 1)
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// The film's unnormalised state after some passes.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Checkpoint {
    /// The settings that determine the image, as a JSON object (see `render.rs`); a
    /// resume, and every part of a merge, must match it key by key.
    pub key: serde_json::Map<String, serde_json::Value>,
    /// The shard this film holds (None: all the samples).
    pub shard: Option<Shard>,
    pub width: u32,
    pub height: u32,
    /// Whether splats count in the image (the integrator splats, or a sample splatted).
    pub any_splat: bool,
    /// Whether the EXR made from this film has the X, Y, Z channels (`--xyz`).
    pub xyz_channels: bool,
    pub passes_done: u32,
    /// Samples per pixel held (of this shard's range).
    pub spp_done: u32,
    pub rays: u64,
    pub shadow_rays: u64,
    pub nonfinite: u64,
    pub sum_xyz: Vec<[i128; 3]>,
    pub sum_bins: Vec<i128>,
    pub good: Vec<u32>,
    pub splat: Vec<[i128; 3]>,
    pub splat_bins: Vec<i128>,
    /// Whether the film keeps the sums of squares below (`--variance`).
    pub variance: bool,
    /// Per pixel, Σ c² of the finite samples' linear sRGB components (empty without
    /// `variance`).
    pub sum_sq: Vec<[SquareSum; 3]>,
    /// Per pixel, Σ sⱼ² of the samples' splats into it (empty without `variance` or
    /// when the integrator does not splat).
    pub splat_sq: Vec<[SquareSum; 3]>,
    /// Photon mapping's per-pixel state (photon count N and squared radius R²), which a
    /// resumed `sppm` render continues from; None for the other integrators, and for
    /// a merged film (whose shards were independent chains: see `render.rs`).
    pub sppm: Option<SppmPixels>,
    /// Polarised renders: per pixel, the sums of S1, S2, S3 as XYZ over the finite
    /// samples (empty otherwise).
    pub sum_stokes: Vec<[i128; 9]>,
    /// Polarised renders with spectral bins: per pixel, the bins of S1, then of S2, then
    /// of S3 (3 × bins per pixel, as `sum_bins` holds S0's; empty otherwise).
    pub sum_stokes_bins: Vec<i128>,
    /// Polarised renders of a splatting integrator (light tracing, BDPT): per pixel, the
    /// splatted S1, S2, S3 as XYZ, and with spectral bins their splatted bins (3 ×
    /// bins per pixel); empty otherwise.
    pub splat_stokes: Vec<[i128; 9]>,
    pub splat_stokes_bins: Vec<i128>,
}

fn err(path: &Path, message: impl Into<String>) -> HeronError {
    HeronError::Io {
        path: path.to_path_buf(),
        message: message.into(),
    }
}

impl Checkpoint {
    /// The bytes of the file.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut b = Vec::new();
        b.extend_from_slice(MAGIC.as_bytes());
        let mut header = serde_json::json!({
            "settings": serde_json::Value::Object(self.key.clone()),
            "shard": self.shard.map(|s| [s.index, s.count]),
            "width": self.width,
            "height": self.height,
            "anySplat": self.any_splat,
            "xyzChannels": self.xyz_channels,
        });
        if self.variance {
            header["variance"] = true.into();
        }
        if self.sppm.is_some() {
            header["sppm"] = true.into();
        }
        // Only when polarised, so that other films keep their bytes.
        if !self.sum_stokes.is_empty() {
            header["stokes"] = true.into();
        }
        if !self.splat_stokes.is_empty() {
            header["stokesSplats"] = true.into();
        }
        b.extend_from_slice(header.to_string().as_bytes());
        b.push(b'\n');
        for v in [self.passes_done, self.spp_done] {
            b.extend_from_slice(&v.to_le_bytes());
        }
        for v in [self.rays, self.shadow_rays, self.nonfinite] {
            b.extend_from_slice(&v.to_le_bytes());
        }
        for len in [
            self.sum_xyz.len(),
            self.sum_bins.len(),
            self.splat.len(),
            self.splat_bins.len(),
        ] {
            b.extend_from_slice(&(len as u64).to_le_bytes());
        }
        for c in self.sum_xyz.iter().chain(&self.splat).flatten() {
            b.extend_from_slice(&c.to_le_bytes());
        }
        for v in self.sum_bins.iter().chain(&self.splat_bins) {
            b.extend_from_slice(&v.to_le_bytes());
        }
        for g in &self.good {
            b.extend_from_slice(&g.to_le_bytes());
        }
        if self.variance {
            for len in [self.sum_sq.len(), self.splat_sq.len()] {
                b.extend_from_slice(&(len as u64).to_le_bytes());
            }
            for q in self.sum_sq.iter().chain(&self.splat_sq).flatten() {
                b.extend_from_slice(&q.to_le_bytes());
            }
        }
        if let Some(s) = &self.sppm {
            b.extend_from_slice(&(s.n.len() as u64).to_le_bytes());
            for v in s.n.iter().chain(&s.r2) {
                b.extend_from_slice(&v.to_le_bytes());
            }
        }
        for v in self
            .sum_stokes
            .iter()
            .flatten()
            .chain(&self.sum_stokes_bins)
            .chain(self.splat_stokes.iter().flatten())
            .chain(&self.splat_stokes_bins)
        {
            b.extend_from_slice(&v.to_le_bytes());
        }
        b
    }

    /// Reads a checkpoint; every error names the file and what was wrong.
    pub fn read(path: &Path) -> Result<Checkpoint> {
        Self::read_as(path, "checkpoint")
    }

    /// Reads a film file; errors call it `what` ("checkpoint", "film file").
    pub fn read_as(path: &Path, what: &str) -> Result<Checkpoint> {
        let bytes =
            std::fs::read(path).map_err(|e| err(path, format!("cannot read the {what}: {e}")))?;
        Self::from_bytes(&bytes).map_err(|m| err(path, format!("not a heron {what}: {m}")))
    }

    fn from_bytes(bytes: &[u8]) -> std::result::Result<Checkpoint, String> {
        if bytes.starts_with(OLD_MAGIC.as_bytes()) {
            return Err(
                "it was written by an older heron (heron-checkpoint 1); render again".into(),
            );
        }
        let rest = bytes
            .strip_prefix(MAGIC.as_bytes())
            .ok_or("expected the first line \"heron-film 1\"")?;
        let nl = rest
            .iter()
            .position(|&c| c == b'\n')
            .ok_or("no header line")?;
        let header: serde_json::Value =
            serde_json::from_slice(&rest[..nl]).map_err(|_| "the header line is not JSON")?;
        let bad = |k: &str| format!("the header's {k:?} is missing or of the wrong type");
        let key = match header.get("settings") {
            Some(serde_json::Value::Object(m)) => m.clone(),
            _ => return Err(bad("settings")),
        };
        let u32_of = |k: &str| -> std::result::Result<u32, String> {
            header
                .get(k)
                .and_then(|v| v.as_u64())
                .and_then(|v| u32::try_from(v).ok())
                .ok_or_else(|| bad(k))
        };
        let bool_of = |k: &str| {
            header
                .get(k)
                .and_then(|v| v.as_bool())
                .ok_or_else(|| bad(k))
        };
        let shard = match header.get("shard") {
            Some(serde_json::Value::Null) => None,
            Some(v) => {
                let s: [u32; 2] = serde_json::from_value(v.clone()).map_err(|_| bad("shard"))?;
                if s[1] == 0 || s[0] >= s[1] {
                    return Err(bad("shard"));
                }
                Some(Shard {
                    index: s[0],
                    count: s[1],
                })
            }
            None => return Err(bad("shard")),
        };
        let (width, height) = (u32_of("width")?, u32_of("height")?);
        let (any_splat, xyz_channels) = (bool_of("anySplat")?, bool_of("xyzChannels")?);
        let flag = |k: &str| match header.get(k) {
            None => Ok(false),
            Some(v) => v.as_bool().ok_or_else(|| bad(k)),
        };
        let (variance, has_sppm) = (flag("variance")?, flag("sppm")?);
        let has_stokes = flag("stokes")?;
        let has_stokes_splats = flag("stokesSplats")?;
        if has_stokes_splats && !has_stokes {
            return Err("its header has stokesSplats without stokes".into());
        }
        let mut r = Reader { b: &rest[nl + 1..] };
        let passes_done = r.u32()?;
        let spp_done = r.u32()?;
        let (rays, shadow_rays, nonfinite) = (r.u64()?, r.u64()?, r.u64()?);
        let (n_xyz, n_bins, n_splat, n_splat_bins) = (r.len()?, r.len()?, r.len()?, r.len()?);
        if n_xyz as u64 != width as u64 * height as u64 || n_splat != n_xyz {
            return Err(format!("its arrays do not fit its {width}x{height} image"));
        }
        let mut triples = |n: usize| -> std::result::Result<Vec<[i128; 3]>, String> {
            (0..n)
                .map(|_| Ok([r.i128()?, r.i128()?, r.i128()?]))
                .collect()
        };
        let sum_xyz = triples(n_xyz)?;
        let splat = triples(n_splat)?;
        let sum_bins = (0..n_bins)
            .map(|_| r.i128())
            .collect::<std::result::Result<_, _>>()?;
        let splat_bins = (0..n_splat_bins)
            .map(|_| r.i128())
            .collect::<std::result::Result<_, _>>()?;
        let good = (0..n_xyz)
            .map(|_| r.u32())
            .collect::<std::result::Result<_, _>>()?;
        let (mut sum_sq, mut splat_sq) = (Vec::new(), Vec::new());
        if variance {
            let (n_sq, n_splat_sq) = (r.len()?, r.len()?);
            if n_sq != n_xyz || (n_splat_sq != 0 && n_splat_sq != n_xyz) {
                return Err(format!(
                    "its arrays of squares do not fit its {width}x{height} image"
                ));
            }
            let mut squares = |n: usize| -> std::result::Result<Vec<[SquareSum; 3]>, String> {
                (0..n)
                    .map(|_| Ok([r.square()?, r.square()?, r.square()?]))
                    .collect()
            };
            sum_sq = squares(n_sq)?;
            splat_sq = squares(n_splat_sq)?;
        }
        let sppm = if has_sppm {
            let n = r.len()?;
            if n != n_xyz {
                return Err(format!(
                    "its photon-mapping state does not fit its {width}x{height} image"
                ));
            }
            let mut floats = || {
                (0..n)
                    .map(|_| r.f32())
                    .collect::<std::result::Result<Vec<_>, _>>()
            };
            let counts = floats()?;
            let r2 = floats()?;
            Some(SppmPixels { n: counts, r2 })
        } else {
            None
        };
        let nines = |r: &mut Reader, on: bool| -> std::result::Result<Vec<[i128; 9]>, String> {
            if !on {
                return Ok(Vec::new());
            }
            (0..n_xyz)
                .map(|_| {
                    let mut v = [0i128; 9];
                    for x in v.iter_mut() {
                        *x = r.i128()?;
                    }
                    Ok(v)
                })
                .collect()
        };
        let ints = |r: &mut Reader, n: usize| -> std::result::Result<Vec<i128>, String> {
            (0..n).map(|_| r.i128()).collect()
        };
        let sum_stokes = nines(&mut r, has_stokes)?;
        // S1–S3's bins follow their XYZ sums, three per bin of S0 (the header's flag and
        // the bins' count say how many); then, for a splatting integrator, the same of
        // the splats.
        let sum_stokes_bins = ints(&mut r, if has_stokes { 3 * n_bins } else { 0 })?;
        let splat_stokes = nines(&mut r, has_stokes_splats)?;
        let splat_stokes_bins = ints(
            &mut r,
            if has_stokes_splats {
                3 * n_splat_bins
            } else {
                0
            },
        )?;
        if !r.b.is_empty() {
            return Err(format!("{} bytes after the data", r.b.len()));
        }
        Ok(Checkpoint {
            key,
            shard,
            width,
            height,
            any_splat,
            xyz_channels,
            passes_done,
            spp_done,
            rays,
            shadow_rays,
            nonfinite,
            sum_xyz,
            sum_bins,
            good,
            splat,
            splat_bins,
            variance,
            sum_sq,
            splat_sq,
            sppm,
            sum_stokes,
            sum_stokes_bins,
            splat_stokes,
            splat_stokes_bins,
        })
    }

    /// Writes the file atomically: a temporary file in the same folder, renamed.
    pub fn write(&self, path: &Path) -> Result<()> {
        let bytes = self.to_bytes();
        crate::files::Staged::write(path, |tmp| {
            std::fs::write(tmp, &bytes).map_err(|e| format!("cannot write the film state: {e}"))
        })?
        .commit()
    }

    /// None if `key` matches this checkpoint's settings, else the first key that differs
    /// as "key: checkpoint value, this render value".
    pub fn mismatch(&self, key: &serde_json::Map<String, serde_json::Value>) -> Option<String> {
        self.differs(key, "in the checkpoint", "in this render")
    }

    /// The first setting in which this film and `key` differ, as "key: A <mine>, B <theirs>".
    fn differs(
        &self,
        key: &serde_json::Map<String, serde_json::Value>,
        mine: &str,
        theirs: &str,
    ) -> Option<String> {
        // The provenance's settings first (in their order: spp before the pass size it
        // implies), then the rest by name.
        let rank = |k: &str| crate::provenance::KEYS.iter().position(|&p| p == k);
        let mut names: Vec<&String> = self.key.keys().chain(key.keys()).collect();
        names.sort_by(|a, b| match (rank(a), rank(b)) {
            (Some(x), Some(y)) => x.cmp(&y),
            (Some(_), None) => std::cmp::Ordering::Less,
            (None, Some(_)) => std::cmp::Ordering::Greater,
            (None, None) => a.cmp(b),
        });
        names.dedup();
        names.into_iter().find_map(|k| {
            let (a, b) = (self.key.get(k), key.get(k));
            (a != b).then(|| {
                let show =
                    |v: Option<&serde_json::Value>| v.map_or("(none)".into(), |v| v.to_string());
                format!("{k}: {} {mine}, {} {theirs}", show(a), show(b))
            })
        })
    }

    /// The samples per pixel this film should hold when complete: its shard's share of
    /// the render's spp (all of it without a shard).
    pub fn spp_expected(&self) -> Option<u32> {
        let spp: u32 = self.key.get("spp")?.as_str()?.parse().ok()?;
        Some(match self.shard {
            Some(s) => s.samples(spp).len() as u32,
            None => spp,
        })
    }

    /// The image: each pixel's mean over its finite samples, plus the splats divided by
    /// the samples per pixel (a splat estimates the whole image per pixel sample).
    pub fn film(&self) -> Film {
        let npix = self.sum_xyz.len();
        let nb = self.sum_bins.len().checked_div(npix).unwrap_or(0);
        let inv = |n: u32| if n > 0 { 1.0 / n as f64 } else { 0.0 };
        let inv_spp = 1.0 / self.spp_done.max(1) as f64;
        let any_splat = self.any_splat;
        let mean = |sum: i128, n: u32, splat: Option<i128>| -> f32 {
            let v = to_f64(sum) * inv(n);
            match splat {
                Some(s) if any_splat => (v + to_f64(s) * inv_spp) as f32,
                _ => v as f32,
            }
        };
        let xyz = (0..npix)
            .map(|i| {
                std::array::from_fn(|j| {
                    mean(self.sum_xyz[i][j], self.good[i], Some(self.splat[i][j]))
                })
            })
            .collect();
        let spectral = (nb > 0).then(|| {
            let data = (0..npix * nb)
                .map(|j| {
                    mean(
                        self.sum_bins[j],
                        self.good[j / nb],
                        self.splat_bins.get(j).copied(),
                    )
                })
                .collect();
            (SpectralBins { count: nb }, data)
        });
        let stokes = (!self.sum_stokes.is_empty()).then(|| {
            (0..npix)
                .map(|i| {
                    std::array::from_fn(|k| {
                        std::array::from_fn(|j| {
                            mean(
                                self.sum_stokes[i][3 * k + j],
                                self.good[i],
                                self.splat_stokes.get(i).map(|s| s[3 * k + j]),
                            )
                        })
                    })
                })
                .collect()
        });
        // S1–S3's bins: per pixel, 3 × nb means.
        let stokes_spectral = (nb > 0 && !self.sum_stokes_bins.is_empty()).then(|| {
            (0..3 * npix * nb)
                .map(|j| {
                    mean(
                        self.sum_stokes_bins[j],
                        self.good[j / (3 * nb)],
                        self.splat_stokes_bins.get(j).copied(),
                    )
                })
                .collect()
        });
        Film {
            width: self.width,
            height: self.height,
            xyz,
            spectral,
            variance: self.variance.then(|| self.variance_image()),
            stokes,
            stokes_spectral,
        }
    }

    /// The variance of each pixel's linear sRGB value, from the sums of squares (see the
    /// module's documentation); infinite where a pixel has fewer than two samples.
    fn variance_image(&self) -> Vec<[f32; 3]> {
        let npix = self.sum_xyz.len();
        let spp = self.spp_done as f64;
        let n_all = npix as f64 * spp;
        let rgb = |s: &[i128; 3]| linear_srgb_f64(s.map(to_f64));
        (0..npix)
            .map(|i| {
                let n = self.good[i] as f64;
                if self.good[i] < 2 {
                    return [f32::INFINITY; 3];
                }
                let s1 = rgb(&self.sum_xyz[i]);
                let splat = self.any_splat && !self.splat_sq.is_empty() && n_all > 1.0;
                let t1 = rgb(&self.splat[i]);
                std::array::from_fn(|c| {
                    let s2 = self.sum_sq[i][c].to_f64();
                    let mut v = (s2 - s1[c] * s1[c] / n).max(0.0) / (n * (n - 1.0));
                    if splat {
                        let t2 = self.splat_sq[i][c].to_f64();
                        v += (t2 - t1[c] * t1[c] / n_all).max(0.0) * n_all
                            / ((n_all - 1.0) * spp * spp);
                    }
                    v as f32
                })
            })
            .collect()
    }

    /// Adds another part's sums and counts to this one's. Integer sums, so the result
    /// does not depend on the order of the parts.
    fn add(&mut self, o: &Checkpoint) {
        let add3 = |a: &mut [i128; 3], b: &[i128; 3]| {
            for (x, y) in a.iter_mut().zip(b) {
                *x = x.wrapping_add(*y);
            }
        };
        for (a, b) in self.sum_xyz.iter_mut().zip(&o.sum_xyz) {
            add3(a, b);
        }
        for (a, b) in self.splat.iter_mut().zip(&o.splat) {
            add3(a, b);
        }
        for (a, b) in self.sum_bins.iter_mut().zip(&o.sum_bins) {
            *a = a.wrapping_add(*b);
        }
        for (a, b) in self.splat_bins.iter_mut().zip(&o.splat_bins) {
            *a = a.wrapping_add(*b);
        }
        for (a, b) in self.good.iter_mut().zip(&o.good) {
            *a += b;
        }
        for (a, b) in self.sum_stokes.iter_mut().zip(&o.sum_stokes) {
            for (x, y) in a.iter_mut().zip(b) {
                *x = x.wrapping_add(*y);
            }
        }
        for (a, b) in self.splat_stokes.iter_mut().zip(&o.splat_stokes) {
            for (x, y) in a.iter_mut().zip(b) {
                *x = x.wrapping_add(*y);
            }
        }
        for (a, b) in self
            .sum_stokes_bins
            .iter_mut()
            .zip(&o.sum_stokes_bins)
            .chain(self.splat_stokes_bins.iter_mut().zip(&o.splat_stokes_bins))
        {
            *a = a.wrapping_add(*b);
        }
        for (a, b) in self
            .sum_sq
            .iter_mut()
            .zip(&o.sum_sq)
            .chain(self.splat_sq.iter_mut().zip(&o.splat_sq))
        {
            for (x, y) in a.iter_mut().zip(b) {
                x.add(*y);
            }
        }
        self.any_splat |= o.any_splat;
        self.passes_done += o.passes_done;
        self.spp_done += o.spp_done;
        self.rays += o.rays;
        self.shadow_rays += o.shadow_rays;
        self.nonfinite += o.nonfinite;
    }
}

/// Merges the parts of a sharded render (`heron merge`): every shard K/N of one render
/// exactly once, each complete. The result is the film of one render with all the
/// samples, bit for bit, in whatever order the parts come. Errors name the part.
pub fn merge(parts: &[(std::path::PathBuf, Checkpoint)]) -> Result<Checkpoint> {
    let (first_path, first) = parts
        .first()
        .ok_or_else(|| HeronError::Invalid("merge: expected at least one film file".into()))?;
    let shard_of = |p: &Path, c: &Checkpoint| -> Result<Shard> {
        Ok(c.shard.unwrap_or(Shard { index: 0, count: 1 })).and_then(|s| {
            if c.shard.is_none() && parts.len() > 1 {
                Err(err(
                    p,
                    "holds a whole render, not a shard (made without --shard)",
                ))
            } else {
                Ok(s)
            }
        })
    };
    let n = shard_of(first_path, first)?.count;
    let mut owner: Vec<Option<&Path>> = vec![None; n as usize];
    for (p, c) in parts {
        let s = shard_of(p, c)?;
        if s.count != n {
            return Err(err(
                p,
                format!(
                    "is shard {s}, but {} is a shard of {n}: the parts come from different splits",
                    first_path.display()
                ),
            ));
        }
        if c.variance != first.variance {
            let with = |v: bool| if v { "with" } else { "without" };
            return Err(err(
                p,
                format!(
                    "was rendered {} --variance, {} {} it: render every shard with the same flags",
                    with(c.variance),
                    first_path.display(),
                    with(first.variance)
                ),
            ));
        }
        if let Some(m) = c.differs(&first.key, "here", &format!("in {}", first_path.display())) {
            return Err(err(p, format!("is from another render ({m})")));
        }
        if (c.width, c.height, c.sum_bins.len(), c.splat_bins.len())
            != (
                first.width,
                first.height,
                first.sum_bins.len(),
                first.splat_bins.len(),
            )
            || (c.sum_sq.len(), c.splat_sq.len()) != (first.sum_sq.len(), first.splat_sq.len())
            || c.xyz_channels != first.xyz_channels
            || c.sum_stokes.len() != first.sum_stokes.len()
            || c.sum_stokes_bins.len() != first.sum_stokes_bins.len()
            || c.splat_stokes.len() != first.splat_stokes.len()
            || c.splat_stokes_bins.len() != first.splat_stokes_bins.len()
        {
            return Err(err(
                p,
                format!("its film does not fit {}'s", first_path.display()),
            ));
        }
        let want = c
            .spp_expected()
            .ok_or_else(|| err(p, "its settings have no spp"))?;
        if c.spp_done != want {
            return Err(err(
                p,
                format!(
                    "shard {s} is incomplete: it holds {} of its {want} samples per pixel (finish it with heron render --resume {})",
                    c.spp_done,
                    p.display()
                ),
            ));
        }
        if let Some(q) = owner[s.index as usize] {
            return Err(err(p, format!("is shard {s}, and so is {}", q.display())));
        }
        owner[s.index as usize] = Some(p);
    }
    let missing: Vec<String> = owner
        .iter()
        .enumerate()
        .filter(|(_, o)| o.is_none())
        .map(|(k, _)| format!("{k}/{n}"))
        .collect();
    if !missing.is_empty() {
        return Err(HeronError::Invalid(format!(
            "merge: missing shard{} {} (no part given holds {})",
            if missing.len() > 1 { "s" } else { "" },
            missing.join(", "),
            if missing.len() > 1 { "them" } else { "it" }
        )));
    }
    let mut total = Checkpoint {
        shard: None,
        passes_done: 0,
        spp_done: 0,
        rays: 0,
        shadow_rays: 0,
        nonfinite: 0,
        any_splat: false,
        sum_xyz: vec![[0; 3]; first.sum_xyz.len()],
        splat: vec![[0; 3]; first.splat.len()],
        sum_bins: vec![0; first.sum_bins.len()],
        splat_bins: vec![0; first.splat_bins.len()],
        good: vec![0; first.good.len()],
        sum_sq: vec![Default::default(); first.sum_sq.len()],
        splat_sq: vec![Default::default(); first.splat_sq.len()],
        sppm: None,
        sum_stokes: vec![[0; 9]; first.sum_stokes.len()],
        sum_stokes_bins: vec![0; first.sum_stokes_bins.len()],
        splat_stokes: vec![[0; 9]; first.splat_stokes.len()],
        splat_stokes_bins: vec![0; first.splat_stokes_bins.len()],
        ..first.clone()
    };
    for (_, c) in parts {
        total.add(c);
    }
    Ok(total)
}

struct Reader<'a> {
    b: &'a [u8],
}

impl Reader<'_> {
    fn take<const K: usize>(&mut self) -> std::result::Result<[u8; K], String> {
        if self.b.len() < K {
            return Err("the file is truncated".into());
        }
        let (h, t) = self.b.split_at(K);
        self.b = t;
        Ok(h.try_into().unwrap())
    }
    fn u32(&mut self) -> std::result::Result<u32, String> {
        Ok(u32::from_le_bytes(self.take()?))
    }
    fn u64(&mut self) -> std::result::Result<u64, String> {
        Ok(u64::from_le_bytes(self.take()?))
    }
    fn f32(&mut self) -> std::result::Result<f32, String> {
        Ok(f32::from_le_bytes(self.take()?))
    }
    fn i128(&mut self) -> std::result::Result<i128, String> {
        Ok(i128::from_le_bytes(self.take()?))
    }
    fn square(&mut self) -> std::result::Result<SquareSum, String> {
        Ok(SquareSum::from_le_bytes(self.take()?))
    }
    /// An array length, bounded by what is left of the file (so a corrupt length cannot
    /// ask for an absurd allocation).
    fn len(&mut self) -> std::result::Result<usize, String> {
        let n = self.u64()?;
        if n > self.b.len() as u64 {
            return Err(format!("an array length of {n} exceeds the file"));
        }
        Ok(n as usize)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_truncation() {
        let mut key = serde_json::Map::new();
        key.insert("spp".into(), 64.into());
        let c = Checkpoint {
            key,
            shard: Some(Shard { index: 1, count: 3 }),
            width: 2,
            height: 1,
            any_splat: true,
            xyz_channels: true,
            passes_done: 3,
            spp_done: 12,
            rays: 5,
            shadow_rays: 6,
            nonfinite: 1,
            sum_xyz: vec![[1, -2, 3 << 90], [4, 5, i128::MIN]],
            sum_bins: vec![7; 4],
            good: vec![12, 11],
            splat: vec![[-9; 3]; 2],
            splat_bins: vec![],
            variance: false,
            sum_sq: vec![],
            splat_sq: vec![],
            sppm: None,
            sum_stokes: vec![],
            sum_stokes_bins: vec![],
            splat_stokes: vec![],
            splat_stokes_bins: vec![],
        };
        let b = c.to_bytes();
        assert_eq!(Checkpoint::from_bytes(&b).unwrap(), c);
        // With photon mapping's state.
        let s = Checkpoint {
            sppm: Some(SppmPixels {
                n: vec![3.5, 0.0],
                r2: vec![1e-4, 2.5],
            }),
            ..c.clone()
        };
        let sb = s.to_bytes();
        assert_eq!(Checkpoint::from_bytes(&sb).unwrap(), s);
        assert!(Checkpoint::from_bytes(&sb[..sb.len() - 1]).is_err());
        // With a polarised render's Stokes sums.
        let p = Checkpoint {
            sum_stokes: vec![[-1, 2, -3, 4, -5, 6, -7, 8, i128::MIN], [9; 9]],
            ..c.clone()
        };
        let pb = p.to_bytes();
        // c has bins (2 per pixel), so a polarised film has S1–S3's too: 3 × 4 of them.
        assert!(Checkpoint::from_bytes(&pb).is_err());
        let p = Checkpoint {
            sum_stokes_bins: (0..12)
                .map(|k| (k * (-1i128).pow(k as u32)) << 70)
                .collect(),
            ..p
        };
        let pb = p.to_bytes();
        assert_eq!(Checkpoint::from_bytes(&pb).unwrap(), p);
        assert!(Checkpoint::from_bytes(&pb[..pb.len() - 16]).is_err());
        // With a polarised splatting integrator's splats of S1–S3 (and of their bins:
        // none, as c's splats have none).
        let q = Checkpoint {
            splat_stokes: vec![[3 << 100; 9], [-4; 9]],
            ..p.clone()
        };
        let qb = q.to_bytes();
        assert_eq!(Checkpoint::from_bytes(&qb).unwrap(), q);
        assert_eq!(
            qb.len(),
            pb.len() + 2 * 9 * 16 + r#","stokesSplats":true"#.len()
        );
        assert!(Checkpoint::from_bytes(&qb[..qb.len() - 16]).is_err());
        for cut in [0, 5, MAGIC.len() + 3, b.len() - 1] {
            assert!(Checkpoint::from_bytes(&b[..cut]).is_err(), "{cut}");
        }
        let mut other = c.key.clone();
        other.insert("spp".into(), 128.into());
        assert_eq!(
            c.mismatch(&other).unwrap(),
            "spp: 64 in the checkpoint, 128 in this render"
        );
        assert_eq!(c.mismatch(&c.key), None);
    }

    #[test]
    fn shards_split_the_samples_exactly() {
        for spp in [1u32, 2, 5, 16, 1000, u32::MAX] {
            for n in [1u32, 2, 3, 7, 64] {
                let mut next = 0u32;
                for k in 0..n {
                    let r = Shard { index: k, count: n }.samples(spp);
                    assert_eq!(r.start, next, "spp {spp}, shard {k}/{n}");
                    assert!(r.len() as u64 * n as u64 <= spp as u64 + n as u64);
                    next = r.end;
                }
                assert_eq!(next, spp);
            }
        }
        assert_eq!(Shard::parse("2/5"), Ok(Shard { index: 2, count: 5 }));
        for bad in ["5/5", "1/0", "-1/3", "1", "a/b", "1/2/3"] {
            let e = Shard::parse(bad).unwrap_err();
            assert!(e.contains("expected K/N"), "{bad}: {e}");
        }
    }
}
