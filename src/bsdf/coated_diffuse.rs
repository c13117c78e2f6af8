//! A coated diffuse surface: a dielectric coat of index η (constant or dispersive) and
//! roughness α over an optional absorbing layer of optical depth τ over a Lambertian
//! base of reflectance ρ(λ) — plastic, varnished wood, glazed ceramics, paint.
//!
//! **The closed form** (Weidlich & Wilkie 2007, "Arbitrarily Layered Micro-Facet
//! Surfaces", GRAPHITE, §3–4; the form of Mitsuba 3 `src/bsdfs/plastic.cpp` and
//! `roughplastic.cpp`; pbrt-v4's `CoatedDiffuseBxDF` (`LayeredBxDF` in
//! `src/pbrt/bxdfs.h`) estimates the same layering stochastically). With ωo, ωi on the
//! outer side, μ = cos θ:
//!
//! - the *specular lobe* is the coat's own reflection: for a smooth coat the Fresnel
//!   delta F(μo) (pbrt-v4 §9.5), for a rough coat the Torrance–Sparrow GGX reflection
//!   D G F/(4 μo μi) (Walter et al. 2007, eq. 20; [`super::microfacet`]);
//! - the *diffuse lobe* is the light the coat lets through, that crosses the layer
//!   (attenuation A), reaches the base, and comes back out after any number of round
//!   trips between base and coat:
//!
//!   f_d(ωo, ωi) = (1 − E(μo)) (1 − E(μi)) A(μo) A(μi) ρ / (π η² (1 − ρ K)),
//!
//!   where E(μ) is the coat's directional reflection albedo (F for a smooth coat;
//!   ∫ f_spec μi dωi for a rough one, tabulated over μ per η when the material is
//!   built), 1 − E the light it transmits (a rough coat's multiple scattering counted as
//!   transmitted), 1/η² the compression of radiance into the denser layer's narrower
//!   cone (Veach 1997 §5.2), and K the fraction of the base's cosine-distributed light
//!   that the coat sends back down to it (the internal round trip).
//!
//! **K and A.** Inside, a direction μ' refracts to μ outside by Snell
//! (η² (1 − μ'²) = 1 − μ²), so μ' dμ' = μ dμ / η²; directions below the critical
//! μc = √(1 − 1/η²) are totally reflected, the others are reflected with the outside
//! albedo E(μ) by reciprocity. The layer absorbs exp(−τ/μ') on each crossing (pbrt-v4's
//! `thickness` with albedo 0: `Tr(thickness, w)` in `LayeredBxDF`), so A(μ) = exp(−τ/μ'(μ)),
//! and a round trip from the base back to it keeps
//!
//!   K = 2∫₀^μc e^(−2τ/μ') μ' dμ' + (2/η²) ∫₀¹ E(μ) A(μ)² μ dμ,
//!
//! while the fraction that escapes on each trip is T̄/η² with T̄ = 2∫₀¹ (1 − E(μ)) A(μ) μ dμ.
//! With τ = 0 this is K = 1 − (1 − Ē)/η², Ē = 2∫ E μ dμ: for a smooth coat the diffuse
//! internal Fresnel reflectance F_dr(1/η) (Mitsuba's `m_fdr_int`) by reciprocity. A
//! rough coat's K is instead, as in Mitsuba 3's roughplastic.cpp
//! (`m_internal_reflectance`), 2∫ E_in(μ') e^(−2τ/μ') μ' dμ' with E_in the GGX
//! single-scattering reflection albedo of the coat seen from inside: it loses the light
//! the microfacets shadow at the grazing angles of total internal reflection, so a rough
//! coat's white furnace falls short of 1 (0.93 at α = 0.1, 0.74 at α = 0.3;
//! `tests/coated.rs`).
//!
//! **Energy.** The directional albedo of the diffuse lobe is
//! (1 − E(μo)) A(μo) ρ T̄ / (η² (1 − ρK)), and since T̄/η² + K ≤ 1 (escaping plus
//! returning light is at most what left the base; the rough coat's single-scattering K
//! is below the reciprocal one) the total albedo
//! E(μo) + (1 − E(μo)) A(μo) ρ T̄/(η²(1 − ρK)) ≤ E(μo) + (1 − E(μo)) A(μo) ≤ 1, with
//! equality for a white base, τ = 0 and a smooth coat (`tests/coated.rs` measures it).
//! The closed form assumes the light inside is diffuse after the first bounce off the
//! base (as Mitsuba's plastics do), ignores a rough coat's spread of the refracted
//! direction in A (the macro-surface's refraction is used), and is exact for a smooth
//! coat and a Lambertian base otherwise.
//!
//! **Mitsuba's `nonlinear = false`** (its default): the base's multiple reflections are
//! counted as ρ/(1 − K) instead of ρ/(1 − ρK), so that a textured base keeps its look
//! (plastic.cpp); `linear` reproduces it (still ≤ 1: it equals the nonlinear form with
//! a base ρ' = c/(1 + cK), c = ρ/(1 − K), and ρ' ≤ 1).
//!
//! **Wavelengths.** The coat's directions do not depend on η (reflection, and the
//! diffuse lobe's cosine), so every lane keeps its own η(λ), E, K and T̄; no companion
//! lane ends. K, T̄ and (rough coat) E(μ) are tabulated when the material is built over
//! a grid of η spanning n(λ) on 360–830 nm (one point for a constant index) and
//! interpolated per lane: no allocation per sample.
//!
//! **Sampling.** The specular lobe is chosen with probability E(μo)/(E(μo) + a_d), a_d
//! the diffuse lobe's albedo averaged over the lanes (so that a lane whose ρ is positive
//! always has a strategy); the diffuse lobe is cosine-sampled, the rough specular lobe
//! from the visible normals (Heitz 2018). A rough coat's pdf is the mixture of both, as
//! in pbrt-v4 and Mitsuba's roughplastic; a smooth coat's delta is taken apart.
//!
//! **Polarisation.** The smooth coat's delta reflection is the dielectric's Fresnel
//! reflection Mueller matrix per lane; the diffuse lobe (and the rough coat, whose
//! evaluation sums both lobes) depolarises.
//!
//! The surface is two-sided, as heron's Lambertian: ωo below the surface sees the same
//! layering mirrored.
//!
//! **Textures.** ρ may be a reflectance texture (`rho_texture`, looked up at the hit,
//! clamped to [0, 1]): ρ enters only the closed form's per-lane factor, so nothing is
//! tabulated for it. The roughness α may be a texture too ([`CoatedDiffuse::textured_alpha`]),
//! but E(μ) and K are tabulated per α when the material is built: the material then holds
//! one coat per *level* of α and each hit takes the level nearest to the texture's value
//! (its luminance). A texture of constants and checkerboards has its few values as the
//! levels, exactly; an image (or a mix) is quantised to [`ALPHA_LEVELS`] levels uniform
//! over its range of α (an error of at most half a step, (max − min)/62 in α).
use super::fresnel::fresnel_dielectric;
use super::microfacet::TrowbridgeReitz;
use super::polarization::{normalized, s_of_plane, Polarizing};
use super::texture_params::{alpha_at, reflectance_at};
use super::{
    reflect, reflect_local, same_hemisphere, BsdfContext, BsdfEval, BsdfModel, BsdfSample,
    LobeFlags,
};
use crate::math::warp::{cosine_hemisphere, cosine_hemisphere_pdf};
use crate::math::Frame;
use crate::optics::mueller;
use crate::spectrum::ior::Ior;
use crate::spectrum::{DenseSpectrum, SampledSpectrum, SampledWavelengths};
use crate::texture::Texture;
use glam::{Vec2, Vec3};
use num_complex::Complex64;
use std::f32::consts::FRAC_1_PI;
use std::sync::Arc;

/// Levels of α of a coat whose roughness is an image texture (module doc).
pub const ALPHA_LEVELS: usize = 32;

/// Points of the rough coat's E(μ) table, uniform in μ on [0, 1].
const N_MU: usize = 64;
/// Points of the η grid of a dispersive rough coat. Its diffuse lobe integrates the
/// same interpolated E(μ) that gave K and T̄, so the grid only sets how closely E
/// follows η.
const N_ETA: usize = 16;
/// Points of the η grid of a dispersive smooth coat, whose lobes use the exact F(μ, η)
/// while K and T̄ are interpolated: with 16 points the white furnace of N-SF11 missed 1
/// by 1.4e-5, with 128 by the f32 rounding (below 1e-6; `tests/coated.rs`).
const N_ETA_SMOOTH: usize = 128;
/// Midpoints of the quadratures over x = μ² that give K and T̄ (F(√x) has a √x cusp at
/// grazing incidence: the rule errs by ~N^(−3/2)).
const N_QUAD: usize = 16384;
/// Stratified visible-normal samples per side of the square for a rough E(μ).
const N_VNDF: usize = 64;

const DIFFUSE: LobeFlags = LobeFlags::DIFFUSE.union(LobeFlags::REFLECTION);
const SPECULAR: LobeFlags = LobeFlags::SPECULAR.union(LobeFlags::REFLECTION);
const GLOSSY: LobeFlags = LobeFlags::GLOSSY.union(LobeFlags::REFLECTION);

#[derive(Clone, Debug)]
pub struct CoatedDiffuse {
    /// The base's reflectance ρ(λ) in [0, 1].
    pub rho: DenseSpectrum,
    /// The coat's index relative to the outside, n(λ).
    pub ior: Ior,
    /// The coat's roughness; None for a smooth coat.
    pub distribution: Option<TrowbridgeReitz>,
    /// The absorbing layer's optical depth τ ≥ 0 (normal incidence, one way).
    pub thickness: f32,
    /// Mitsuba's `nonlinear = false`: ρ/(1 − K) instead of ρ/(1 − ρK).
    pub linear: bool,
    /// ρ over the surface's uv, replacing `rho` (None: the constant).
    pub rho_texture: Option<Arc<Texture>>,
    /// A roughness texture's levels (None: `distribution` everywhere).
    by_alpha: Option<Arc<AlphaLevels>>,
    table: CoatTable,
}

/// The coats of a textured roughness, one per level of α (sorted), all sharing the
/// base's reflectance.
#[derive(Clone, Debug)]
struct AlphaLevels {
    texture: Arc<Texture>,
    alphas: Vec<f32>,
    coats: Vec<CoatedDiffuse>,
}

impl AlphaLevels {
    /// The coat whose α is nearest to the texture's at the hit.
    #[inline]
    fn pick(&self, ctx: &BsdfContext) -> &CoatedDiffuse {
        let a = alpha_at(&self.texture, ctx).alpha;
        let i = self.alphas.partition_point(|&x| x < a);
        let i = if i == 0 {
            0
        } else if i == self.alphas.len() || a - self.alphas[i - 1] <= self.alphas[i] - a {
            i - 1
        } else {
            i
        };
        &self.coats[i]
    }
}

/// K, T̄ and (rough coat) E(μ) at `n` values of η from `eta_lo` in steps of `d_eta`.
#[derive(Clone, Debug)]
struct CoatTable {
    eta_lo: f32,
    d_eta: f32,
    n: usize,
    k: Vec<f32>,
    tbar: Vec<f32>,
    /// E(μ_j, η_i) at `i * N_MU + j`; empty for a smooth coat.
    e: Vec<f32>,
}

/// One lane's coat: η, its place on the η grid (index, fraction), K and T̄.
#[derive(Clone, Copy, Debug, Default)]
struct Lane {
    eta: f32,
    at: (usize, f32),
    k: f32,
    tbar: f32,
}

impl CoatedDiffuse {
    /// The material with its tables; α below [`super::microfacet::MIN_ALPHA`] is the
    /// caller's to turn into None (a smooth coat).
    pub fn new(
        rho: DenseSpectrum,
        ior: Ior,
        distribution: Option<TrowbridgeReitz>,
        thickness: f32,
        linear: bool,
    ) -> CoatedDiffuse {
        let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
        for l in (360..=830).step_by(5) {
            let n = ior.eval(l as f32);
            lo = lo.min(n);
            hi = hi.max(n);
        }
        let n = match (ior.is_dispersive() && hi > lo, distribution) {
            (false, _) => 1,
            (true, None) => N_ETA_SMOOTH,
            (true, Some(_)) => N_ETA,
        };
        let d_eta = if n > 1 {
            (hi - lo) / (n - 1) as f32
        } else {
            0.0
        };
        let mut table = CoatTable {
            eta_lo: lo,
            d_eta,
            n,
            k: Vec::with_capacity(n),
            tbar: Vec::with_capacity(n),
            e: Vec::new(),
        };
        let geometry = distribution.map(|d| vndf_geometry(&d));
        for i in 0..n {
            let eta = lo + d_eta * i as f32;
            // E(μ) per row of visible normals, with the relative index n_i/n_t the
            // light meets: 1/η from outside, η from inside.
            let albedo_rows = |eta_it: f32| {
                geometry.as_ref().map(|g| {
                    g.iter()
                        .map(|row| {
                            let s: f64 = row
                                .iter()
                                .map(|&(cos_m, w)| {
                                    w as f64 * fresnel_dielectric(cos_m, eta_it) as f64
                                })
                                .sum();
                            (s / row.len().max(1) as f64) as f32
                        })
                        .collect::<Vec<f32>>()
                })
            };
            let e_row = albedo_rows(1.0 / eta);
            let e_of = |mu: f32| match &e_row {
                Some(row) => lerp_table(row, mu),
                None => fresnel_dielectric(mu, 1.0 / eta),
            };
            let (mut k, tbar) = round_trip(eta, thickness, e_of);
            if let Some(inside) = albedo_rows(eta) {
                k = rough_round_trip(thickness, &inside);
            }
            table.k.push(k);
            table.tbar.push(tbar);
            if let Some(row) = e_row {
                table.e.extend(row);
            }
        }
        CoatedDiffuse {
            rho,
            ior,
            distribution,
            thickness,
            linear,
            rho_texture: None,
            by_alpha: None,
            table,
        }
    }

    /// The material with ρ looked up in `rho` at each hit.
    pub fn with_rho_texture(mut self, rho: Arc<Texture>) -> CoatedDiffuse {
        if let Some(l) = &mut self.by_alpha {
            for c in &mut Arc::make_mut(l).coats {
                c.rho_texture = Some(rho.clone());
            }
        }
        self.rho_texture = Some(rho);
        self
    }

    /// A rough coat whose α is the texture `alpha`'s luminance at each hit, clamped to
    /// [`super::microfacet::MIN_ALPHA`], 1]: one coat per level of α (module doc).
    pub fn textured_alpha(
        rho: DenseSpectrum,
        ior: Ior,
        alpha: Arc<Texture>,
        thickness: f32,
        linear: bool,
    ) -> CoatedDiffuse {
        let clamp = |a: f32| a.clamp(super::microfacet::MIN_ALPHA, 1.0);
        let mut alphas: Vec<f32> = match alpha.scalar_values(ALPHA_LEVELS) {
            Some(v) => v.into_iter().map(clamp).collect(),
            None => {
                let (lo, hi) = alpha.scalar_range();
                let (lo, hi) = (clamp(lo), clamp(hi));
                (0..ALPHA_LEVELS)
                    .map(|i| lo + (hi - lo) * i as f32 / (ALPHA_LEVELS - 1) as f32)
                    .collect()
            }
        };
        alphas.dedup();
        let coats: Vec<CoatedDiffuse> = alphas
            .iter()
            .map(|&alpha| {
                let d = TrowbridgeReitz { alpha };
                CoatedDiffuse::new(rho.clone(), ior.clone(), Some(d), thickness, linear)
            })
            .collect();
        // The outer material answers flags and mueller (rough, as every level); each
        // query goes to the level at the hit.
        let mut outer = coats[0].clone();
        outer.by_alpha = Some(Arc::new(AlphaLevels {
            texture: alpha,
            alphas,
            coats,
        }));
        outer
    }

    /// Whether a parameter is a texture (the hit's uv is read).
    pub fn is_textured(&self) -> bool {
        self.rho_texture.is_some() || self.by_alpha.is_some()
    }

    /// ρ per lane at the hit.
    #[inline]
    fn rho_at<const N: usize>(
        &self,
        wl: &SampledWavelengths<N>,
        ctx: &BsdfContext,
    ) -> SampledSpectrum<N> {
        match &self.rho_texture {
            None => wl.eval(&self.rho),
            Some(t) => reflectance_at(t, ctx, wl),
        }
    }

    /// The lane at `lambda` nm.
    #[inline]
    fn lane(&self, lambda: f32) -> Lane {
        let t = &self.table;
        let eta = self.ior.eval(lambda);
        if t.n == 1 {
            return Lane {
                eta,
                at: (0, 0.0),
                k: t.k[0],
                tbar: t.tbar[0],
            };
        }
        let x = ((eta - t.eta_lo) / t.d_eta).clamp(0.0, (t.n - 1) as f32);
        let i = (x as usize).min(t.n - 2);
        let f = x - i as f32;
        let mix = |v: &[f32]| v[i] + f * (v[i + 1] - v[i]);
        Lane {
            eta,
            at: (i, f),
            k: mix(&t.k),
            tbar: mix(&t.tbar),
        }
    }

    /// Every lane's coat; computed once when the index is constant.
    #[inline]
    fn lanes<const N: usize>(&self, wl: &SampledWavelengths<N>) -> [Lane; N] {
        if self.table.n == 1 && !self.ior.is_dispersive() {
            [self.lane(wl.lambda[0]); N]
        } else {
            std::array::from_fn(|i| self.lane(wl.lambda[i]))
        }
    }

    /// The coat's directional reflection albedo E(μ) for the lane `l`.
    #[inline]
    fn albedo(&self, l: &Lane, mu: f32) -> f32 {
        if self.distribution.is_none() {
            return fresnel_dielectric(mu, 1.0 / l.eta);
        }
        let (i, f) = l.at;
        let row = |i: usize| lerp_table(&self.table.e[i * N_MU..(i + 1) * N_MU], mu);
        if f == 0.0 {
            row(i)
        } else {
            (1.0 - f) * row(i) + f * row(i + 1)
        }
    }

    /// The layer's transmittance A(μ) = exp(−τ/μ') along the refracted direction.
    #[inline]
    fn attenuation(&self, eta: f32, mu: f32) -> f32 {
        attenuation(self.thickness, eta, mu)
    }

    /// (1 − E(μ)) A(μ) for each lane: the light that crosses the coat and the layer.
    #[inline]
    fn entry<const N: usize>(&self, lanes: &[Lane; N], mu: f32) -> [f32; N] {
        std::array::from_fn(|i| {
            (1.0 - self.albedo(&lanes[i], mu)) * self.attenuation(lanes[i].eta, mu)
        })
    }

    /// ρ/(π η² (1 − ρK)) per lane (or ρ/(1 − K) when `linear`): the diffuse lobe without
    /// its two entry factors.
    #[inline]
    fn base<const N: usize>(&self, lanes: &[Lane; N], rho: &SampledSpectrum<N>) -> [f32; N] {
        std::array::from_fn(|i| {
            let (l, r) = (&lanes[i], rho.0[i]);
            let k = if self.linear { l.k } else { r * l.k };
            r * FRAC_1_PI / (l.eta * l.eta * (1.0 - k).max(1e-6))
        })
    }

    /// The diffuse lobe f_d(ωo, ωi) per lane, both on the outer side (μ > 0).
    #[inline]
    fn diffuse<const N: usize>(
        &self,
        lanes: &[Lane; N],
        base: &[f32; N],
        entry_o: &[f32; N],
        mu_i: f32,
    ) -> SampledSpectrum<N> {
        let entry_i = self.entry(lanes, mu_i);
        SampledSpectrum(std::array::from_fn(|i| base[i] * entry_o[i] * entry_i[i]))
    }

    /// The rough coat's reflection D G F/(4 μo μi) per lane, both on the outer side.
    #[inline]
    fn glossy<const N: usize>(
        &self,
        d: &TrowbridgeReitz,
        lanes: &[Lane; N],
        wo: Vec3,
        wi: Vec3,
    ) -> SampledSpectrum<N> {
        let h = wo + wi;
        if h.length_squared() == 0.0 {
            return SampledSpectrum::zero();
        }
        let wm = h.normalize();
        let k = d.d(wm) * d.g(wo, wi) / (4.0 * wo.z * wi.z);
        let c = wo.dot(wm).abs();
        SampledSpectrum(std::array::from_fn(|i| {
            k * fresnel_dielectric(c, 1.0 / lanes[i].eta)
        }))
    }

    /// The probability of choosing the specular lobe at ωo under `ctx.lobes`, from the
    /// hero's E(μo) and the lanes' mean diffuse albedo.
    #[inline]
    fn p_specular<const N: usize>(
        &self,
        lanes: &[Lane; N],
        base: &[f32; N],
        entry_o: &[f32; N],
        mu_o: f32,
        ctx: &BsdfContext,
    ) -> f32 {
        let spec = if self.distribution.is_some() {
            GLOSSY
        } else {
            SPECULAR
        };
        let ws = if ctx.lobes.allows(spec) {
            self.albedo(&lanes[0], mu_o)
        } else {
            0.0
        };
        let wd = if ctx.lobes.allows(DIFFUSE) {
            (0..N)
                .map(|i| base[i] * std::f32::consts::PI * entry_o[i] * lanes[i].tbar)
                .sum::<f32>()
                / N as f32
        } else {
            0.0
        };
        if ws + wd <= 0.0 {
            return f32::NAN;
        }
        ws / (ws + wd)
    }

    /// Everything a query at ωo (outer side, μo > 0) needs.
    #[inline]
    fn setup<const N: usize>(
        &self,
        mu_o: f32,
        wl: &SampledWavelengths<N>,
        ctx: &BsdfContext,
    ) -> ([Lane; N], [f32; N], [f32; N], f32) {
        let lanes = self.lanes(wl);
        let base = self.base(&lanes, &self.rho_at(wl, ctx));
        let entry_o = self.entry(&lanes, mu_o);
        let ps = self.p_specular(&lanes, &base, &entry_o, mu_o, ctx);
        (lanes, base, entry_o, ps)
    }

    /// The density of a non-delta ωi (outer side) given the choice probability `ps`.
    #[inline]
    fn pdf_up(&self, wo: Vec3, wi: Vec3, ps: f32) -> f32 {
        let pd = (1.0 - ps) * cosine_hemisphere_pdf(wi.z);
        match &self.distribution {
            None => pd,
            Some(d) => {
                let h = wo + wi;
                if h.length_squared() == 0.0 || ps == 0.0 {
                    return pd;
                }
                let wm = h.normalize();
                pd + ps * d.d_visible(wo, wm) / (4.0 * wo.dot(wm).abs())
            }
        }
    }
}

/// ωo, ωi turned to the outer side (z > 0) together; None when on opposite sides.
#[inline]
fn upper(wo: Vec3, wi: Vec3) -> Option<(Vec3, Vec3)> {
    if !same_hemisphere(wo, wi) {
        return None;
    }
    let s = Vec3::new(1.0, 1.0, wo.z.signum());
    Some((wo * s, wi * s))
}

/// A(μ) = exp(−τ/μ'), μ' the cosine of the direction refracted into a coat of index η.
#[inline]
fn attenuation(tau: f32, eta: f32, mu: f32) -> f32 {
    if tau == 0.0 {
        return 1.0;
    }
    let mu_t = (1.0 - (1.0 - mu * mu) / (eta * eta)).max(0.0).sqrt();
    if mu_t == 0.0 {
        return 0.0;
    }
    (-tau / mu_t).exp()
}

/// The value at μ ∈ [0, 1] of a table uniform in μ, linearly interpolated.
#[inline]
fn lerp_table(row: &[f32], mu: f32) -> f32 {
    let x = mu.clamp(0.0, 1.0) * (row.len() - 1) as f32;
    let i = (x as usize).min(row.len() - 2);
    let f = x - i as f32;
    row[i] + f * (row[i + 1] - row[i])
}

/// (K, T̄) of a coat of index η over a layer of depth τ whose outer albedo is `e_of`,
/// by the midpoint rule in x = μ² (2∫ g(μ) μ dμ = ∫₀¹ g(√x) dx), in f64.
fn round_trip(eta: f32, tau: f32, e_of: impl Fn(f32) -> f32) -> (f32, f32) {
    let (mut escape, mut back) = (0.0f64, 0.0f64);
    for j in 0..N_QUAD {
        let mu = (((j as f64 + 0.5) / N_QUAD as f64).sqrt()) as f32;
        let (e, a) = (e_of(mu) as f64, attenuation(tau, eta, mu) as f64);
        escape += (1.0 - e) * a;
        back += e * a * a;
    }
    let (tbar, reflected) = (escape / N_QUAD as f64, back / N_QUAD as f64);
    let eta2 = (eta as f64) * (eta as f64);
    // Total internal reflection below μc: 2∫₀^μc e^(−2τ/μ') μ' dμ' = ∫₀^(μc²) e^(−2τ/√x) dx.
    let c2 = (1.0 - 1.0 / eta2).max(0.0);
    let tir = if tau == 0.0 {
        c2
    } else {
        (0..N_QUAD)
            .map(|j| {
                let x = (j as f64 + 0.5) / N_QUAD as f64 * c2;
                (-2.0 * tau as f64 / x.sqrt()).exp()
            })
            .sum::<f64>()
            * c2
            / N_QUAD as f64
    };
    ((tir + reflected / eta2) as f32, tbar as f32)
}

/// A rough coat's K: 2∫ E_in(μ') e^(−2τ/μ') μ' dμ' from the single-scattering
/// reflection albedo `inside` of the coat seen from within (a table over μ'), by the
/// midpoint rule in x = μ'², as Mitsuba 3's roughplastic.cpp (`m_internal_reflectance`).
/// It is below the reciprocal 1 − (1 − Ē)/η² by the light the microfacets lose at the
/// grazing internal angles of total reflection (single scattering only), which is what
/// makes a rough coat's white furnace fall short of 1.
fn rough_round_trip(tau: f32, inside: &[f32]) -> f32 {
    let sum: f64 = (0..N_QUAD)
        .map(|j| {
            let x = (j as f64 + 0.5) / N_QUAD as f64;
            let mu = x.sqrt();
            let a = if tau == 0.0 {
                1.0
            } else {
                (-2.0 * tau as f64 / mu).exp()
            };
            lerp_table(inside, mu as f32) as f64 * a
        })
        .sum();
    (sum / N_QUAD as f64) as f32
}

/// For each μ of the E(μ) table, the visible normals of a stratified grid: (ωo·ωm, the
/// weight G2/G1 of the reflected direction, 0 below the surface). E(μ) is then the mean
/// of F(ωo·ωm) × weight: f μi / pdf = F G2/G1 for visible-normal sampling (Heitz 2018).
fn vndf_geometry(d: &TrowbridgeReitz) -> Vec<Vec<(f32, f32)>> {
    (0..N_MU)
        .map(|j| {
            let mu = (j as f32 / (N_MU - 1) as f32).max(1e-3);
            let wo = Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
            let mut row = Vec::with_capacity(N_VNDF * N_VNDF);
            for a in 0..N_VNDF {
                for b in 0..N_VNDF {
                    let u = Vec2::new(
                        (a as f32 + 0.5) / N_VNDF as f32,
                        (b as f32 + 0.5) / N_VNDF as f32,
                    );
                    let wm = d.sample_wm(wo, u);
                    let wi = reflect(wo, wm);
                    let w = if wi.z > 0.0 {
                        d.g(wo, wi) / d.g1(wo)
                    } else {
                        0.0
                    };
                    row.push((wo.dot(wm).abs(), w));
                }
            }
            row
        })
        .collect()
}

impl BsdfModel for CoatedDiffuse {
    #[inline]
    fn flags(&self) -> LobeFlags {
        let spec = if self.distribution.is_some() {
            GLOSSY
        } else {
            SPECULAR
        };
        if self.rho.max_value() > 0.0 || self.rho_texture.is_some() {
            spec | DIFFUSE
        } else {
            spec
        }
    }

    #[inline]
    fn eval<const N: usize>(
        &self,
        wo: Vec3,
        wi: Vec3,
        wl: &SampledWavelengths<N>,
        ctx: &BsdfContext,
    ) -> BsdfEval<N> {
        if let Some(l) = &self.by_alpha {
            return l.pick(ctx).eval(wo, wi, wl, ctx);
        }
        let Some((wo, wi)) = upper(wo, wi) else {
            return BsdfEval::zero();
        };
        let lanes = self.lanes(wl);
        let base = self.base(&lanes, &self.rho_at(wl, ctx));
        let entry_o = self.entry(&lanes, wo.z);
        let mut f = self.diffuse(&lanes, &base, &entry_o, wi.z);
        if let Some(d) = &self.distribution {
            f += self.glossy(d, &lanes, wo, wi);
        }
        BsdfEval::keep(f)
    }

    #[inline]
    fn pdf<const N: usize>(
        &self,
        wo: Vec3,
        wi: Vec3,
        wl: &SampledWavelengths<N>,
        ctx: &BsdfContext,
    ) -> f32 {
        if let Some(l) = &self.by_alpha {
            return l.pick(ctx).pdf(wo, wi, wl, ctx);
        }
        let Some((wo, wi)) = upper(wo, wi) else {
            return 0.0;
        };
        let (_, _, _, ps) = self.setup(wo.z, wl, ctx);
        if ps.is_nan() {
            return 0.0;
        }
        self.pdf_up(wo, wi, ps)
    }

    #[inline]
    fn sample<const N: usize>(
        &self,
        wo: Vec3,
        uc: f32,
        u: Vec2,
        wl: &SampledWavelengths<N>,
        ctx: &BsdfContext,
    ) -> Option<BsdfSample<N>> {
        if let Some(l) = &self.by_alpha {
            return l.pick(ctx).sample(wo, uc, u, wl, ctx);
        }
        let flip = Vec3::new(1.0, 1.0, wo.z.signum());
        let wo = wo * flip;
        let (lanes, base, entry_o, ps) = self.setup(wo.z, wl, ctx);
        if ps.is_nan() {
            return None;
        }
        let specular = uc < ps;
        let wi = match (&self.distribution, specular) {
            (None, true) => {
                let f =
                    SampledSpectrum(std::array::from_fn(|i| self.albedo(&lanes[i], wo.z) / wo.z));
                return Some(BsdfSample {
                    wi: reflect_local(wo) * flip,
                    f,
                    pdf: ps,
                    flags: SPECULAR,
                    eta: 1.0,
                    ended_companions: false,
                });
            }
            (Some(d), true) => reflect(wo, d.sample_wm(wo, u)),
            (_, false) => cosine_hemisphere(u),
        };
        if wi.z <= 0.0 {
            return None;
        }
        let pdf = self.pdf_up(wo, wi, ps);
        if !(pdf > 0.0) {
            return None;
        }
        let mut f = self.diffuse(&lanes, &base, &entry_o, wi.z);
        if let Some(d) = &self.distribution {
            f += self.glossy(d, &lanes, wo, wi);
        }
        Some(BsdfSample {
            wi: wi * flip,
            f,
            pdf,
            flags: match (&self.distribution, specular) {
                (_, false) => DIFFUSE,
                _ => GLOSSY,
            },
            eta: 1.0,
            ended_companions: false,
        })
    }

    /// The smooth coat's delta reflection: the dielectric's Fresnel reflection per lane
    /// (as [`super::Dielectric`]'s, in the plane of incidence); the diffuse lobe and a
    /// rough coat depolarise.
    #[inline]
    fn mueller<const N: usize>(
        &self,
        _: Vec3,
        wi: Vec3,
        lobe: LobeFlags,
        wl: &SampledWavelengths<N>,
        _: &Frame,
    ) -> Polarizing<N> {
        if !lobe.is_specular() || self.distribution.is_some() {
            return Polarizing::Depolarizing;
        }
        let x = s_of_plane(wi);
        let cos = wi.z.abs() as f64;
        let m = std::array::from_fn(|i| {
            let eta = self.ior.eval(wl.lambda[i]) as f64;
            normalized(&mueller::reflection(cos, Complex64::new(eta, 0.0)))
        });
        Polarizing::Mueller {
            m,
            x_in: x,
            x_out: x,
        }
    }
}
