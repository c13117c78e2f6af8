//! Pixel reconstruction filters by filter importance sampling (Ernst et al. 2006,
//! "Filter importance sampling"; pbrt-v4 `base/filter.h`, `filters.h`): a camera
//! sample's film position is drawn about its pixel's centre from the filter's
//! distribution, p ∝ |f|, and its value is weighted by f/(p ∫f). The film's plain mean
//! of weight × L per pixel is then an unbiased estimate of ∫ f(x − c) L(x) dx / ∫ f,
//! without splatting samples into neighbouring pixels, so a pixel's value still depends
//! only on its own samples (determinism, resumes and shard merges stay exact).
//!
//! Every filter is separable, f(x, y) = h(x) h(y), so each axis is sampled apart: the
//! box and the tent exactly (weight 1), the Gaussian and Mitchell–Netravali from a
//! table of |h| ([`table::Table1D`]). The filter is made once per tile from
//! [`PixelFilter`], the settings' plain description.
pub mod box_filter;
pub mod gaussian;
pub mod mitchell;
pub mod table;
pub mod tent;

use crate::settings::PixelFilter;
use box_filter::BoxFilter;
use gaussian::GaussianFilter;
use glam::Vec2;
use mitchell::MitchellFilter;
use table::Table1D;
use tent::TentFilter;

/// A filter ready to sample.
#[derive(Clone, Debug)]
pub enum Filter {
    Box(BoxFilter),
    Tent(TentFilter),
    /// The Gaussian or Mitchell–Netravali with the table of its profile.
    Tabulated(Box<(Profile, Table1D)>),
}

/// A tabulated filter's profile h.
#[derive(Clone, Copy, Debug)]
pub enum Profile {
    Gaussian(GaussianFilter),
    Mitchell(MitchellFilter),
}

impl Profile {
    #[inline]
    fn eval(&self, x: f64) -> f64 {
        match self {
            Profile::Gaussian(g) => g.eval(x),
            Profile::Mitchell(m) => m.eval(x),
        }
    }
}

/// A sampled film offset from the pixel's centre (pixels) and its weight f/(p ∫f).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FilterSample {
    pub offset: Vec2,
    pub weight: f32,
}

impl Filter {
    pub fn new(spec: &PixelFilter) -> Filter {
        match *spec {
            PixelFilter::Box { radius } => Filter::Box(BoxFilter { radius }),
            PixelFilter::Tent { radius } => Filter::Tent(TentFilter { radius }),
            PixelFilter::Gaussian { radius, stddev } => {
                Filter::tabulated(Profile::Gaussian(GaussianFilter { radius, stddev }), radius)
            }
            PixelFilter::Mitchell { radius, b, c } => {
                Filter::tabulated(Profile::Mitchell(MitchellFilter { radius, b, c }), radius)
            }
        }
    }

    fn tabulated(profile: Profile, radius: f32) -> Filter {
        let table = Table1D::new(radius, |x| profile.eval(x));
        Filter::Tabulated(Box::new((profile, table)))
    }

    /// The 1D profile h at offset `x` (pixels).
    pub fn eval_1d(&self, x: f32) -> f64 {
        match self {
            Filter::Box(b) => b.eval(x) as f64,
            Filter::Tent(t) => t.eval(x) as f64,
            Filter::Tabulated(t) => t.0.eval(x as f64),
        }
    }

    /// f(p) = h(p.x) h(p.y).
    pub fn eval(&self, p: Vec2) -> f64 {
        self.eval_1d(p.x) * self.eval_1d(p.y)
    }

    /// ∫h over one axis; ∫f is its square.
    pub fn integral_1d(&self) -> f64 {
        match self {
            Filter::Box(b) => b.integral(),
            Filter::Tent(t) => t.integral(),
            Filter::Tabulated(t) => t.1.integral(),
        }
    }

    /// The density of [`Filter::sample`]'s offsets at `p`.
    pub fn pdf(&self, p: Vec2) -> f32 {
        let axis = |x: f32| match self {
            Filter::Box(b) => b.pdf(x),
            Filter::Tent(t) => t.pdf(x),
            Filter::Tabulated(t) => t.1.pdf(x),
        };
        axis(p.x) * axis(p.y)
    }

    /// An offset from the pixel's centre for `u` in [0, 1)², and its weight.
    #[inline]
    pub fn sample(&self, u: Vec2) -> FilterSample {
        match self {
            Filter::Box(b) => FilterSample {
                offset: Vec2::new(b.sample(u.x), b.sample(u.y)),
                weight: 1.0,
            },
            Filter::Tent(t) => FilterSample {
                offset: Vec2::new(t.sample(u.x), t.sample(u.y)),
                weight: 1.0,
            },
            Filter::Tabulated(t) => {
                let (profile, table) = &**t;
                let axis = |u: f32| {
                    let (x, pdf) = table.sample(u);
                    (x, profile.eval(x as f64) / (pdf as f64 * table.integral()))
                };
                let ((x, wx), (y, wy)) = (axis(u.x), axis(u.y));
                FilterSample {
                    offset: Vec2::new(x, y),
                    weight: (wx * wy) as f32,
                }
            }
        }
    }

    /// The film position (pixels, (0, 0) at the image's top-left corner) of a camera
    /// sample of pixel (`px`, `py`) drawn from the pixel sample `u`, and its weight.
    /// A box of radius 0.5 gives (px + u.x, py + u.y) to the bit, the jitter heron
    /// always used, so images rendered without a filter keep their bytes.
    // Inlined into the tile loop so that the default box costs what the jitter did;
    // the sampled filters go through a call.
    #[inline(always)]
    pub fn film_point(&self, px: u32, py: u32, u: Vec2) -> (f32, f32, f32) {
        match self {
            Filter::Box(b) => {
                let (lo, span) = (0.5 - b.radius, 2.0 * b.radius);
                (
                    px as f32 + lo + span * u.x,
                    py as f32 + lo + span * u.y,
                    1.0,
                )
            }
            _ => self.sampled_point(px, py, u),
        }
    }

    /// [`Self::film_point`] for the filters sampled through [`Self::sample`].
    #[inline(never)]
    fn sampled_point(&self, px: u32, py: u32, u: Vec2) -> (f32, f32, f32) {
        let s = self.sample(u);
        (
            px as f32 + 0.5 + s.offset.x,
            py as f32 + 0.5 + s.offset.y,
            s.weight,
        )
    }
}
