//! `heron.lens`: `heron lens`'s report of a lens prescription from Python, computed by
//! the same `heron::lensdesign::analyse`; its tables' keys are the CSV files' columns
//! (`lensdesign::PARAXIAL_COLUMNS`, `FOCAL_SHIFT_COLUMNS`, `SPOT_COLUMNS`), read here
//! from the same lists the CSV writer reads.
use crate::convert::{numbers, to_toml};
use crate::{err, guard, lib_err};
use heron_core::camera::lens::LensSystem;
use heron_core::lensdesign::{
    self, Column, Value, DEFAULT_FIELDS, DEFAULT_RAYS, FOCAL_SHIFT_COLUMNS, PARAXIAL_COLUMNS,
    SPOT_COLUMNS,
};
use heron_core::scene::load::lens::{read_prescription, surfaces_from_values};
use numpy::{IntoPyArray, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyTuple};
use std::path::{Path, PathBuf};

/// The flags of `heron lens`, by this function's argument names.
const RENAMES: &[(&str, &str)] = &[
    ("--fields", "fields"),
    ("--rays", "rays"),
    ("--reference-wavelength", "reference_wavelength"),
];

/// The name of a prescription given as a list of surfaces (the report's `name`).
const LIST_NAME: &str = "<list>";

/// The first-order numbers, the chromatic focal shift and real-ray spot diagrams of a
/// lens prescription, as `heron lens` computes them (the same code: the numbers equal
/// the CSV files of `heron lens --out` exactly).
///
/// prescription: a path (str or os.PathLike) to heron's TOML prescription or a pbrt-v4
/// lens file (*.dat, with an optional fifth column naming a catalogue glass), or a list
/// of dicts like the TOML's `[[surface]]` tables, from the object side: radius (mm, 0 =
/// flat, positive when the centre of curvature is on the image side), thickness (mm to
/// the next vertex; the last one to the film), semi_aperture (mm), optionally medium
/// (the medium behind the surface: "air", the default, or any `heron.ior` model; a
/// table file is relative to the current directory) and stop (exactly one surface is
/// the stop). fields: field angles in degrees, in (−90°, 90°), a number or a sequence.
/// rays: points across the pupil of the spot diagrams' square grid (at least 2; the
/// grid's points inside the unit disc are traced). reference_wavelength: nm in
/// 360–830, the focus of the spot diagrams and the zero of the focal shift (default the
/// prescription's, else the d line 587.5618 nm).
///
/// Returns a dict:
/// - "name": the prescription's name; "reference_wavelength_nm": the reference used;
/// - "paraxial": a list of three dicts, at the F, d and C lines, with the columns of
///   paraxial.csv: wavelength_nm, efl_mm, bfl_mm, f_number, entrance_pupil_z_mm (from
///   the first vertex), entrance_pupil_diameter_mm, exit_pupil_z_mm (from the last
///   vertex), exit_pupil_diameter_mm;
/// - "focal_shift": a dict of float64 arrays with the columns of focal_shift.csv, one
///   element per 5 nm over 400–700 nm: wavelength_nm, bfl_mm, focal_shift_mm (BFL(λ) −
///   BFL(reference));
/// - "spots": a list of dicts, per field angle and then per F, d, C line, with the
///   columns of spots.csv (field_deg, wavelength_nm, rays (an int), rms_radius_mm,
///   geo_radius_mm, centroid_x_mm, centroid_y_mm, vignetted_fraction) and "points_mm":
///   a rays × 2 float64 array of the image-plane points (x, y) in mm, in the reference
///   wavelength's paraxial image plane (spot_points.csv writes them minus the centroid);
/// - "summary": the text `heron lens` prints.
///
/// Bad input raises HeronError (a ValueError) with the CLI's one-line message, naming
/// the file and surface, or the argument (for a list: "prescription: surface N").
#[pyfunction]
#[pyo3(
    signature = (prescription, fields=None, rays=DEFAULT_RAYS as i64, reference_wavelength=None),
    text_signature = "(prescription, fields=(0, 14, 20), rays=64, reference_wavelength=None)"
)]
pub fn lens<'py>(
    py: Python<'py>,
    prescription: &Bound<'py, PyAny>,
    fields: Option<&Bound<'py, PyAny>>,
    rays: i64,
    reference_wavelength: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    guard(|| {
        let sys = prescription_arg(py, prescription)?;
        let fields = match fields {
            None => DEFAULT_FIELDS.to_vec(),
            Some(f) => numbers(f, "fields")?,
        };
        let rays =
            usize::try_from(rays).map_err(|_| lib_err(lensdesign::rays_error(rays), RENAMES))?;
        let report = py
            .detach(|| lensdesign::analyse(&sys, &fields, rays, reference_wavelength))
            .map_err(|e| lib_err(e, RENAMES))?;
        let d = PyDict::new(py);
        d.set_item("name", &report.name)?;
        d.set_item("reference_wavelength_nm", report.reference_wavelength)?;
        let paraxial = PyList::empty(py);
        for p in &report.first_order {
            paraxial.append(record(py, PARAXIAL_COLUMNS, p)?)?;
        }
        d.set_item("paraxial", paraxial)?;
        let shift = PyDict::new(py);
        for c in FOCAL_SHIFT_COLUMNS {
            let column: Vec<f64> = report
                .focal_shift
                .iter()
                .map(|r| match (c.value)(r) {
                    Value::Real(x) => x,
                    Value::Count(n) => n as f64,
                })
                .collect();
            shift.set_item(c.name, column.into_pyarray(py))?;
        }
        d.set_item("focal_shift", shift)?;
        let spots = PyList::empty(py);
        for s in &report.spots {
            let r = record(py, SPOT_COLUMNS, s)?;
            let n = s.points.len();
            let flat: Vec<f64> = s.points.iter().flat_map(|&(x, y)| [x, y]).collect();
            r.set_item("points_mm", flat.into_pyarray(py).reshape([n, 2])?)?;
            spots.append(r)?;
        }
        d.set_item("spots", spots)?;
        d.set_item("summary", report.summary())?;
        Ok(d)
    })
}

/// One row of a report table as a dict keyed by its columns' names (the CSV headers):
/// real values as floats, counts as ints.
fn record<'py, T>(py: Python<'py>, columns: &[Column<T>], row: &T) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for c in columns {
        match (c.value)(row) {
            Value::Real(x) => d.set_item(c.name, x)?,
            Value::Count(n) => d.set_item(c.name, n)?,
        }
    }
    Ok(d)
}

/// The `prescription` argument: a list (or tuple) of surface dicts, read as the TOML's
/// `[[surface]]` tables by the loader's `surfaces_from_values` (errors say
/// "prescription: surface N"), or a path read by `read_prescription`, as `heron lens`
/// reads its file (errors start with the path).
fn prescription_arg(py: Python<'_>, v: &Bound<'_, PyAny>) -> PyResult<LensSystem> {
    if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        let mut values = Vec::new();
        for (i, item) in v.try_iter()?.enumerate() {
            let item = item?;
            let at = format!("prescription: surface {}", i + 1);
            let Ok(surface) = item.cast::<PyDict>() else {
                return Err(err(format!(
                    "{at}: expected a dict with radius, thickness, semi_aperture and optionally medium and stop (a [[surface]] table), got {} ({})",
                    item.repr()?,
                    item.get_type().name()?
                )));
            };
            // Key by key, so that a value's error reads as the loader's ("surface 2:
            // medium: ...").
            let mut table = toml::Table::new();
            for (k, x) in surface.iter() {
                let Ok(key) = k.extract::<String>() else {
                    return Err(err(format!(
                        "{at}: expected string keys, got {} ({})",
                        k.repr()?,
                        k.get_type().name()?
                    )));
                };
                let value = to_toml(&x, &format!("{at}: {key}"))?;
                table.insert(key, value);
            }
            values.push(toml::Value::Table(table));
        }
        return surfaces_from_values("prescription: ", LIST_NAME, &values, Path::new(""))
            .map_err(err);
    }
    match v.extract::<PathBuf>() {
        Ok(path) => py.detach(|| read_prescription(&path)).map_err(err),
        Err(_) => Err(err(format!(
            "prescription: expected a path to a lens prescription (heron TOML or pbrt-v4 .dat) or a list of surface dicts, got {} ({})",
            v.repr()?,
            v.get_type().name()?
        ))),
    }
}
