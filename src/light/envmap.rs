//! An environment map: radiance at infinity read from an RGB image (OpenEXR, Radiance
//! HDR or PNG), importance-sampled by its texels (Mitsuba 3 `envmap`, pbrt-v4
//! `ImageInfiniteLight`). It replaces the scene's constant background inside
//! [`super::EnvironmentLight`].
//!
//! # Layouts
//!
//! - `latlong` (equirectangular, Mitsuba 3's `envmap`): in the map's own frame, +y is
//!   the zenith, the image's top row. A direction d has u = atan2(d.x, −d.z)/2π (so the
//!   left edge looks along −z, a quarter of the way along +x, the centre along +z) and
//!   v = acos(d.y)/π. Texel centres sit at u = (i + ½)/W, wrapping around in u, and at
//!   v = j/(H − 1), so the first and last rows are the poles (Mitsuba 3.9
//!   `src/emitters/envmap.cpp`, `direction_to_uv` and `eval_spectrum`). Radiance is the
//!   bilinear interpolation of the four texels around (u, v).
//! - `equal-area` (pbrt-v4's image infinite lights): a square image on Clarberg's
//!   equal-area octahedral map ([`crate::math::warp::equal_area_square_to_sphere`]),
//!   +z at the centre, texels looked up nearest as pbrt-v4 does (`ImageLe`,
//!   `LookupNearestChannel`).
//!
//! # Colour
//!
//! Every texel's linear sRGB is uplifted once, when the map is loaded, as pbrt-v4's
//! `RGBIlluminantSpectrum` and Mitsuba 3's `envmap` do: with m = 2 max(r, g, b), the
//! Jakob–Hanika sigmoid of rgb/m (whose largest component is ½, where the fitted table
//! is smooth; the table's trilinear lookup, without the Gauss–Newton polish heron spends
//! on a scene's few colours), times m, times D65 at luminance 1. A lookup interpolates
//! the texels' spectra, Σ wₖ mₖ Sₖ(λ) · D65(λ), at each lane's wavelength. (Mitsuba
//! interpolates the sigmoids and the scales separately and multiplies them; the two
//! agree wherever neighbouring texels share a colour or a brightness.)
//!
//! # Sampling
//!
//! Directions are drawn from a piecewise-constant density over the map's cells
//! ([`Distribution2D`]): for `latlong` the W × (H − 1) cells between texel centres, each
//! weighted by the mean of its four corners' λ-averaged radiance times sin θ at its
//! centre (a bilinear patch is zero only where its four corners are, so the density is
//! positive wherever radiance is), and dω = 2π² sin θ du dv; for `equal-area` the texels
//! themselves, dω = 4π du dv.
use crate::math::distribution::Distribution2D;
use crate::math::warp::{equal_area_sphere_to_square, equal_area_square_to_sphere};
use crate::spectrum::cie::d65_unit;
use crate::spectrum::rgb2spec::{srgb_table, SigmoidPolynomial};
use crate::spectrum::{SampledSpectrum, SampledWavelengths, LAMBDA_MAX, LAMBDA_MIN};
use glam::{Mat3, Vec2, Vec3};
use std::f32::consts::PI;

/// How the image covers the sphere (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EnvMapping {
    LatLong,
    EqualArea,
}

impl EnvMapping {
    pub const NAMES: &'static [&'static str] = &["latlong", "equal-area"];

    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "latlong" => Some(EnvMapping::LatLong),
            "equal-area" => Some(EnvMapping::EqualArea),
            _ => None,
        }
    }
}

/// One texel's uplifted radiance: m · S(c; λ) (before D65 and the map's scale, which
/// `m` already includes).
#[derive(Clone, Copy, Debug)]
struct Texel {
    c: [f32; 3],
    m: f32,
}

impl Texel {
    fn new(rgb: [f32; 3], scale: f32) -> Texel {
        let rgb = rgb.map(|v| if v.is_finite() { v.max(0.0) } else { 0.0 });
        let m = 2.0 * rgb[0].max(rgb[1]).max(rgb[2]);
        if m <= 0.0 {
            return Texel {
                c: [0.0; 3],
                m: 0.0,
            };
        }
        let norm = rgb.map(|v| v / m);
        Texel {
            c: srgb_table().texel(norm).c,
            m: m * scale,
        }
    }

    #[inline]
    fn eval(&self, lambda: f32) -> f32 {
        if self.m == 0.0 {
            return 0.0;
        }
        self.m * SigmoidPolynomial { c: self.c }.eval(lambda)
    }

    /// The radiance averaged over 360–830 nm under D65 (the sampling weight), from 48
    /// wavelengths: the sigmoid is smooth, so that is within a fraction of a percent.
    fn mean(&self) -> f32 {
        if self.m == 0.0 {
            return 0.0;
        }
        const K: usize = 48;
        let d65 = d65_unit();
        let mut s = 0.0;
        for k in 0..K {
            let l = LAMBDA_MIN + (k as f32 + 0.5) * (LAMBDA_MAX - LAMBDA_MIN) / K as f32;
            s += self.eval(l) * d65.eval(l);
        }
        s / K as f32
    }
}

#[derive(Clone, Debug)]
pub struct EnvMap {
    mapping: EnvMapping,
    width: usize,
    height: usize,
    /// Row by row from the image's top row.
    texels: Vec<Texel>,
    /// The map's frame in the scene (orthogonal) and its inverse (the transpose).
    to_world: Mat3,
    to_local: Mat3,
    dist: Distribution2D,
    /// ∫ L dω averaged over wavelength.
    power_per_area: f32,
}

impl EnvMap {
    /// A map of `width × height` linear sRGB pixels (row by row from the top), times
    /// `scale`, placed by the orthogonal `to_world`. The caller checks the sizes: at
    /// least 1 × 2 for `latlong`, a square for `equal-area`.
    pub fn new(
        mapping: EnvMapping,
        width: usize,
        height: usize,
        rgb: &[[f32; 3]],
        scale: f32,
        to_world: Mat3,
    ) -> EnvMap {
        assert_eq!(rgb.len(), width * height);
        assert!(width >= 1 && height >= 1);
        let texels: Vec<Texel> = rgb.iter().map(|&c| Texel::new(c, scale)).collect();
        let mean: Vec<f32> = texels.iter().map(Texel::mean).collect();
        let (dist, power_per_area) = match mapping {
            EnvMapping::LatLong => {
                assert!(height >= 2);
                let rows = height - 1;
                let mut w = vec![0.0f32; width * rows];
                for j in 0..rows {
                    let theta = PI * (j as f32 + 0.5) / rows as f32;
                    let sin = theta.sin();
                    for i in 0..width {
                        let i1 = (i + 1) % width;
                        let corners = mean[j * width + i]
                            + mean[j * width + i1]
                            + mean[(j + 1) * width + i]
                            + mean[(j + 1) * width + i1];
                        w[j * width + i] = 0.25 * corners * sin;
                    }
                }
                let d = Distribution2D::new(&w, width, rows);
                let power = 2.0 * PI * PI * d.integral();
                (d, power)
            }
            EnvMapping::EqualArea => {
                let d = Distribution2D::new(&mean, width, height);
                let power = 4.0 * PI * d.integral();
                (d, power)
            }
        };
        EnvMap {
            mapping,
            width,
            height,
            texels,
            to_world,
            to_local: to_world.transpose(),
            dist,
            power_per_area,
        }
    }

    /// ∫ L dω averaged over wavelength (for the light's power).
    pub fn power_per_area(&self) -> f32 {
        self.power_per_area
    }

    /// Radiance arriving from direction `dir` (unit, in the scene's frame).
    #[inline]
    pub fn le<const N: usize>(&self, dir: Vec3, wl: &SampledWavelengths<N>) -> SampledSpectrum<N> {
        let d = self.to_local * dir;
        let d65 = wl.eval(d65_unit());
        let mut s = SampledSpectrum::<N>::zero();
        match self.mapping {
            EnvMapping::LatLong => {
                let w = self.width;
                let u = wrap01(d.x.atan2(-d.z) * (0.5 / PI));
                let v = polar(d) / PI;
                // Texel centres at integer x = uW − ½ (wrapping) and y = v(H − 1).
                let x = u * w as f32 - 0.5;
                let x0 = x.floor();
                let fx = x - x0;
                let i0 = (x0 as i64).rem_euclid(w as i64) as usize;
                let i1 = (i0 + 1) % w;
                let y = v * (self.height - 1) as f32;
                let j0 = (y.floor() as usize).min(self.height - 2);
                let fy = (y - j0 as f32).clamp(0.0, 1.0);
                let t = |i: usize, j: usize| &self.texels[j * w + i];
                let corners = [
                    (t(i0, j0), (1.0 - fx) * (1.0 - fy)),
                    (t(i1, j0), fx * (1.0 - fy)),
                    (t(i0, j0 + 1), (1.0 - fx) * fy),
                    (t(i1, j0 + 1), fx * fy),
                ];
                for k in 0..N {
                    let l = wl.lambda[k];
                    let mut acc = 0.0;
                    for (tx, wt) in &corners {
                        if *wt > 0.0 {
                            acc += wt * tx.eval(l);
                        }
                    }
                    s.0[k] = acc * d65.0[k];
                }
            }
            EnvMapping::EqualArea => {
                let p = equal_area_sphere_to_square(d);
                let t = &self.texels[self.nearest(p)];
                for k in 0..N {
                    s.0[k] = t.eval(wl.lambda[k]) * d65.0[k];
                }
            }
        }
        s
    }

    fn nearest(&self, p: Vec2) -> usize {
        let i = ((p.x * self.width as f32) as usize).min(self.width - 1);
        let j = ((p.y * self.height as f32) as usize).min(self.height - 1);
        j * self.width + i
    }

    /// A direction drawn from the map's density, and that density (solid angle).
    #[inline]
    pub fn sample(&self, u: Vec2) -> (Vec3, f32) {
        let (p, pdf) = self.dist.sample(u);
        if !(pdf > 0.0) {
            return (Vec3::Z, 0.0);
        }
        match self.mapping {
            EnvMapping::LatLong => {
                // Cell columns start at a texel centre, half a texel past u = 0.
                let uu = wrap01(p.x + 0.5 / self.width as f32);
                let theta = PI * p.y;
                let phi = 2.0 * PI * uu;
                let (st, ct) = theta.sin_cos();
                let (sp, cp) = phi.sin_cos();
                if !(st > 0.0) {
                    return (Vec3::Z, 0.0);
                }
                let local = Vec3::new(sp * st, ct, -cp * st);
                // sin θ of the direction returned, as `pdf` computes it (sin(π y) in f32
                // is 2% off within 0.1° of a pole).
                let st = local.x.hypot(local.z);
                (
                    (self.to_world * local).normalize(),
                    pdf / (2.0 * PI * PI * st),
                )
            }
            EnvMapping::EqualArea => {
                let local = equal_area_square_to_sphere(p);
                ((self.to_world * local).normalize(), pdf / (4.0 * PI))
            }
        }
    }

    /// The density of [`Self::sample`] for direction `dir`.
    #[inline]
    pub fn pdf(&self, dir: Vec3) -> f32 {
        let d = self.to_local * dir;
        match self.mapping {
            EnvMapping::LatLong => {
                let u = wrap01(d.x.atan2(-d.z) * (0.5 / PI) - 0.5 / self.width as f32);
                let st = d.x.hypot(d.z) / d.length();
                if !(st > 0.0) {
                    return 0.0;
                }
                let v = (polar(d) / PI).min(1.0 - f32::EPSILON / 2.0);
                self.dist.pdf(Vec2::new(u, v)) / (2.0 * PI * PI * st)
            }
            EnvMapping::EqualArea => {
                let p = equal_area_sphere_to_square(d);
                let p = p.clamp(Vec2::ZERO, Vec2::splat(1.0 - f32::EPSILON / 2.0));
                self.dist.pdf(p) / (4.0 * PI)
            }
        }
    }
}

/// The polar angle θ from +y, accurate near the poles (where acos(y) is not).
#[inline]
fn polar(d: Vec3) -> f32 {
    d.x.hypot(d.z).atan2(d.y)
}

/// x − ⌊x⌋, kept below 1 (a tiny negative x rounds up to 1.0 in f32).
#[inline]
fn wrap01(x: f32) -> f32 {
    let f = x - x.floor();
    if f >= 1.0 {
        0.0
    } else {
        f
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn wl() -> SampledWavelengths<4> {
        SampledWavelengths::<4>::sample_uniform(0.37)
    }

    /// A map whose texels are all different, warm in one corner.
    fn ramp(w: usize, h: usize) -> Vec<[f32; 3]> {
        (0..w * h)
            .map(|k| {
                let (i, j) = (k % w, k / w);
                [
                    0.2 + i as f32 / w as f32,
                    0.1 + 2.0 * j as f32 / h as f32,
                    0.05 + ((i * 7 + j * 3) % 5) as f32,
                ]
            })
            .collect()
    }

    #[test]
    fn white_map_is_d65_everywhere() {
        for mapping in [EnvMapping::LatLong, EnvMapping::EqualArea] {
            let m = EnvMap::new(mapping, 8, 8, &[[1.0; 3]; 64], 2.0, Mat3::IDENTITY);
            let wl = wl();
            let d65 = wl.eval(d65_unit());
            for d in [
                Vec3::X,
                Vec3::Y,
                -Vec3::Z,
                Vec3::new(0.3, -0.5, 0.8).normalize(),
            ] {
                let l = m.le(d, &wl);
                for k in 0..4 {
                    assert!(
                        (l.0[k] - 2.0 * d65.0[k]).abs() < 1e-5 * d65.0[k],
                        "{mapping:?}"
                    );
                }
            }
            // ∫ L dω of radiance 2·D65 (mean over λ ≈ its λ-mean).
            let mean_d65 = d65_unit().mean();
            assert!(
                (m.power_per_area() / (4.0 * PI * 2.0 * mean_d65) - 1.0).abs() < 0.01,
                "{mapping:?}: {}",
                m.power_per_area()
            );
        }
    }

    #[test]
    fn latlong_texel_centres_are_where_mitsuba_puts_them() {
        // One bright texel at (i, j) = (3, 2) of an 8 × 5 map: full value at its centre
        // u = 3.5/8, v = 2/4, and along its direction only.
        let mut rgb = vec![[0.0f32; 3]; 40];
        rgb[2 * 8 + 3] = [1.0; 3];
        let m = EnvMap::new(EnvMapping::LatLong, 8, 5, &rgb, 1.0, Mat3::IDENTITY);
        let (theta, phi) = (PI * 0.5, 2.0 * PI * 3.5 / 8.0);
        let d = Vec3::new(
            phi.sin() * theta.sin(),
            theta.cos(),
            -phi.cos() * theta.sin(),
        );
        let wl = wl();
        let d65 = wl.eval(d65_unit());
        let l = m.le(d, &wl);
        assert!(
            (l.0[0] / d65.0[0] - 1.0).abs() < 1e-4,
            "{}",
            l.0[0] / d65.0[0]
        );
        // Half a texel to the side, half the value (bilinear).
        let phi2 = 2.0 * PI * 4.0 / 8.0;
        let d2 = Vec3::new(
            phi2.sin() * theta.sin(),
            theta.cos(),
            -phi2.cos() * theta.sin(),
        );
        assert!((m.le(d2, &wl).0[0] / d65.0[0] - 0.5).abs() < 1e-3);
        // The image centre looks along +z, the left edge along −z.
        let mut rgb = vec![[0.0f32; 3]; 40];
        rgb[2 * 8 + 4] = [1.0; 3];
        rgb[2 * 8 + 3] = [1.0; 3];
        let m = EnvMap::new(EnvMapping::LatLong, 8, 5, &rgb, 1.0, Mat3::IDENTITY);
        assert!(m.le(Vec3::Z, &wl).0[0] > 0.99 * d65.0[0]);
        assert_eq!(m.le(-Vec3::Z, &wl).0[0], 0.0);
    }

    #[test]
    fn sampled_density_is_the_pdf_and_integrates_to_one() {
        let rot = Mat3::from_rotation_y(0.7) * Mat3::from_rotation_x(-0.4);
        for (mapping, w, h) in [(EnvMapping::LatLong, 16, 9), (EnvMapping::EqualArea, 8, 8)] {
            let m = EnvMap::new(mapping, w, h, &ramp(w, h), 1.0, rot);
            let n = 256;
            let mut total = 0.0f64;
            for a in 0..n {
                for b in 0..n {
                    let u = Vec2::new((a as f32 + 0.5) / n as f32, (b as f32 + 0.5) / n as f32);
                    let (d, pdf) = m.sample(u);
                    assert!((d.length() - 1.0).abs() < 1e-5);
                    let p2 = m.pdf(d);
                    assert!(
                        (pdf - p2).abs() <= 2e-3 * pdf,
                        "{mapping:?} u={u} pdf {pdf} vs {p2}"
                    );
                    // ∫ pdf dω by uniform directions over the sphere.
                    let s = crate::math::warp::uniform_sphere(u);
                    total += (m.pdf(s) * 4.0 * PI) as f64 / (n * n) as f64;
                }
            }
            assert!((total - 1.0).abs() < 0.01, "{mapping:?}: {total}");
        }
    }

    #[test]
    fn density_is_positive_wherever_there_is_light() {
        // A single lit texel: every direction with radiance has a density, so sampling
        // is unbiased.
        let mut rgb = vec![[0.0f32; 3]; 6 * 4];
        rgb[6 + 5] = [0.0, 0.0, 3.0];
        let m = EnvMap::new(EnvMapping::LatLong, 6, 4, &rgb, 1.0, Mat3::IDENTITY);
        let wl = wl();
        for a in 0..200 {
            for b in 0..200 {
                let d = crate::math::warp::uniform_sphere(Vec2::new(
                    (a as f32 + 0.5) / 200.0,
                    (b as f32 + 0.5) / 200.0,
                ));
                if m.le(d, &wl).max_value() > 0.0 {
                    assert!(m.pdf(d) > 0.0, "{d}");
                }
            }
        }
    }
}
