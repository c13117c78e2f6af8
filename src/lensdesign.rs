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

/// The field angles (degrees) of the spot diagrams when none are given: the Cooke
/// triplet's design fields (`heron.lens(fields=...)`, and `heron lens --fields`, whose
/// clap default is the text "0,14,20": tests/python/test_lens_python.py holds the two
/// together).
pub const DEFAULT_FIELDS: [f64; 3] = [0.0, 14.0, 20.0];

/// Points across the pupil of the spot diagrams' grid when not given: 64, whose 3096
/// points in the disc are Optiland's "uniform" pupil of the same size.
pub const DEFAULT_RAYS: usize = 64;

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
/// across the pupil, focused at `reference_wavelength` (nm; default the prescription's).
/// The errors name the CLI's flags (`--rays`, `--fields`, `--reference-wavelength`); the
/// Python module renames them to its arguments.
pub fn analyse(
    sys: &LensSystem,
    fields: &[f64],
    rays: usize,
    reference_wavelength: Option<f64>,
) -> Result<LensReport> {
    if rays < 2 {
        return Err(rays_error(rays));
    }
    if fields.is_empty() {
        return Err(HeronError::Invalid(
            "--fields: expected at least one field angle (degrees)".into(),
        ));
    }
    if let Some(f) = fields.iter().find(|f| !(f.is_finite() && f.abs() < 90.0)) {
        return Err(HeronError::Invalid(format!(
            "--fields: expected field angles in (−90°, 90°), got {f}"
        )));
    }
    let overridden;
    let sys = match reference_wavelength {
        None => sys,
        Some(l) => {
            if !(360.0..=830.0).contains(&l) {
                return Err(HeronError::Invalid(format!(
                    "--reference-wavelength: expected a wavelength in 360–830 nm, got {l}"
                )));
            }
            let mut s = sys.clone();
            s.reference_wavelength = l;
            overridden = s;
            &overridden
        }
    };
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

/// The error for a grid of `got` points across the pupil (fewer than 2), also for
/// front ends whose number can be negative.
pub fn rays_error(got: impl std::fmt::Display) -> HeronError {
    HeronError::Invalid(format!(
        "--rays: expected at least 2 points across the pupil, got {got}"
    ))
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

/// A value in one of the report's tables.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Value {
    /// A length (mm), angle (degrees), wavelength (nm), ratio or fraction.
    Real(f64),
    /// A number of rays.
    Count(usize),
}

impl std::fmt::Display for Value {
    /// As the CSV files write it: the shortest text that reads back as the same number.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Value::Real(x) => write!(f, "{x}"),
            Value::Count(n) => write!(f, "{n}"),
        }
    }
}

/// How the summary `heron lens` prints shows a column: right-aligned in `width`
/// characters (then `suffix`), `decimals` after the point, the value times `scale`.
#[derive(Clone, Copy, Debug)]
pub struct Shown {
    pub header: &'static str,
    pub width: usize,
    pub decimals: usize,
    pub scale: f64,
    pub suffix: &'static str,
}

/// One column of a table the report writes: its name (the CSV header, and the key in
/// the Python module's records), its value in a row, and how the summary shows it (if
/// it does). One list per table, read by the CSV writer, the summary and the Python
/// module alike, so the three cannot disagree.
pub struct Column<T> {
    pub name: &'static str,
    pub value: fn(&T) -> Value,
    pub shown: Option<Shown>,
}

/// A summary column of a real number: `decimals` after the point in `width` characters.
const fn shown(header: &'static str, width: usize, decimals: usize) -> Option<Shown> {
    Some(Shown {
        header,
        width,
        decimals,
        scale: 1.0,
        suffix: "",
    })
}

/// paraxial.csv: first order per wavelength (F, d, C), lengths in mm.
pub const PARAXIAL_COLUMNS: &[Column<Paraxial>] = &[
    Column {
        name: "wavelength_nm",
        value: |p| Value::Real(p.wavelength_nm),
        shown: shown("lambda_nm", 10, 4),
    },
    Column {
        name: "efl_mm",
        value: |p| Value::Real(p.efl),
        shown: shown("EFL", 10, 4),
    },
    Column {
        name: "bfl_mm",
        value: |p| Value::Real(p.bfl),
        shown: shown("BFL", 10, 4),
    },
    Column {
        name: "f_number",
        value: |p| Value::Real(p.f_number),
        shown: shown("f/#", 7, 3),
    },
    Column {
        name: "entrance_pupil_z_mm",
        value: |p| Value::Real(p.entrance_pupil_z),
        shown: shown("EP_z", 9, 4),
    },
    Column {
        name: "entrance_pupil_diameter_mm",
        value: |p| Value::Real(p.entrance_pupil_diameter),
        shown: shown("EPD", 9, 4),
    },
    Column {
        name: "exit_pupil_z_mm",
        value: |p| Value::Real(p.exit_pupil_z),
        shown: shown("XP_z", 9, 4),
    },
    Column {
        name: "exit_pupil_diameter_mm",
        value: |p| Value::Real(p.exit_pupil_diameter),
        shown: shown("XPD", 9, 4),
    },
];

/// focal_shift.csv: a row (λ nm, BFL mm, BFL − BFL(reference) mm) of
/// [`LensReport::focal_shift`].
pub const FOCAL_SHIFT_COLUMNS: &[Column<(f64, f64, f64)>] = &[
    Column {
        name: "wavelength_nm",
        value: |r| Value::Real(r.0),
        shown: None,
    },
    Column {
        name: "bfl_mm",
        value: |r| Value::Real(r.1),
        shown: None,
    },
    Column {
        name: "focal_shift_mm",
        value: |r| Value::Real(r.2),
        shown: None,
    },
];

/// spots.csv: one row per field and wavelength; the summary shows the radii in µm and
/// the vignetted share in percent.
pub const SPOT_COLUMNS: &[Column<Spot>] = &[
    Column {
        name: "field_deg",
        value: |s| Value::Real(s.field_deg),
        shown: shown("field_deg", 9, 2),
    },
    Column {
        name: "wavelength_nm",
        value: |s| Value::Real(s.wavelength_nm),
        shown: shown("lambda_nm", 10, 4),
    },
    Column {
        name: "rays",
        value: |s| Value::Count(s.rays),
        shown: shown("rays", 6, 0),
    },
    Column {
        name: "rms_radius_mm",
        value: |s| Value::Real(s.rms_radius),
        shown: Some(Shown {
            header: "RMS_um",
            width: 12,
            decimals: 3,
            scale: 1e3,
            suffix: "",
        }),
    },
    Column {
        name: "geo_radius_mm",
        value: |s| Value::Real(s.geo_radius),
        shown: Some(Shown {
            header: "geo_um",
            width: 12,
            decimals: 3,
            scale: 1e3,
            suffix: "",
        }),
    },
    Column {
        name: "centroid_x_mm",
        value: |s| Value::Real(s.centroid.0),
        shown: None,
    },
    Column {
        name: "centroid_y_mm",
        value: |s| Value::Real(s.centroid.1),
        shown: None,
    },
    Column {
        name: "vignetted_fraction",
        value: |s| Value::Real(s.vignetted_fraction),
        shown: Some(Shown {
            header: "vignetted",
            width: 10,
            decimals: 1,
            scale: 100.0,
            suffix: "%",
        }),
    },
];

/// `rows` as CSV with a header line, by `columns`.
fn csv<T>(columns: &[Column<T>], rows: &[T]) -> String {
    let names: Vec<&str> = columns.iter().map(|c| c.name).collect();
    let mut s = names.join(",");
    s.push('\n');
    for r in rows {
        let cells: Vec<String> = columns.iter().map(|c| (c.value)(r).to_string()).collect();
        s.push_str(&cells.join(","));
        s.push('\n');
    }
    s
}

/// The summary's table of `rows`: the columns that are shown, separated by a space.
fn summary_table<T>(columns: &[Column<T>], rows: &[T]) -> String {
    let shown: Vec<(&Column<T>, Shown)> = columns
        .iter()
        .filter_map(|c| c.shown.map(|f| (c, f)))
        .collect();
    let header: Vec<String> = shown
        .iter()
        .map(|(_, f)| format!("{:>w$}", f.header, w = f.width + f.suffix.chars().count()))
        .collect();
    let mut s = header.join(" ");
    s.push('\n');
    for r in rows {
        let cells: Vec<String> = shown
            .iter()
            .map(|(c, f)| match (c.value)(r) {
                Value::Real(x) => format!(
                    "{:>w$.d$}{}",
                    f.scale * x,
                    f.suffix,
                    w = f.width,
                    d = f.decimals
                ),
                Value::Count(n) => format!("{n:>w$}{}", f.suffix, w = f.width),
            })
            .collect();
        s.push_str(&cells.join(" "));
        s.push('\n');
    }
    s
}

impl LensReport {
    /// paraxial.csv
    pub fn paraxial_csv(&self) -> String {
        csv(PARAXIAL_COLUMNS, &self.first_order)
    }

    /// focal_shift.csv
    pub fn focal_shift_csv(&self) -> String {
        csv(FOCAL_SHIFT_COLUMNS, &self.focal_shift)
    }

    /// spots.csv
    pub fn spots_csv(&self) -> String {
        csv(SPOT_COLUMNS, &self.spots)
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
        s.push_str(&summary_table(PARAXIAL_COLUMNS, &self.first_order));
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
        s.push_str(&summary_table(SPOT_COLUMNS, &self.spots));
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

    /// The grid is Optiland's "uniform" pupil: 3096 of 64² points in the disc.
    #[test]
    fn spot_grid_and_vignetting() {
        let surf = Surface::constant;
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
    /// The checks `heron lens` and `heron.lens` share, and the reference override.
    #[test]
    fn analyse_checks_arguments_and_moves_the_reference() {
        let path = Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/lenses/singlet-bk7.toml"
        ));
        let sys = crate::scene::load::lens::read_prescription(path).unwrap();
        let msg = |r: Result<LensReport>| r.unwrap_err().to_string();
        assert!(msg(analyse(&sys, &[], 8, None)).contains("--fields: expected at least one"));
        assert!(msg(analyse(&sys, &[0.0, 90.0], 8, None)).contains("got 90"));
        assert!(msg(analyse(&sys, &[0.0], 1, None)).contains("--rays: expected at least 2"));
        let e = msg(analyse(&sys, &[0.0], 8, Some(300.0)));
        assert!(e.contains("--reference-wavelength: expected"), "{e}");
        let r = analyse(&sys, &[0.0, 5.0], 8, Some(550.0)).unwrap();
        assert_eq!(r.reference_wavelength, 550.0);
        assert_eq!(
            sys.reference_wavelength, D_LINE,
            "the system itself is unchanged"
        );
        let at_550 = r.focal_shift.iter().find(|f| f.0 == 550.0).unwrap();
        assert_eq!(at_550.2, 0.0);
        assert_eq!(r.spots.len(), 6);
        // The CSV headers are the columns' names; the summary shows the same rows.
        let header = |t: String| t.lines().next().unwrap().to_string();
        assert_eq!(header(r.paraxial_csv()), "wavelength_nm,efl_mm,bfl_mm,f_number,entrance_pupil_z_mm,entrance_pupil_diameter_mm,exit_pupil_z_mm,exit_pupil_diameter_mm");
        assert_eq!(header(r.spots_csv()), "field_deg,wavelength_nm,rays,rms_radius_mm,geo_radius_mm,centroid_x_mm,centroid_y_mm,vignetted_fraction");
        assert_eq!(r.summary().lines().count(), 1 + 4 + 1 + 7);
    }
}
