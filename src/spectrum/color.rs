//! Colour spaces: CIE XYZ to linear sRGB and the sRGB transfer function.
//!
//! The matrices are the ones printed in IEC 61966-2-1:1999 (sRGB), rounded to four
//! digits; colour-science 0.4.7 uses exactly these for `RGB_COLOURSPACES['sRGB']`, so
//! heron's conversions match it digit for digit. XYZ is D65-relative, so no chromatic
//! adaptation is applied.

pub const XYZ_TO_SRGB: [[f32; 3]; 3] = [
    [3.2406, -1.5372, -0.4986],
    [-0.9689, 1.8758, 0.0415],
    [0.0557, -0.2040, 1.0570],
];

pub const SRGB_TO_XYZ: [[f32; 3]; 3] = [
    [0.4124, 0.3576, 0.1805],
    [0.2126, 0.7152, 0.0722],
    [0.0193, 0.1192, 0.9505],
];

/// CIE xy chromaticities of the sRGB primaries and white, for the EXR
/// `chromaticities` attribute: red, green, blue, white.
pub const SRGB_CHROMATICITIES: [[f32; 2]; 4] =
    [[0.64, 0.33], [0.30, 0.60], [0.15, 0.06], [0.3127, 0.3290]];

#[inline]
pub fn mat3_mul(m: &[[f32; 3]; 3], v: [f32; 3]) -> [f32; 3] {
    [
        m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2],
        m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
        m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2],
    ]
}

pub fn xyz_to_linear_srgb(xyz: [f32; 3]) -> [f32; 3] {
    mat3_mul(&XYZ_TO_SRGB, xyz)
}

/// sRGB opto-electronic transfer function (IEC 61966-2-1), for the PNG preview.
pub fn srgb_encode(c: f32) -> f32 {
    let c = c.clamp(0.0, 1.0);
    if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}
