//! OpenEXR output: float32 R, G, B in linear sRGB with the standard `chromaticities`
//! attribute (sRGB primaries, D65 white), so any reader knows the colour space.
//! Optionally the CIE XYZ channels X, Y, Z, and spectral channels in the layout of
//! Fichet, Pacanowski & Wilkie 2021 ("An OpenEXR Layout for Spectral Images", JCGT
//! 10(3)): one emissive channel `S0.<λ>nm` per bin (λ the bin centre, written with a
//! decimal comma as the paper specifies), the `spectralLayoutVersion` attribute "1.0"
//! and `emissiveUnits` "W.m^-2.sr^-1". With a variance estimate (`heron render
//! --variance`), the channels `variance.R`, `variance.G`, `variance.B`: the variance of
//! each pixel's R, G, B value (of the mean over its samples, not of one sample; the
//! layer `variance` in OpenEXR's `layer.channel` naming), which `heron compare` reads.
//! A polarised render adds the Stokes components `S1.R` … `S3.B` ([`STOKES_CHANNELS`]),
//! and with spectral bins Fichet et al.'s polarised layout: `S1.<λ>nm`, `S2.<λ>nm`,
//! `S3.<λ>nm` beside `S0.<λ>nm`, and the attribute `polarisationHandedness` "right"
//! (S3 > 0 is right-circular light, Collett's convention).
use super::Film;
use crate::files::Staged;
use crate::provenance::{Provenance, PREFIX};
use crate::spectrum::color::SRGB_CHROMATICITIES;
use exr::prelude::*;
use std::path::Path;

/// The names of the variance channels, for R, G and B.
pub const VARIANCE_CHANNELS: [&str; 3] = ["variance.R", "variance.G", "variance.B"];

/// The channels of S1, S2, S3 of a polarised render (R, G, B each, linear sRGB in the
/// camera's Stokes frame; R, G, B are S0), Mitsuba 3's `stokes` integrator's names.
pub const STOKES_CHANNELS: [[&str; 3]; 3] = [
    ["S1.R", "S1.G", "S1.B"],
    ["S2.R", "S2.G", "S2.B"],
    ["S3.R", "S3.G", "S3.B"],
];

/// Which channels go into the EXR besides R, G, B (and the variance channels, written
/// whenever the film has a variance estimate).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ExrChannels {
    /// Add X, Y, Z (CIE 1931, the film's convention).
    pub xyz: bool,
    /// Add the spectral S0 channels (when the film has spectral bins).
    pub spectral: bool,
}

/// The Fichet et al. 2021 channel name of an emissive bin centred at `lambda` nm.
pub fn spectral_channel_name(lambda: f32) -> String {
    stokes_channel_name(0, lambda)
}

/// The Fichet et al. 2021 channel name of Stokes component `k` (0–3) of a bin centred
/// at `lambda` nm.
pub fn stokes_channel_name(k: usize, lambda: f32) -> String {
    format!("S{k}.{}nm", format!("{lambda:.6}").replace('.', ","))
}

/// The channels of the EXR [`stage_exr`] writes for `film`, by name, each a plane of
/// `width × height` values row-major from the top-left: R, G, B (linear sRGB), then as
/// `which` and the film have them X, Y, Z, the variance channels, S1–S3 in linear sRGB,
/// the spectral S0 bins and their S1–S3. `heron view` shows a render in progress from
/// these, so that it sees the channels the finished file will have.
pub fn channel_planes(film: &Film, which: ExrChannels) -> Vec<(String, Vec<f32>)> {
    let n = film.width as usize * film.height as usize;
    let rgb = film.linear_srgb();
    let plane = |f: &dyn Fn(usize) -> f32| (0..n).map(f).collect::<Vec<f32>>();
    let mut list = Vec::new();
    for (c, name) in ["R", "G", "B"].iter().enumerate() {
        list.push((name.to_string(), plane(&|i| rgb[i][c])));
    }
    if which.xyz {
        for (c, name) in ["X", "Y", "Z"].iter().enumerate() {
            list.push((name.to_string(), plane(&|i| film.xyz[i][c])));
        }
    }
    if let Some(var) = &film.variance {
        for (c, name) in VARIANCE_CHANNELS.iter().enumerate() {
            list.push((name.to_string(), plane(&|i| var[i][c])));
        }
    }
    if let Some(stokes) = &film.stokes {
        // S1–S3 in linear sRGB through the film's matrix (linear, so signed XYZ gives
        // signed RGB); R, G, B are S0.
        let rgb: Vec<[[f32; 3]; 3]> = stokes
            .iter()
            .map(|s| s.map(crate::spectrum::color::xyz_to_linear_srgb))
            .collect();
        for (k, names) in STOKES_CHANNELS.iter().enumerate() {
            for (c, name) in names.iter().enumerate() {
                list.push((name.to_string(), plane(&|i| rgb[i][k][c])));
            }
        }
    }
    if let (true, Some((bins, data))) = (which.spectral, &film.spectral) {
        for k in 0..bins.count {
            let name = spectral_channel_name(bins.centre(k));
            list.push((name, plane(&|i| data[i * bins.count + k])));
        }
        if let Some(st) = &film.stokes_spectral {
            let nb = bins.count;
            for k in 1..4 {
                for b in 0..nb {
                    let name = stokes_channel_name(k, bins.centre(b));
                    list.push((name, plane(&|i| st[(3 * i + k - 1) * nb + b])));
                }
            }
        }
    }
    list
}

/// Writes the EXR file to a temporary file, to be committed later. `provenance` goes
/// into the header as text attributes `heron.<key>` ([`crate::provenance`]).
pub fn stage_exr(
    film: &Film,
    path: &Path,
    which: ExrChannels,
    provenance: &Provenance,
) -> crate::Result<Staged> {
    let (w, h) = (film.width as usize, film.height as usize);
    let list: SmallVec<[AnyChannel<FlatSamples>; 4]> = channel_planes(film, which)
        .into_iter()
        .map(|(name, plane)| AnyChannel::new(name.as_str(), FlatSamples::F32(plane)))
        .collect();
    let mut layer_attrs = LayerAttributes::named("heron");
    for (k, v) in &provenance.0 {
        layer_attrs.other.insert(
            Text::from(format!("{PREFIX}{k}").as_str()),
            attribute::AttributeValue::Text(Text::from(v.as_str())),
        );
    }
    if let (true, Some(_)) = (which.spectral, &film.spectral) {
        layer_attrs.other.insert(
            Text::from("spectralLayoutVersion"),
            attribute::AttributeValue::Text(Text::from("1.0")),
        );
        layer_attrs.other.insert(
            Text::from("emissiveUnits"),
            attribute::AttributeValue::Text(Text::from("W.m^-2.sr^-1")),
        );
        if film.stokes_spectral.is_some() {
            layer_attrs.other.insert(
                Text::from("polarisationHandedness"),
                attribute::AttributeValue::Text(Text::from("right")),
            );
        }
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
        let mut bytes = std::io::Cursor::new(Vec::new());
        image
            .write()
            .non_parallel()
            .to_buffered(&mut bytes)
            .map_err(|e| format!("cannot write EXR: {e}"))?;
        let mut bytes = bytes.into_inner();
        sort_header_attributes(&mut bytes)?;
        std::fs::write(tmp, bytes).map_err(|e| format!("cannot write EXR: {e}"))
    })
}

/// Sorts the attributes of a single-part EXR header by name, in place. The exr crate
/// keeps custom attributes in a `HashMap` and writes them in its (per-process random)
/// order, which would make identical renders differ in their header bytes. Attribute
/// order is free in OpenEXR, and sorting keeps the header's length, so the offset table
/// and pixel data that follow stay valid. Layout (OpenEXR file layout, "Header"): magic
/// and version (8 bytes), then attributes `name\0 type\0 size:i32le value[size]`, then a
/// zero byte.
fn sort_header_attributes(bytes: &mut [u8]) -> std::result::Result<(), String> {
    let bad = || "cannot write EXR: unexpected header layout".to_string();
    let start = 8;
    let mut at = start;
    let mut attrs: Vec<(Vec<u8>, std::ops::Range<usize>)> = Vec::new();
    let cstr = |from: usize| -> Option<usize> {
        bytes[from..].iter().position(|&b| b == 0).map(|n| from + n)
    };
    loop {
        if *bytes.get(at).ok_or_else(bad)? == 0 {
            break;
        }
        let name_end = cstr(at).ok_or_else(bad)?;
        let type_end = cstr(name_end + 1).ok_or_else(bad)?;
        let size_at = type_end + 1;
        let size: [u8; 4] = bytes
            .get(size_at..size_at + 4)
            .ok_or_else(bad)?
            .try_into()
            .unwrap();
        let end = size_at + 4 + i32::from_le_bytes(size).max(0) as usize;
        if end > bytes.len() {
            return Err(bad());
        }
        attrs.push((bytes[at..name_end].to_vec(), at..end));
        at = end;
    }
    let region: Vec<u8> = bytes[start..at].to_vec();
    attrs.sort_by(|a, b| a.0.cmp(&b.0));
    let mut out = Vec::with_capacity(region.len());
    for (_, r) in &attrs {
        out.extend_from_slice(&region[r.start - start..r.end - start]);
    }
    bytes[start..at].copy_from_slice(&out);
    Ok(())
}

/// The `heron.*` text attributes of the EXR at `path` (the provenance `heron info`
/// prints), sorted by key. Errors name the file.
pub fn read_provenance(path: &Path) -> crate::Result<Vec<(String, String)>> {
    let meta =
        exr::meta::MetaData::read_from_file(path, false).map_err(|e| crate::HeronError::Io {
            path: path.to_path_buf(),
            message: format!("cannot read it as OpenEXR: {e}"),
        })?;
    let mut out = Vec::new();
    for h in &meta.headers {
        for (k, v) in h
            .own_attributes
            .other
            .iter()
            .chain(&h.shared_attributes.other)
        {
            let key = k.to_string();
            if let (Some(name), attribute::AttributeValue::Text(t)) = (key.strip_prefix(PREFIX), v)
            {
                out.push((name.to_string(), t.to_string()));
            }
        }
    }
    out.sort();
    Ok(out)
}

/// The R, G, B channels of the EXR at `path` (the first layer that has them; half,
/// float or integer samples), as heron writes them: linear sRGB. Returns the width, the
/// height and the pixels row-major from the top-left. A file whose `chromaticities`
/// attribute names other primaries or another white point is refused (no attribute means
/// Rec. 709 primaries and D65, sRGB's, as OpenEXR specifies). Errors name the file.
pub fn read_linear_srgb(path: &Path) -> crate::Result<(u32, u32, Vec<[f32; 3]>)> {
    let err = |message: String| crate::HeronError::Io {
        path: path.to_path_buf(),
        message,
    };
    let image = read_first_rgba_layer_from_file(
        path,
        |size, _| (size.width(), vec![[0.0f32; 3]; size.area()]),
        |(w, px): &mut (usize, Vec<[f32; 3]>), at, (r, g, b, _): (f32, f32, f32, f32)| {
            px[at.y() * *w + at.x()] = [r, g, b];
        },
    )
    .map_err(|e| err(format!("cannot read R, G, B from it as OpenEXR: {e}")))?;
    if let Some(c) = image.attributes.chromaticities {
        let [r, g, b, wp] = SRGB_CHROMATICITIES;
        let got = [c.red, c.green, c.blue, c.white];
        let same = [r, g, b, wp]
            .iter()
            .zip(&got)
            .all(|(w, v)| (w[0] - v.0).abs() < 1e-3 && (w[1] - v.1).abs() < 1e-3);
        if !same {
            return Err(err(format!(
                "expected linear sRGB (chromaticities R {r:?}, G {g:?}, B {b:?}, white {wp:?}), \
                 the file has R ({}, {}), G ({}, {}), B ({}, {}), white ({}, {})",
                c.red.0, c.red.1, c.green.0, c.green.1, c.blue.0, c.blue.1, c.white.0, c.white.1
            )));
        }
    }
    let size = image.layer_data.size;
    let (w, h) = (size.width(), size.height());
    if w == 0 || h == 0 || w > u32::MAX as usize || h > u32::MAX as usize {
        return Err(err(format!("expected a non-empty image, got {w}×{h}")));
    }
    let (_, px) = image.layer_data.channel_data.pixels;
    Ok((w as u32, h as u32, px))
}
