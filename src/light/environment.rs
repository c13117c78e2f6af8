//! The environment: the scene's constant background and its `[sky]` model, as one light
//! at infinity that every escaping ray sees (pbrt-v4 `UniformInfiniteLight` and
//! `ImageInfiniteLight`; Mitsuba 3 `constant` and `envmap`). The sun's disk is a light
//! of its own ([`super::SunLight`]).
//!
//! Without a sky, directions are sampled uniformly on the sphere. A sky depends only on
//! the angle θ from the antisolar point (it is symmetric about the sun's axis), so it is
//! importance-sampled in u = cos θ from its own (θ, λ) table: the table's θ nodes become
//! bins in u, each weighted by the larger of its two ends' radiance averaged over
//! 360–830 nm (the table interpolates linearly between nodes, so that bound never misses
//! light), and φ is uniform. The density is then p(ω) = p_u(cos θ)/(2π).
//!
//! A halo sky ([`crate::sky::halo`]) depends on the direction about the sun too, so it
//! is sampled by its table's cells over (θ, ψ), ψ unfolded over both sides of the sun's
//! vertical: each cell weighted by the largest radiance among it and its neighbours
//! (the table interpolates between cell centres) averaged over λ, plus the background,
//! times sin θ; a point uniform in (θ, ψ) within the cell, so
//! p(ω) = p(θ, ψ)/(2π² sin θ) over θ ∈ [0, π], ψ ∈ [−π, π).
use super::envmap::EnvMap;
use super::{LightLeSample, LightLiSample, SceneBounds};
use crate::math::distribution::Distribution2D;
use crate::math::warp::{uniform_sphere, UNIFORM_SPHERE_PDF};
use crate::math::Frame;
use crate::sky::halo::table::{Placed, N_PSI, N_THETA, PSI_STEP, THETA_STEP};
use crate::sky::halo::FORWARD_CUT_DEG;
use crate::sky::table::SkyShape;
use crate::sky::SceneSky;
use crate::spectrum::{DenseSpectrum, SampledSpectrum, SampledWavelengths, LAMBDA_MAX, LAMBDA_MIN};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;
use std::sync::Arc;

#[derive(Clone, Debug)]
pub struct EnvironmentLight {
    pub background: DenseSpectrum,
    pub sky: Option<Arc<SceneSky>>,
    /// An image of the environment, in place of the background (never with a sky: the
    /// scene loader refuses both).
    pub map: Option<Arc<EnvMap>>,
    /// Importance sampling of the sky in u = cos θ about the antisolar axis.
    zones: Option<Zones>,
    /// Importance sampling of a halo sky by its cells.
    cells: Option<Box<Cells>>,
    /// ∫ L dω, averaged over wavelength.
    power_per_area: f32,
}

/// A piecewise-constant density over u ∈ [−1, 1] with bins of any width.
#[derive(Clone, Debug)]
struct Zones {
    frame: Frame,
    /// Bin edges in u, increasing; `edges.len() == density.len() + 1`.
    edges: Vec<f32>,
    /// Density in u per bin (integrates to 1).
    density: Vec<f32>,
    /// CDF at the edges.
    cdf: Vec<f32>,
}

impl Zones {
    fn sample(&self, u: Vec2) -> (Vec3, f32) {
        let n = self.density.len();
        let i = (self.cdf.partition_point(|&c| c <= u.x).max(1) - 1).min(n - 1);
        let (c0, c1) = (self.cdf[i], self.cdf[i + 1]);
        let t = if c1 > c0 {
            ((u.x - c0) / (c1 - c0)).clamp(0.0, 1.0)
        } else {
            0.5
        };
        let z = (self.edges[i] + t * (self.edges[i + 1] - self.edges[i])).clamp(-1.0, 1.0);
        let r = (1.0 - z * z).max(0.0).sqrt();
        let phi = 2.0 * PI * u.y;
        let w = self
            .frame
            .to_world(Vec3::new(r * phi.cos(), r * phi.sin(), z));
        (w, self.density[i] / (2.0 * PI))
    }

    fn pdf(&self, w: Vec3) -> f32 {
        let z = w.dot(self.frame.n).clamp(-1.0, 1.0);
        let n = self.density.len();
        let i = (self.edges.partition_point(|&e| e <= z).max(1) - 1).min(n - 1);
        self.density[i] / (2.0 * PI)
    }
}

/// The cells of a halo table as a 2D distribution over (θ, ψ) ∈ [0, π] × [−π, π).
#[derive(Clone, Debug)]
struct Cells {
    dist: Distribution2D,
    placed: Placed,
}

impl Cells {
    /// The cells of `sky`'s halo table, weighted as the module documentation says, and
    /// ∫ L dω; None for a sky without light.
    fn new(sky: &SceneSky, halo: &crate::sky::halo::PlacedHalo, bg: f32) -> (Option<Cells>, f32) {
        let rows = ((LAMBDA_MAX - LAMBDA_MIN) / 5.0).round() as usize;
        let f_mean: f32 = (0..=rows)
            .map(|k| sky.factor.eval(LAMBDA_MIN + 5.0 * k as f32))
            .sum::<f32>()
            / (rows + 1) as f32;
        // Mean over the table's rows times the factor's mean over λ: a sampling weight,
        // not the radiance (the product's mean would weigh rows by the sun's spectrum).
        // Inside the forward cone the sky reads the first cell outside it (at
        // `CAP_DEG`, its centre): the cells there take that cell's value.
        let first_outside = (FORWARD_CUT_DEG / THETA_STEP).ceil() as usize;
        let mean: Vec<f32> = (0..N_PSI)
            .flat_map(|k| (0..N_THETA).map(move |j| (k, j)))
            .map(|(k, j)| halo.table.cell_mean(k, j.max(first_outside)) * f_mean)
            .collect();
        let at = |k: usize, j: usize| mean[k * N_THETA + j];
        let mut power = 0.0f64;
        // Rows y: ψ from −180° to 180°, the mirror image of the folded table first.
        let mut func = vec![0.0f32; 2 * N_PSI * N_THETA];
        for y in 0..2 * N_PSI {
            let k = if y < N_PSI { N_PSI - 1 - y } else { y - N_PSI };
            for j in 0..N_THETA {
                let mut m = 0.0f32;
                for kk in k.saturating_sub(1)..=(k + 1).min(N_PSI - 1) {
                    for jj in j.saturating_sub(1)..=(j + 1).min(N_THETA - 1) {
                        m = m.max(at(kk, jj));
                    }
                }
                let theta = ((j as f64 + 0.5) * THETA_STEP).to_radians();
                func[y * N_THETA + j] = (m + bg) * theta.sin() as f32;
                let (t0, t1) = (
                    (j as f64 * THETA_STEP).to_radians(),
                    ((j + 1) as f64 * THETA_STEP).to_radians(),
                );
                power += (at(k, j) + bg) as f64 * (t0.cos() - t1.cos()) * PSI_STEP.to_radians();
            }
        }
        if !(power > 0.0) {
            return (None, 0.0);
        }
        let cells = Cells {
            dist: Distribution2D::new(&func, N_THETA, 2 * N_PSI),
            placed: halo.placed.clone(),
        };
        (Some(cells), power as f32)
    }

    fn sample(&self, u: Vec2) -> (Vec3, f32) {
        let (p, pdf_uv) = self.dist.sample(u);
        // Off the pole at θ = 0, where the density in (θ, ψ) has no solid angle.
        let theta = (p.x as f64).max(1e-9) * 180.0;
        let psi = p.y as f64 * 360.0 - 180.0;
        let w = crate::sky::halo::table::from_sun_coordinates(
            theta,
            psi,
            self.placed.sun,
            self.placed.zenith,
        )
        .as_vec3();
        let s = theta.to_radians().sin() as f32;
        if !(s > 0.0) {
            return (w, 0.0);
        }
        (w, pdf_uv / (2.0 * PI * PI * s))
    }

    fn pdf(&self, w: Vec3) -> f32 {
        let (theta, psi) = self.placed.coordinates(w);
        let s = theta.to_radians().sin() as f32;
        if !(s > 0.0) {
            return 0.0;
        }
        // Symmetric about ψ = 0: the positive half's cell.
        let p = Vec2::new((theta / 180.0) as f32, ((psi + 180.0) / 360.0) as f32);
        self.dist.pdf(p.clamp(Vec2::ZERO, Vec2::splat(0.999_999_9))) / (2.0 * PI * PI * s)
    }
}

impl EnvironmentLight {
    pub fn new(
        background: DenseSpectrum,
        sky: Option<Arc<SceneSky>>,
        map: Option<Arc<EnvMap>>,
    ) -> Self {
        if let Some(m) = &map {
            let power_per_area = m.power_per_area();
            return EnvironmentLight {
                background,
                sky: None,
                map,
                zones: None,
                cells: None,
                power_per_area,
            };
        }
        let Some(s) = &sky else {
            let power_per_area = 4.0 * PI * background.mean();
            return EnvironmentLight {
                background,
                sky,
                map: None,
                zones: None,
                cells: None,
                power_per_area,
            };
        };
        let table = match &s.shape {
            SkyShape::Profile(t) => t,
            SkyShape::Halo(h) => {
                let (cells, power_per_area) = Cells::new(s, h, background.mean());
                return EnvironmentLight {
                    background,
                    sky,
                    map: None,
                    zones: None,
                    cells: cells.map(Box::new),
                    power_per_area,
                };
            }
        };
        // Mean radiance over λ at each θ node, on the table's own 5 nm rows.
        let rows = ((LAMBDA_MAX - LAMBDA_MIN) / 5.0).round() as usize;
        let lambdas: Vec<f32> = (0..=rows).map(|k| LAMBDA_MIN + 5.0 * k as f32).collect();
        let bg = if s.replaces_background {
            0.0
        } else {
            background.mean()
        };
        let grid = table.theta_grid();
        let mean: Vec<f32> = grid
            .iter()
            .map(|&t| {
                let sum: f32 = lambdas
                    .iter()
                    .map(|&l| table.eval(t, l) * s.factor.eval(l))
                    .sum();
                sum / lambdas.len() as f32 + bg
            })
            .collect();
        // Bins in increasing u = cos θ, i.e. θ from 180° down to 0°.
        let k = grid.len();
        let mut edges = Vec::with_capacity(k);
        let mut weight = Vec::with_capacity(k - 1);
        let mut integral = 0.0f64;
        for j in (0..k).rev() {
            edges.push((grid[j].to_radians().cos() as f32).clamp(-1.0, 1.0));
        }
        edges[0] = -1.0;
        edges[k - 1] = 1.0;
        for b in 0..k - 1 {
            // Bin b spans θ nodes k−1−b (lower u) and k−2−b.
            let (hi, lo) = (k - 1 - b, k - 2 - b);
            weight.push(mean[hi].max(mean[lo]));
            integral += 0.5 * (mean[hi] + mean[lo]) as f64 * (edges[b + 1] - edges[b]) as f64;
        }
        let mass: f64 = weight
            .iter()
            .enumerate()
            .map(|(b, &w)| w as f64 * (edges[b + 1] - edges[b]) as f64)
            .sum();
        let power_per_area = (2.0 * std::f64::consts::PI * integral) as f32;
        if !(mass > 0.0) {
            // An all-black sky and background: no light, nothing to sample.
            return EnvironmentLight {
                background,
                sky,
                map: None,
                zones: None,
                cells: None,
                power_per_area: 0.0,
            };
        }
        let density: Vec<f32> = weight.iter().map(|&w| (w as f64 / mass) as f32).collect();
        let mut cdf = vec![0.0f32; density.len() + 1];
        let mut acc = 0.0f64;
        for b in 0..density.len() {
            acc += weight[b] as f64 * (edges[b + 1] - edges[b]) as f64 / mass;
            cdf[b + 1] = acc as f32;
        }
        let last = cdf.len() - 1;
        cdf[last] = 1.0;
        let zones = Zones {
            frame: Frame::from_z(-s.sun_dir),
            edges,
            density,
            cdf,
        };
        EnvironmentLight {
            background,
            sky,
            map: None,
            zones: Some(zones),
            cells: None,
            power_per_area,
        }
    }

    /// Radiance arriving along a ray that leaves the scene in direction `dir`: the
    /// background, or the sky model that contains it or adds to it.
    #[inline]
    pub fn le<const N: usize>(&self, dir: Vec3, wl: &SampledWavelengths<N>) -> SampledSpectrum<N> {
        if let Some(m) = &self.map {
            return m.le(dir, wl);
        }
        match &self.sky {
            None => wl.eval(&self.background),
            Some(sky) => {
                let mut s = SampledSpectrum::<N>::zero();
                match &sky.shape {
                    SkyShape::Profile(table) => {
                        // θ once per ray; the table per lane.
                        let theta = crate::sky::antisolar_angle(dir, sky.sun_dir).to_degrees();
                        for i in 0..N {
                            let lambda = wl.lambda[i];
                            s.0[i] = table.eval(theta, lambda) * sky.factor.eval(lambda);
                        }
                    }
                    SkyShape::Halo(h) => {
                        let at = h.placed.coordinates(dir);
                        for i in 0..N {
                            let lambda = wl.lambda[i];
                            s.0[i] = h.eval(at, lambda) * sky.factor.eval(lambda);
                        }
                    }
                }
                if sky.replaces_background {
                    s
                } else {
                    s + wl.eval(&self.background)
                }
            }
        }
    }

    /// S1 of the sky's light along `dir` and its frame x̂ = (sun × dir)/|…|, perpendicular
    /// to the scattering plane ([`crate::light::Light::le_linear`]); None without a
    /// polarised sky.
    pub fn le_linear<const N: usize>(
        &self,
        dir: Vec3,
        wl: &SampledWavelengths<N>,
    ) -> Option<(SampledSpectrum<N>, Vec3)> {
        let sky = self.sky.as_ref()?;
        let table = sky.linear_table()?;
        let theta = crate::sky::antisolar_angle(dir, sky.sun_dir).to_degrees();
        let s1 = SampledSpectrum(std::array::from_fn(|i| {
            let lambda = wl.lambda[i];
            table.eval(theta, lambda) * sky.factor.eval(lambda)
        }));
        let x = sky.sun_dir.cross(dir);
        let x = if x.length_squared() > 1e-12 {
            x.normalize()
        } else {
            crate::spectrum::stokes::any_perpendicular(dir)
        };
        Some((s1, x))
    }

    #[inline]
    fn sample_dir(&self, u: Vec2) -> (Vec3, f32) {
        if let Some(m) = &self.map {
            return m.sample(u);
        }
        if let Some(c) = &self.cells {
            return c.sample(u);
        }
        match &self.zones {
            Some(z) => z.sample(u),
            None => (uniform_sphere(u), UNIFORM_SPHERE_PDF),
        }
    }

    #[inline]
    pub fn sample_li<const N: usize>(
        &self,
        u: Vec2,
        wl: &SampledWavelengths<N>,
    ) -> Option<LightLiSample<N>> {
        let (wi, pdf) = self.sample_dir(u);
        if !(pdf > 0.0) {
            return None;
        }
        Some(LightLiSample {
            l: self.le(wi, wl),
            wi,
            pdf,
            dist: f32::INFINITY,
            delta: false,
            n: Vec3::ZERO,
            p: Vec3::ZERO,
            p_err: Vec3::ZERO,
        })
    }

    #[inline]
    pub fn pdf_li(&self, wi: Vec3) -> f32 {
        if let Some(m) = &self.map {
            return m.pdf(wi);
        }
        if let Some(c) = &self.cells {
            return c.pdf(wi);
        }
        match &self.zones {
            Some(z) => z.pdf(wi),
            None => UNIFORM_SPHERE_PDF,
        }
    }

    /// A ray coming in from a sampled direction through a point uniform on the disk
    /// covering the scene's bounding sphere.
    #[inline]
    pub fn sample_le<const N: usize>(
        &self,
        u1: Vec2,
        u2: Vec2,
        wl: &SampledWavelengths<N>,
        bounds: &SceneBounds,
    ) -> Option<LightLeSample<N>> {
        let (w, pdf_dir) = self.sample_dir(u1);
        if !(pdf_dir > 0.0) {
            return None;
        }
        let (origin, pdf_pos) = bounds.disk_point(w, u2);
        Some(LightLeSample {
            origin,
            origin_err: Vec3::ZERO,
            dir: -w,
            l: self.le(w, wl),
            pdf_pos,
            pdf_dir,
            normal: Some(-w),
            uv: Vec2::ZERO,
        })
    }

    /// Φ = π R² ∫ L dω (pbrt-v4's convention for lights at infinity).
    pub fn phi(&self, bounds: &SceneBounds) -> f32 {
        bounds.disk_area() * self.power_per_area
    }
}
