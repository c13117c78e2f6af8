//! The Aristotelian rainbow, exactly as in the seed lecture (Frisvad, Christensen &
//! Falster 2007, "The Aristotelian rainbow: from philosophy to computer graphics",
//! GRAPHITE 2007, pp. 119–128): the bow is where ω·ω′ = cos 42°, ω the view direction and
//! ω′ the unit direction toward the antisolar point. The sun is a disk of angular radius
//! α, so the antisolar point is smeared over a disk too: ω′_high and ω′_low are ω′ tilted
//! by α in the plane of ω and ω′ away from and toward ω, and
//!
//!   a = ω·ω′_high = cos(θ + α),  b = ω·ω′_low = cos(θ − α)   (a ≤ b).
//!
//! Where a < cos 42° < b (that is |θ − 42°| < α), the colour is looked up in a 1D spectral
//! texture at t = smoothstep(a, b, cos 42°) = 3s² − 2s³, s = (cos 42° − a)/(b − a); t = 0 at
//! the inner edge (θ = 42° − α) and 1 at the outer edge (θ = 42° + α). Elsewhere: the
//! background.
//!
//! The texture is spectra/aristotle_bow.csv (derivation in spectra/README.md and
//! [`derive_texture_csv`]): for each t a premultiplied spectral radiance R(t, λ) and a
//! coverage α_t; the bow is composited *over* the background:
//! L = s·R(t, λ) + (1 − s·α_t)·L_bg(λ), s = `strength` ∈ [0, 1].
use crate::spectrum::DenseSpectrum;
use glam::Vec3;
use std::sync::OnceLock;

/// cos 42°, the seed's 0.7431.
pub const COS_42: f64 = 0.743_144_825_477_394_2;

const TEXTURE_CSV: &str = include_str!("../../spectra/aristotle_bow.csv");

/// Texture rows t = 0, 1/(T_ROWS−1), …, 1.
pub const T_ROWS: usize = 41;
/// Texture columns every 5 nm over 360–830 nm.
pub const LAMBDA_STEP: f32 = 5.0;
pub const LAMBDA_COLUMNS: usize = 95;
/// The band of wavelengths spread across the bow: violet inside, red outside.
pub const BAND_VIOLET_NM: f64 = 400.0;
pub const BAND_RED_NM: f64 = 700.0;
/// Gaussian width (standard deviation) of each row's spectrum, nm.
pub const BAND_SIGMA_NM: f64 = 12.0;

/// The parsed texture: coverage per row and spectral radiance per row and column.
pub struct BowTexture {
    pub alpha: Vec<f32>,
    pub radiance: Vec<[f32; LAMBDA_COLUMNS]>,
}

impl BowTexture {
    /// Parses the CSV layout written by [`derive_texture_csv`].
    pub fn parse(csv: &str) -> Result<BowTexture, String> {
        let mut lines = csv
            .lines()
            .filter(|l| !l.trim().is_empty() && !l.starts_with('#'));
        let header = lines.next().ok_or("empty texture")?;
        let cols: Vec<&str> = header.split(',').collect();
        if cols.len() != 2 + LAMBDA_COLUMNS || cols[0] != "t" || cols[1] != "alpha" {
            return Err(format!("unexpected header {header:?}"));
        }
        let mut alpha = Vec::new();
        let mut radiance = Vec::new();
        for (r, line) in lines.enumerate() {
            let v: Vec<f32> = line
                .split(',')
                .map(|x| x.trim().parse::<f32>().map_err(|e| format!("row {r}: {e}")))
                .collect::<Result<_, _>>()?;
            if v.len() != 2 + LAMBDA_COLUMNS {
                return Err(format!("row {r}: {} values", v.len()));
            }
            let want_t = r as f32 / (T_ROWS - 1) as f32;
            if (v[0] - want_t).abs() > 1e-6 {
                return Err(format!("row {r}: t = {} instead of {want_t}", v[0]));
            }
            alpha.push(v[1]);
            let mut row = [0.0; LAMBDA_COLUMNS];
            row.copy_from_slice(&v[2..]);
            radiance.push(row);
        }
        if alpha.len() != T_ROWS {
            return Err(format!("{} rows instead of {T_ROWS}", alpha.len()));
        }
        Ok(BowTexture { alpha, radiance })
    }

    /// The embedded spectra/aristotle_bow.csv.
    pub fn embedded() -> &'static BowTexture {
        static T: OnceLock<BowTexture> = OnceLock::new();
        T.get_or_init(|| BowTexture::parse(TEXTURE_CSV).expect("spectra/aristotle_bow.csv"))
    }

    fn row_pos(t: f64) -> (usize, f32) {
        let x = (t.clamp(0.0, 1.0) * (T_ROWS - 1) as f64) as f32;
        let i = (x as usize).min(T_ROWS - 2);
        (i, x - i as f32)
    }

    /// Coverage α_t at t (linear interpolation between rows).
    pub fn coverage(&self, t: f64) -> f32 {
        let (i, f) = Self::row_pos(t);
        self.alpha[i] + f * (self.alpha[i + 1] - self.alpha[i])
    }

    /// Premultiplied radiance R(t, λ) (bilinear; 0 outside 360–830 nm).
    pub fn radiance(&self, t: f64, lambda_nm: f32) -> f32 {
        let y = (lambda_nm - 360.0) / LAMBDA_STEP;
        if !(0.0..=(LAMBDA_COLUMNS - 1) as f32).contains(&y) {
            return 0.0;
        }
        let j = (y as usize).min(LAMBDA_COLUMNS - 2);
        let g = y - j as f32;
        let (i, f) = Self::row_pos(t);
        let at = |r: &[f32; LAMBDA_COLUMNS]| r[j] + g * (r[j + 1] - r[j]);
        let (a, b) = (at(&self.radiance[i]), at(&self.radiance[i + 1]));
        a + f * (b - a)
    }
}

/// Hermite smoothstep(e0, e1, x) = 3s² − 2s³, s = clamp((x − e0)/(e1 − e0), 0, 1).
#[inline]
pub fn smoothstep(e0: f64, e1: f64, x: f64) -> f64 {
    let s = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    s * s * (3.0 - 2.0 * s)
}

/// The Aristotelian rainbow over a background sky.
#[derive(Clone, Debug)]
pub struct AristotleSky {
    /// Sun angular radius α, radians (> 0).
    pub sun_radius: f64,
    /// Background sky radiance L_bg(λ).
    pub background: DenseSpectrum,
    /// Opacity of the bow over the background, in [0, 1].
    pub strength: f32,
}

impl AristotleSky {
    pub fn new(sun_radius: f64, background: DenseSpectrum) -> Self {
        AristotleSky {
            sun_radius,
            background,
            strength: 1.0,
        }
    }

    /// Composites the texture at t over the background.
    fn shade(&self, t: Option<f64>, lambda_nm: f32) -> f32 {
        let bg = self.background.eval(lambda_nm);
        match t {
            None => bg,
            Some(t) => {
                let tex = BowTexture::embedded();
                self.strength * tex.radiance(t, lambda_nm)
                    + (1.0 - self.strength * tex.coverage(t)) * bg
            }
        }
    }

    /// The seed's lookup coordinate from a = ω·ω′_high and b = ω·ω′_low: Some(t) where
    /// a < cos 42° < b.
    #[inline]
    pub fn lookup(a: f64, b: f64) -> Option<f64> {
        (a < COS_42 && COS_42 < b).then(|| smoothstep(a, b, COS_42))
    }

    /// The seed's formula with vectors: ω′ = −sun_dir, ω′_high/low = ω′ tilted by ∓α in the
    /// plane of ω and ω′ (away from / toward ω).
    pub fn radiance(&self, view_dir: Vec3, lambda_nm: f32, sun_dir: Vec3) -> f32 {
        let w = view_dir.as_dvec3().normalize();
        let wp = -sun_dir.as_dvec3().normalize();
        let perp = w - w.dot(wp) * wp;
        let len = perp.length();
        if len < 1e-12 {
            // Looking at the antisolar point: θ = 0, far from the bow.
            return self.shade(None, lambda_nm);
        }
        let e = perp / len;
        let (s, c) = self.sun_radius.sin_cos();
        let high = c * wp - s * e;
        let low = c * wp + s * e;
        self.shade(Self::lookup(w.dot(high), w.dot(low)), lambda_nm)
    }

    /// The same at angle θ from the antisolar point: a = cos(θ + α), b = cos(θ − α).
    pub fn profile(&self, theta_rad: f64, lambda_nm: f32) -> f32 {
        let a = (theta_rad + self.sun_radius).cos();
        let b = (theta_rad - self.sun_radius).cos();
        self.shade(Self::lookup(a, b), lambda_nm)
    }
}

/// λ(t) across the bow: the wavelength whose Descartes primary angle for water sits at
/// fraction t between that of 400 nm (t = 0, inside) and 700 nm (t = 1, outside).
pub fn band_wavelength(t: f64) -> f64 {
    let water = crate::spectrum::ior::named("water").expect("water");
    let angle = |l: f64| super::descartes::rainbow_angle(water.eval(l as f32) as f64, 1);
    if t <= 0.0 {
        return BAND_VIOLET_NM;
    }
    if t >= 1.0 {
        return BAND_RED_NM;
    }
    let (a0, a1) = (angle(BAND_VIOLET_NM), angle(BAND_RED_NM));
    let target = a0 + t * (a1 - a0);
    let (mut lo, mut hi) = (BAND_VIOLET_NM, BAND_RED_NM);
    for _ in 0..60 {
        let m = 0.5 * (lo + hi);
        if angle(m) < target {
            lo = m;
        } else {
            hi = m;
        }
    }
    0.5 * (lo + hi)
}

/// Writes spectra/aristotle_bow.csv (see spectra/README.md): header
/// `t,alpha,360,365,…,830`; row r has t = r/40, coverage α_t = sin(πt), and
/// R(t, λ) = α_t · C · exp(−(λ − λ(t))²/(2σ²)), σ = 12 nm, λ(t) = [`band_wavelength`], with C
/// such that every unit-coverage row has the same radiant power and the brightest has
/// luminance Y = 1 under heron's film convention.
pub fn derive_texture_csv() -> String {
    let obs = crate::spectrum::cie::cie1931();
    let gauss = |l: f64, c: f64| (-(l - c).powi(2) / (2.0 * BAND_SIGMA_NM.powi(2))).exp();
    let centres: Vec<f64> = (0..T_ROWS)
        .map(|r| band_wavelength(r as f64 / (T_ROWS - 1) as f64))
        .collect();
    // Luminance (film convention, 1 nm sums) of the unit-area Gaussian at each centre.
    let norm = (2.0 * std::f64::consts::PI).sqrt() * BAND_SIGMA_NM;
    let y_of = |c: f64| {
        (0..crate::spectrum::DENSE_LEN)
            .map(|i| {
                let l = 360.0 + i as f64;
                gauss(l, c) / norm * obs.y.values()[i] as f64
            })
            .sum::<f64>()
            / obs.y_integral as f64
    };
    let y_max = centres.iter().map(|&c| y_of(c)).fold(0.0, f64::max);
    let scale = 1.0 / (norm * y_max);
    let mut out = String::from("t,alpha");
    for j in 0..LAMBDA_COLUMNS {
        out.push_str(&format!(",{}", 360 + 5 * j));
    }
    out.push('\n');
    for (r, &c) in centres.iter().enumerate() {
        let t = r as f64 / (T_ROWS - 1) as f64;
        let cov = (std::f64::consts::PI * t).sin().max(0.0);
        let cov = if cov < 1e-12 { 0.0 } else { cov };
        out.push_str(&format!("{t},{cov:.6}"));
        for j in 0..LAMBDA_COLUMNS {
            let l = 360.0 + 5.0 * j as f64;
            let v = cov * scale * gauss(l, c);
            out.push_str(&format!(",{}", fmt_sig(v)));
        }
        out.push('\n');
    }
    out
}

/// Six significant digits, plain zero for values below 1e-12.
fn fmt_sig(v: f64) -> String {
    if v.abs() < 1e-12 {
        "0".into()
    } else {
        format!("{v:.5e}")
    }
}
