//! Checkpoints of a render in progress (`heron render --checkpoint FILE`, `--resume FILE`).
//!
//! A render runs in passes of samples (`render.rs`); after a pass the film's running
//! sums are complete for the samples so far. A checkpoint holds those sums, the passes
//! done and the settings that determine the image, so a render killed at any moment
//! (even with `kill -9`: the file is written to a temporary name and renamed, so it is
//! always a whole checkpoint) resumes where the last checkpoint left it, and finishes
//! with the same bytes as a render that was never interrupted: every pixel's sums are
//! accumulated in sample order across passes.
//!
//! File layout: the line `heron-checkpoint 1`, a line of JSON with the settings key,
//! then little-endian binary: passes done, samples per pixel done (u32 each), camera and
//! shadow rays and non-finite samples (u64 each), then the arrays XYZ sums (f64, 3 per
//! pixel), spectral bin sums (f64), finite-sample counts (u32 per pixel), splatted XYZ
//! (f64, 3 per pixel) and splatted bins (f64).
use crate::{HeronError, Result};
use std::path::Path;

const MAGIC: &str = "heron-checkpoint 1\n";

/// The film's running state after some passes.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Checkpoint {
    /// The settings that determine the image, as a JSON object (see `render.rs`); a
    /// resume must match it key by key.
    pub key: serde_json::Map<String, serde_json::Value>,
    pub passes_done: u32,
    pub spp_done: u32,
    pub rays: u64,
    pub shadow_rays: u64,
    pub nonfinite: u64,
    pub sum_xyz: Vec<[f64; 3]>,
    pub sum_bins: Vec<f64>,
    pub good: Vec<u32>,
    pub splat: Vec<[f64; 3]>,
    pub splat_bins: Vec<f64>,
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
        b.extend_from_slice(
            serde_json::Value::Object(self.key.clone())
                .to_string()
                .as_bytes(),
        );
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
        b
    }

    /// Reads a checkpoint; every error names the file and what was wrong.
    pub fn read(path: &Path) -> Result<Checkpoint> {
        let bytes = std::fs::read(path)
            .map_err(|e| err(path, format!("cannot read the checkpoint: {e}")))?;
        Self::from_bytes(&bytes).map_err(|m| err(path, format!("not a heron checkpoint: {m}")))
    }

    fn from_bytes(bytes: &[u8]) -> std::result::Result<Checkpoint, String> {
        let rest = bytes
            .strip_prefix(MAGIC.as_bytes())
            .ok_or("expected the first line \"heron-checkpoint 1\"")?;
        let nl = rest
            .iter()
            .position(|&c| c == b'\n')
            .ok_or("no settings line")?;
        let key = match serde_json::from_slice(&rest[..nl]) {
            Ok(serde_json::Value::Object(m)) => m,
            _ => return Err("the settings line is not a JSON object".into()),
        };
        let mut r = Reader { b: &rest[nl + 1..] };
        let passes_done = r.u32()?;
        let spp_done = r.u32()?;
        let (rays, shadow_rays, nonfinite) = (r.u64()?, r.u64()?, r.u64()?);
        let (n_xyz, n_bins, n_splat, n_splat_bins) = (r.len()?, r.len()?, r.len()?, r.len()?);
        let mut triples = |n: usize| -> std::result::Result<Vec<[f64; 3]>, String> {
            (0..n).map(|_| Ok([r.f64()?, r.f64()?, r.f64()?])).collect()
        };
        let sum_xyz = triples(n_xyz)?;
        let splat = triples(n_splat)?;
        let sum_bins = (0..n_bins)
            .map(|_| r.f64())
            .collect::<std::result::Result<_, _>>()?;
        let splat_bins = (0..n_splat_bins)
            .map(|_| r.f64())
            .collect::<std::result::Result<_, _>>()?;
        let good = (0..n_xyz)
            .map(|_| r.u32())
            .collect::<std::result::Result<_, _>>()?;
        if !r.b.is_empty() {
            return Err(format!("{} bytes after the data", r.b.len()));
        }
        Ok(Checkpoint {
            key,
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
        })
    }

    /// Writes the checkpoint atomically: a temporary file in the same folder, renamed.
    pub fn write(&self, path: &Path) -> Result<()> {
        let bytes = self.to_bytes();
        crate::film::Staged::write(path, |tmp| {
            std::fs::write(tmp, &bytes).map_err(|e| format!("cannot write the checkpoint: {e}"))
        })?
        .commit()
    }

    /// None if `key` matches this checkpoint's settings, else the first key that differs
    /// as "key: checkpoint value, this render value".
    pub fn mismatch(&self, key: &serde_json::Map<String, serde_json::Value>) -> Option<String> {
        let mut names: Vec<&String> = self.key.keys().chain(key.keys()).collect();
        names.sort();
        names.dedup();
        names.into_iter().find_map(|k| {
            let (a, b) = (self.key.get(k), key.get(k));
            (a != b).then(|| {
                let show =
                    |v: Option<&serde_json::Value>| v.map_or("(none)".into(), |v| v.to_string());
                format!(
                    "{k}: {} in the checkpoint, {} in this render",
                    show(a),
                    show(b)
                )
            })
        })
    }
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
    fn f64(&mut self) -> std::result::Result<f64, String> {
        Ok(f64::from_le_bytes(self.take()?))
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
            passes_done: 3,
            spp_done: 12,
            rays: 5,
            shadow_rays: 6,
            nonfinite: 1,
            sum_xyz: vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.5]],
            sum_bins: vec![0.25; 4],
            good: vec![12, 11],
            splat: vec![[0.5; 3]; 2],
            splat_bins: vec![],
        };
        let b = c.to_bytes();
        assert_eq!(Checkpoint::from_bytes(&b).unwrap(), c);
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
}
