//! The charts of `heron sky profile --plot` (radiance against the angle from the
//! antisolar point, one line per wavelength, each drawn in that wavelength's hue) and of
//! `heron halo profile --plot` (against the angle from the sun, per great circle).
use super::{Chart, Scale, Series};
use crate::sky::halo::profile::HaloProfile;
use crate::sky::profile::Profile;
use crate::spectrum::cie;
use crate::spectrum::color::{srgb_encode, xyz_to_linear_srgb};
use crate::spectrum::DenseSpectrum;

/// Largest relative luminance of a line colour, so that yellow and green still read on
/// white.
const MAX_LUMINANCE: f64 = 0.3;

/// A line colour for wavelength `lambda` nm: the CIE 1931 x̄ȳz̄(λ) taken to linear sRGB
/// (IEC 61966-2-1), moved toward white by adding the same amount to each channel until
/// none is negative (monochromatic light lies outside the sRGB gamut), scaled to a
/// largest channel of 1, darkened to a relative luminance of at most 0.3, and encoded.
/// A hue cue for the legend, not a colorimetric rendering of the light.
pub fn wavelength_colour(lambda: f32) -> [u8; 3] {
    let (i, t) = DenseSpectrum::position(lambda);
    let v = cie::cie1931().xyz_at(i, t);
    let mut c = xyz_to_linear_srgb([v.x, v.y, v.z]).map(f64::from);
    let lo = c.iter().copied().fold(f64::INFINITY, f64::min);
    if lo < 0.0 {
        c = c.map(|x| x - lo);
    }
    let hi = c.iter().copied().fold(0.0, f64::max);
    if hi <= 0.0 {
        return [0, 0, 0];
    }
    c = c.map(|x| x / hi);
    let y = 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
    if y > MAX_LUMINANCE {
        c = c.map(|x| x * MAX_LUMINANCE / y);
    }
    c.map(|x| (srgb_encode(x as f32) * 255.0 + 0.5) as u8)
}

/// The chart of a profile of sky model `model` ([`crate::sky::profile::profile`]). The
/// physical models' values are radiance per unit solar irradiance in sr⁻¹ (the module
/// documentation of [`crate::sky`]); `constant` and `aristotle` give a relative radiance.
pub fn chart(title: &str, model: &str, p: &Profile) -> Chart {
    let (lambdas, thetas_deg, table) = (&p.lambdas, &p.thetas_deg, &p.table);
    let n = lambdas.len().max(1);
    let series = lambdas
        .iter()
        .enumerate()
        .map(|(j, &l)| Series {
            label: format!("{l} nm"),
            colour: wavelength_colour(l),
            points: thetas_deg
                .iter()
                .zip(table.chunks(n))
                .map(|(&t, row)| (t, row[j] as f64))
                .collect(),
            dashed: false,
            markers: false,
        })
        .collect();
    Chart {
        title: title.to_string(),
        x_label: "angle from the antisolar point θ (°)".into(),
        y_label: match model {
            "constant" | "aristotle" => "radiance (relative)".into(),
            _ => "radiance per unit solar irradiance (sr⁻¹)".into(),
        },
        x_scale: Scale::Linear,
        y_scale: Scale::Linear,
        y_from_zero: true,
        series,
    }
}

/// The chart of `heron halo profile --plot`: one line per great circle and wavelength, in the wavelength's hue,
/// the second and later circles dashed; radiance on a log axis (the forward peak is
/// 10⁴–10⁵ times the halos).
pub fn halo_chart(title: &str, p: &HaloProfile) -> Chart {
    let (np, nl) = (p.psis_deg.len(), p.lambdas.len());
    let mut series = Vec::new();
    for (i, psi) in p.psis_deg.iter().enumerate() {
        for (j, &l) in p.lambdas.iter().enumerate() {
            series.push(Series {
                label: format!("ψ = {psi}°, {l} nm"),
                colour: wavelength_colour(l),
                points: p
                    .thetas_deg
                    .iter()
                    .enumerate()
                    .map(|(k, &t)| (t, p.table[(k * np + i) * nl + j] as f64))
                    .collect(),
                dashed: i > 0,
                markers: false,
            });
        }
    }
    Chart {
        title: title.to_string(),
        x_label: "angle from the sun (°)".into(),
        y_label: "radiance per unit solar irradiance (sr⁻¹)".into(),
        x_scale: Scale::Linear,
        y_scale: Scale::Log,
        y_from_zero: false,
        series,
    }
}
