//! RGB to spectrum after Jakob & Hanika (2019), "A Low-Dimensional Function Space for
//! Efficient Spectral Upsampling", Computer Graphics Forum 38(2) (Proc. Eurographics).
//!
//! A reflectance is the sigmoid of a quadratic polynomial in wavelength:
//!
//! ```text
//! s(λ) = S(c0 t² + c1 t + c2),   S(x) = ½ + x / (2 √(1 + x²)),
//! t = (λ − 595 nm) / 235 nm       (so t ∈ [−1, 1] over heron's 360–830 nm)
//! ```
//!
//! heron uses a normalised wavelength t rather than λ in nm (the paper's and pbrt-v4's
//! convention) because the basis {t², t, 1} is well conditioned on [−1, 1], which keeps
//! the Gauss–Newton fits stable and the f32 evaluation free of cancellation. The two are
//! related by a fixed linear map of the coefficients, so trilinear interpolation of the
//! coefficients means the same thing in either.
//!
//! S maps the real line into (0, 1), so every spectrum of this family is a valid
//! reflectance at every wavelength. Three coefficients per colour are found by the fit
//! in [`fit`] (Gauss–Newton in CIELAB against heron's own film convention, D65 and CIE
//! 1931 2°) on a grid over the sRGB cube and stored in `spectra/rgb2spec_srgb.bin`
//! (format in spectra/README.md; regenerate with `cargo run --release --example
//! fit_rgb2spec`). The table is embedded with `include_bytes!`: nothing is read at run
//! time. A lookup interpolates the coefficients trilinearly, as the paper does.
use super::DenseSpectrum;
use std::fmt;
use std::sync::OnceLock;

pub mod fit;

/// Centre of the normalised wavelength t, nm.
pub const LAMBDA_CENTRE: f32 = 595.0;
/// Half width of the normalised wavelength t, nm: t = (λ − 595) / 235.
pub const LAMBDA_HALF_WIDTH: f32 = 235.0;

/// Normalised wavelength t = (λ − 595 nm) / 235 nm of a wavelength in nm.
#[inline]
pub fn normalised_lambda(lambda_nm: f64) -> f64 {
    (lambda_nm - LAMBDA_CENTRE as f64) / LAMBDA_HALF_WIDTH as f64
}

/// The paper's sigmoid S(x) = ½ + x / (2 √(1 + x²)), with S(±∞) = 1, 0 exactly (used by
/// white and black) and no overflow for huge |x|.
#[inline]
pub fn sigmoid(x: f64) -> f64 {
    if x.abs() > 1e150 {
        return if x > 0.0 { 1.0 } else { 0.0 };
    }
    0.5 + 0.5 * x / (1.0 + x * x).sqrt()
}

/// [`sigmoid`] in single precision.
#[inline]
pub fn sigmoid_f32(x: f32) -> f32 {
    if x.abs() > 1e18 {
        return if x > 0.0 { 1.0 } else { 0.0 };
    }
    0.5 + 0.5 * x / (1.0 + x * x).sqrt()
}

/// Coefficients (c0, c1, c2) of s(λ) = S(c0 t² + c1 t + c2) in the normalised wavelength
/// t (see the module docs). Infinite c2 with c0 = c1 = 0 is allowed: ±∞ is the constant
/// 1 or 0 (white, black).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SigmoidPolynomial {
    pub c: [f32; 3],
}

impl SigmoidPolynomial {
    /// The constant spectrum g (g in [0, 1]): c = (0, 0, (g − ½) / √(g (1 − g))), which
    /// is −∞ for g = 0 and +∞ for g = 1.
    pub fn grey(g: f32) -> Self {
        let g = g.clamp(0.0, 1.0) as f64;
        let c2 = if g <= 0.0 {
            f64::NEG_INFINITY
        } else if g >= 1.0 {
            f64::INFINITY
        } else {
            (g - 0.5) / (g * (1.0 - g)).sqrt()
        };
        SigmoidPolynomial {
            c: [0.0, 0.0, c2 as f32],
        }
    }

    /// s(λ) at a wavelength in nm. For c0 = c1 = 0 the polynomial is c2 exactly, so a
    /// grey is the same value at every wavelength.
    #[inline]
    pub fn eval(&self, lambda_nm: f32) -> f32 {
        let t = (lambda_nm - LAMBDA_CENTRE) / LAMBDA_HALF_WIDTH;
        let [c0, c1, c2] = self.c;
        sigmoid_f32((c0 * t + c1) * t + c2)
    }

    /// The spectrum on heron's 1 nm grid. The polynomial is evaluated in double precision
    /// (cheap: this runs when a scene is loaded) so that large coefficients of saturated
    /// colours lose nothing to cancellation.
    pub fn to_dense(&self) -> DenseSpectrum {
        let [c0, c1, c2] = self.c.map(f64::from);
        if c0 == 0.0 && c1 == 0.0 {
            return DenseSpectrum::constant(sigmoid(c2) as f32);
        }
        DenseSpectrum::from_fn(|l| {
            let t = normalised_lambda(l as f64);
            sigmoid((c0 * t + c1) * t + c2) as f32
        })
    }
}

/// Why a coefficient table could not be parsed.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum TableError {
    TooShort(usize),
    BadMagic,
    UnsupportedVersion(u32),
    BadResolution(u32),
    WrongWavelengthMapping,
    WrongSize { expected: usize, actual: usize },
    NonFinite(usize),
    ZNodesNotIncreasing,
}

impl fmt::Display for TableError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TableError::TooShort(n) => write!(f, "{n} bytes is shorter than the header"),
            TableError::BadMagic => write!(f, "the file does not start with {:?}", MAGIC),
            TableError::UnsupportedVersion(v) => write!(f, "version {v}, expected {VERSION}"),
            TableError::BadResolution(r) => write!(f, "resolution {r}, expected 2..=256"),
            TableError::WrongWavelengthMapping => write!(
                f,
                "wavelength normalisation differs from t = (λ − {LAMBDA_CENTRE}) / {LAMBDA_HALF_WIDTH}"
            ),
            TableError::WrongSize { expected, actual } => {
                write!(f, "{actual} bytes, expected {expected} for this resolution")
            }
            TableError::NonFinite(i) => write!(f, "coefficient {i} is not finite"),
            TableError::ZNodesNotIncreasing => {
                write!(f, "the z nodes do not rise strictly from 0 to 1")
            }
        }
    }
}

impl std::error::Error for TableError {}

/// First 8 bytes of a table file.
pub const MAGIC: &[u8; 8] = b"HRGB2SPC";
/// Format version in the header.
pub const VERSION: u32 = 1;
/// Header size in bytes: magic, version, resolution, λ centre, λ half width.
pub const HEADER_LEN: usize = 24;

/// Size in bytes of a table file of resolution `res`: header, `res` z nodes, then
/// 3 · res³ · 3 coefficients, all little-endian 32-bit.
pub const fn table_file_len(res: usize) -> usize {
    HEADER_LEN + 4 * res + 4 * 9 * res * res * res
}

/// A coefficient table after Jakob & Hanika (2019), §4: for each ordering l (which of
/// r, g, b is largest), a res³ grid over (x, y, z) where z is the largest component and
/// x, y are the components (l + 1) mod 3 and (l + 2) mod 3 divided by z. x and y are
/// uniform in [0, 1]; z sits on `z_nodes` (smoothstep∘smoothstep spacing, dense near 0
/// and 1, where the coefficients change fastest).
#[derive(Clone, Debug, PartialEq)]
pub struct Rgb2SpecTable {
    res: usize,
    z_nodes: Vec<f32>,
    /// Index ((((l · res + k) · res + yi) · res + xi) · 3 + j) for ordering l, z node k,
    /// y node yi, x node xi, coefficient j.
    coeffs: Vec<f32>,
}

/// smoothstep(x) = x² (3 − 2x).
pub fn smoothstep(x: f64) -> f64 {
    x * x * (3.0 - 2.0 * x)
}

/// The z nodes of a table of resolution `res`: smoothstep(smoothstep(k / (res − 1))).
pub fn z_nodes(res: usize) -> Vec<f32> {
    (0..res)
        .map(|k| smoothstep(smoothstep(k as f64 / (res - 1) as f64)) as f32)
        .collect()
}

impl Rgb2SpecTable {
    /// A table from its parts; `coeffs` is laid out as documented on the struct.
    pub fn new(res: usize, coeffs: Vec<f32>) -> Self {
        assert!(res >= 2);
        assert_eq!(coeffs.len(), 9 * res * res * res);
        Rgb2SpecTable {
            res,
            z_nodes: z_nodes(res),
            coeffs,
        }
    }

    pub fn res(&self) -> usize {
        self.res
    }

    pub fn z_nodes(&self) -> &[f32] {
        &self.z_nodes
    }

    /// Flat index of coefficient 0 of a node.
    #[inline]
    pub fn node_index(&self, l: usize, k: usize, yi: usize, xi: usize) -> usize {
        (((l * self.res + k) * self.res + yi) * self.res + xi) * 3
    }

    /// Coefficients stored at a node.
    pub fn node(&self, l: usize, k: usize, yi: usize, xi: usize) -> [f32; 3] {
        let i = self.node_index(l, k, yi, xi);
        [self.coeffs[i], self.coeffs[i + 1], self.coeffs[i + 2]]
    }

    /// The linear sRGB colour a node was fitted to.
    pub fn node_rgb(&self, l: usize, k: usize, yi: usize, xi: usize) -> [f64; 3] {
        let z = self.z_nodes[k] as f64;
        let s = (self.res - 1) as f64;
        let mut rgb = [0.0; 3];
        rgb[l] = z;
        rgb[(l + 1) % 3] = xi as f64 / s * z;
        rgb[(l + 2) % 3] = yi as f64 / s * z;
        rgb
    }

    /// Serialises to the file format documented in spectra/README.md.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(table_file_len(self.res));
        out.extend_from_slice(MAGIC);
        out.extend_from_slice(&VERSION.to_le_bytes());
        out.extend_from_slice(&(self.res as u32).to_le_bytes());
        out.extend_from_slice(&LAMBDA_CENTRE.to_le_bytes());
        out.extend_from_slice(&LAMBDA_HALF_WIDTH.to_le_bytes());
        for v in self.z_nodes.iter().chain(&self.coeffs) {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out
    }

    /// Parses the file format documented in spectra/README.md, checking the header, the
    /// size, the z nodes (they must be the ones this code would compute) and that every
    /// coefficient is finite.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, TableError> {
        if bytes.len() < HEADER_LEN {
            return Err(TableError::TooShort(bytes.len()));
        }
        if &bytes[0..8] != MAGIC {
            return Err(TableError::BadMagic);
        }
        let u32_at = |o: usize| u32::from_le_bytes(bytes[o..o + 4].try_into().unwrap());
        let f32_at = |o: usize| f32::from_le_bytes(bytes[o..o + 4].try_into().unwrap());
        let version = u32_at(8);
        if version != VERSION {
            return Err(TableError::UnsupportedVersion(version));
        }
        let res = u32_at(12);
        if !(2..=256).contains(&res) {
            return Err(TableError::BadResolution(res));
        }
        if f32_at(16) != LAMBDA_CENTRE || f32_at(20) != LAMBDA_HALF_WIDTH {
            return Err(TableError::WrongWavelengthMapping);
        }
        let res = res as usize;
        let expected = table_file_len(res);
        if bytes.len() != expected {
            return Err(TableError::WrongSize {
                expected,
                actual: bytes.len(),
            });
        }
        let floats: Vec<f32> = bytes[HEADER_LEN..]
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
            .collect();
        let (zs, coeffs) = floats.split_at(res);
        if zs != z_nodes(res).as_slice() {
            return Err(TableError::ZNodesNotIncreasing);
        }
        if let Some(i) = coeffs.iter().position(|v| !v.is_finite()) {
            return Err(TableError::NonFinite(i));
        }
        Ok(Rgb2SpecTable {
            res,
            z_nodes: zs.to_vec(),
            coeffs: coeffs.to_vec(),
        })
    }

    /// Sigmoid-polynomial coefficients for a linear sRGB colour (components clamped to
    /// [0, 1]; NaN counts as 0). Exact greys, black included, are the constant spectrum
    /// ([`SigmoidPolynomial::grey`]); other colours interpolate the table trilinearly.
    pub fn lookup(&self, rgb: [f32; 3]) -> SigmoidPolynomial {
        let rgb = rgb.map(|v| if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) });
        if rgb[0] == rgb[1] && rgb[1] == rgb[2] {
            return SigmoidPolynomial::grey(rgb[0]);
        }
        let l = if rgb[0] >= rgb[1] && rgb[0] >= rgb[2] {
            0
        } else if rgb[1] >= rgb[2] {
            1
        } else {
            2
        };
        let z = rgb[l]; // > 0: the components are not all equal and none is negative
        let n = self.res;
        let scale = (n - 1) as f32 / z;
        let x = (rgb[(l + 1) % 3] * scale).min((n - 1) as f32);
        let y = (rgb[(l + 2) % 3] * scale).min((n - 1) as f32);
        let xi = (x as usize).min(n - 2);
        let yi = (y as usize).min(n - 2);
        let zi = self
            .z_nodes
            .partition_point(|&v| v <= z)
            .saturating_sub(1)
            .min(n - 2);
        let dx = x - xi as f32;
        let dy = y - yi as f32;
        let dz = ((z - self.z_nodes[zi]) / (self.z_nodes[zi + 1] - self.z_nodes[zi])).min(1.0);
        let mut c = [0.0f32; 3];
        for (j, cj) in c.iter_mut().enumerate() {
            let at =
                |k: usize, yy: usize, xx: usize| self.coeffs[self.node_index(l, k, yy, xx) + j];
            let lerp = |a: f32, b: f32, t: f32| a + t * (b - a);
            let plane = |k: usize| {
                lerp(
                    lerp(at(k, yi, xi), at(k, yi, xi + 1), dx),
                    lerp(at(k, yi + 1, xi), at(k, yi + 1, xi + 1), dx),
                    dy,
                )
            };
            *cj = lerp(plane(zi), plane(zi + 1), dz);
        }
        SigmoidPolynomial { c }
    }

    /// Coefficients at the grid node nearest to a non-grey colour in [0, 1]³ (a second
    /// start for [`Self::coefficients`]).
    fn nearest_node(&self, rgb: [f32; 3]) -> [f64; 3] {
        let l = (0..3).fold(0, |m, i| if rgb[i] > rgb[m] { i } else { m });
        let z = rgb[l];
        let n = self.res - 1;
        let x = ((rgb[(l + 1) % 3] / z * n as f32).round() as usize).min(n);
        let y = ((rgb[(l + 2) % 3] / z * n as f32).round() as usize).min(n);
        let k = self
            .z_nodes
            .iter()
            .enumerate()
            .min_by(|a, b| (a.1 - z).abs().total_cmp(&(b.1 - z).abs()))
            .map_or(1, |(k, _)| k.max(1));
        self.node(l, k, y, x).map(f64::from)
    }

    /// Coefficients whose reflectance has linear sRGB colour `rgb` (components clamped
    /// to [0, 1]) through heron's film, to ΔE*ab 1e-8: the trilinear [`Self::lookup`]
    /// followed by Gauss–Newton ([`fit::ColourModel::fit`]) from the interpolated
    /// coefficients.
    ///
    /// Why the polish: the paper's trilinear interpolation alone misses by up to ~2e-3
    /// (res 64) for saturated colours and by up to ~1.5e-2 next to the white corner,
    /// where the coefficients grow without bound (white itself is c2 = +∞); see the
    /// measurements in spectra/README.md. So the interpolated coefficients are only a
    /// (very good) start. heron uplifts a colour once, when a scene is loaded, so the few
    /// Gauss–Newton steps (microseconds) cost nothing that matters, and the result is
    /// still one sigmoid polynomial of the paper's space. Greys (black and white
    /// included) are the exact constant spectrum and need no fit.
    /// The coefficients of an image's texel (components in [0, 1]): greys exact, others
    /// the table's trilinear [`Self::lookup`] without the polish, which an image's
    /// millions of texels could not afford (within ~2e-3 of the colour for saturated
    /// ones; environment maps and textures, as Mitsuba 3 and pbrt-v4 do).
    pub fn texel(&self, rgb: [f32; 3]) -> SigmoidPolynomial {
        if rgb[0] == rgb[1] && rgb[1] == rgb[2] {
            SigmoidPolynomial::grey(rgb[0])
        } else {
            self.lookup(rgb)
        }
    }

    pub fn coefficients(&self, rgb: [f32; 3]) -> SigmoidPolynomial {
        self.coefficients_and_fit(rgb).0
    }

    /// [`Self::coefficients`] and how its Gauss–Newton polish went (None for a grey).
    pub fn coefficients_and_fit(&self, rgb: [f32; 3]) -> (SigmoidPolynomial, Option<fit::Fit>) {
        let rgb = rgb.map(|v| if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) });
        if rgb[0] == rgb[1] && rgb[1] == rgb[2] {
            return (SigmoidPolynomial::grey(rgb[0]), None);
        }
        let model = fit::ColourModel::heron();
        let target = rgb.map(f64::from);
        let starts = [
            self.lookup(rgb).c.map(f64::from),
            self.nearest_node(rgb),
            fit::grey_start(model.xyz_of_rgb(target)[1]),
        ];
        let f = model.fit_from(target, &starts, fit::FitOptions::default());
        let c = SigmoidPolynomial {
            c: f.c.map(|v| v as f32),
        };
        (c, Some(f))
    }
}

const SRGB_TABLE_BYTES: &[u8] = include_bytes!("../../spectra/rgb2spec_srgb.bin");

/// The table for linear sRGB (IEC 61966-2-1) under D65 and CIE 1931 2°, embedded from
/// spectra/rgb2spec_srgb.bin and parsed on first use. The file is part of the build, so
/// a malformed one is a bug, caught by the tests.
pub fn srgb_table() -> &'static Rgb2SpecTable {
    static T: OnceLock<Rgb2SpecTable> = OnceLock::new();
    T.get_or_init(|| {
        Rgb2SpecTable::from_bytes(SRGB_TABLE_BYTES)
            .unwrap_or_else(|e| panic!("spectra/rgb2spec_srgb.bin: {e}"))
    })
}

/// The embedded table file's bytes, for tests that check its header.
pub fn srgb_table_bytes() -> &'static [u8] {
    SRGB_TABLE_BYTES
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sigmoid_limits_and_grey_coefficients() {
        assert_eq!(sigmoid(f64::INFINITY), 1.0);
        assert_eq!(sigmoid(f64::NEG_INFINITY), 0.0);
        assert_eq!(sigmoid(0.0), 0.5);
        assert_eq!(sigmoid_f32(f32::INFINITY), 1.0);
        assert_eq!(sigmoid_f32(-1e30), 0.0);
        for g in [0.0f32, 1e-6, 0.01, 0.18, 0.5, 0.8, 0.999, 1.0] {
            let s = SigmoidPolynomial::grey(g);
            assert_eq!(&s.c[..2], &[0.0, 0.0]);
            for l in [360.0, 555.5, 830.0] {
                assert!((s.eval(l) - g).abs() < 1e-6, "{g} at {l}: {}", s.eval(l));
            }
            let d = s.to_dense();
            assert!(d.is_constant() && (d.values()[0] - g).abs() < 1e-6, "{g}");
        }
    }

    #[test]
    fn table_bytes_round_trip_and_corruptions_are_rejected() {
        let res = 3;
        let coeffs: Vec<f32> = (0..9 * res * res * res)
            .map(|i| i as f32 * 0.5 - 7.0)
            .collect();
        let t = Rgb2SpecTable::new(res, coeffs);
        let b = t.to_bytes();
        assert_eq!(b.len(), table_file_len(res));
        assert_eq!(Rgb2SpecTable::from_bytes(&b).unwrap(), t);
        assert_eq!(
            Rgb2SpecTable::from_bytes(&b[..10]),
            Err(TableError::TooShort(10))
        );
        let mut bad = b.clone();
        bad[0] = b'X';
        assert_eq!(Rgb2SpecTable::from_bytes(&bad), Err(TableError::BadMagic));
        let mut bad = b.clone();
        bad[8] = 2;
        assert_eq!(
            Rgb2SpecTable::from_bytes(&bad),
            Err(TableError::UnsupportedVersion(2))
        );
        let mut bad = b.clone();
        bad[16..20].copy_from_slice(&600.0f32.to_le_bytes());
        assert_eq!(
            Rgb2SpecTable::from_bytes(&bad),
            Err(TableError::WrongWavelengthMapping)
        );
        assert!(matches!(
            Rgb2SpecTable::from_bytes(&b[..b.len() - 4]),
            Err(TableError::WrongSize { .. })
        ));
        let mut bad = b.clone();
        let o = HEADER_LEN + 4 * res + 4 * 5;
        bad[o..o + 4].copy_from_slice(&f32::NAN.to_le_bytes());
        assert_eq!(
            Rgb2SpecTable::from_bytes(&bad),
            Err(TableError::NonFinite(5))
        );
        let mut bad = b;
        bad[HEADER_LEN + 4..HEADER_LEN + 8].copy_from_slice(&0.7f32.to_le_bytes());
        assert_eq!(
            Rgb2SpecTable::from_bytes(&bad),
            Err(TableError::ZNodesNotIncreasing)
        );
    }

    #[test]
    fn lookup_hits_nodes_exactly_and_interpolates_between_them() {
        // A table whose coefficients are an affine function of the node coordinates is
        // reproduced exactly by trilinear interpolation.
        let res = 5;
        let zn = z_nodes(res);
        let mut coeffs = vec![0.0f32; 9 * res * res * res];
        let f = |l: usize, k: usize, yi: usize, xi: usize, j: usize| {
            (l as f32 + 1.0) * (j as f32 + 1.0) * (xi as f32 - 2.0 * yi as f32) + zn[k] * 3.0
        };
        for l in 0..3 {
            for k in 0..res {
                for yi in 0..res {
                    for xi in 0..res {
                        for j in 0..3 {
                            coeffs[(((l * res + k) * res + yi) * res + xi) * 3 + j] =
                                f(l, k, yi, xi, j);
                        }
                    }
                }
            }
        }
        let t = Rgb2SpecTable::new(res, coeffs);
        // Green largest (l = 1): x = b / g, y = r / g.
        let rgb = [0.25 * zn[3], zn[3], 0.5 * zn[3]];
        let c = t.lookup(rgb).c;
        for (j, cj) in c.iter().enumerate() {
            assert!((cj - f(1, 3, 1, 2, j)).abs() < 1e-5, "{c:?}");
        }
        // Half way between nodes in x and y at the same z: the average.
        let z = zn[2];
        let c = t.lookup([z, 0.125 * z, 0.625 * z]).c; // red largest: x = 0.5, y = 2.5
        for (j, cj) in c.iter().enumerate() {
            let want = (1.0 * (j as f32 + 1.0)) * (0.5 - 5.0) + z * 3.0;
            assert!((cj - want).abs() < 1e-4, "{j}: {cj} vs {want}");
        }
        assert_eq!(t.lookup([0.0; 3]), SigmoidPolynomial::grey(0.0));
        assert_eq!(t.lookup([0.3; 3]), SigmoidPolynomial::grey(0.3));
    }

    #[test]
    fn embedded_table_parses() {
        let t = srgb_table();
        assert!(t.res() >= 16);
        assert_eq!(srgb_table_bytes().len(), table_file_len(t.res()));
    }
}
