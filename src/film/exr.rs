//! OpenEXR output: float32 R, G, B in linear sRGB with the standard `chromaticities`
//! attribute (sRGB primaries, D65 white), so any reader knows the colour space.
use super::{Film, Staged};
use crate::spectrum::color::SRGB_CHROMATICITIES;
use exr::prelude::*;
use std::path::Path;

/// Writes the EXR file; see [`stage_exr`] to write several outputs together.
pub fn write_exr(film: &Film, path: &Path) -> crate::Result<()> {
    stage_exr(film, path)?.commit()
}

/// Writes the EXR file to a temporary file, to be committed later.
pub fn stage_exr(film: &Film, path: &Path) -> crate::Result<Staged> {
    let rgb = film.linear_srgb();
    let (w, h) = (film.width as usize, film.height as usize);
    let channels = SpecificChannels::rgb(|pos: Vec2<usize>| {
        let c = rgb[pos.y() * w + pos.x()];
        (c[0], c[1], c[2])
    });
    let layer = Layer::new(
        (w, h),
        LayerAttributes::named("heron"),
        Encoding::SMALL_LOSSLESS,
        channels,
    );
    let mut image = Image::from_layer(layer);
    let [r, g, b, wp] = SRGB_CHROMATICITIES;
    image.attributes.chromaticities = Some(attribute::Chromaticities {
        red: Vec2(r[0], r[1]),
        green: Vec2(g[0], g[1]),
        blue: Vec2(b[0], b[1]),
        white: Vec2(wp[0], wp[1]),
    });
    Staged::write(path, |tmp| {
        // Single-threaded compression keeps the bytes independent of scheduling.
        image
            .write()
            .non_parallel()
            .to_file(tmp)
            .map_err(|e| format!("cannot write EXR: {e}"))
    })
}
