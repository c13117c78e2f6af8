//! `heron.compare`: `heron compare`'s region z-test (heron::compare) from Python.
use crate::convert::json_to_py;
use crate::scene::RenderResult;
use crate::{err, guard, lib_err};
use heron_core::compare::{compare as compare_images, Correction, Image, Options};
use numpy::{AllowTypeChange, IntoPyArray, PyArrayLike3, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use std::path::PathBuf;

/// The flags of `heron compare`, by this function's argument names.
const RENAMES: &[(&str, &str)] = &[
    ("--region", "region"),
    ("--alpha", "alpha"),
    ("--correction", "correction"),
    ("--tolerance", "tolerance"),
    ("--heatmap", "heatmap"),
];

/// An H×W×3 array-like as (width, height, pixels); `what` names it in errors.
fn array3(v: &Bound<'_, PyAny>, what: &str) -> PyResult<(u32, u32, Vec<[f32; 3]>)> {
    let a = v
        .extract::<PyArrayLike3<'_, f32, AllowTypeChange>>()
        .map_err(|_| {
            err(format!(
                "{what}: expected an EXR path, a heron.RenderResult, an H×W×3 array or a tuple (image, variance) of them, got {}",
                v.get_type().name().map(|n| n.to_string()).unwrap_or_default()
            ))
        })?;
    let view = a.as_array();
    let (h, w, c) = view.dim();
    if c != 3 || w == 0 || h == 0 {
        return Err(err(format!(
            "{what}: expected an H×W×3 array, got shape ({h}, {w}, {c})"
        )));
    }
    let too_big = || err(format!("{what}: the image is too large"));
    let (w32, h32) = (
        u32::try_from(w).map_err(|_| too_big())?,
        u32::try_from(h).map_err(|_| too_big())?,
    );
    let px = (0..h * w)
        .map(|i| std::array::from_fn(|k| view[[i / w, i % w, k]]))
        .collect();
    Ok((w32, h32, px))
}

/// One image argument of `compare`: a path to an EXR, a RenderResult (its R, G, B and
/// variance), an H×W×3 array (no variance), or a tuple (array, variance array).
fn image_arg(py: Python<'_>, v: &Bound<'_, PyAny>, what: &str) -> PyResult<Image> {
    if let Ok(r) = v.cast::<RenderResult>() {
        let r = r.get();
        let (w, h, px) = array3(r.rgb_array(py).bind(py).as_any(), what)?;
        let var = match r.variance_array(py) {
            Some(a) => Some(array3(a.bind(py).as_any(), what)?.2),
            None => None,
        };
        return Image::new(what, w, h, ["R", "G", "B"], px, var).map_err(|e| lib_err(e, &[]));
    }
    if let Ok(t) = v.cast::<PyTuple>() {
        if t.len() != 2 {
            return Err(err(format!(
                "{what}: expected a tuple (image, variance), got {} items",
                t.len()
            )));
        }
        let (w, h, px) = array3(&t.get_item(0)?, what)?;
        let (vw, vh, var) = array3(&t.get_item(1)?, &format!("{what} variance"))?;
        if (vw, vh) != (w, h) {
            return Err(err(format!(
                "{what}: the variance is {vw}x{vh}, the image {w}x{h}: expected the same size"
            )));
        }
        return Image::new(what, w, h, ["R", "G", "B"], px, Some(var)).map_err(|e| lib_err(e, &[]));
    }
    if let Ok(p) = v.extract::<PathBuf>() {
        return py
            .detach(|| Image::read_exr(&p))
            .map_err(|e| lib_err(e, &[]));
    }
    let (w, h, px) = array3(v, what)?;
    Image::new(what, w, h, ["R", "G", "B"], px, None).map_err(|e| lib_err(e, &[]))
}

/// Are two renders the same image up to noise? `heron compare`'s test: the mean
/// difference per region and channel against its standard error, from both images'
/// variance (`Scene.render(variance=True)`, `heron render --variance`) or, when either
/// lacks it, from the spread of the differences within each region (Student t); the
/// whole image is one more test per channel; the family of tests is held at `alpha` by
/// Šidák's or Bonferroni's correction.
///
/// a, b: each a path to an EXR (its R, G, B and variance.R/G/B channels), a
/// heron.RenderResult (its rgb and variance), an H×W×3 array (no variance) or a tuple
/// (array, variance array). b is the reference of the relative errors. region: edge in
/// pixels (16); alpha: family-wise significance level (0.01); correction: "sidak" or
/// "bonferroni"; mask: optional H×W booleans, the pixels to compare; tolerance: a
/// relative margin, mean differences within it allowed (0; e.g. 0.05 for sppm's radius
/// bias); heatmap: optional
/// path of a PNG heat map of the z-scores (written atomically).
///
/// Returns a dict: "same" (the verdict), "status" (0 same, 1 different: the CLI's exit
/// status), "report" (the CLI's text), "tests", "per_test_alpha", "critical_z",
/// "variance_from" ("channels" or "spread"), "rel_rmse", "rel_mse", "mean_difference"
/// and "standard_error" (3 floats each: the whole image's test), "failing" (the failing
/// tests, largest |z| first, as dicts), "regions" and "whole" (every test), "identical"
/// (regions left out as equal and noiseless) and "z" (rows × columns × 3 float64 array
/// of the regions' z, NaN where not tested). Errors (different sizes, unreadable files,
/// bad options) raise HeronError, where the CLI exits with status 2.
#[pyfunction]
#[pyo3(signature = (a, b, *, region=16, alpha=0.01, correction="sidak", mask=None, tolerance=0.0, heatmap=None))]
pub fn compare<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    region: i64,
    alpha: f64,
    correction: &str,
    mask: Option<&Bound<'py, PyAny>>,
    tolerance: f64,
    heatmap: Option<PathBuf>,
) -> PyResult<Bound<'py, PyDict>> {
    guard(|| {
        let region = u32::try_from(region)
            .ok()
            .filter(|&r| r >= 1)
            .ok_or_else(|| err(format!("region: expected at least 1 pixel, got {region}")))?;
        let correction =
            Correction::parse(correction).map_err(|e| err(format!("correction: {e}")))?;
        let (ia, ib) = (image_arg(py, a, "a")?, image_arg(py, b, "b")?);
        let mask = match mask {
            None => None,
            Some(m) => {
                let arr = m
                    .extract::<numpy::PyArrayLike2<'_, bool, AllowTypeChange>>()
                    .map_err(|_| err("mask: expected an H×W array of booleans"))?;
                let view = arr.as_array();
                let (h, w) = view.dim();
                if (w as u64, h as u64) != (ia.width as u64, ia.height as u64) {
                    return Err(err(format!(
                        "mask: expected {}x{} (the images' size), got {w}x{h}",
                        ia.width, ia.height
                    )));
                }
                Some(
                    (0..h * w)
                        .map(|i| view[[i / w, i % w]])
                        .collect::<Vec<bool>>(),
                )
            }
        };
        let opts = Options {
            region,
            alpha,
            correction,
            mask,
            tolerance,
        };
        let c = py
            .detach(|| compare_images(&ia, &ib, &opts))
            .map_err(|e| lib_err(e, RENAMES))?;
        if let Some(path) = &heatmap {
            if path.extension().and_then(|e| e.to_str()) != Some("png") {
                return Err(err(format!(
                    "heatmap {}: expected a path ending in .png",
                    path.display()
                )));
            }
            c.write_heat_map(path, opts.mask.as_deref())
                .map_err(|e| lib_err(e, RENAMES))?;
        }
        let json = serde_json::to_value(&c)
            .map_err(|e| err(format!("cannot convert the comparison: {e}")))?;
        let d = json_to_py(py, &json)?
            .cast_into::<PyDict>()
            .map_err(|_| err("internal error in heron: the comparison is not a dict"))?;
        let same = c.same();
        d.set_item("same", same)?;
        d.set_item("status", if same { 0 } else { 1 })?;
        d.set_item("tests", c.tests())?;
        d.set_item("report", c.report("a", "b", 20))?;
        let failing = serde_json::to_value(c.failing())
            .map_err(|e| err(format!("cannot convert the comparison: {e}")))?;
        d.set_item("failing", json_to_py(py, &failing)?)?;
        let whole = |f: fn(&heron_core::compare::RegionTest) -> f64| {
            let mut v = [f64::NAN; 3];
            for t in &c.whole {
                v[t.channel] = f(t);
            }
            v.to_vec()
        };
        d.set_item("mean_difference", whole(|t| t.difference))?;
        d.set_item("standard_error", whole(|t| t.standard_error))?;
        let (rows, cols, z) = c.z_grid();
        d.set_item("z", z.into_pyarray(py).reshape([rows, cols, 3])?)?;
        Ok(d)
    })
}
