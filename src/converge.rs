//! `heron converge`: run time against error. Renders a reference at many samples per
//! pixel (8 lanes, independent numbers, another seed, and its own integrator if asked),
//! then the same scene at each (lanes, spp) setting, and reports the wall time, the time
//! per sample and the errors against the reference.
//!
//! Errors, over linear sRGB, every pixel and channel, defined once in
//! [`crate::compare::errors`] (which `heron compare` reports too):
//!
//! - relative RMSE √(Σ (x − r)² / Σ r²): a global measure, which the brightest pixels
//!   dominate (a sun's image hundreds of times brighter than the floor decides it);
//! - relMSE, the mean over pixels and channels of (x − r)² / (r² + ε) with
//!   ε = [`crate::compare::REL_MSE_EPSILON`] = 10⁻² (Rousselle, Knaus & Zwicker 2011):
//!   every pixel weighs alike, by its relative error, dark ones regularised;
//! - both again over a region of interest ([`Roi`], a pixel rectangle), to judge an
//!   integrator on one feature (a caustic) rather than on the whole image.
//!
//! The reference's own noise is part of every measured error: with independent runs,
//! E‖x − r‖² = E‖x − truth‖² + E‖r − truth‖², so it adds the reference's own squared
//! error. The reference is rendered as its two shards (`--shard 0/2` and `1/2`: the same
//! samples, merged into the same bits as one render) and its own error estimated from
//! their difference: halves of n₁ and n₂ samples (n = n₁ + n₂) have
//! E(h₁ − h₂)² = σ²(1/n₁ + 1/n₂) per value, where σ² is one sample's variance, and the
//! whole reference has σ²/n, so its squared error is n₁n₂/n² · (h₁ − h₂)² (¼ of it for
//! equal halves), summed into the same measures with the whole reference in the
//! denominators. For an unbiased reference this is the error it adds to every row.
use crate::checkpoint::{merge, Shard};
use crate::compare::{errors, heat_colour, rel_squared_error, ErrorSums, Errors, HEAT_LEFT_OUT};
use crate::files::Staged;
use crate::film::Film;
use crate::render::{RenderOptions, Renderer};
use crate::scene::Scene;
use crate::settings::{IntegratorKind, Lanes};
use crate::{HeronError, Result};
use serde::Serialize;
use std::path::{Path, PathBuf};

#[derive(Clone, Debug, Serialize)]
pub struct ConvergeRow {
    pub lanes: usize,
    pub spp: u32,
    pub wall_s: f64,
    pub ns_per_sample: f64,
    pub rel_rmse: f64,
    /// Error × sqrt(time): constant for an unbiased estimator whose variance falls as
    /// 1/time; smaller is more efficient.
    pub rmse_sqrt_time: f64,
    /// Mean relative squared error per pixel and channel ([`crate::compare::errors`]).
    pub rel_mse: f64,
    /// The relative RMSE and the relMSE over the region of interest, when there is one.
    pub roi_rel_rmse: Option<f64>,
    pub roi_rel_mse: Option<f64>,
}

/// A region of interest: the pixels with x0 ≤ x < x1 and y0 ≤ y < y1, counted from the
/// image's top-left (half-open, as numpy's `image[y0:y1, x0:x1]`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Roi {
    pub x0: u32,
    pub y0: u32,
    pub x1: u32,
    pub y1: u32,
}

impl Roi {
    /// Parses `X0,Y0,X1,Y1`; the message says what was expected.
    pub fn parse(s: &str) -> std::result::Result<Roi, String> {
        let bad = || format!("expected X0,Y0,X1,Y1 (four whole numbers of pixels), got {s:?}");
        let v: Vec<u32> = s
            .split(',')
            .map(|p| p.trim().parse::<u32>())
            .collect::<std::result::Result<_, _>>()
            .map_err(|_| bad())?;
        let [x0, y0, x1, y1] = v[..] else {
            return Err(bad());
        };
        if x0 >= x1 || y0 >= y1 {
            return Err(format!(
                "expected X0 < X1 and Y0 < Y1 (the rectangle's top-left, then one past its bottom-right), got {s:?}"
            ));
        }
        Ok(Roi { x0, y0, x1, y1 })
    }

    /// Whether the rectangle lies inside a `width` × `height` image.
    pub fn check(&self, width: u32, height: u32) -> std::result::Result<(), String> {
        if self.x1 > width || self.y1 > height {
            return Err(format!(
                "{self} reaches outside the {width}x{height} image: expected X1 <= {width} and Y1 <= {height}"
            ));
        }
        Ok(())
    }

    pub fn contains(&self, x: u32, y: u32) -> bool {
        (self.x0..self.x1).contains(&x) && (self.y0..self.y1).contains(&y)
    }

    /// The row-major indices of its pixels in an image `width` wide.
    pub fn pixels(&self, width: u32) -> impl Iterator<Item = usize> + '_ {
        (self.y0..self.y1)
            .flat_map(move |y| (self.x0..self.x1).map(move |x| (y * width + x) as usize))
    }

    pub fn area(&self) -> u64 {
        (self.x1 - self.x0) as u64 * (self.y1 - self.y0) as u64
    }
}

impl std::fmt::Display for Roi {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{},{},{},{}", self.x0, self.y0, self.x1, self.y1)
    }
}

/// The heat maps' scale of per-pixel relative squared error: white at or below the
/// first (10⁻⁴, a 1% error), full colour at or above the second (10², a 1000% error),
/// linear in log₁₀ between (so each decade is a sixth of the way).
pub const HEAT_RANGE: (f64, f64) = (1e-4, 1e2);

/// A pixel's relative squared error: the mean over its channels of
/// [`rel_squared_error`], the quantity the relMSE averages.
pub fn pixel_rel_squared_error(x: [f32; 3], r: [f32; 3]) -> f64 {
    (0..3)
        .map(|c| rel_squared_error(x[c] as f64 - r[c] as f64, r[c] as f64))
        .sum::<f64>()
        / 3.0
}

/// The error heat map of image `x` against `reference` (row-major linear sRGB,
/// `width` × `height`): each pixel's [`pixel_rel_squared_error`] on the
/// [`HEAT_RANGE`] scale in [`heat_colour`]'s colours, red where the run is brighter
/// than the reference (its channels' differences sum to more than zero), blue where it
/// is darker; the region of interest's border pixels black.
pub fn heat_map(
    x: &[[f32; 3]],
    reference: &[[f32; 3]],
    width: u32,
    height: u32,
    roi: Option<Roi>,
) -> image::RgbImage {
    let (lo, hi) = (HEAT_RANGE.0.log10(), HEAT_RANGE.1.log10());
    image::RgbImage::from_fn(width, height, |px, py| {
        let i = (py * width + px) as usize;
        let on_border = roi.is_some_and(|r| {
            r.contains(px, py) && (px == r.x0 || py == r.y0 || px + 1 == r.x1 || py + 1 == r.y1)
        });
        if on_border {
            return image::Rgb([0, 0, 0]);
        }
        let (a, b) = (x[i], reference[i]);
        if a.iter().chain(&b).any(|v| !v.is_finite()) {
            return image::Rgb(HEAT_LEFT_OUT);
        }
        let e = pixel_rel_squared_error(a, b);
        let s = if e > 0.0 {
            ((e.log10() - lo) / (hi - lo)).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let brighter = (0..3).map(|c| a[c] as f64 - b[c] as f64).sum::<f64>() > 0.0;
        image::Rgb(heat_colour(if brighter { s } else { -s }))
    })
}

/// Where `heron converge --heatmap DIR` writes the heat map of one setting.
pub fn heat_map_path(dir: &Path, integrator: IntegratorKind, lanes: usize, spp: u32) -> PathBuf {
    dir.join(format!("{}-lanes{lanes}-spp{spp}.png", integrator.name()))
}

/// What to measure.
#[derive(Clone, Debug)]
pub struct Plan {
    /// The reference's samples per pixel.
    pub reference_spp: u32,
    /// The reference's integrator; None: the runs'.
    pub reference_integrator: Option<IntegratorKind>,
    pub lanes: Vec<Lanes>,
    pub spps: Vec<u32>,
    pub roi: Option<Roi>,
    /// A folder to write one heat map per setting into ([`heat_map_path`]).
    pub heat_maps: Option<PathBuf>,
}

/// The reference and its own error.
#[derive(Clone, Debug, Serialize)]
pub struct Reference {
    pub spp: u32,
    pub integrator: &'static str,
    pub wall_s: f64,
    /// Its own error estimated from its two halves (None below 2 spp): what it adds to
    /// every measured row (module documentation).
    pub own: Option<Errors>,
    /// The same over the region of interest.
    pub own_roi: Option<Errors>,
}

#[derive(Clone, Debug, Serialize)]
pub struct Convergence {
    pub reference: Reference,
    pub rows: Vec<ConvergeRow>,
}

/// Renders the reference (`plan.reference_spp`, 8 lanes, independent numbers, seed
/// `seed + 1`, as its two halves) and one run per (lanes, spp) with `base`'s settings.
/// Heat maps are written only once every render has succeeded.
pub fn converge(scene: &Scene, base: &RenderOptions, plan: &Plan) -> Result<Convergence> {
    let (w, h) = (scene.camera.width, scene.camera.height);
    if let Some(r) = plan.roi {
        r.check(w, h)
            .map_err(|e| HeronError::Invalid(format!("region of interest {e}")))?;
    }
    let renderer = Renderer::with_threads(scene, base.threads)?;
    let mut o = base.clone();
    o.progress = None;
    o.settings.spp = plan.reference_spp;
    o.settings.lanes = Lanes::Eight;
    o.settings.seed = base.settings.seed.wrapping_add(1);
    o.settings.sampler = crate::settings::SamplerKind::Independent;
    if let Some(k) = plan.reference_integrator {
        o.settings.integrator = k;
    }
    let (reference, reference_wall, halves) = render_reference(&renderer, &o)?;
    let r = reference.linear_srgb();
    let all = 0..r.len();
    let own = |pixels: &mut dyn Iterator<Item = usize>| {
        halves.as_ref().map(|(a, b, k)| {
            let mut s = ErrorSums::default();
            for i in pixels {
                for c in 0..3 {
                    s.add(k * (a[i][c] as f64 - b[i][c] as f64), r[i][c] as f64);
                }
            }
            s.errors()
        })
    };
    let reference_report = Reference {
        spp: plan.reference_spp,
        integrator: o.settings.integrator.name(),
        wall_s: reference_wall,
        own: own(&mut all.clone()),
        own_roi: plan.roi.and_then(|q| own(&mut q.pixels(w))),
    };
    let mut rows = Vec::new();
    let mut maps = Vec::new();
    for &l in &plan.lanes {
        for &spp in &plan.spps {
            let mut o = base.clone();
            o.progress = None;
            o.settings.lanes = l;
            o.settings.spp = spp;
            let (film, stats) = renderer.render(&o)?;
            let x = film.linear_srgb();
            let wall = stats.wall.as_secs_f64();
            let e = errors(&x, &r, all.clone());
            let e_roi = plan.roi.map(|q| errors(&x, &r, q.pixels(w)));
            rows.push(ConvergeRow {
                lanes: l.count(),
                spp,
                wall_s: wall,
                ns_per_sample: wall * 1e9 / stats.samples as f64,
                rel_rmse: e.rel_rmse,
                rmse_sqrt_time: e.rel_rmse * wall.sqrt(),
                rel_mse: e.rel_mse,
                roi_rel_rmse: e_roi.map(|e| e.rel_rmse),
                roi_rel_mse: e_roi.map(|e| e.rel_mse),
            });
            if let Some(dir) = &plan.heat_maps {
                let path = heat_map_path(dir, base.settings.integrator, l.count(), spp);
                maps.push((path, heat_map(&x, &r, w, h, plan.roi)));
            }
        }
    }
    // Every map staged before any is renamed into place: a failure leaves none.
    let staged = maps
        .iter()
        .map(|(path, img)| {
            Staged::write(path, |tmp| {
                img.save_with_format(tmp, image::ImageFormat::Png)
                    .map_err(|e| format!("cannot write PNG: {e}"))
            })
        })
        .collect::<Result<Vec<_>>>()?;
    for s in staged {
        s.commit()?;
    }
    Ok(Convergence {
        reference: reference_report,
        rows,
    })
}

/// Halves' linear sRGB and the factor √(n₁n₂)/n that scales their difference to the
/// whole reference's error.
type Halves = (Vec<[f32; 3]>, Vec<[f32; 3]>, f64);

/// The reference as one render would give it (its two shards merged, bit for bit), its
/// wall time, and its halves when it has at least 2 samples per pixel.
fn render_reference(renderer: &Renderer, o: &RenderOptions) -> Result<(Film, f64, Option<Halves>)> {
    let spp = o.settings.spp;
    if spp < 2 {
        let (film, stats) = renderer.render(o)?;
        return Ok((film, stats.wall.as_secs_f64(), None));
    }
    let mut parts = Vec::new();
    let mut wall = 0.0;
    for index in 0..2 {
        let shard = Shard { index, count: 2 };
        let mut oh = o.clone();
        oh.shard = Some(shard);
        let (state, stats) = renderer.render_state(&oh)?;
        wall += stats.wall.as_secs_f64();
        parts.push((PathBuf::from(format!("reference half {shard}")), state));
    }
    let whole = merge(&parts)?.film.image();
    let (n1, n2) = (
        Shard { index: 0, count: 2 }.samples(spp).len() as f64,
        Shard { index: 1, count: 2 }.samples(spp).len() as f64,
    );
    let k = (n1 * n2).sqrt() / (n1 + n2);
    let halves = (
        parts[0].1.film.image().linear_srgb(),
        parts[1].1.film.image().linear_srgb(),
        k,
    );
    Ok((whole, wall, Some(halves)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn roi_parses_checks_and_lists_its_pixels() {
        let r = Roi::parse("1, 2,4,3").unwrap();
        assert_eq!(
            r,
            Roi {
                x0: 1,
                y0: 2,
                x1: 4,
                y1: 3
            }
        );
        assert_eq!(r.to_string(), "1,2,4,3");
        // Row 2 of a 5-wide image, columns 1–3.
        assert_eq!(r.pixels(5).collect::<Vec<_>>(), vec![11, 12, 13]);
        assert_eq!(r.area(), 3);
        assert!(r.contains(3, 2) && !r.contains(4, 2) && !r.contains(1, 3));
        assert!(r.check(4, 3).is_ok());
        let e = r.check(3, 3).unwrap_err();
        assert!(
            e.contains("1,2,4,3") && e.contains("3x3") && e.contains("X1 <= 3"),
            "{e}"
        );
        for bad in [
            "1,2,3",
            "1,2,3,4,5",
            "a,0,1,1",
            "-1,0,1,1",
            "",
            "2,0,2,1",
            "0,5,1,4",
        ] {
            let e = Roi::parse(bad).unwrap_err();
            assert!(e.starts_with("expected X0"), "{bad}: {e}");
            assert!(!e.contains('\n'));
        }
    }

    /// A 4×2 image against a reference of 1 in every channel, the run's error set per
    /// pixel: the whole image and a region of interest get the values worked out by hand.
    #[test]
    fn errors_over_the_image_and_a_region_of_interest() {
        let r = vec![[1.0f32; 3]; 8];
        let mut x = r.clone();
        x[5] = [2.0, 1.0, 1.0]; // (1, 1): one channel off by 1
        x[0] = [1.0, 1.0, 4.0]; // (0, 0): one channel off by 3
        let roi = Roi::parse("1,1,3,2").unwrap(); // pixels 5 and 6
        let e = errors(&x, &r, roi.pixels(4));
        // Σd² = 1 over Σr² = 6; relMSE (1/1.01)/6.
        assert!((e.rel_rmse - (1.0f64 / 6.0).sqrt()).abs() < 1e-12);
        assert!((e.rel_mse - 1.0 / 1.01 / 6.0).abs() < 1e-12);
        let e = errors(&x, &r, 0..8);
        assert!((e.rel_rmse - (10.0f64 / 24.0).sqrt()).abs() < 1e-12);
        assert!((e.rel_mse - 10.0 / 1.01 / 24.0).abs() < 1e-12);
        assert!((pixel_rel_squared_error(x[0], r[0]) - 9.0 / 1.01 / 3.0).abs() < 1e-12);
    }

    #[test]
    fn heat_map_follows_the_scale_and_outlines_the_roi() {
        let (w, h) = (6, 5);
        let r = vec![[1.0f32; 3]; 30];
        let mut x = r.clone();
        // Relative squared errors per pixel (mean over channels, r² + ε = 1.01):
        // 10² or more (full red), about 10⁻¹ (half way on the log scale, blue), 0.
        x[7] = [12.0, 12.0, 12.0]; // (1, 1): 121/1.01 > 100
        x[9] = [1.0 - 0.3178, 1.0 - 0.3178, 1.0 - 0.3178]; // (3, 1): darker, 0.1
        let roi = Roi::parse("2,2,6,5").unwrap();
        let img = heat_map(&x, &r, w, h, Some(roi));
        assert_eq!(img.dimensions(), (w, h));
        assert_eq!(img.get_pixel(1, 1).0, [255, 0, 0]);
        let half = img.get_pixel(3, 1).0;
        assert_eq!(half[2], 255);
        assert!(
            (half[0] as i32 - 128).abs() <= 1 && half[0] == half[1],
            "{half:?}"
        );
        assert_eq!(img.get_pixel(0, 0).0, [255, 255, 255]);
        // The region's border is black, its inside and the outside show the errors.
        for (px, py) in [(2, 2), (5, 2), (2, 4), (5, 4), (3, 2)] {
            assert_eq!(img.get_pixel(px, py).0, [0, 0, 0], "({px}, {py})");
        }
        assert_eq!(img.get_pixel(3, 3).0, [255, 255, 255]);
        assert_eq!(img.get_pixel(1, 4).0, [255, 255, 255]);
    }
}
