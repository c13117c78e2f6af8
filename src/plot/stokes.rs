//! False-colour previews of a polarised render (`[render] polarization`): the degree
//! and the angle of linear polarisation of each pixel, as PNG files with a colour-bar
//! legend, for looking at a render without an EXR viewer that knows Stokes channels.
//!
//! # What is shown
//!
//! Both images use the luminance (CIE Y, index 1) of each pixel's Stokes components:
//! S0 is the film's `xyz`, S1 and S2 are the first two of `Film::stokes` (S3, circular
//! polarisation, is not shown). The Stokes frame is the camera's
//! (`Camera::stokes_x`, Collett's convention as in `optics::mueller`): x̂ is the
//! picture's horizontal (rightward) and ŷ its up, so S1 > 0 is light polarised
//! horizontally in the picture and S2 > 0 light polarised at +45°, counter-clockwise
//! from the horizontal as the viewer sees the picture.
//!
//! * **Degree of linear polarisation**, DoLP = √(S1² + S2²) / S0, clamped to [0, 1]
//!   (Monte Carlo noise can push the estimate past 1), and 0 where S0 ≤ 0 or anything is
//!   not finite (a black pixel has no polarisation to speak of). Coloured with viridis
//!   (`VIRIDIS`), a perceptually uniform sequential map: equal steps in DoLP look
//!   like equal steps in colour, and lightness rises monotonically, so the image also
//!   reads correctly in grey.
//! * **Angle of linear polarisation**, AoLP = ½ atan2(S2, S1) in (−90°, 90°] (Born &
//!   Wolf, *Principles of Optics*, § 1.4.2: tan 2ψ = S2/S1), the angle of the major
//!   axis of the polarisation ellipse from the picture's horizontal, counter-clockwise
//!   as the viewer sees it. An axis has no direction, so the angle has period 180°
//!   and is coloured with a hue wheel of that period (`hue_wheel`): 0° (horizontal)
//!   red, 45° yellow-green, ±90° (vertical) cyan, −45° violet; −90° and +90° are the
//!   same colour. The wheel's value (HSV brightness) is the DoLP, so unpolarised pixels
//!   are black and only polarised light shows its angle: the angle of weakly polarised
//!   light is mostly noise, and a full-brightness hue there would hide that. (Mapping
//!   the angle to hue goes back to Tyo, Rowe, Pugh & Engheta 1998, "Colorimetric
//!   representations for use with polarization-difference imaging of objects in
//!   scattering media", JOSA A 15(2), 367–374, who put the DoLP in saturation and the
//!   intensity in value; a preview without the intensity commonly puts the DoLP in
//!   value instead, as here.) The HSV wheel is not perceptually uniform (its
//!   yellow and cyan look lighter than its red and blue); it is used because it is the
//!   convention readers of such images expect.
//!
//! # The files
//!
//! Each PNG holds the image at its own resolution, one image pixel per PNG pixel,
//! centred on a white canvas at least 320 pixels (`MIN_WIDTH`) wide so that the legend
//! stays readable for small images, with a legend strip below it: the colour bar, its
//! ticks and labels and a title, drawn with plotters in the embedded DejaVu Sans (see
//! the parent module), scaled with the canvas width. The strip is below the image for
//! every aspect ratio, tall images included: that keeps the colour bar horizontal
//! and the title's text upright. The bytes depend only on the film (no clock, no
//! randomness; `libm` for atan2 and hypot rather than the platform's C library).
use super::{check_path, plot_err, register_font, rgb, FAMILY};
use crate::files::Staged;
use crate::film::Film;
use crate::{HeronError, Result};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;

/// The narrowest canvas: an image narrower than this is centred on a white canvas this
/// wide, so that the legend's title and labels fit at a readable size.
const MIN_WIDTH: u32 = 320;

/// Viridis (van der Walt & Smith, matplotlib's default colour map since 2.0, 2015: "A
/// Better Default Colormap for Matplotlib", SciPy 2015; the 256-entry table is
/// `_viridis_data` in matplotlib's `lib/matplotlib/_cm_listed.py`, CC0) at 17 equally
/// spaced positions 0, 1/16, …, 1: the table linearly interpolated there and rounded
/// to 8-bit sRGB. Linear interpolation between these anchors in sRGB stays within
/// 6/255 of the full table (the largest deviation is in the yellow-green end, where
/// the map curves most).
const VIRIDIS: [[u8; 3]; 17] = [
    [68, 1, 84],
    [72, 24, 106],
    [71, 45, 123],
    [66, 64, 134],
    [59, 82, 139],
    [51, 99, 141],
    [44, 114, 142],
    [38, 129, 142],
    [33, 144, 140],
    [31, 159, 136],
    [40, 174, 128],
    [62, 188, 116],
    [93, 201, 99],
    [130, 211, 76],
    [171, 220, 50],
    [213, 226, 26],
    [253, 231, 37],
];

/// Viridis at `t` in [0, 1] (clamped), linearly interpolated in sRGB between the
/// anchors of [`VIRIDIS`].
fn viridis(t: f64) -> [u8; 3] {
    let x = t.clamp(0.0, 1.0) * 16.0;
    // 15 at most, so that t = 1 interpolates to the last anchor with weight 1.
    let k = (x.floor() as usize).min(15);
    let f = x - k as f64;
    let (a, b) = (VIRIDIS[k], VIRIDIS[k + 1]);
    std::array::from_fn(|i| (a[i] as f64 + f * (b[i] as f64 - a[i] as f64)).round() as u8)
}

/// The AoLP colour of an axis at `angle_deg` (any real; period 180°) with HSV value
/// `value` in [0, 1] (clamped) and full saturation: hue = 2 × angle, so 0° is red
/// (255, 0, 0), 45° yellow-green (128, 255, 0), ±90° cyan (0, 255, 255) and −45°
/// violet (128, 0, 255) at value 1. Standard HSV to RGB (Smith 1978, "Color gamut
/// transform pairs", SIGGRAPH '78), on 8-bit sRGB.
fn hue_wheel(angle_deg: f64, value: f64) -> [u8; 3] {
    let v = if value.is_finite() {
        value.clamp(0.0, 1.0)
    } else {
        0.0
    };
    // The fraction of the 180° period, in [0, 1): −90° and 90° both give ½.
    let turns = if angle_deg.is_finite() {
        (angle_deg / 180.0).rem_euclid(1.0)
    } else {
        0.0
    };
    let h6 = turns * 6.0;
    // rem_euclid can round up to exactly 1.0 for tiny negative angles: sector 6 is 0.
    let sector = (h6.floor() as usize) % 6;
    let f = h6 - h6.floor();
    let (up, down) = (v * f, v * (1.0 - f));
    let c = match sector {
        0 => [v, up, 0.0],
        1 => [down, v, 0.0],
        2 => [0.0, v, up],
        3 => [0.0, down, v],
        4 => [up, 0.0, v],
        _ => [v, 0.0, down],
    };
    c.map(|x| (x * 255.0).round() as u8)
}

/// (DoLP in [0, 1], AoLP in degrees in (−90, 90]) of one pixel's Y Stokes components;
/// (0, 0) where S0 ≤ 0 or a value is not finite.
fn polarisation(s0: f64, s1: f64, s2: f64) -> (f64, f64) {
    if !(s0 > 0.0 && s0.is_finite()) {
        return (0.0, 0.0);
    }
    let d = libm::hypot(s1, s2) / s0;
    if !d.is_finite() {
        return (0.0, 0.0);
    }
    let mut a = 0.5 * libm::atan2(s2, s1).to_degrees();
    // atan2(−0, −1) = −π: keep the half-open range, (−90°, 90°].
    if a <= -90.0 {
        a += 180.0;
    }
    (d.min(1.0), a)
}

/// Each pixel's (DoLP, AoLP), in the film's order; pixels without Stokes components
/// (a film without them, or a shorter list) count as unpolarised.
fn per_pixel(film: &Film) -> impl Iterator<Item = (f64, f64)> + '_ {
    film.xyz.iter().enumerate().map(move |(i, xyz)| {
        let [s1, s2, _] = film
            .stokes
            .as_ref()
            .and_then(|s| s.get(i))
            .map_or([0.0; 3], |s| s.map(|c| c[1]));
        polarisation(xyz[1] as f64, s1 as f64, s2 as f64)
    })
}

/// The DoLP image without its legend: one sRGB colour per pixel of `film`, row-major
/// from the top-left like `film.xyz` (`film.width` × `film.height`), viridis of the
/// DoLP. A film without Stokes components gives DoLP 0 everywhere.
pub fn dolp_rgb(film: &Film) -> Vec<[u8; 3]> {
    per_pixel(film).map(|(d, _)| viridis(d)).collect()
}

/// The AoLP image without its legend, in the same layout as [`dolp_rgb`]: the hue
/// wheel at the AoLP with value = DoLP. A film without Stokes components is black.
pub fn aolp_rgb(film: &Film) -> Vec<[u8; 3]> {
    per_pixel(film).map(|(d, a)| hue_wheel(a, d)).collect()
}

/// Which legend to draw.
#[derive(Clone, Copy)]
enum Kind {
    Dolp,
    Aolp,
}

impl Kind {
    /// The legend's title in phrases, where a narrow legend may break it.
    fn title(self) -> &'static [&'static str] {
        match self {
            Kind::Dolp => &["degree of linear polarisation"],
            Kind::Aolp => &["angle of linear polarisation", "(hue; brightness = DoLP)"],
        }
    }

    fn labels(self) -> [&'static str; 5] {
        match self {
            Kind::Dolp => ["0", "0.25", "0.5", "0.75", "1"],
            // U+2212 minus signs, as typeset, not hyphens.
            Kind::Aolp => ["\u{2212}90°", "\u{2212}45°", "0°", "45°", "90°"],
        }
    }

    /// The colour bar's colour at `t` in [0, 1] of its length.
    fn bar(self, t: f64) -> [u8; 3] {
        match self {
            Kind::Dolp => viridis(t),
            // At full value: the legend shows the hues, the image's brightness is DoLP.
            Kind::Aolp => hue_wheel(-90.0 + 180.0 * t, 1.0),
        }
    }
}

/// Where everything goes on the canvas, pixels from its top-left.
#[derive(Clone, Debug, PartialEq)]
struct Layout {
    width: u32,
    height: u32,
    /// The image's left column (it starts at row 0).
    image_x: u32,
    /// The colour bar: left, top, width, height; column i shows t = i / (width − 1),
    /// so its first and last columns are the map's ends.
    bar: [i32; 4],
    title_lines: Vec<String>,
    /// The top of the first title line and the spacing of lines.
    title_y: i32,
    title_line: i32,
    title_px: f64,
    tick_len: i32,
    label_y: i32,
    label_px: f64,
}

/// Greedy wrap of `parts` (phrases, joined by spaces) into lines at most `max` pixels
/// wide in `font`: phrases are kept whole where they fit on a line of their own, so a
/// title breaks between its phrases; a longer phrase is broken between words (a word
/// wider than `max` gets a line of its own).
fn wrap(parts: &[&str], font: &FontDesc<'_>, max: u32) -> Result<Vec<String>> {
    let fits = |s: &str| -> Result<bool> { Ok(font.box_size(s).map_err(plot_err)?.0 <= max) };
    let mut units: Vec<&str> = Vec::new();
    for part in parts {
        if fits(part)? {
            units.push(part);
        } else {
            units.extend(part.split(' '));
        }
    }
    let mut lines: Vec<String> = Vec::new();
    for unit in units {
        if let Some(last) = lines.last_mut() {
            let joined = format!("{last} {unit}");
            if fits(&joined)? {
                *last = joined;
                continue;
            }
        }
        lines.push(unit.to_string());
    }
    Ok(lines)
}

fn layout(width: u32, height: u32, kind: Kind) -> Result<Layout> {
    register_font()?;
    let cw = width.max(MIN_WIDTH);
    // Sizes below are for a 640-pixel canvas and grow with wider ones (up to 2.5×), so
    // that the legend keeps its proportion to a large image; narrower canvases keep
    // the 640-pixel sizes, which are the smallest that read well.
    let s = (cw as f64 / 640.0).clamp(1.0, 2.5);
    let px = |v: f64| (v * s).round() as i32;
    let title_px = 15.0 * s;
    let label_px = 13.0 * s;
    let side = px(28.0);
    let font = FontDesc::new(FontFamily::Name(FAMILY), title_px, FontStyle::Normal);
    let title_lines = wrap(kind.title(), &font, cw.saturating_sub(2 * px(8.0) as u32))?;
    let title_line = (title_px * 1.3).round() as i32;
    let title_y = height as i32 + px(10.0);
    let bar_w = (cw as i32 - 2 * side).min(px(480.0));
    let bar_h = px(16.0);
    let bar_y = title_y + title_line * title_lines.len() as i32 + px(6.0);
    let tick_len = px(5.0);
    let label_y = bar_y + bar_h + tick_len + px(3.0);
    let bottom = label_y + (label_px * 1.3).round() as i32 + px(8.0);
    Ok(Layout {
        width: cw,
        height: bottom as u32,
        image_x: (cw - width) / 2,
        bar: [(cw as i32 - bar_w) / 2, bar_y, bar_w, bar_h],
        title_lines,
        title_y,
        title_line,
        title_px,
        tick_len,
        label_y,
        label_px,
    })
}

/// The image `pixels` (`width` × `height`) with `kind`'s legend, as RGB bytes of a
/// canvas [`layout`] gives.
fn draw(width: u32, height: u32, pixels: &[[u8; 3]], kind: Kind) -> Result<(Layout, Vec<u8>)> {
    let l = layout(width, height, kind)?;
    let (cw, ch) = (l.width as usize, l.height as usize);
    let mut buf = vec![255u8; cw * ch * 3];
    // The image is copied, not drawn: its pixels stay exactly the colours computed.
    for (row, line) in pixels.chunks(width.max(1) as usize).enumerate() {
        let start = (row * cw + l.image_x as usize) * 3;
        for (i, c) in line.iter().enumerate() {
            buf[start + 3 * i..start + 3 * i + 3].copy_from_slice(c);
        }
    }
    {
        let root = BitMapBackend::with_buffer(&mut buf, (l.width, l.height)).into_drawing_area();
        let [x0, y0, bw, bh] = l.bar;
        let t_of = |i: i32| {
            if bw > 1 {
                i as f64 / (bw - 1) as f64
            } else {
                0.0
            }
        };
        // Pixel by pixel: each column exactly the map's colour at its t.
        for i in 0..bw {
            let c = rgb(kind.bar(t_of(i)));
            for y in y0..y0 + bh {
                root.draw_pixel((x0 + i, y), &c).map_err(plot_err)?;
            }
        }
        // A thin frame outside the bar, so that its ends show against white.
        let frame = RGBColor(120, 120, 120);
        root.draw(&Rectangle::new(
            [(x0 - 1, y0 - 1), (x0 + bw, y0 + bh)],
            frame.stroke_width(1),
        ))
        .map_err(plot_err)?;
        let label_font = FontDesc::new(FontFamily::Name(FAMILY), l.label_px, FontStyle::Normal)
            .color(&BLACK)
            .pos(Pos::new(HPos::Center, VPos::Top));
        for (k, label) in kind.labels().iter().enumerate() {
            let x = x0 + ((bw - 1) as f64 * k as f64 / 4.0).round() as i32;
            root.draw(&PathElement::new(
                vec![(x, y0 + bh), (x, y0 + bh + l.tick_len)],
                BLACK.stroke_width(1),
            ))
            .map_err(plot_err)?;
            root.draw(&Text::new(*label, (x, l.label_y), label_font.clone()))
                .map_err(plot_err)?;
        }
        let title_font = FontDesc::new(FontFamily::Name(FAMILY), l.title_px, FontStyle::Normal)
            .color(&BLACK)
            .pos(Pos::new(HPos::Center, VPos::Top));
        for (n, line) in l.title_lines.iter().enumerate() {
            let y = l.title_y + l.title_line * n as i32;
            root.draw(&Text::new(
                line.as_str(),
                (l.width as i32 / 2, y),
                title_font.clone(),
            ))
            .map_err(plot_err)?;
        }
        root.present().map_err(plot_err)?;
    }
    Ok((l, buf))
}

fn png(width: u32, height: u32, rgb: Vec<u8>) -> Result<Vec<u8>> {
    let img = image::RgbImage::from_raw(width, height, rgb)
        .ok_or_else(|| plot_err("buffer size does not match the picture"))?;
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png)
        .map_err(plot_err)?;
    Ok(out.into_inner())
}

const FLAG: &str = "polarisation preview";

/// Writes the DoLP and AoLP previews of a polarised render to `dolp_path` and
/// `aolp_path` (the CLI names them `<stem>.dolp.png` and `<stem>.aolp.png`), each the
/// image with its legend (module documentation). Both PNGs are encoded before either
/// file is touched, then staged and renamed into place together, so an error leaves
/// neither file (short of a failure between the two renames).
///
/// Errors: the film has no Stokes components (not a polarised render), the film's
/// lists do not match its size, a path does not end in `.png` or its folder does not
/// exist, the two paths are the same, or a file cannot be written.
pub fn write_previews(film: &Film, dolp_path: &Path, aolp_path: &Path) -> Result<()> {
    let Some(stokes) = &film.stokes else {
        return Err(HeronError::Invalid(
            "polarisation previews need a polarised render: the film has no Stokes \
             components (render with --polarization or [render] polarization = true)"
                .into(),
        ));
    };
    let n = film.width as usize * film.height as usize;
    if film.xyz.len() != n || stokes.len() != n {
        return Err(HeronError::Invalid(format!(
            "polarisation previews: the film is {} × {} pixels but has {} colours and {} \
             Stokes vectors",
            film.width,
            film.height,
            film.xyz.len(),
            stokes.len()
        )));
    }
    check_path(dolp_path, FLAG)?;
    check_path(aolp_path, FLAG)?;
    if dolp_path == aolp_path {
        return Err(HeronError::Invalid(format!(
            "{FLAG}: the DoLP and AoLP images would both be written to {}",
            dolp_path.display()
        )));
    }
    let encode = |pixels: Vec<[u8; 3]>, kind: Kind| -> Result<Vec<u8>> {
        let (l, buf) = draw(film.width, film.height, &pixels, kind)?;
        png(l.width, l.height, buf)
    };
    let dolp = encode(dolp_rgb(film), Kind::Dolp)?;
    let aolp = encode(aolp_rgb(film), Kind::Aolp)?;
    let stage = |path: &Path, bytes: &[u8]| {
        Staged::write(path, |tmp| {
            std::fs::write(tmp, bytes).map_err(|e| format!("{FLAG}: cannot write the PNG: {e}"))
        })
    };
    // Both staged before either is renamed: if the second cannot be written, the first
    // is dropped uncommitted and its temporary file removed.
    let dolp = stage(dolp_path, &dolp)?;
    let aolp = stage(aolp_path, &aolp)?;
    dolp.commit()?;
    aolp.commit()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A film of `pixels` (S0, S1, S2, S3 as luminance; X and Z set to other values so
    /// that a mix-up of components shows), `width` wide.
    fn film(width: u32, pixels: &[[f32; 4]]) -> Film {
        let height = pixels.len() as u32 / width;
        let xyz3 = |y: f32| [0.5 * y + 7.0, y, -3.0 * y + 1.0];
        Film {
            width,
            height,
            xyz: pixels.iter().map(|p| xyz3(p[0])).collect(),
            spectral: None,
            variance: None,
            stokes_spectral: None,
            stokes: Some(
                pixels
                    .iter()
                    .map(|p| [xyz3(p[1]), xyz3(p[2]), xyz3(p[3])])
                    .collect(),
            ),
        }
    }

    /// The hue of an sRGB colour in degrees [0, 360), HSV's.
    fn hsv_hue(c: [u8; 3]) -> f64 {
        let [r, g, b] = c.map(|v| v as f64);
        let max = r.max(g).max(b);
        let d = max - r.min(g).min(b);
        assert!(d > 0.0, "{c:?} has no hue");
        let h = if max == r {
            (g - b) / d
        } else if max == g {
            2.0 + (b - r) / d
        } else {
            4.0 + (r - g) / d
        };
        (h * 60.0).rem_euclid(360.0)
    }

    const UNPOLARISED: [f32; 4] = [1.0, 0.0, 0.0, 0.0];
    const HORIZONTAL: [f32; 4] = [1.0, 1.0, 0.0, 0.0];
    const PLUS_45: [f32; 4] = [1.0, 0.0, 1.0, 0.0];
    const VERTICAL: [f32; 4] = [1.0, -1.0, 0.0, 0.0];
    const MINUS_45: [f32; 4] = [1.0, 0.0, -1.0, 0.0];

    #[test]
    fn known_stokes_vectors_give_the_maps_ends_and_the_wheels_hues() {
        let f = film(3, &[UNPOLARISED, HORIZONTAL, PLUS_45]);
        assert_eq!(
            dolp_rgb(&f),
            vec![VIRIDIS[0], VIRIDIS[16], VIRIDIS[16]],
            "DoLP 0, 1, 1"
        );
        assert_eq!(VIRIDIS[0], [68, 1, 84]);
        assert_eq!(VIRIDIS[16], [253, 231, 37]);
        let a = aolp_rgb(&f);
        assert_eq!(a[0], [0, 0, 0], "unpolarised: value 0");
        assert_eq!(a[1], hue_wheel(0.0, 1.0));
        assert_eq!(a[2], hue_wheel(45.0, 1.0));
        // The wheel itself: hue = 2 × angle, horizontal red.
        assert_eq!(a[1], [255, 0, 0]);
        assert_eq!(a[2], [128, 255, 0]);
    }

    #[test]
    fn the_wheel_has_a_period_of_180_degrees() {
        let f = film(4, &[HORIZONTAL, VERTICAL, PLUS_45, MINUS_45]);
        let a = aolp_rgb(&f);
        // The hue angle is twice the axis angle: axes 90° apart are half a turn apart.
        let axis = |c: [u8; 3]| hsv_hue(c) / 2.0;
        assert_eq!((axis(a[1]) - axis(a[0])).rem_euclid(180.0), 90.0);
        // 45° and 135° to within the 8-bit rounding of (128, 255, 0) and (128, 0, 255).
        assert!(((axis(a[2]) - axis(a[0])).rem_euclid(180.0) - 45.0).abs() < 0.1);
        assert!(((axis(a[3]) - axis(a[0])).rem_euclid(180.0) - 135.0).abs() < 0.1);
        assert_eq!(a[1], hue_wheel(90.0, 1.0));
        assert_eq!(a[1], [0, 255, 255]);
        assert_eq!(hue_wheel(-90.0, 1.0), hue_wheel(90.0, 1.0));
        assert_eq!(hue_wheel(-45.0, 1.0), hue_wheel(135.0, 1.0));
        assert_eq!(hue_wheel(-1e-300, 1.0), hue_wheel(0.0, 1.0));
        // Vertical with S2 = −0 (atan2 gives −π) is the same colour as with S2 = +0.
        assert_eq!(polarisation(1.0, -1.0, -0.0), (1.0, 90.0));
        assert_eq!(polarisation(1.0, -1.0, 0.0), (1.0, 90.0));
        // Counter-clockwise: S2 > 0 is +45°.
        assert_eq!(polarisation(1.0, 0.0, 1.0), (1.0, 45.0));
    }

    #[test]
    fn partial_polarisation_scales_dolp_and_brightness() {
        // S0 = 2, S1 = 1: half polarised; S1 = 3 S0 is noise and clamps to 1.
        let f = film(2, &[[2.0, 1.0, 0.0, 0.5], [1.0, 3.0, 0.0, 0.0]]);
        assert_eq!(dolp_rgb(&f), vec![VIRIDIS[8], VIRIDIS[16]]);
        assert_eq!(aolp_rgb(&f), vec![[128, 0, 0], [255, 0, 0]]);
        // S3 does not count: circular light has no linear polarisation.
        let f = film(1, &[[1.0, 0.0, 0.0, 1.0]]);
        assert_eq!(dolp_rgb(&f), vec![VIRIDIS[0]]);
        assert_eq!(aolp_rgb(&f), vec![[0, 0, 0]]);
        assert_eq!(viridis(0.5), VIRIDIS[8]);
        assert_eq!(viridis(-1.0), VIRIDIS[0]);
        assert_eq!(viridis(2.0), VIRIDIS[16]);
    }

    #[test]
    fn zero_negative_and_non_finite_s0_give_dolp_0() {
        let f = film(
            5,
            &[
                [0.0, 0.3, 0.2, 0.0],
                [0.0, 0.0, 0.0, 0.0],
                [-1.0, 0.5, 0.0, 0.0],
                [f32::NAN, 0.5, 0.0, 0.0],
                [1.0, f32::INFINITY, 0.0, 0.0],
            ],
        );
        assert_eq!(dolp_rgb(&f), vec![VIRIDIS[0]; 5]);
        assert_eq!(aolp_rgb(&f), vec![[0, 0, 0]; 5]);
        // No Stokes at all: unpolarised.
        let mut f = film(2, &[HORIZONTAL, PLUS_45]);
        f.stokes = None;
        assert_eq!(dolp_rgb(&f), vec![VIRIDIS[0]; 2]);
        assert_eq!(aolp_rgb(&f), vec![[0, 0, 0]; 2]);
    }

    #[test]
    fn the_legend_shows_the_maps_ends_and_wraps_for_narrow_canvases() {
        let f = film(3, &[UNPOLARISED, HORIZONTAL, PLUS_45]);
        for kind in [Kind::Dolp, Kind::Aolp] {
            let pixels = match kind {
                Kind::Dolp => dolp_rgb(&f),
                Kind::Aolp => aolp_rgb(&f),
            };
            let (l, buf) = draw(3, 1, &pixels, kind).unwrap();
            assert_eq!(l.width, MIN_WIDTH);
            assert_eq!(buf.len(), (l.width * l.height * 3) as usize);
            let at = |x: i32, y: i32| {
                let i = ((y as u32 * l.width + x as u32) * 3) as usize;
                [buf[i], buf[i + 1], buf[i + 2]]
            };
            // The image, centred in row 0, its neighbours white.
            for (i, c) in pixels.iter().enumerate() {
                assert_eq!(at(l.image_x as i32 + i as i32, 0), *c);
            }
            assert_eq!(at(l.image_x as i32 - 1, 0), [255; 3]);
            assert_eq!(at(l.image_x as i32 + 3, 0), [255; 3]);
            let [x0, y0, bw, bh] = l.bar;
            let mid = y0 + bh / 2;
            assert_eq!(at(x0, mid), kind.bar(0.0));
            assert_eq!(at(x0 + bw - 1, mid), kind.bar(1.0));
            assert!(bw >= 200 && l.title_px >= 15.0 && l.label_px >= 13.0);
            // Some title text is drawn (dark pixels above the bar).
            let dark = (l.title_y..y0 - 1)
                .flat_map(|y| (0..l.width as i32).map(move |x| (x, y)))
                .filter(|&(x, y)| at(x, y).iter().all(|&v| v < 100))
                .count();
            assert!(dark > 50, "{dark}");
        }
        assert_eq!(layout(3, 1, Kind::Dolp).unwrap().title_lines.len(), 1);
        // The long AoLP title does not fit 320 pixels on one line; on a wide canvas it does.
        let narrow = layout(3, 1, Kind::Aolp).unwrap();
        assert_eq!(narrow.title_lines.len(), 2, "{:?}", narrow.title_lines);
        assert_eq!(narrow.title_lines, Kind::Aolp.title());
        assert_eq!(layout(900, 10, Kind::Aolp).unwrap().title_lines.len(), 1);
        // A wide image keeps its width and is not shifted.
        let wide = layout(1000, 5, Kind::Dolp).unwrap();
        assert_eq!((wide.width, wide.image_x), (1000, 0));
    }

    #[test]
    fn write_previews_writes_two_decodable_pngs_with_legends() {
        let dir = tempfile::tempdir().unwrap();
        let (d, a) = (dir.path().join("x.dolp.png"), dir.path().join("x.aolp.png"));
        let pixels: Vec<[f32; 4]> = (0..15)
            .map(|i| {
                let t = i as f32 / 15.0 * std::f32::consts::PI;
                [1.0, t.cos() * 0.8, t.sin() * 0.8, 0.0]
            })
            .collect();
        let f = film(5, &pixels);
        write_previews(&f, &d, &a).unwrap();
        for (path, want) in [(&d, dolp_rgb(&f)), (&a, aolp_rgb(&f))] {
            let img = image::open(path).unwrap().to_rgb8();
            assert!(
                img.width() >= MIN_WIDTH && img.height() > 3 + 40,
                "{path:?}"
            );
            let x0 = (img.width() - 5) / 2;
            for (i, c) in want.iter().enumerate() {
                let (x, y) = (x0 + i as u32 % 5, i as u32 / 5);
                assert_eq!(img.get_pixel(x, y).0, *c, "{path:?} pixel {i}");
            }
        }
        // The same film gives the same bytes.
        let first = (std::fs::read(&d).unwrap(), std::fs::read(&a).unwrap());
        write_previews(&f, &d, &a).unwrap();
        assert_eq!(
            first,
            (std::fs::read(&d).unwrap(), std::fs::read(&a).unwrap())
        );
        assert_ne!(first.0, first.1);
        // Only the two files: no temporary file left behind.
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
    }

    #[test]
    fn write_previews_refuses_unpolarised_films_and_leaves_no_file_on_error() {
        let dir = tempfile::tempdir().unwrap();
        let (d, a) = (dir.path().join("y.dolp.png"), dir.path().join("y.aolp.png"));
        let mut f = film(1, &[HORIZONTAL]);
        f.stokes = None;
        let e = write_previews(&f, &d, &a).unwrap_err().to_string();
        assert!(e.contains("no Stokes components"), "{e}");
        assert!(!e.contains('\n'), "{e}");
        let f = film(1, &[HORIZONTAL]);
        let missing = dir.path().join("no-such-folder").join("y.aolp.png");
        let e = write_previews(&f, &d, &missing).unwrap_err().to_string();
        assert!(e.contains("does not exist"), "{e}");
        let e = write_previews(&f, &d, &d).unwrap_err().to_string();
        assert!(e.contains("both be written"), "{e}");
        let mut short = f.clone();
        short.stokes = Some(vec![]);
        let e = write_previews(&short, &d, &a).unwrap_err().to_string();
        assert!(e.contains("0 Stokes vectors"), "{e}");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }
}
