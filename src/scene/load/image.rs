//! RGB images a scene reads (environment maps): OpenEXR through the `exr` crate (its
//! first RGB(A) layer; heron's own renders qualify), Radiance HDR and PNG through the
//! `image` crate. Pixels come back as linear sRGB, row by row from the top of the image;
//! PNG's 8- or 16-bit values are sRGB-encoded and decoded with the IEC 61966-2-1 curve
//! (as Mitsuba 3 and pbrt-v4 decode LDR images).
use std::path::Path;

/// A decoded image: `width × height` linear RGB pixels, top row first.
pub struct RgbImage {
    pub width: usize,
    pub height: usize,
    pub pixels: Vec<[f32; 3]>,
}

/// Reads `path` by its extension (`.exr`, `.hdr`, `.png`, in any case). The error names
/// the file and what was wrong with it.
pub fn read_rgb(path: &Path) -> Result<RgbImage, String> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    let shown = path.display();
    let img = match ext.as_str() {
        "exr" => read_exr(path).map_err(|e| format!("{shown}: {e}"))?,
        "hdr" | "png" => {
            read_with_image(path, ext == "png").map_err(|e| format!("{shown}: {e}"))?
        }
        _ => {
            return Err(format!(
                "{shown}: expected an image file ending in .exr, .hdr or .png, got {:?}",
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

fn read_with_image(path: &Path, srgb: bool) -> Result<RgbImage, String> {
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
            if srgb {
                c.map(srgb_decode)
            } else {
                c
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
