//! An image to compare: linear sRGB and, when the EXR has them, its variance channels.
use super::*;

/// A three-channel image to compare, with an optional per-pixel variance of each
/// channel's value (the variance of the pixel's mean, as `heron render --variance`
/// writes it).
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    /// The channels' names (for the report), e.g. R, G, B.
    pub channels: [String; 3],
    /// Row-major from the top-left.
    pub values: Vec<[f32; 3]>,
    pub variance: Option<Vec<[f32; 3]>>,
}

impl Image {
    /// An image from its values; `what` names it in errors. Values must be finite;
    /// variances ≥ 0 (+∞ stands for unknown: such a pixel makes its region's test pass).
    pub fn new(
        what: &str,
        width: u32,
        height: u32,
        channels: [&str; 3],
        values: Vec<[f32; 3]>,
        variance: Option<Vec<[f32; 3]>>,
    ) -> Result<Image> {
        let n = width as usize * height as usize;
        let bad = |m: String| HeronError::Invalid(format!("{what}: {m}"));
        if width == 0 || height == 0 {
            return Err(bad("the image is empty".into()));
        }
        if values.len() != n || variance.as_ref().is_some_and(|v| v.len() != n) {
            return Err(bad(format!(
                "expected {n} pixels for {width}x{height}, got {}",
                values.len()
            )));
        }
        let at = |i: usize| format!("({}, {})", i % width as usize, i / width as usize);
        if let Some(i) = values.iter().position(|v| v.iter().any(|x| !x.is_finite())) {
            return Err(bad(format!(
                "pixel {} is not finite ({:?}): expected finite values",
                at(i),
                values[i]
            )));
        }
        if let Some(var) = &variance {
            if let Some(i) = var.iter().position(|v| v.iter().any(|x| !(*x >= 0.0))) {
                return Err(bad(format!(
                    "the variance of pixel {} is {:?}: expected values >= 0",
                    at(i),
                    var[i]
                )));
            }
        }
        Ok(Image {
            width,
            height,
            channels: channels.map(String::from),
            values,
            variance,
        })
    }

    /// A film's linear sRGB and, when it has one, its variance estimate: what `heron
    /// render` writes into the EXR's R, G, B and variance channels.
    pub fn from_film(film: &Film) -> Image {
        Image {
            width: film.width,
            height: film.height,
            channels: ["R", "G", "B"].map(String::from),
            values: film.linear_srgb(),
            variance: film.variance.clone(),
        }
    }

    /// A film's CIE XYZ, without variance (the film estimates the variance of linear
    /// sRGB only).
    pub fn from_film_xyz(film: &Film) -> Image {
        Image {
            width: film.width,
            height: film.height,
            channels: ["X", "Y", "Z"].map(String::from),
            values: film.xyz.clone(),
            variance: None,
        }
    }

    /// The R, G, B channels of an OpenEXR file, and `variance.R`, `variance.G`,
    /// `variance.B` when it has them (from the first layer with R, G and B). Errors name
    /// the file.
    pub fn read_exr(path: &Path) -> Result<Image> {
        let err = |m: String| HeronError::Io {
            path: path.to_path_buf(),
            message: m,
        };
        let image = exr::prelude::read_all_flat_layers_from_file(path)
            .map_err(|e| err(format!("cannot read it as OpenEXR: {e}")))?;
        let mut names = Vec::new();
        for layer in &image.layer_data {
            let find = |name: &str| {
                layer
                    .channel_data
                    .list
                    .iter()
                    .find(|c| c.name.to_string() == name)
                    .map(|c| c.sample_data.values_as_f32().collect::<Vec<f32>>())
            };
            names.extend(layer.channel_data.list.iter().map(|c| c.name.to_string()));
            let (Some(r), Some(g), Some(b)) = (find("R"), find("G"), find("B")) else {
                continue;
            };
            let (w, h) = (layer.size.width(), layer.size.height());
            let zip = |r: Vec<f32>, g: Vec<f32>, b: Vec<f32>| -> Vec<[f32; 3]> {
                (0..w * h).map(|i| [r[i], g[i], b[i]]).collect()
            };
            let var: Vec<Option<Vec<f32>>> = VARIANCE_CHANNELS.iter().map(|c| find(c)).collect();
            let variance = match (&var[0], &var[1], &var[2]) {
                (Some(r), Some(g), Some(b)) => Some(zip(r.clone(), g.clone(), b.clone())),
                (None, None, None) => None,
                _ => {
                    let missing: Vec<&str> = VARIANCE_CHANNELS
                        .iter()
                        .zip(&var)
                        .filter(|(_, v)| v.is_none())
                        .map(|(c, _)| *c)
                        .collect();
                    return Err(err(format!(
                        "has some variance channels but not {}: expected variance.R, variance.G and variance.B, or none",
                        missing.join(", ")
                    )));
                }
            };
            let (w32, h32) = (
                u32::try_from(w).map_err(|_| err("the image is too wide".into()))?,
                u32::try_from(h).map_err(|_| err("the image is too tall".into()))?,
            );
            return Image::new(
                &path.display().to_string(),
                w32,
                h32,
                ["R", "G", "B"],
                zip(r, g, b),
                variance,
            );
        }
        names.sort();
        names.dedup();
        Err(err(format!(
            "no R, G and B channels to compare (it has {})",
            if names.is_empty() {
                "none".to_string()
            } else {
                names.join(", ")
            }
        )))
    }
}
