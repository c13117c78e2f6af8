//! PNG preview: linear sRGB clamped to [0, 1] and encoded with the sRGB transfer
//! function, 8 bits per channel. For looking at, not for measuring: use the EXR.
use super::Film;
use crate::files::Staged;
use crate::spectrum::color::srgb_encode;
use std::path::Path;

/// Writes the PNG file to a temporary file, to be committed later.
pub fn stage_png(film: &Film, path: &Path) -> crate::Result<Staged> {
    let mut bytes = Vec::with_capacity(film.xyz.len() * 3);
    for c in film.linear_srgb() {
        for v in c {
            bytes.push((srgb_encode(v) * 255.0 + 0.5) as u8);
        }
    }
    let img = image::RgbImage::from_raw(film.width, film.height, bytes)
        .expect("buffer size matches the film");
    Staged::write(path, |tmp| {
        img.save_with_format(tmp, image::ImageFormat::Png)
            .map_err(|e| format!("cannot write PNG: {e}"))
    })
}
