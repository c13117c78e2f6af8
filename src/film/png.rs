//! PNG preview: linear sRGB through a display transform (exposure, then the hue-preserving
//! gamut map or per-channel clipping, `spectrum::display`) and the sRGB transfer
//! function, 8 bits per channel. For looking at, not for measuring: use the EXR.
use super::Film;
use crate::files::Staged;
use crate::spectrum::display::DisplayTransform;
use rayon::prelude::*;
use std::path::Path;

/// Writes the film's PNG to a temporary file, to be committed later.
pub fn stage_png(film: &Film, path: &Path, display: &DisplayTransform) -> crate::Result<Staged> {
    stage_png_rgb(film.width, film.height, &film.linear_srgb(), path, display)
}

/// Writes a PNG of `width` × `height` linear sRGB pixels (row-major from the top-left) to
/// a temporary file, to be committed later.
pub fn stage_png_rgb(
    width: u32,
    height: u32,
    rgb: &[[f32; 3]],
    path: &Path,
    display: &DisplayTransform,
) -> crate::Result<Staged> {
    assert_eq!(rgb.len(), width as usize * height as usize);
    // Each pixel on its own: the same bytes for any thread count.
    let bytes: Vec<u8> = rgb
        .par_iter()
        .flat_map_iter(|&c| display.encode_u8(c))
        .collect();
    let img =
        image::RgbImage::from_raw(width, height, bytes).expect("buffer size matches the image");
    Staged::write(path, |tmp| {
        img.save_with_format(tmp, image::ImageFormat::Png)
            .map_err(|e| format!("cannot write PNG: {e}"))
    })
}
