//! OpenEXR output: float32 R, G, B in linear sRGB with the standard `chromaticities`
//! attribute (sRGB primaries, D65 white), so any reader knows the colour space.
//! Optionally the CIE XYZ channels X, Y, Z, and spectral channels in the layout of
//! Fichet, Pacanowski & Wilkie 2021 ("An OpenEXR Layout for Spectral Images", JCGT
//! 10(3)): one emissive channel `S0.<λ>nm` per bin (λ the bin centre, written with a
//! decimal comma as the paper specifies), the `spectralLayoutVersion` attribute "1.0"
//! and `emissiveUnits` "W.m^-2.sr^-1".
use super::{Film, Staged};
use crate::spectrum::color::SRGB_CHROMATICITIES;
use exr::prelude::*;
use std::path::Path;

/// Which channels go into the EXR besides R, G, B.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ExrChannels {
    /// Add X, Y, Z (CIE 1931, the film's convention).
    pub xyz: bool,
    /// Add the spectral S0 channels (when the film has spectral bins).
    pub spectral: bool,
}

/// The Fichet et al. 2021 channel name of an emissive bin centred at `lambda` nm.
pub fn spectral_channel_name(lambda: f32) -> String {
    format!("S0.{}nm", format!("{lambda:.6}").replace('.', ","))
}

/// Writes the EXR file; see [`stage_exr`] to write several outputs together.
pub fn write_exr(film: &Film, path: &Path, channels: ExrChannels) -> crate::Result<()> {
    stage_exr(film, path, channels)?.commit()
}

/// Writes the EXR file to a temporary file, to be committed later.
pub fn stage_exr(film: &Film, path: &Path, which: ExrChannels) -> crate::Result<Staged> {
    let (w, h) = (film.width as usize, film.height as usize);
    let rgb = film.linear_srgb();
    let plane = |f: &dyn Fn(usize) -> f32| FlatSamples::F32((0..w * h).map(f).collect());
    let mut list: SmallVec<[AnyChannel<FlatSamples>; 4]> = SmallVec::new();
    for (c, name) in ["R", "G", "B"].iter().enumerate() {
        list.push(AnyChannel::new(*name, plane(&|i| rgb[i][c])));
    }
    if which.xyz {
        for (c, name) in ["X", "Y", "Z"].iter().enumerate() {
            list.push(AnyChannel::new(*name, plane(&|i| film.xyz[i][c])));
        }
    }
    let mut layer_attrs = LayerAttributes::named("heron");
    if let (true, Some((bins, data))) = (which.spectral, &film.spectral) {
        for k in 0..bins.count {
            let name = spectral_channel_name(bins.centre(k));
            list.push(AnyChannel::new(
                name.as_str(),
                plane(&|i| data[i * bins.count + k]),
            ));
        }
        layer_attrs.other.insert(
            Text::from("spectralLayoutVersion"),
            attribute::AttributeValue::Text(Text::from("1.0")),
        );
        layer_attrs.other.insert(
            Text::from("emissiveUnits"),
            attribute::AttributeValue::Text(Text::from("W.m^-2.sr^-1")),
        );
    }
    let layer = Layer::new(
        (w, h),
        layer_attrs,
        Encoding::SMALL_LOSSLESS,
        AnyChannels::sort(list),
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
