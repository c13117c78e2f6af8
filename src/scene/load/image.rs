//! RGB images a scene reads (environment maps and textures): OpenEXR through the `exr`
//! crate (its first RGB(A) layer; heron's own renders qualify), Radiance HDR, PNG and
//! JPEG through the `image` crate, and PFM (Portable Float Map) by [`parse_pfm`]. Pixels
//! come back as linear sRGB, row by row from the top of the image; PNG's and JPEG's 8- or
//! 16-bit values are sRGB-encoded and decoded with the IEC 61966-2-1 curve (as Mitsuba 3
//! and pbrt-v4 decode LDR images).
use std::path::Path;

/// A decoded image: `width × height` linear RGB pixels, top row first.
pub struct RgbImage {
    pub width: usize,
    pub height: usize,
    pub pixels: Vec<[f32; 3]>,
}

/// The extensions [`read_rgb`] reads, as its error lists them.
const EXTENSIONS: &str = ".exr, .hdr, .pfm, .png, .jpg or .jpeg";

/// Reads `path` by its extension (`.exr`, `.hdr`, `.pfm`, `.png`, `.jpg`, `.jpeg`, in any
/// case). The error names the file and what was wrong with it.
pub fn read_rgb(path: &Path) -> Result<RgbImage, String> {
    read_rgb_encoded(path, Encoding::Srgb)
}

/// How an 8- or 16-bit image's (PNG's, JPEG's) values become linear (pbrt-v4's
/// `ColorEncoding`: `sRGB`, `linear`, `gamma g`); OpenEXR, HDR and PFM are linear.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Encoding {
    Srgb,
    Linear,
    /// value^g.
    Gamma(f32),
}

impl Encoding {
    /// `"srgb"`, `"linear"` or `"gamma G"` (G > 0), as a scene file writes it.
    pub fn parse(s: &str) -> Result<Encoding, String> {
        let bad = || format!("expected \"srgb\", \"linear\" or \"gamma G\" with G > 0, got {s:?}");
        match s {
            "srgb" => Ok(Encoding::Srgb),
            "linear" => Ok(Encoding::Linear),
            _ => {
                let g = s.strip_prefix("gamma ").ok_or_else(bad)?;
                let g: f32 = g.trim().parse().map_err(|_| bad())?;
                if g.is_finite() && g > 0.0 {
                    Ok(Encoding::Gamma(g))
                } else {
                    Err(bad())
                }
            }
        }
    }
}

/// [`read_rgb`] with a PNG's or JPEG's values decoded by `encoding`.
pub fn read_rgb_encoded(path: &Path, encoding: Encoding) -> Result<RgbImage, String> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    let shown = path.display();
    let img = match ext.as_str() {
        "exr" => read_exr(path).map_err(|e| format!("{shown}: {e}"))?,
        "hdr" | "png" | "jpg" | "jpeg" => {
            let encoding = if ext == "hdr" {
                Encoding::Linear
            } else {
                encoding
            };
            read_with_image(path, encoding).map_err(|e| format!("{shown}: {e}"))?
        }
        "pfm" => std::fs::read(path)
            .map_err(|e| format!("cannot open it: {e}"))
            .and_then(|b| parse_pfm(&b))
            .map_err(|e| format!("{shown}: {e}"))?,
        _ => {
            return Err(format!(
                "{shown}: expected an image file ending in {EXTENSIONS}, got {:?}",
                path.extension()
                    .map(|e| e.to_string_lossy().into_owned())
                    .unwrap_or_default()
            ))
        }
    };
    if img.width == 0 || img.height == 0 {
        return Err(format!(
            "{shown}: the image is empty ({} × {})",
            img.width, img.height
        ));
    }
    if let Some(k) = img
        .pixels
        .iter()
        .position(|p| p.iter().any(|v| !v.is_finite() || *v < 0.0))
    {
        let p = img.pixels[k];
        return Err(format!(
            "{shown}: pixel ({}, {}) is {p:?}: expected finite values ≥ 0",
            k % img.width,
            k / img.width
        ));
    }
    Ok(img)
}

fn read_exr(path: &Path) -> Result<RgbImage, String> {
    use exr::prelude::*;
    let meta = exr::meta::MetaData::read_from_file(path, false)
        .map_err(|e| format!("cannot read it as OpenEXR: {e}"))?;
    let header = meta
        .headers
        .first()
        .ok_or_else(|| "cannot read it as OpenEXR: no layer".to_string())?;
    for c in ["R", "G", "B"] {
        if !header
            .channels
            .list
            .iter()
            .any(|ch| ch.name.to_string() == c)
        {
            return Err(format!(
                "expected the channels R, G and B in its first layer, it has no {c}"
            ));
        }
    }
    let image = read_first_rgba_layer_from_file(
        path,
        |res, _| RgbImage {
            width: res.width(),
            height: res.height(),
            pixels: vec![[0.0; 3]; res.width() * res.height()],
        },
        |img: &mut RgbImage, pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            let w = img.width;
            img.pixels[pos.y() * w + pos.x()] = [r, g, b];
        },
    )
    .map_err(|e| format!("cannot read it as OpenEXR: {e}"))?;
    Ok(image.layer_data.channel_data.pixels)
}

fn read_with_image(path: &Path, encoding: Encoding) -> Result<RgbImage, String> {
    let reader = image::ImageReader::open(path)
        .map_err(|e| format!("cannot open it: {e}"))?
        .with_guessed_format()
        .map_err(|e| format!("cannot open it: {e}"))?;
    let img = reader
        .decode()
        .map_err(|e| format!("cannot decode it: {e}"))?;
    let (w, h) = (img.width() as usize, img.height() as usize);
    let rgb = img.into_rgb32f();
    let pixels = rgb
        .pixels()
        .map(|p| {
            let c = [p.0[0], p.0[1], p.0[2]];
            match encoding {
                Encoding::Srgb => c.map(srgb_decode),
                Encoding::Linear => c,
                Encoding::Gamma(g) => c.map(|v| v.powf(g)),
            }
        })
        .collect();
    Ok(RgbImage {
        width: w,
        height: h,
        pixels,
    })
}

/// The sRGB transfer function's inverse (IEC 61966-2-1).
fn srgb_decode(v: f32) -> f32 {
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

/// A Portable Float Map: the header `PF` (RGB) or `Pf` (grey), the width and the height,
/// and a scale whose sign gives the byte order (negative: little-endian) and whose
/// magnitude multiplies the values, each followed by whitespace (one byte after the
/// scale); then 32-bit floats, rows from the bottom of the image to the top. Mitsuba 3
/// (`Bitmap::read_pfm`) and pbrt-v4 (`ReadPFM`) read it so, scale included; bytes after
/// the pixels are ignored, as they ignore them.
pub(crate) fn parse_pfm(bytes: &[u8]) -> Result<RgbImage, String> {
    let mut pos = 0;
    let mut word = |what: &str| -> Result<String, String> {
        let rest = &bytes[pos.min(bytes.len())..];
        let start = rest
            .iter()
            .position(|b| !b.is_ascii_whitespace())
            .ok_or(format!("expected {what} in the PFM header, the file ends"))?;
        let len = rest[start..]
            .iter()
            .position(|b| b.is_ascii_whitespace())
            .ok_or(format!(
                "expected whitespace after {what} in the PFM header"
            ))?;
        // The word and the one whitespace byte after it.
        pos += start + len + 1;
        let w = &rest[start..start + len];
        Ok(String::from_utf8_lossy(&w[..w.len().min(40)]).into_owned())
    };
    let channels = match word("PF or Pf")?.as_str() {
        "PF" => 3,
        "Pf" => 1,
        other => {
            return Err(format!(
                "expected the PFM header PF (colour) or Pf (grey), got {other:?}"
            ))
        }
    };
    let mut size = |what: &str| -> Result<usize, String> {
        let w = word(&format!("the {what}"))?;
        w.parse::<usize>().ok().filter(|&n| n > 0).ok_or(format!(
            "expected the {what} as a positive integer, got {w:?}"
        ))
    };
    let (width, height) = (size("width")?, size("height")?);
    let w = word("the scale")?;
    let scale: f32 = w
        .parse()
        .ok()
        .filter(|s: &f32| s.is_finite() && *s != 0.0)
        .ok_or(format!(
            "expected the scale as a non-zero number (negative: little-endian), got {w:?}"
        ))?;
    let little = scale < 0.0;
    let need = width
        .checked_mul(height)
        .and_then(|n| n.checked_mul(channels * 4));
    let data = bytes.get(pos..).unwrap_or_default();
    let Some(need) = need.filter(|&n| n <= data.len()) else {
        return Err(format!(
            "the pixels end early: {width} × {height} × {channels} floats need {} bytes, the file has {} after its header",
            need.map_or("more than 2^64".into(), |n| n.to_string()),
            data.len()
        ));
    };
    let factor = scale.abs();
    let values: Vec<f32> = data[..need]
        .chunks_exact(4)
        .map(|c| {
            let b = [c[0], c[1], c[2], c[3]];
            factor
                * if little {
                    f32::from_le_bytes(b)
                } else {
                    f32::from_be_bytes(b)
                }
        })
        .collect();
    let row = width * channels;
    let pixels = values
        .chunks_exact(row)
        .rev()
        .flat_map(|r| {
            r.chunks_exact(channels).map(|p| match p {
                [y] => [*y; 3],
                _ => [p[0], p[1], p[2]],
            })
        })
        .collect();
    Ok(RgbImage {
        width,
        height,
        pixels,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A PFM of `rows` (bottom row first, as the file stores them).
    fn pfm(magic: &str, w: usize, h: usize, scale: &str, little: bool, values: &[f32]) -> Vec<u8> {
        let mut b = format!("{magic}\n{w} {h}\n{scale}\n").into_bytes();
        for v in values {
            b.extend(if little {
                v.to_le_bytes()
            } else {
                v.to_be_bytes()
            });
        }
        b
    }

    #[test]
    fn pfm_colour_and_grey_in_both_byte_orders_come_back_top_row_first() {
        // 2 × 2: the file's first row is the image's bottom row.
        let rgb = [
            1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 10.0, 11.0, 12.0,
        ];
        for (scale, little) in [("-1.0", true), ("1.0", false)] {
            let img = parse_pfm(&pfm("PF", 2, 2, scale, little, &rgb)).unwrap();
            assert_eq!((img.width, img.height), (2, 2));
            assert_eq!(
                img.pixels,
                vec![
                    [7.0, 8.0, 9.0],
                    [10.0, 11.0, 12.0],
                    [1.0, 2.0, 3.0],
                    [4.0, 5.0, 6.0]
                ],
                "scale {scale}"
            );
            let img = parse_pfm(&pfm("Pf", 3, 1, scale, little, &rgb[..3])).unwrap();
            assert_eq!(
                img.pixels,
                vec![[1.0; 3], [2.0; 3], [3.0; 3]],
                "scale {scale}"
            );
        }
        // The scale's magnitude multiplies the values (as Mitsuba 3 and pbrt-v4 apply it).
        let img = parse_pfm(&pfm("Pf", 1, 1, "-0.5", true, &[3.0])).unwrap();
        assert_eq!(img.pixels, vec![[1.5; 3]]);
        // One whitespace byte ends the header, whatever it is; bytes past the pixels are
        // ignored.
        let mut b = b"PF 1 1 -1 ".to_vec();
        b.extend([0.25f32, 0.5, 0.75].iter().flat_map(|v| v.to_le_bytes()));
        b.extend(b"trailing");
        assert_eq!(parse_pfm(&b).unwrap().pixels, vec![[0.25, 0.5, 0.75]]);
    }

    fn pfm_error(b: &[u8]) -> String {
        match parse_pfm(b) {
            Ok(i) => panic!("expected an error, read {} × {}", i.width, i.height),
            Err(e) => e,
        }
    }

    #[test]
    fn bad_pfm_files_say_what_was_expected() {
        let good = pfm("PF", 2, 2, "-1", true, &[0.5; 12]);
        let e = pfm_error(&good[..good.len() - 1]);
        assert!(
            e.contains("the pixels end early: 2 × 2 × 3 floats need 48 bytes"),
            "{e}"
        );
        for (text, want) in [
            (
                "P6\n2 2\n255\n",
                "expected the PFM header PF (colour) or Pf (grey), got \"P6\"",
            ),
            (
                "PF\n2\n",
                "expected the height in the PFM header, the file ends",
            ),
            (
                "PF\n2 x\n-1\n",
                "expected the height as a positive integer, got \"x\"",
            ),
            (
                "PF\n0 2\n-1\n",
                "expected the width as a positive integer, got \"0\"",
            ),
            ("PF\n2 2\n0\n", "expected the scale as a non-zero number"),
            ("PF\n2 2\nnan\n", "expected the scale as a non-zero number"),
            ("", "expected PF or Pf in the PFM header, the file ends"),
            ("PF\n99999999999 99999999999\n-1\n", "more than 2^64"),
        ] {
            let e = pfm_error(text.as_bytes());
            assert!(e.contains(want), "{text:?}: {e}");
        }
    }

    /// A JPEG is sRGB-decoded as a PNG is, top row first: two flat halves come back as
    /// their 8-bit values through the sRGB curve (JPEG is lossy, so within a step).
    #[test]
    fn jpeg_is_srgb_decoded_top_row_first() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("halves.JPG");
        let (top, bottom) = ([200u8, 60, 30], [20u8, 120, 230]);
        let img =
            image::RgbImage::from_fn(32, 32, |_, y| image::Rgb(if y < 16 { top } else { bottom }));
        let mut out = std::fs::File::create(&path).unwrap();
        image::codecs::jpeg::JpegEncoder::new_with_quality(&mut out, 100)
            .encode_image(&img)
            .unwrap();
        drop(out);
        let got = read_rgb(&path).unwrap();
        assert_eq!((got.width, got.height), (32, 32));
        for (y, want) in [(4, top), (28, bottom)] {
            let p = got.pixels[y * 32 + 16];
            for c in 0..3 {
                let lo = srgb_decode((want[c] as f32 - 2.0) / 255.0);
                let hi = srgb_decode((want[c] as f32 + 2.0) / 255.0);
                assert!(
                    (lo..=hi).contains(&p[c]),
                    "row {y} channel {c}: {} not in [{lo}, {hi}]",
                    p[c]
                );
            }
        }
    }
}
