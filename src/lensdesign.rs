//! `heron lens`: a prescription's optics numbers from the renderer's own lens code
//! ([`crate::camera::lens`]), in the conventions of optical design programs, so that
//! they can be held against one (tests/python/test_lens.py holds them against
//! Optiland):
//!
//! - first order per wavelength (F, d, C): effective and back focal lengths, f-number,
//!   entrance and exit pupils ([`paraxial`]);
//! - the chromatic focal shift, BFL(λ) − BFL(reference), over 400–700 nm;
//! - spot diagrams from real rays: for each field angle θ (in the y–z plane, object at
//!   infinity) and wavelength, rays of direction (0, sin θ, cos θ) through the points of
//!   a square grid of `rays` × `rays` points spanning [−1, 1]² (both ends included) that
//!   fall in the unit disc, scaled to the reference wavelength's paraxial entrance pupil
//!   (paraxial ray aiming: design programs' default); traced without the rims (design
//!   programs fill the pupil and report vignetting apart: `vignetted_fraction` is the
//!   share the rims and the stop would stop); measured in the reference wavelength's
//!   paraxial image plane: the centroid, the RMS radius about it and the largest
//!   distance from it (the geometric radius).
use crate::camera::lens::paraxial::{paraxial, Paraxial};
use crate::camera::lens::system::{C_LINE, D_LINE, F_LINE};
use crate::camera::lens::trace::{trace_forward, LensRay, Rims};
use crate::camera::lens::LensSystem;
use crate::plot::{Chart, Scale, Series};
use crate::{HeronError, Result};
use glam::DVec3;
use std::fmt::Write as _;
use std::path::Path;

/// The wavelengths of the first-order table and the spot diagrams: F, d, C.
pub const LINES: [f64; 3] = [F_LINE, D_LINE, C_LINE];

/// One spot: a field angle at one wavelength.
#[derive(Clone, Debug, PartialEq)]
pub struct Spot {
    pub field_deg: f64,
    pub wavelength_nm: f64,
    /// Rays that reached the image plane.
    pub rays: usize,
    pub rms_radius: f64,
    pub geo_radius: f64,
    pub centroid: (f64, f64),
    /// Share of the rays a rim or the stop would stop.
    pub vignetted_fraction: f64,
    /// Image-plane points (mm), for the spot diagram.
    pub points: Vec<(f64, f64)>,
}

/// Everything `heron lens` reports.
#[derive(Clone, Debug)]
pub struct LensReport {
    pub name: String,
    pub reference_wavelength: f64,
    pub first_order: Vec<Paraxial>,
    /// (λ nm, BFL mm, BFL − BFL(reference) mm) every 5 nm over 400–700 nm.
    pub focal_shift: Vec<(f64, f64, f64)>,
    pub spots: Vec<Spot>,
}

/// The report for `sys` with spots at `fields` (degrees) on a grid of `rays` points
/// across the pupil.
pub fn analyse(sys: &LensSystem, fields: &[f64], rays: usize) -> Result<LensReport> {
    if rays < 2 {
        return Err(HeronError::Invalid(format!(
            "--rays: expected at least 2 points across the pupil, got {rays}"
        )));
    }
    if let Some(f) = fields.iter().find(|f| !(f.is_finite() && f.abs() < 90.0)) {
        return Err(HeronError::Invalid(format!(
            "--fields: expected field angles in (−90°, 90°), got {f}"
        )));
    }
    let reference = sys.reference_wavelength;
    let first_order = LINES.iter().map(|&l| paraxial(sys, l)).collect();
    let bfl_ref = paraxial(sys, reference).bfl;
    let focal_shift = (0..=60)
        .map(|k| {
            let l = 400.0 + 5.0 * k as f64;
            let b = paraxial(sys, l).bfl;
            (l, b, b - bfl_ref)
        })
        .collect();
    let mut spots = Vec::new();
    for &f in fields {
        for &l in &LINES {
            spots.push(spot(sys, f, l, rays));
        }
    }
    Ok(LensReport {
        name: sys.name.clone(),
        reference_wavelength: reference,
        first_order,
        focal_shift,
        spots,
    })
}

/// The spot of field `field_deg` at `lambda_nm` (see the module docs).
pub fn spot(sys: &LensSystem, field_deg: f64, lambda_nm: f64, rays: usize) -> Spot {
    let p = paraxial(sys, sys.reference_wavelength);
    let z_image = sys.length() + p.bfl;
    let r_ep = 0.5 * p.entrance_pupil_diameter;
    let t = field_deg.to_radians();
    let d = DVec3::new(0.0, t.sin(), t.cos());
    // Rays start in object space (air), in front of every surface.
    let z0 = p.entrance_pupil_z.min(0.0) - 2.0 * sys.surfaces[0].semi_aperture - 1.0;
    let mut points = Vec::new();
    let (mut total, mut vignetted) = (0usize, 0usize);
    let n = rays;
    for i in 0..n {
        let gy = -1.0 + 2.0 * i as f64 / (n - 1) as f64;
        for j in 0..n {
            let gx = -1.0 + 2.0 * j as f64 / (n - 1) as f64;
            if gx * gx + gy * gy > 1.0 {
                continue;
            }
            total += 1;
            let at_pupil = DVec3::new(gx * r_ep, gy * r_ep, p.entrance_pupil_z);
            let o = at_pupil - d * ((p.entrance_pupil_z - z0) / d.z);
            let r = LensRay { o, d };
            if trace_forward(sys, r, lambda_nm, Rims::Stop).is_err() {
                vignetted += 1;
            }
            if let Ok(out) = trace_forward(sys, r, lambda_nm, Rims::Ignore) {
                let s = (z_image - out.o.z) / out.d.z;
                let q = out.o + s * out.d;
                if q.is_finite() {
                    points.push((q.x, q.y));
                }
            }
        }
    }
    let m = points.len().max(1) as f64;
    let cx = points.iter().map(|p| p.0).sum::<f64>() / m;
    let cy = points.iter().map(|p| p.1).sum::<f64>() / m;
    let d2 = |p: &(f64, f64)| (p.0 - cx).powi(2) + (p.1 - cy).powi(2);
    let rms = (points.iter().map(d2).sum::<f64>() / m).sqrt();
    let geo = points.iter().map(d2).fold(0.0f64, f64::max).sqrt();
    Spot {
        field_deg,
        wavelength_nm: lambda_nm,
        rays: points.len(),
        rms_radius: rms,
        geo_radius: geo,
        centroid: (cx, cy),
        vignetted_fraction: vignetted as f64 / total.max(1) as f64,
        points,
    }
}

impl LensReport {
    /// paraxial.csv
    pub fn paraxial_csv(&self) -> String {
        let mut s = String::from("wavelength_nm,efl_mm,bfl_mm,f_number,entrance_pupil_z_mm,entrance_pupil_diameter_mm,exit_pupil_z_mm,exit_pupil_diameter_mm\n");
        for p in &self.first_order {
            let _ = writeln!(
                s,
                "{},{},{},{},{},{},{},{}",
                p.wavelength_nm,
                p.efl,
                p.bfl,
                p.f_number,
                p.entrance_pupil_z,
                p.entrance_pupil_diameter,
                p.exit_pupil_z,
                p.exit_pupil_diameter
            );
        }
        s
    }

    /// focal_shift.csv
    pub fn focal_shift_csv(&self) -> String {
        let mut s = String::from("wavelength_nm,bfl_mm,focal_shift_mm\n");
        for (l, b, d) in &self.focal_shift {
            let _ = writeln!(s, "{l},{b},{d}");
        }
        s
    }

    /// spots.csv
    pub fn spots_csv(&self) -> String {
        let mut s = String::from("field_deg,wavelength_nm,rays,rms_radius_mm,geo_radius_mm,centroid_x_mm,centroid_y_mm,vignetted_fraction\n");
        for p in &self.spots {
            let _ = writeln!(
                s,
                "{},{},{},{},{},{},{},{}",
                p.field_deg,
                p.wavelength_nm,
                p.rays,
                p.rms_radius,
                p.geo_radius,
                p.centroid.0,
                p.centroid.1,
                p.vignetted_fraction
            );
        }
        s
    }

    /// spot_points.csv: every ray's image point, relative to its spot's centroid.
    pub fn spot_points_csv(&self) -> String {
        let mut s = String::from("field_deg,wavelength_nm,x_mm,y_mm\n");
        for p in &self.spots {
            for q in &p.points {
                let _ = writeln!(
                    s,
                    "{},{},{},{}",
                    p.field_deg,
                    p.wavelength_nm,
                    q.0 - p.centroid.0,
                    q.1 - p.centroid.1
                );
            }
        }
        s
    }

    /// The summary `heron lens` prints.
    pub fn summary(&self) -> String {
        let mut s = format!("{}\n", self.name);
        let _ = writeln!(
            s,
            "{:>10} {:>10} {:>10} {:>7} {:>9} {:>9} {:>9} {:>9}",
            "lambda_nm", "EFL", "BFL", "f/#", "EP_z", "EPD", "XP_z", "XPD"
        );
        for p in &self.first_order {
            let _ = writeln!(
                s,
                "{:>10.4} {:>10.4} {:>10.4} {:>7.3} {:>9.4} {:>9.4} {:>9.4} {:>9.4}",
                p.wavelength_nm,
                p.efl,
                p.bfl,
                p.f_number,
                p.entrance_pupil_z,
                p.entrance_pupil_diameter,
                p.exit_pupil_z,
                p.exit_pupil_diameter
            );
        }
        let shift = |l: f64| {
            self.focal_shift
                .iter()
                .find(|r| r.0 == l)
                .map_or(f64::NAN, |r| r.2)
        };
        let _ = writeln!(
            s,
            "chromatic focal shift from {:.4} nm: {:+.4} mm at 400 nm, {:+.4} mm at 700 nm",
            self.reference_wavelength,
            shift(400.0),
            shift(700.0)
        );
        let _ = writeln!(
            s,
            "{:>9} {:>10} {:>6} {:>12} {:>12} {:>11}",
            "field_deg", "lambda_nm", "rays", "RMS_um", "geo_um", "vignetted"
        );
        for p in &self.spots {
            let _ = writeln!(
                s,
                "{:>9.2} {:>10.4} {:>6} {:>12.3} {:>12.3} {:>10.1}%",
                p.field_deg,
                p.wavelength_nm,
                p.rays,
                1e3 * p.rms_radius,
                1e3 * p.geo_radius,
                100.0 * p.vignetted_fraction
            );
        }
        s
    }

    /// The focal-shift curve.
    pub fn focal_shift_chart(&self) -> Chart {
        Chart {
            title: format!("{}: chromatic focal shift", self.name),
            x_label: "wavelength (nm)".into(),
            y_label: format!("BFL(λ) − BFL({:.1} nm) (mm)", self.reference_wavelength),
            x_scale: Scale::Linear,
            y_scale: Scale::Linear,
            y_from_zero: false,
            series: vec![Series {
                label: "paraxial focus".into(),
                colour: [40, 40, 40],
                points: self.focal_shift.iter().map(|r| (r.0, r.2)).collect(),
                dashed: false,
                markers: false,
            }],
        }
    }

    /// RMS spot radius against field angle, one line per wavelength.
    pub fn spot_chart(&self) -> Chart {
        let series = LINES
            .iter()
            .map(|&l| Series {
                label: format!("{l:.1} nm"),
                colour: crate::plot::sky::wavelength_colour(l as f32),
                points: self
                    .spots
                    .iter()
                    .filter(|s| s.wavelength_nm == l)
                    .map(|s| (s.field_deg, 1e3 * s.rms_radius))
                    .collect(),
                dashed: false,
                markers: true,
            })
            .collect();
        Chart {
            title: format!("{}: RMS spot radius", self.name),
            x_label: "field angle (°)".into(),
            y_label: "RMS spot radius (µm)".into(),
            x_scale: Scale::Linear,
            y_scale: Scale::Linear,
            y_from_zero: true,
            series,
        }
    }

    /// Writes the CSV files and the two plots into `dir` (created if missing), each
    /// through a temporary file renamed into place.
    pub fn write(&self, dir: &Path) -> Result<Vec<std::path::PathBuf>> {
        std::fs::create_dir_all(dir).map_err(|e| {
            HeronError::Invalid(format!("--out {}: cannot create it: {e}", dir.display()))
        })?;
        let mut written = Vec::new();
        for (name, text) in [
            ("paraxial.csv", self.paraxial_csv()),
            ("focal_shift.csv", self.focal_shift_csv()),
            ("spots.csv", self.spots_csv()),
            ("spot_points.csv", self.spot_points_csv()),
        ] {
            let p = dir.join(name);
            crate::files::write_atomically(&p, |tmp| {
                std::fs::write(tmp, text.as_bytes()).map_err(|e| e.to_string())
            })?;
            written.push(p);
        }
        for (name, chart) in [
            ("focal_shift.png", self.focal_shift_chart()),
            ("spots.png", self.spot_chart()),
        ] {
            let p = dir.join(name);
            crate::plot::write_png(&p, &chart, "--out")?;
            written.push(p);
        }
        Ok(written)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::lens::Surface;
    use crate::spectrum::ior::Ior;

    /// The grid is Optiland's "uniform" pupil: 3096 of 64² points in the disc.
    #[test]
    fn spot_grid_and_vignetting() {
        let surf = |radius, thickness, n: f32, sa, stop| Surface {
            radius,
            thickness,
            medium: Ior::Constant(n),
            semi_aperture: sa,
            stop,
        };
        let sys = LensSystem::new(
            "singlet",
            vec![
                surf(0.0, 1.0, 1.0, 5.0, true),
                surf(50.0, 5.0, 1.5, 6.0, false),
                surf(0.0, 90.0, 1.0, 6.0, false),
            ],
        )
        .unwrap();
        let s = spot(&sys, 0.0, D_LINE, 64);
        assert_eq!(s.rays, 3096);
        assert!(s.centroid.0.abs() < 1e-12 && s.centroid.1.abs() < 1e-12);
        assert!(s.rms_radius > 0.0 && s.geo_radius >= s.rms_radius);
        // On axis the paraxial pupil fills the stop: the edge rays are at its rim.
        assert!(s.vignetted_fraction < 0.01, "{}", s.vignetted_fraction);
        // At 40° the beam through the stop reaches the lens's 6 mm rims.
        let far = spot(&sys, 40.0, D_LINE, 64);
        assert!(far.vignetted_fraction > 0.1, "{}", far.vignetted_fraction);
    }
}
