//! An image as the viewer holds it: every channel of an EXR (or of a render in progress)
//! as a plane of f32, the provenance, and what can be shown of it.
use crate::film::exr::VARIANCE_CHANNELS;
use crate::film::exr::{channel_planes, read_provenance, ExrChannels, STOKES_CHANNELS};
use crate::film::Film;
use crate::spectrum::color::{mat3_mul, SRGB_TO_XYZ};
use crate::{HeronError, Result};
use exr::prelude::*;
use rayon::prelude::*;
use std::path::Path;

/// One channel: its EXR name and its values row-major from the top-left.
#[derive(Clone, Debug, PartialEq)]
pub struct Channel {
    pub name: String,
    pub data: Vec<f32>,
}

/// One spectral bin of a Fichet et al. 2021 layout: its centre and the channels of its
/// Stokes components (S0 always; S1–S3 in a polarised render).
#[derive(Clone, Debug, PartialEq)]
pub struct Bin {
    pub lambda: f32,
    /// Indices into [`ViewImage::channels`] of S0, S1, S2, S3 at this bin.
    pub stokes: [Option<usize>; 4],
}

/// An image the viewer serves.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewImage {
    /// What the page calls it: the file name as given on the command line.
    pub name: String,
    pub width: u32,
    pub height: u32,
    pub channels: Vec<Channel>,
    /// The `heron.*` attributes (`heron info`), sorted by key; empty for a render in
    /// progress.
    pub provenance: Vec<(String, String)>,
}

impl ViewImage {
    /// Checks that `path` is an OpenEXR file whose header can be read, without decoding
    /// its pixels: the quick check before the viewer starts (and the decoding) goes on.
    pub fn check_exr(path: &Path) -> Result<()> {
        exr::meta::MetaData::read_from_file(path, false)
            .map(|_| ())
            .map_err(|e| HeronError::Io {
                path: path.to_path_buf(),
                message: format!("cannot read it as OpenEXR: {e}"),
            })
    }

    /// Every channel of the first layer of the EXR at `path` (half, float and integer
    /// samples as f32) and its provenance. Errors name the file and what was expected.
    pub fn read_exr(path: &Path) -> Result<ViewImage> {
        let err = |message: String| HeronError::Io {
            path: path.to_path_buf(),
            message,
        };
        let image = read()
            .no_deep_data()
            .largest_resolution_level()
            .all_channels()
            .first_valid_layer()
            .all_attributes()
            .from_file(path)
            .map_err(|e| err(format!("cannot read it as OpenEXR: {e}")))?;
        let layer = image.layer_data;
        let (w, h) = (layer.size.width(), layer.size.height());
        if w == 0 || h == 0 || w > u32::MAX as usize || h > u32::MAX as usize {
            return Err(err(format!("expected a non-empty image, got {w}×{h}")));
        }
        let mut channels: Vec<Channel> = layer
            .channel_data
            .list
            .into_iter()
            .map(|c| Channel {
                name: c.name.to_string(),
                data: match c.sample_data {
                    FlatSamples::F16(v) => v.into_iter().map(f32::from).collect(),
                    FlatSamples::F32(v) => v,
                    FlatSamples::U32(v) => v.into_iter().map(|x| x as f32).collect(),
                },
            })
            .collect();
        // OpenEXR stores channels sorted by name (B, G, R, …); the menu lists them in
        // the order heron writes them.
        channels.sort_by(|a, b| order(&a.name).total_cmp(&order(&b.name)));
        Ok(ViewImage {
            name: path.display().to_string(),
            width: w as u32,
            height: h as u32,
            channels,
            provenance: read_provenance(path)?,
        })
    }

    /// The channels the EXR of `film` will have (with XYZ and the spectral bins when the
    /// film has them): a render in progress.
    pub fn from_film(name: &str, film: &Film) -> ViewImage {
        let which = ExrChannels {
            xyz: true,
            spectral: true,
        };
        ViewImage {
            name: name.to_string(),
            width: film.width,
            height: film.height,
            channels: channel_planes(film, which)
                .into_iter()
                .map(|(name, data)| Channel { name, data })
                .collect(),
            provenance: Vec::new(),
        }
    }

    pub fn pixels(&self) -> usize {
        self.width as usize * self.height as usize
    }

    /// The index of the channel called `name`.
    pub fn find(&self, name: &str) -> Option<usize> {
        self.channels.iter().position(|c| c.name == name)
    }

    /// The three channels called `names`, when all are there.
    pub fn triple(&self, names: [&str; 3]) -> Option<[&[f32]; 3]> {
        let [a, b, c] = names.map(|n| self.find(n));
        Some([a?, b?, c?].map(|i| self.channels[i].data.as_slice()))
    }

    /// Linear sRGB: R, G, B, or, for a file with only X, Y, Z, those converted.
    pub fn rgb(&self, i: usize) -> Option<[f32; 3]> {
        if let Some(c) = self.triple(["R", "G", "B"]) {
            return Some(c.map(|p| p[i]));
        }
        self.triple(["X", "Y", "Z"])
            .map(|c| crate::spectrum::color::xyz_to_linear_srgb(c.map(|p| p[i])))
    }

    /// CIE XYZ: the X, Y, Z channels, or R, G, B converted (IEC 61966-2-1's matrix).
    pub fn xyz(&self, i: usize) -> Option<[f32; 3]> {
        if let Some(c) = self.triple(["X", "Y", "Z"]) {
            return Some(c.map(|p| p[i]));
        }
        self.triple(["R", "G", "B"])
            .map(|c| mat3_mul(&SRGB_TO_XYZ, c.map(|p| p[i])))
    }

    /// The variance channels' R, G, B.
    pub fn variance(&self) -> Option<[&[f32]; 3]> {
        self.triple(VARIANCE_CHANNELS)
    }

    /// S1, S2, S3 in linear sRGB (R, G, B each), when the render was polarised.
    pub fn stokes(&self) -> Option<[[&[f32]; 3]; 3]> {
        let [a, b, c] = STOKES_CHANNELS.map(|names| self.triple(names));
        Some([a?, b?, c?])
    }

    /// The spectral bins, by wavelength: channels named `S<k>.<λ>nm` with a decimal
    /// comma or point (Fichet et al. 2021, §3).
    pub fn bins(&self) -> Vec<Bin> {
        let mut bins: Vec<Bin> = Vec::new();
        for (i, c) in self.channels.iter().enumerate() {
            let Some((k, lambda)) = stokes_bin(&c.name) else {
                continue;
            };
            match bins.iter_mut().find(|b| b.lambda == lambda) {
                Some(b) => b.stokes[k] = Some(i),
                None => {
                    let mut stokes = [None; 4];
                    stokes[k] = Some(i);
                    bins.push(Bin { lambda, stokes });
                }
            }
        }
        bins.retain(|b| b.stokes[0].is_some());
        bins.sort_by(|a, b| a.lambda.total_cmp(&b.lambda));
        bins
    }

    /// The channels `keep` (indices) averaged over `step × step` blocks (the last row
    /// and column of blocks take what is left): the picture of a view at a zoom below
    /// 1/step, from its linear values (the mean of Stokes vectors, the mean variance), as
    /// a mipmap level is. The channels keep their names and the order of `keep`.
    pub fn downsample(&self, step: u32, keep: &[usize]) -> ViewImage {
        let (w, h) = (self.width as usize, self.height as usize);
        let s = step.max(1) as usize;
        let (dw, dh) = (w.div_ceil(s), h.div_ceil(s));
        let channels = keep
            .iter()
            .map(|&c| {
                let src = &self.channels[c].data;
                let mut data = vec![0f32; dw * dh];
                data.par_chunks_mut(dw).enumerate().for_each(|(by, row)| {
                    let ys = by * s..((by + 1) * s).min(h);
                    for (bx, out) in row.iter_mut().enumerate() {
                        let xs = bx * s..((bx + 1) * s).min(w);
                        let mut sum = 0f64;
                        for y in ys.clone() {
                            sum += src[y * w + xs.start..y * w + xs.end]
                                .iter()
                                .map(|&v| v as f64)
                                .sum::<f64>();
                        }
                        *out = (sum / (ys.len() * xs.len()) as f64) as f32;
                    }
                });
                Channel {
                    name: self.channels[c].name.clone(),
                    data,
                }
            })
            .collect();
        ViewImage {
            name: self.name.clone(),
            width: dw as u32,
            height: dh as u32,
            channels,
            provenance: Vec::new(),
        }
    }

    /// A film with this image's S0 (as XYZ) and Stokes components, for the DoLP and AoLP
    /// pictures `heron render` writes beside a polarised render (`plot::stokes`).
    pub fn stokes_film(&self) -> Option<Film> {
        let s = self.stokes()?;
        let n = self.pixels();
        let xyz = (0..n).map(|i| self.xyz(i).unwrap_or([0.0; 3])).collect();
        let stokes = (0..n)
            .map(|i| s.map(|rgb| mat3_mul(&SRGB_TO_XYZ, rgb.map(|p| p[i]))))
            .collect();
        Some(Film {
            width: self.width,
            height: self.height,
            xyz,
            spectral: None,
            variance: None,
            stokes: Some(stokes),
            stokes_spectral: None,
        })
    }
}

/// Where a channel goes in the menu: R, G, B, X, Y, Z, the variance, S1–S3 (R, G, B),
/// then the spectral bins by Stokes component and wavelength; other channels last (a
/// stable sort keeps their order).
fn order(name: &str) -> f64 {
    const FIRST: [&str; 18] = [
        "R",
        "G",
        "B",
        "X",
        "Y",
        "Z",
        "variance.R",
        "variance.G",
        "variance.B",
        "S1.R",
        "S1.G",
        "S1.B",
        "S2.R",
        "S2.G",
        "S2.B",
        "S3.R",
        "S3.G",
        "S3.B",
    ];
    if let Some(i) = FIRST.iter().position(|f| *f == name) {
        return i as f64;
    }
    match stokes_bin(name) {
        Some((k, lambda)) => 100.0 + 1000.0 * k as f64 + lambda as f64,
        None => 1e9,
    }
}

/// `S<k>.<λ>nm` → (k, λ): a Fichet et al. 2021 emissive or polarised spectral channel.
fn stokes_bin(name: &str) -> Option<(usize, f32)> {
    let rest = name.strip_prefix('S')?;
    let (k, rest) = rest.split_once('.')?;
    let k: usize = k.parse().ok().filter(|&k| k < 4)?;
    let lambda: f32 = rest.strip_suffix("nm")?.replace(',', ".").parse().ok()?;
    lambda.is_finite().then_some((k, lambda))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_average_their_pixels_and_the_edge_blocks_what_is_left() {
        let img = ViewImage {
            name: "a".into(),
            width: 5,
            height: 3,
            channels: vec![
                Channel {
                    name: "R".into(),
                    data: (0..15).map(|v| v as f32).collect(),
                },
                Channel {
                    name: "G".into(),
                    data: vec![1.0; 15],
                },
            ],
            provenance: Vec::new(),
        };
        let d = img.downsample(2, &[1, 0]);
        assert_eq!((d.width, d.height), (3, 2));
        assert_eq!(d.channels[0].name, "G");
        assert_eq!(d.channels[0].data, vec![1.0; 6]);
        // Rows 0-1 × columns 0-1: (0 + 1 + 5 + 6) / 4; the last column is one wide, the
        // last row one high.
        assert_eq!(d.channels[1].data, vec![3.0, 5.0, 6.5, 10.5, 12.5, 14.0]);
        assert_eq!(img.downsample(1, &[0, 1]).channels, img.channels);
    }

    #[test]
    fn spectral_channel_names_parse_with_a_comma_or_a_point() {
        assert_eq!(stokes_bin("S0.412,5nm"), Some((0, 412.5)));
        assert_eq!(stokes_bin("S3.700.25nm"), Some((3, 700.25)));
        assert_eq!(stokes_bin("S4.500nm"), None);
        assert_eq!(stokes_bin("S1.R"), None);
        assert_eq!(stokes_bin("R"), None);
    }
}
