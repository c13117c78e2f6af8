//! The film's state as a file: checkpoints of a render in progress (`heron render
//! --checkpoint FILE`, `--resume FILE`) and the parts of a sharded render (`heron render
//! --shard K/N -o part.heronfilm`, `heron merge`); the checks that a checkpoint fits the
//! render that resumes it, and that parts fit each other.
//!
//! A render runs in passes of samples (`render/passes.rs`); after a pass the film's sums are
//! complete for the samples so far. The file holds those sums (the film's planes, fixed
//! point, so that they do not depend on how the samples were grouped: `film/fixed.rs`),
//! the passes done and the settings that determine the image. A render killed at any
//! moment (even with `kill -9`: the file is written to a temporary name and renamed)
//! resumes where the last checkpoint left it and finishes with the same bytes as a render
//! never interrupted; and the parts of a sharded render add up, in any order, to the sums
//! of one render with all the samples.
//!
//! File layout: the line `heron-film 2`; a line of JSON with `settings` (the
//! [`FilmKey`]), `shard` ([K, N] or null), the film's layout (`width`, `height`, `bins`,
//! `splats`, `variance`, `stokes`: `film/planes.rs`), `xyzChannels`, `planes` (the
//! names of the planes that follow, which the layout decides) and, for an integrator
//! that keeps a per-pixel state of its own (photon mapping), `integrator` with its
//! `name` and the count of its `values`; then little-endian binary: passes done, samples
//! per pixel done (u32 each), camera and shadow rays and non-finite samples (u64 each),
//! every plane in order (i128 sums, u32 counts, 192-bit sums of squares), and the
//! integrator's values (f32).
use crate::film::planes::{Layout, Planes};
use crate::film::state::{FilmState, IntegratorPlane};
use crate::{HeronError, Result};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

const MAGIC: &str = "heron-film 2\n";
/// The first lines of the files of older herons' film formats.
const OLD_MAGICS: [&str; 2] = ["heron-checkpoint 1\n", "heron-film 1\n"];

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

/// The settings that determine a render's image, which a resumed render and every part
/// of a merge must match: the provenance (scene and input hashes, integrator, sampler,
/// spp, seed, lanes, wavelengths, depth, packets, bins, …), the image size, the pass
/// size and whether the film keeps squares.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FilmKey {
    /// The render's samples per pixel (all shards'); a string in the file, as the
    /// provenance writes it.
    #[serde(with = "decimal")]
    pub spp: u32,
    pub width: u32,
    pub height: u32,
    /// Samples per pixel of a pass (a splatting integrator's splats are summed pass by
    /// pass, so the pass size is part of what decides its image).
    #[serde(rename = "passSpp")]
    pub pass_spp: u32,
    /// `--variance`; left out of the file when false.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub variance: bool,
    /// The rest of the provenance, by key.
    #[serde(flatten)]
    pub provenance: BTreeMap<String, String>,
}

/// A u32 written as a decimal string.
mod decimal {
    use serde::{de::Error, Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer>(v: &u32, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(v)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<u32, D::Error> {
        let s = String::deserialize(d)?;
        s.parse()
            .map_err(|_| D::Error::custom(format!("expected a count, got {s:?}")))
    }
}

impl FilmKey {
    /// The key of a render of `spp` samples per pixel whose provenance is `provenance`
    /// (its own "spp" entry is the `spp` field), of a `width` × `height` image in passes
    /// of `pass_spp`.
    pub fn new(
        provenance: &crate::provenance::Provenance,
        spp: u32,
        (width, height): (u32, u32),
        pass_spp: u32,
        variance: bool,
    ) -> FilmKey {
        FilmKey {
            spp,
            width,
            height,
            pass_spp,
            variance,
            provenance: provenance
                .0
                .iter()
                .filter(|(k, _)| *k != "spp")
                .map(|(k, v)| (k.to_string(), v.clone()))
                .collect(),
        }
    }

    /// The key as the file's JSON object (keys sorted).
    fn json(&self) -> serde_json::Map<String, serde_json::Value> {
        match serde_json::to_value(self) {
            Ok(serde_json::Value::Object(m)) => m,
            _ => unreachable!("a struct of strings and numbers serialises to an object"),
        }
    }

    /// The first setting in which this key and `other` differ, as "key: A <mine>, B
    /// <theirs>"; None if they are the same.
    fn differs(&self, other: &FilmKey, mine: &str, theirs: &str) -> Option<String> {
        let (a, b) = (self.json(), other.json());
        // The provenance's settings first (in their order: spp before the pass size it
        // implies), then the rest by name.
        let rank = |k: &str| crate::provenance::KEYS.iter().position(|&p| p == k);
        let mut names: Vec<&String> = a.keys().chain(b.keys()).collect();
        names.sort_by(|x, y| match (rank(x), rank(y)) {
            (Some(i), Some(j)) => i.cmp(&j),
            (Some(_), None) => std::cmp::Ordering::Less,
            (None, Some(_)) => std::cmp::Ordering::Greater,
            (None, None) => x.cmp(y),
        });
        names.dedup();
        names.into_iter().find_map(|k| {
            let (x, y) = (a.get(k), b.get(k));
            (x != y).then(|| {
                let show =
                    |v: Option<&serde_json::Value>| v.map_or("(none)".into(), |v| v.to_string());
                format!("{k}: {} {mine}, {} {theirs}", show(x), show(y))
            })
        })
    }
}

/// A film's state with what decides it: a checkpoint, or a shard's part.
#[derive(Clone, Debug, PartialEq)]
pub struct Checkpoint {
    pub key: FilmKey,
    /// The shard this film holds (None: all the samples).
    pub shard: Option<Shard>,
    /// Whether the EXR made from this film has the X, Y, Z channels (`--xyz`).
    pub xyz_channels: bool,
    pub film: FilmState,
}

fn err(path: &Path, message: impl Into<String>) -> HeronError {
    HeronError::Io {
        path: path.to_path_buf(),
        message: message.into(),
    }
}

fn with(v: bool) -> &'static str {
    if v {
        "with"
    } else {
        "without"
    }
}

impl Checkpoint {
    /// The bytes of the file.
    pub fn to_bytes(&self) -> Vec<u8> {
        let f = &self.film;
        let l = &f.layout;
        let mut header = serde_json::json!({
            "settings": serde_json::Value::Object(self.key.json()),
            "shard": self.shard.map(|s| [s.index, s.count]),
            "width": l.width,
            "height": l.height,
            "bins": l.bins,
            "splats": l.splats,
            "variance": l.variance,
            "stokes": l.stokes,
            "xyzChannels": self.xyz_channels,
            "planes": Planes::names(l),
        });
        if let Some(p) = &f.integrator {
            header["integrator"] = serde_json::json!({"name": p.name, "values": p.values.len()});
        }
        let mut b = MAGIC.as_bytes().to_vec();
        b.extend_from_slice(header.to_string().as_bytes());
        b.push(b'\n');
        for v in [f.passes_done, f.spp_done] {
            b.extend_from_slice(&v.to_le_bytes());
        }
        for v in [f.rays, f.shadow_rays, f.nonfinite] {
            b.extend_from_slice(&v.to_le_bytes());
        }
        f.planes.write(&mut b);
        for v in f.integrator.iter().flat_map(|p| &p.values) {
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
        if let Some(old) = OLD_MAGICS.iter().find(|m| bytes.starts_with(m.as_bytes())) {
            return Err(format!(
                "it was written by an older heron ({}); render again",
                old.trim_end()
            ));
        }
        let rest = bytes
            .strip_prefix(MAGIC.as_bytes())
            .ok_or("expected the first line \"heron-film 2\"")?;
        let nl = rest
            .iter()
            .position(|&c| c == b'\n')
            .ok_or("no header line")?;
        let h: serde_json::Value =
            serde_json::from_slice(&rest[..nl]).map_err(|_| "the header line is not JSON")?;
        let bad = |k: &str| format!("the header's {k:?} is missing or of the wrong type");
        let key: FilmKey = h
            .get("settings")
            .and_then(|v| serde_json::from_value(v.clone()).ok())
            .ok_or_else(|| bad("settings"))?;
        let u32_of = |k: &str| {
            h.get(k)
                .and_then(|v| v.as_u64())
                .and_then(|v| u32::try_from(v).ok())
                .ok_or_else(|| bad(k))
        };
        let bool_of = |k: &str| h.get(k).and_then(|v| v.as_bool()).ok_or_else(|| bad(k));
        let shard = match h.get("shard") {
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
        let bins = u32_of("bins")?;
        if bins > u16::MAX as u32 {
            return Err(bad("bins"));
        }
        let layout = Layout {
            width: u32_of("width")?,
            height: u32_of("height")?,
            bins: bins as usize,
            splats: bool_of("splats")?,
            variance: bool_of("variance")?,
            stokes: bool_of("stokes")?,
        };
        let names: Vec<String> = h
            .get("planes")
            .and_then(|v| serde_json::from_value(v.clone()).ok())
            .ok_or_else(|| bad("planes"))?;
        let want = Planes::names(&layout);
        if names != want {
            return Err(format!(
                "its planes {names:?} are not those of its layout ({want:?})"
            ));
        }
        let integrator = match h.get("integrator") {
            None => None,
            Some(v) => {
                let name = v.get("name").and_then(|n| n.as_str());
                let count = v.get("values").and_then(|n| n.as_u64());
                let (Some(name), Some(count)) = (name, count) else {
                    return Err(bad("integrator"));
                };
                Some((name.to_string(), count))
            }
        };
        let mut r = &rest[nl + 1..];
        let mut take = |n: usize| -> std::result::Result<&[u8], String> {
            if r.len() < n {
                return Err("the file is truncated".into());
            }
            let (a, b) = r.split_at(n);
            r = b;
            Ok(a)
        };
        let u32_at =
            |b: &[u8], k: usize| u32::from_le_bytes(b[4 * k..4 * k + 4].try_into().unwrap());
        let u64_at =
            |b: &[u8], k: usize| u64::from_le_bytes(b[8 * k..8 * k + 8].try_into().unwrap());
        let counts = take(8)?;
        let (passes_done, spp_done) = (u32_at(counts, 0), u32_at(counts, 1));
        let rays = take(24)?;
        let (planes, after) = Planes::read(&layout, r).map_err(String::from)?;
        r = after;
        let integrator = match integrator {
            None => None,
            Some((name, count)) => {
                if count > r.len() as u64 / 4 {
                    return Err("the file is truncated".into());
                }
                let values = r[..4 * count as usize]
                    .chunks_exact(4)
                    .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
                    .collect();
                r = &r[4 * count as usize..];
                Some(IntegratorPlane { name, values })
            }
        };
        if !r.is_empty() {
            return Err(format!("{} bytes after the data", r.len()));
        }
        Ok(Checkpoint {
            key,
            shard,
            xyz_channels: bool_of("xyzChannels")?,
            film: FilmState {
                layout,
                passes_done,
                spp_done,
                rays: u64_at(rays, 0),
                shadow_rays: u64_at(rays, 1),
                nonfinite: u64_at(rays, 2),
                planes,
                integrator,
            },
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
    pub fn mismatch(&self, key: &FilmKey) -> Option<String> {
        self.key.differs(key, "in the checkpoint", "in this render")
    }

    /// This checkpoint as the state a render continues from: the render's settings
    /// `key`, its `shard`, its film's `layout`, its count of `passes` and the
    /// integrator's own plane (name, values per pixel) must fit, or the error says what
    /// does not.
    pub fn resume(
        &self,
        key: &FilmKey,
        shard: Option<Shard>,
        layout: &Layout,
        passes: usize,
        integrator: Option<(&str, usize)>,
    ) -> Result<Checkpoint> {
        if self.key.variance != key.variance {
            return Err(HeronError::Invalid(format!(
                "--resume: the checkpoint was made {} --variance, this render is {} it",
                with(self.key.variance),
                with(key.variance)
            )));
        }
        if let Some(m) = self.mismatch(key) {
            return Err(HeronError::Invalid(format!(
                "--resume: the checkpoint was made with other settings ({m})"
            )));
        }
        if self.shard != shard {
            let show = |s: Option<Shard>| s.map_or("no shard".into(), |s| format!("shard {s}"));
            return Err(HeronError::Invalid(format!(
                "--resume: the checkpoint holds {}, this render {}",
                show(self.shard),
                show(shard)
            )));
        }
        let plane = self
            .film
            .integrator
            .as_ref()
            .map(|p| (p.name.as_str(), p.values.len()));
        if self.film.layout != *layout
            || self.film.passes_done as usize > passes
            || plane != integrator.map(|(n, per)| (n, per * layout.pixels()))
        {
            return Err(HeronError::Invalid(
                "--resume: the checkpoint's film does not fit this render".into(),
            ));
        }
        Ok(self.clone())
    }

    /// The samples per pixel this film should hold when complete: its shard's share of
    /// the render's spp (all of it without a shard).
    pub fn spp_expected(&self) -> u32 {
        match self.shard {
            Some(s) => s.samples(self.key.spp).len() as u32,
            None => self.key.spp,
        }
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
        if c.shard.is_none() && parts.len() > 1 {
            return Err(err(
                p,
                "holds a whole render, not a shard (made without --shard)",
            ));
        }
        Ok(c.shard.unwrap_or(Shard { index: 0, count: 1 }))
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
        if c.key.variance != first.key.variance {
            return Err(err(
                p,
                format!(
                    "was rendered {} --variance, {} {} it: render every shard with the same flags",
                    with(c.key.variance),
                    first_path.display(),
                    with(first.key.variance)
                ),
            ));
        }
        let there = format!("in {}", first_path.display());
        if let Some(m) = c.key.differs(&first.key, "here", &there) {
            return Err(err(p, format!("is from another render ({m})")));
        }
        if c.film.layout != first.film.layout || c.xyz_channels != first.xyz_channels {
            return Err(err(
                p,
                format!("its film does not fit {}'s", first_path.display()),
            ));
        }
        let want = c.spp_expected();
        if c.film.spp_done != want {
            return Err(err(
                p,
                format!(
                    "shard {s} is incomplete: it holds {} of its {want} samples per pixel (finish it with heron render --resume {})",
                    c.film.spp_done,
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
    // Shards of photon mapping are independent chains (see `render/progressive.rs`): their own
    // per-pixel states do not continue as one, so the merged film has none.
    let mut film = FilmState::new(first.film.layout);
    for (_, c) in parts {
        film.add(&c.film);
    }
    Ok(Checkpoint {
        key: first.key.clone(),
        shard: None,
        xyz_channels: first.xyz_channels,
        film,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::film::planes::{Cell, VisitMut};

    fn key() -> FilmKey {
        FilmKey {
            spp: 64,
            width: 2,
            height: 1,
            pass_spp: 4,
            variance: false,
            provenance: [("seed".to_string(), "1".to_string())].into(),
        }
    }

    /// Fills every plane with values that differ from element to element and from plane
    /// to plane, negative, large and small.
    fn fill(film: &mut FilmState) {
        struct Fill(u8);
        impl VisitMut for Fill {
            fn plane<T: Cell>(&mut self, _: &'static str, data: &mut Vec<T>) {
                for v in data.iter_mut() {
                    self.0 = self.0.wrapping_mul(31).wrapping_add(17);
                    let b: Vec<u8> = (0..T::BYTES as u8)
                        .map(|k| self.0 ^ k.wrapping_mul(7))
                        .collect();
                    *v = T::get(&b);
                }
            }
        }
        film.planes.visit_mut(&mut Fill(3));
    }

    fn checkpoint(layout: Layout) -> Checkpoint {
        let mut film = FilmState::new(layout);
        fill(&mut film);
        (film.passes_done, film.spp_done) = (3, 12);
        (film.rays, film.shadow_rays, film.nonfinite) = (5, 6, 1);
        Checkpoint {
            key: key(),
            shard: Some(Shard { index: 1, count: 3 }),
            xyz_channels: true,
            film,
        }
    }

    #[test]
    fn round_trip_and_truncation() {
        let plain = Layout {
            width: 2,
            height: 1,
            ..Default::default()
        };
        // Every combination of the layout's planes, and photon mapping's own plane.
        for bins in [0, 3] {
            for flags in 0..8u32 {
                let layout = Layout {
                    bins,
                    splats: flags & 1 != 0,
                    variance: flags & 2 != 0,
                    stokes: flags & 4 != 0,
                    ..plain
                };
                let mut c = checkpoint(layout);
                if flags == 5 {
                    c.film.integrator = Some(IntegratorPlane {
                        name: "sppm".into(),
                        values: vec![3.5, 0.0, 1e-4, 2.5],
                    });
                }
                let b = c.to_bytes();
                assert_eq!(Checkpoint::from_bytes(&b).unwrap(), c, "{layout:?}");
                for cut in [0, 5, MAGIC.len() + 3, b.len() - 17, b.len() - 1] {
                    assert!(Checkpoint::from_bytes(&b[..cut]).is_err(), "{cut}");
                }
                let mut long = b.clone();
                long.push(0);
                let e = Checkpoint::from_bytes(&long).unwrap_err();
                assert_eq!(e, "1 bytes after the data");
            }
        }
        // The planes the header names must be the layout's.
        let b = checkpoint(plain).to_bytes();
        let text = String::from_utf8_lossy(&b).replace("\"variance\":false", "\"variance\":true");
        let e = Checkpoint::from_bytes(text.as_bytes()).unwrap_err();
        assert!(e.contains("are not those of its layout"), "{e}");
        // Files of older formats are named as such.
        let e = Checkpoint::from_bytes(b"heron-film 1\n{}\n").unwrap_err();
        assert!(e.contains("older heron (heron-film 1)"), "{e}");
        // The settings compare key by key, the provenance's before the rest.
        let c = checkpoint(plain);
        let mut other = key();
        other.spp = 128;
        other.pass_spp = 8;
        assert_eq!(
            c.mismatch(&other).unwrap(),
            "spp: \"64\" in the checkpoint, \"128\" in this render"
        );
        assert_eq!(c.mismatch(&c.key), None);
        assert_eq!(c.spp_expected(), 21);
    }

    #[test]
    fn resume_checks_the_film_against_the_render() {
        let layout = Layout {
            width: 2,
            height: 1,
            bins: 2,
            splats: true,
            ..Default::default()
        };
        let c = checkpoint(layout);
        let shard = c.shard;
        assert_eq!(c.resume(&key(), shard, &layout, 3, None).unwrap(), c);
        let e = |r: Result<Checkpoint>| r.unwrap_err().to_string();
        let fits = "the checkpoint's film does not fit this render";
        let wider = Layout { bins: 4, ..layout };
        assert!(e(c.resume(&key(), shard, &wider, 3, None)).contains(fits));
        assert!(e(c.resume(&key(), shard, &layout, 2, None)).contains(fits));
        assert!(e(c.resume(&key(), shard, &layout, 3, Some(("sppm", 2)))).contains(fits));
        assert!(e(c.resume(&key(), None, &layout, 3, None)).contains("holds shard 1/3"));
        let variance = FilmKey {
            variance: true,
            ..key()
        };
        assert!(e(c.resume(&variance, shard, &layout, 3, None)).contains("made without --variance"));
    }

    #[test]
    fn merged_shards_add_their_planes_and_drop_the_integrator_plane() {
        let layout = Layout {
            width: 2,
            height: 1,
            bins: 1,
            splats: true,
            ..Default::default()
        };
        let parts: Vec<(std::path::PathBuf, Checkpoint)> = (0..2)
            .map(|k| {
                let mut c = checkpoint(layout);
                c.shard = Some(Shard { index: k, count: 2 });
                c.film.spp_done = 32;
                c.film.integrator = Some(IntegratorPlane {
                    name: "sppm".into(),
                    values: vec![1.0; 4],
                });
                (format!("part{k}").into(), c)
            })
            .collect();
        let m = merge(&parts).unwrap();
        assert_eq!(m.film.spp_done, 64);
        assert_eq!(m.film.integrator, None);
        assert_eq!(
            m.film.planes.xyz[0],
            parts[0].1.film.planes.xyz[0].wrapping_mul(2)
        );
        assert_eq!(
            m.film.planes.good[1],
            parts[0].1.film.planes.good[1].wrapping_mul(2)
        );
        let e = merge(&parts[..1]).unwrap_err().to_string();
        assert!(e.contains("missing shard 1/2"), "{e}");
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
