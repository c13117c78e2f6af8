//! Display transforms: the film's linear sRGB to the encoded sRGB of a PNG preview, a
//! figure or a Lee diagram. The EXR never goes through here; it keeps the film's values.
//!
//! Spectral colours lie outside the sRGB gamut (a monochromatic light has negative
//! linear sRGB components), and bright ones are also over range (components above 1).
//! Clipping each channel to [0, 1] (`clip`, heron's first preview) sends whole stretches
//! of a spectrum to the same corner of the RGB cube: Newton's spectrum shows as flat
//! blocks of red, yellow, green and blue, and the colour of a channel that clips first
//! shifts the hue (an over-exposed orange turns yellow).
//!
//! `hue` keeps the hue instead. A colour inside the gamut (every linear component in
//! [0, 1]) is left exactly as it is, so images without such colours encode to the same
//! bytes as under `clip`. A colour outside is brought in in two steps:
//!
//! 1. **Chromaticity.** A negative component means the chromaticity lies outside the
//!    sRGB triangle. White light is added, the same amount to R, G and B (linear sRGB's
//!    white is D65, the film's white), until the smallest component is 0. Adding white
//!    moves the chromaticity along the straight line toward the white point, so the
//!    dominant wavelength, the CIE's hue of a stimulus (CIE 15:2018 Colorimetry, §9.1),
//!    is kept exactly, and with it the hue of HSV/HSI (which adding equal amounts to R,
//!    G, B does not change: S. K. Naik and C. A. Murthy, "Hue-preserving color image
//!    enhancement without gamut problem", IEEE Trans. Image Processing 12(12),
//!    1591–1598, 2003). The colour lands on the gamut's boundary where the line crosses it,
//!    so a spectrum sweeps the boundary continuously instead of piling up in its corners.
//! 2. **Range.** If a component is still above 1, the colour is moved at constant Oklab
//!    hue along the straight line in Oklab toward the mid-grey L = 0.5 until it reaches
//!    the gamut boundary: Ottosson's "project toward L = 0.5" gamut clipping (B.
//!    Ottosson, "sRGB gamut clipping", 2021, https://bottosson.github.io/posts/gamutclipping/;
//!    of his variants the one that keeps the most colourfulness, so over-exposed spectral
//!    colours stay coloured, while over-range whites become white and bright colours stay
//!    lighter than their dimmer neighbours, unlike scaling the colour down by its largest
//!    component). The boundary point is found by bisection on the line, not by
//!    Ottosson's polynomial fit of the gamut's cusp: the gamut seen from mid-grey is
//!    star-shaped (tested below), so every colour on the line up to the boundary is
//!    inside, and the map is continuous.
//!
//! Each step is continuous and is the identity on the boundary it maps to, so the whole
//! map is continuous, and so is the hue of an image whose colours vary continuously.
//! Projecting in Oklab alone (step 2 for every colour) also keeps the hue, but it pins
//! saturated dark colours to the gamut's boundary at constant lightness, whose chroma
//! peaks sharply at the primaries' hues: a spectrum then shows a thin bright blue line
//! and hard edges at green and red that are not in the light.
//!
//! Oklab: B. Ottosson, "A perceptual color space for image processing", 2020,
//! https://bottosson.github.io/posts/oklab/ — linear sRGB → LMS (M₁), cube root, → Lab
//! (M₂), with the matrices and their inverses as published there. Its hue is close to
//! constant perceived hue (unlike CIELAB's, which bends blue toward purple).
//!
//! Exposure: linear values are multiplied by 2^EV before the transform (EV 0, the
//! default, multiplies by exactly 1).

/// How linear sRGB outside [0, 1] is brought to the display.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DisplayMode {
    /// Colours outside the gamut brought to its boundary at constant hue (white added,
    /// then Oklab's projection toward mid-grey).
    #[default]
    Hue,
    /// Each channel clipped to [0, 1].
    Clip,
}

impl DisplayMode {
    /// The names `--display` takes.
    pub const NAMES: &'static [&'static str] = &["hue", "clip"];

    pub fn name(self) -> &'static str {
        match self {
            DisplayMode::Hue => "hue",
            DisplayMode::Clip => "clip",
        }
    }

    pub fn parse(s: &str) -> Result<Self, String> {
        match s {
            "hue" => Ok(DisplayMode::Hue),
            "clip" => Ok(DisplayMode::Clip),
            _ => Err(format!("expected hue or clip, got {s:?}")),
        }
    }
}

impl std::str::FromStr for DisplayMode {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Self::parse(s)
    }
}

/// Largest |EV| `--exposure` takes: 2^±64 keeps every finite film value finite in f32
/// arithmetic up to 1.8e19, far beyond any radiance a render produces.
pub const MAX_EXPOSURE_EV: f64 = 64.0;

/// A display transform: exposure, then the mode's gamut handling, then the sRGB transfer
/// function.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DisplayTransform {
    pub mode: DisplayMode,
    /// Linear values are multiplied by 2^exposure_ev first.
    exposure_ev: f32,
    scale: f32,
}

impl Default for DisplayTransform {
    fn default() -> Self {
        DisplayTransform {
            mode: DisplayMode::Hue,
            exposure_ev: 0.0,
            scale: 1.0,
        }
    }
}

impl DisplayTransform {
    /// A transform with exposure `ev` stops; the message (for `--exposure`) says what was
    /// expected when `ev` is not finite or beyond ±[`MAX_EXPOSURE_EV`].
    pub fn new(mode: DisplayMode, ev: f64) -> Result<Self, String> {
        if !(ev.is_finite() && ev.abs() <= MAX_EXPOSURE_EV) {
            return Err(format!(
                "expected a finite exposure in stops (EV) within ±{MAX_EXPOSURE_EV}, got {ev}"
            ));
        }
        let ev = ev as f32;
        Ok(DisplayTransform {
            mode,
            exposure_ev: ev,
            // exp2(0) is exactly 1, so the default exposure leaves values untouched.
            scale: ev.exp2(),
        })
    }

    pub fn exposure_ev(&self) -> f32 {
        self.exposure_ev
    }

    /// Encoded sRGB in [0, 1] of a linear sRGB colour.
    pub fn encode(&self, rgb: [f32; 3]) -> [f32; 3] {
        let c = rgb.map(|v| v * self.scale);
        let c = match self.mode {
            DisplayMode::Clip => c,
            DisplayMode::Hue => gamut_map(c),
        };
        // srgb_encode clamps to [0, 1]: the clip of `clip`, a no-op after gamut_map.
        c.map(super::color::srgb_encode)
    }

    /// 8-bit encoded sRGB (rounded to nearest), as the PNG preview stores it.
    pub fn encode_u8(&self, rgb: [f32; 3]) -> [u8; 3] {
        self.encode(rgb).map(|v| (v * 255.0 + 0.5) as u8)
    }
}

/// Linear sRGB → LMS (Ottosson 2020, M₁ for linear sRGB).
const M1: [[f64; 3]; 3] = [
    [0.412_221_470_8, 0.536_332_536_3, 0.051_445_992_9],
    [0.211_903_498_2, 0.680_699_545_1, 0.107_396_956_6],
    [0.088_302_461_9, 0.281_718_837_6, 0.629_978_700_5],
];
/// Cube-rooted LMS → Oklab (Ottosson 2020, M₂).
const M2: [[f64; 3]; 3] = [
    [0.210_454_255_3, 0.793_617_785_0, -0.004_072_046_8],
    [1.977_998_495_1, -2.428_592_205_0, 0.450_593_709_9],
    [0.025_904_037_1, 0.782_771_766_2, -0.808_675_766_0],
];
/// Oklab → cube-rooted LMS (M₂⁻¹ as published).
const M2_INV: [[f64; 3]; 3] = [
    [1.0, 0.396_337_777_4, 0.215_803_757_3],
    [1.0, -0.105_561_345_8, -0.063_854_172_8],
    [1.0, -0.089_484_177_5, -1.291_485_548_0],
];
/// LMS → linear sRGB (M₁⁻¹ as published).
const M1_INV: [[f64; 3]; 3] = [
    [4.076_741_662_1, -3.307_711_591_3, 0.230_969_929_2],
    [-1.268_438_004_6, 2.609_757_401_1, -0.341_319_396_5],
    [-0.004_196_086_3, -0.703_418_614_7, 1.707_614_701_0],
];

fn mul(m: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| m[i][0] * v[0] + m[i][1] * v[1] + m[i][2] * v[2])
}

/// Oklab (L, a, b) of a linear sRGB colour (any real values: the cube root is odd).
pub fn linear_srgb_to_oklab(rgb: [f64; 3]) -> [f64; 3] {
    mul(&M2, mul(&M1, rgb).map(f64::cbrt))
}

/// Linear sRGB of an Oklab colour.
pub fn oklab_to_linear_srgb(lab: [f64; 3]) -> [f64; 3] {
    mul(&M1_INV, mul(&M2_INV, lab).map(|v| v * v * v))
}

/// Oklab hue h = atan2(b, a) in degrees, in [0, 360).
pub fn oklab_hue_deg(lab: [f64; 3]) -> f64 {
    lab[2].atan2(lab[1]).to_degrees().rem_euclid(360.0)
}

/// The lightness on the achromatic axis that out-of-gamut colours are moved toward.
const L_ANCHOR: f64 = 0.5;
/// Bisection steps: the boundary point's parameter to 2⁻³² of the line, far below one
/// 8-bit code.
const BISECTION_STEPS: u32 = 32;

fn in_unit_cube(c: [f64; 3]) -> bool {
    c.iter().all(|v| (0.0..=1.0).contains(v))
}

/// The hue-preserving gamut map of `hue` (see the module documentation): `rgb` itself
/// when every component is in [0, 1]; otherwise white added until no component is
/// negative, then, if a component exceeds 1, the point where the Oklab line toward
/// (L = 0.5, a = b = 0) meets the boundary of the sRGB gamut. NaN counts as 0 and ±∞ as
/// ±f32::MAX.
pub fn gamut_map(rgb: [f32; 3]) -> [f32; 3] {
    if rgb.iter().all(|v| (0.0..=1.0).contains(v)) {
        return rgb;
    }
    let c = rgb.map(|v| {
        if v.is_nan() {
            0.0
        } else {
            v.clamp(-f32::MAX, f32::MAX) as f64
        }
    });
    // Step 1: white added (the smallest component becomes exactly 0).
    let lift = c.iter().fold(0.0f64, |m, &v| m.min(v));
    let c = c.map(|v| v - lift);
    if in_unit_cube(c) {
        return c.map(|v| v as f32);
    }
    // Step 2: toward mid-grey at constant Oklab hue.
    let [l, a, b] = linear_srgb_to_oklab(c);
    let at = |t: f64| oklab_to_linear_srgb([L_ANCHOR + t * (l - L_ANCHOR), t * a, t * b]);
    // t = 0 is mid-grey (linear 0.125), inside; t = 1 is the colour, outside.
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    for _ in 0..BISECTION_STEPS {
        let mid = 0.5 * (lo + hi);
        if in_unit_cube(at(mid)) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    at(lo).map(|v| v.clamp(0.0, 1.0) as f32)
}

/// `heron display` on a CSV: `text` has a header line naming columns `X`, `Y` and `Z`
/// (CIE 1931 XYZ as heron's film has it: D65 white at Y = 1; other columns are ignored,
/// `#` lines and blank lines skipped); returns the CSV `sR,sG,sB` of their encoded sRGB
/// in [0, 1] through `t` (before 8-bit rounding), one row per input row. Errors name
/// `name`, the line and the column.
pub fn map_xyz_csv(text: &str, name: &str, t: &DisplayTransform) -> Result<String, String> {
    use std::fmt::Write;
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
    let Some((_, header)) = lines.next() else {
        return Err(format!(
            "{name}: expected a header line with columns X, Y and Z, found no lines"
        ));
    };
    let cols: Vec<&str> = header.split(',').map(str::trim).collect();
    let find = |c: &str| cols.iter().position(|h| *h == c);
    let (Some(ix), Some(iy), Some(iz)) = (find("X"), find("Y"), find("Z")) else {
        return Err(format!(
            "{name}: expected a header line with columns X, Y and Z, got {header:?}"
        ));
    };
    let mut out = String::from("sR,sG,sB\n");
    for (n, line) in lines {
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        let mut xyz = [0.0f32; 3];
        for (v, (i, col)) in xyz.iter_mut().zip([(ix, "X"), (iy, "Y"), (iz, "Z")]) {
            let f = fields.get(i).copied().unwrap_or("");
            *v = f
                .parse::<f32>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| {
                    format!(
                        "{name}:{}: column {col}: expected a finite number, got {f:?}",
                        n + 1
                    )
                })?;
        }
        let [r, g, b] = t.encode(super::color::xyz_to_linear_srgb(xyz));
        writeln!(out, "{r},{g},{b}").expect("writing to a String");
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectrum::color::xyz_to_linear_srgb;

    /// A small deterministic generator (SplitMix64) for the property tests.
    fn numbers(seed: u64) -> impl FnMut() -> f64 {
        let mut s = seed;
        move || {
            s = s.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = s;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    #[test]
    fn published_inverses_invert_the_forward_matrices() {
        for (m, inv) in [(&M1, &M1_INV), (&M2, &M2_INV)] {
            for (i, row) in inv.iter().enumerate() {
                for (j, want) in [1.0, 0.0, 0.0]
                    .iter()
                    .cycle()
                    .skip(3 - i)
                    .take(3)
                    .enumerate()
                {
                    let p: f64 = (0..3).map(|k| row[k] * m[k][j]).sum();
                    assert!((p - *want).abs() < 1e-7, "({i}, {j}): {p}");
                }
            }
        }
    }

    #[test]
    fn oklab_matches_ottossons_reference_values() {
        // The XYZ → Oklab table of Ottosson 2020 ("Table of example XYZ and Oklab
        // pairs"), through heron's XYZ → linear sRGB (IEC 61966-2-1, four digits, hence
        // the tolerance).
        for (xyz, want) in [
            ([0.950, 1.000, 1.089], [1.000, 0.000, 0.000]),
            ([1.000, 0.000, 0.000], [0.450, 1.236, -0.019]),
            ([0.000, 1.000, 0.000], [0.922, -0.671, 0.263]),
            ([0.000, 0.000, 1.000], [0.153, -1.415, -0.449]),
        ] {
            let rgb = xyz_to_linear_srgb(xyz).map(f64::from);
            let lab = linear_srgb_to_oklab(rgb);
            for k in 0..3 {
                assert!(
                    (lab[k] - want[k]).abs() < 2e-3,
                    "XYZ {xyz:?}: Oklab {lab:?}, expected {want:?}"
                );
            }
            let back = oklab_to_linear_srgb(lab);
            for k in 0..3 {
                assert!((back[k] - rgb[k]).abs() < 1e-6 * (1.0 + rgb[k].abs()));
            }
        }
    }

    #[test]
    fn in_gamut_colours_are_untouched_and_encode_as_clip_does() {
        let mut u = numbers(1);
        let hue = DisplayTransform::default();
        let clip = DisplayTransform::new(DisplayMode::Clip, 0.0).unwrap();
        for _ in 0..10_000 {
            let c = [u() as f32, u() as f32, u() as f32];
            assert_eq!(gamut_map(c), c);
            assert_eq!(hue.encode_u8(c), clip.encode_u8(c));
        }
        for c in [[0.0; 3], [1.0; 3], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]] {
            assert_eq!(gamut_map(c), c);
        }
    }

    /// The angle of the CIE 1931 chromaticity about D65's (0.3127, 0.3290), in degrees:
    /// the direction of the dominant wavelength.
    fn xy_angle(rgb: [f64; 3]) -> f64 {
        let m = crate::spectrum::color::SRGB_TO_XYZ;
        let xyz: [f64; 3] =
            std::array::from_fn(|i| (0..3).map(|j| m[i][j] as f64 * rgb[j]).sum::<f64>());
        let s = xyz[0] + xyz[1] + xyz[2];
        (xyz[1] / s - 0.3290)
            .atan2(xyz[0] / s - 0.3127)
            .to_degrees()
    }

    fn angle_diff(a: f64, b: f64) -> f64 {
        (a - b + 540.0).rem_euclid(360.0) - 180.0
    }

    #[test]
    fn out_of_gamut_colours_keep_their_hue_and_land_on_the_boundary() {
        let mut u = numbers(2);
        let (mut lifted, mut projected, mut xy_checked) = (0, 0, 0);
        while lifted + projected < 20_000 {
            // Colours up to 4× over range and down to −1 (spectral colours, highlights),
            // and as many in [−0.5, 1] (dim spectral colours).
            let span = if (lifted + projected) % 2 == 0 {
                5.0
            } else {
                1.5
            };
            let c: [f32; 3] = std::array::from_fn(|_| (span * u() - 0.2 * span) as f32);
            if c.iter().all(|v| (0.0..=1.0).contains(v)) {
                continue;
            }
            let m = gamut_map(c);
            assert!(m.iter().all(|v| (0.0..=1.0).contains(v)), "{c:?} -> {m:?}");
            // On the boundary: some channel at 0 or 1 (to the bisection's precision).
            let edge = m.iter().map(|&v| v.min(1.0 - v)).fold(1.0f32, f32::min);
            assert!(edge < 1e-6, "{c:?} -> {m:?} is not on the gamut boundary");
            let c64 = c.map(f64::from);
            let low = c64.iter().fold(0.0f64, |a, &v| a.min(v));
            let white_added = c64.map(|v| v - low);
            if white_added.iter().all(|&v| v <= 1.0) {
                // Step 1 alone: the chromaticity moved toward D65 on its line (for
                // colours with X, Y, Z ≥ 0, as every real light has; the angle is
                // undefined at the white point).
                lifted += 1;
                assert!(m.iter().zip(&white_added).all(|(&a, &b)| a == b as f32));
                let xyz = crate::spectrum::color::mat3_mul(&crate::spectrum::color::SRGB_TO_XYZ, c);
                if xyz.iter().all(|&v| v > 0.02) && m.iter().any(|&v| v > 0.01) {
                    xy_checked += 1;
                    let d = angle_diff(xy_angle(c64), xy_angle(m.map(f64::from)));
                    assert!(
                        d.abs() < 0.05,
                        "{c:?} -> {m:?}: dominant wavelength moved by {d}°"
                    );
                }
            } else {
                // Step 2: the Oklab hue of the white-added colour is kept, chroma falls.
                projected += 1;
                let (a, b) = (
                    linear_srgb_to_oklab(white_added),
                    linear_srgb_to_oklab(m.map(f64::from)),
                );
                let chroma = |x: [f64; 3]| x[1].hypot(x[2]);
                // Hue is undefined for greys; elsewhere it is kept.
                if chroma(b) > 1e-3 {
                    let d = angle_diff(oklab_hue_deg(a), oklab_hue_deg(b));
                    assert!(d.abs() < 0.05, "{c:?} -> {m:?}: hue moved by {d}°");
                }
                assert!(chroma(b) <= chroma(a) + 1e-5, "{c:?} -> {m:?}");
            }
        }
        assert!(
            lifted > 1000 && projected > 1000 && xy_checked > 100,
            "{lifted} {projected} {xy_checked}"
        );
    }

    #[test]
    fn the_gamut_is_star_shaped_from_mid_grey_so_the_map_is_continuous() {
        // Along every line from mid-grey outward, the colours inside the gamut form one
        // segment [0, t*]: checked on a fine grid of t for random directions. This is
        // what makes the bisection find the boundary and the map continuous.
        let mut u = numbers(3);
        for _ in 0..2_000 {
            let c: [f64; 3] = std::array::from_fn(|_| 6.0 * u() - 2.0);
            let [l, a, b] = linear_srgb_to_oklab(c);
            let mut left = false;
            for k in 0..=400 {
                let t = k as f64 / 400.0;
                let p = oklab_to_linear_srgb([0.5 + t * (l - 0.5), t * a, t * b]);
                let inside = p.iter().all(|v| (-1e-12..=1.0 + 1e-12).contains(v));
                assert!(!(left && inside), "{c:?}: back inside the gamut at t = {t}");
                left |= !inside;
            }
        }
        // Continuity: nearby inputs give nearby outputs.
        for _ in 0..20_000 {
            let c: [f32; 3] = std::array::from_fn(|_| (5.0 * u() - 1.0) as f32);
            let d: [f32; 3] = std::array::from_fn(|i| c[i] + (1e-4 * (u() - 0.5)) as f32);
            let (mc, md) = (gamut_map(c), gamut_map(d));
            let dist = (0..3).map(|i| (mc[i] - md[i]).abs()).fold(0.0f32, f32::max);
            assert!(dist < 2e-3, "{c:?} -> {mc:?} but {d:?} -> {md:?}");
        }
    }

    #[test]
    fn over_range_greys_become_white_and_exposure_scales_first() {
        assert!(gamut_map([3.0, 3.0, 3.0]).iter().all(|&v| (1.0 - v) < 1e-6));
        let t = DisplayTransform::new(DisplayMode::Clip, -1.0).unwrap();
        assert_eq!(t.encode_u8([2.0, 2.0, 2.0]), [255; 3]);
        assert_eq!(
            t.encode_u8([0.5, 0.5, 0.5]),
            DisplayTransform::default().encode_u8([0.25; 3])
        );
        for bad in [f64::NAN, f64::INFINITY, 65.0, -65.0] {
            let e = DisplayTransform::new(DisplayMode::Hue, bad).unwrap_err();
            assert!(e.contains("exposure"), "{e}");
        }
        // Non-finite values still give a colour in the gamut.
        for c in [
            [f32::NAN, 0.5, 0.5],
            [f32::INFINITY, 0.0, 0.0],
            [-f32::INFINITY; 3],
        ] {
            assert!(gamut_map(c).iter().all(|v| (0.0..=1.0).contains(v)));
        }
    }
}
