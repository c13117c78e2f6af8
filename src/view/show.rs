//! What the page can show of an image, drawn here as 8-bit RGBA so that the page shows
//! exactly what `heron display` and the PNG previews would: one display transform, in
//! Rust, rather than a second one in the page's script.
use super::image::ViewImage;
use crate::compare::heat_colour;
use crate::spectrum::display::DisplayTransform;
use rayon::prelude::*;

/// Rec. 709 / sRGB luminance weights (IEC 61966-2-1's Y row): the luminance of a linear
/// sRGB triple, for the Stokes pictures.
const LUMA: [f32; 3] = [0.2126, 0.7152, 0.0722];

/// One way of looking at an image.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum View {
    /// Linear sRGB through the display transform, as the PNG preview.
    Rgb,
    /// CIE X, Y, Z shown as if they were R, G, B (false colour), through the display
    /// transform: where the film's XYZ differs from its colour.
    Xyz,
    /// The standard error √variance of R, G, B, through the display transform.
    StdErr,
    /// S1/S0, S2/S0 or S3/S0 of the luminance, in [−1, 1]: red positive, blue negative.
    Stokes(usize),
    /// The degree of linear polarisation, viridis, as OUT.dolp.png.
    Dolp,
    /// The angle of linear polarisation, hue with brightness DoLP, as OUT.aolp.png.
    Aolp,
    /// One channel: grey through the exposure and the sRGB curve, or, for a signed
    /// Stokes channel (S1–S3), red and blue for its sign at the exposure's scale.
    Channel(usize),
}

impl View {
    /// The views `img` has, as (id, label): what the page's channel menu lists.
    pub fn list(img: &ViewImage) -> Vec<(String, String)> {
        let mut out = Vec::new();
        if img.rgb(0).is_some() {
            out.push(("rgb".into(), "RGB (linear sRGB)".into()));
        }
        if img.triple(["X", "Y", "Z"]).is_some() {
            out.push(("xyz".into(), "XYZ as R, G, B (false colour)".into()));
        }
        if img.variance().is_some() {
            out.push(("stderr".into(), "standard error (√variance)".into()));
        }
        if img.stokes().is_some() {
            for k in 1..4 {
                out.push((format!("s{k}"), format!("S{k}/S0 (luminance)")));
            }
            out.push(("dolp".into(), "DoLP".into()));
            out.push(("aolp".into(), "AoLP (brightness DoLP)".into()));
        }
        for (i, c) in img.channels.iter().enumerate() {
            out.push((format!("ch{i}"), c.name.clone()));
        }
        out
    }

    /// The view called `id` in [`View::list`]'s terms, if `img` has it.
    pub fn parse(id: &str, img: &ViewImage) -> Option<View> {
        let view = match id {
            "rgb" => View::Rgb,
            "xyz" => View::Xyz,
            "stderr" => View::StdErr,
            "s1" => View::Stokes(1),
            "s2" => View::Stokes(2),
            "s3" => View::Stokes(3),
            "dolp" => View::Dolp,
            "aolp" => View::Aolp,
            _ => View::Channel(
                id.strip_prefix("ch")?
                    .parse()
                    .ok()
                    .filter(|&i| i < img.channels.len())?,
            ),
        };
        View::list(img).iter().any(|(v, _)| v == id).then_some(view)
    }

    /// The channels (indices into `img`) this view is drawn from.
    pub fn inputs(self, img: &ViewImage) -> Vec<usize> {
        let names = |ns: &[&str]| -> Vec<usize> { ns.iter().filter_map(|n| img.find(n)).collect() };
        let colour = ["R", "G", "B", "X", "Y", "Z"];
        match self {
            View::Rgb if img.triple(["R", "G", "B"]).is_some() => names(&["R", "G", "B"]),
            View::Rgb => names(&["X", "Y", "Z"]),
            View::Xyz => names(&["X", "Y", "Z"]),
            View::StdErr => names(&crate::film::exr::VARIANCE_CHANNELS),
            View::Stokes(_) | View::Dolp | View::Aolp => {
                let mut v = names(&colour);
                v.extend(
                    crate::film::exr::STOKES_CHANNELS
                        .iter()
                        .flat_map(|n| names(n)),
                );
                v
            }
            View::Channel(c) => vec![c],
        }
    }

    /// The picture at one pixel per `step × step` block of the image (1: every pixel),
    /// from the block means of the view's channels: what the page asks for while it
    /// shows the image smaller than 1/step of its size (a 4K image fitted to a window),
    /// so that opening a large file does not wait for every pixel's colour.
    pub fn draw_scaled(self, img: &ViewImage, t: &DisplayTransform, step: u32) -> Vec<u8> {
        if step <= 1 {
            return self.draw(img, t);
        }
        let keep = self.inputs(img);
        let small = img.downsample(step, &keep);
        let view = match self {
            View::Channel(_) => View::Channel(0),
            v => v,
        };
        view.draw(&small, t)
    }

    /// The picture: `width × height` RGBA, 8 bits per channel, row-major from the top.
    /// Pixels are drawn in parallel (a 4K picture is 8.3 million of them): each is a
    /// function of its own values only, so the bytes do not depend on the threads.
    pub fn draw(self, img: &ViewImage, t: &DisplayTransform) -> Vec<u8> {
        match self {
            View::Rgb => fill(img, |i| t.encode_u8(img.rgb(i).unwrap_or([0.0; 3]))),
            View::Xyz => {
                let xyz = img
                    .triple(["X", "Y", "Z"])
                    .expect("listed only with X, Y, Z");
                fill(img, |i| t.encode_u8(xyz.map(|p| p[i])))
            }
            View::StdErr => {
                let var = img.variance().expect("listed only with variance channels");
                fill(img, |i| t.encode_u8(var.map(|p| p[i].max(0.0).sqrt())))
            }
            View::Stokes(k) => {
                let s = img.stokes().expect("listed only for polarised images")[k - 1];
                fill(img, |i| {
                    let s0 = dot(img.rgb(i).unwrap_or([0.0; 3]));
                    let sk = dot(s.map(|p| p[i]));
                    let r = if s0 > 0.0 { sk / s0 } else { 0.0 };
                    heat_colour(if r.is_finite() { r as f64 } else { 0.0 })
                })
            }
            View::Dolp | View::Aolp => {
                let film = img.stokes_film().expect("listed only for polarised images");
                let colour = if self == View::Dolp {
                    crate::plot::stokes::dolp_rgb(&film)
                } else {
                    crate::plot::stokes::aolp_rgb(&film)
                };
                fill(img, |i| colour[i])
            }
            View::Channel(c) => {
                let ch = &img.channels[c].data;
                let signed = ["S1.", "S2.", "S3."]
                    .iter()
                    .any(|p| img.channels[c].name.starts_with(p));
                let scale = t.exposure_ev().exp2() as f64;
                fill(img, |i| {
                    if signed {
                        let s = ch[i] as f64 * scale;
                        heat_colour(if s.is_finite() { s } else { 0.0 })
                    } else {
                        t.encode_u8([ch[i]; 3])
                    }
                })
            }
        }
    }
}

/// RGBA bytes of `img`'s size, opaque, with pixel i's colour `colour(i)`.
fn fill(img: &ViewImage, colour: impl Fn(usize) -> [u8; 3] + Sync) -> Vec<u8> {
    let mut rgba = vec![255u8; 4 * img.pixels()];
    rgba.par_chunks_mut(4).enumerate().for_each(|(i, px)| {
        px[..3].copy_from_slice(&colour(i));
    });
    rgba
}

fn dot(rgb: [f32; 3]) -> f32 {
    LUMA[0] * rgb[0] + LUMA[1] * rgb[1] + LUMA[2] * rgb[2]
}
