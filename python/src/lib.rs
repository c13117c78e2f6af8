//! The Python module `heron`: heron's library from Python, with numpy arrays.
//!
//! - `load_scene(path)`, `Scene.from_dict(d)`: the scene loader of the CLI (a dict goes
//!   through the same TOML loader as a file, so its errors are the loader's);
//! - `Scene.render(...)` → `RenderResult`: `heron::render::render` with the options
//!   `heron render` sets up (src/main.rs `cmd_render`), so the arrays are the numbers of
//!   the CLI's EXR bit for bit; the GIL is released while rendering, and Ctrl-C stops the
//!   render within a row of a tile (`RenderOptions::cancel`);
//! - `halo_profile`: the core of `heron halo profile`.
//! - `trace`, `sky_profile`, `color`, `ior`: the cores of `heron trace`, `heron sky
//!   profile`, `heron color` (in memory) and the scene files' `ior` values;
//! - `compare`: `heron compare`'s test of two images (EXR paths, render results or
//!   arrays), with the same verdict and statistics;
//! - `lens`: `heron lens`'s report of a lens prescription (a file or a list of surface
//!   dicts): first order at F, d, C, the chromatic focal shift and spot diagrams, with
//!   the CSV files' numbers.
//!
//! Errors: every bad input raises `heron.HeronError`, a subclass of `ValueError`, with
//! the CLI's one-line message; where the CLI names a flag (`--lanes`), the message names
//! the Python argument (`lanes`) instead. No panic crosses into Python: every call runs
//! inside [`guard`], which turns a panic into a `HeronError` naming it as an internal
//! error.
use pyo3::prelude::*;
use std::panic::{catch_unwind, AssertUnwindSafe};

mod compare;
mod convert;
mod lens;
mod scene;
mod tools;

pyo3::create_exception!(
    heron,
    HeronError,
    pyo3::exceptions::PyValueError,
    "Bad input to heron (a scene key, an argument, a file): the message is the one line the \
     heron CLI prints for the same mistake. A subclass of ValueError."
);

/// A heron error as the Python exception.
pub(crate) fn err(msg: impl Into<String>) -> PyErr {
    HeronError::new_err(msg.into())
}

/// A library error (its Display is the CLI's message after `error: `), with the CLI's
/// flag names replaced by the Python arguments' (`renames`: (flag, argument) pairs).
pub(crate) fn lib_err(e: impl std::fmt::Display, renames: &[(&str, &str)]) -> PyErr {
    err(rename_flags(&e.to_string(), renames))
}

/// Replaces each CLI flag of `renames` in `msg` by its Python argument name. A flag is
/// replaced only where it is not followed by another letter or `-` (so `--dir` does not
/// touch `--direction`).
pub(crate) fn rename_flags(msg: &str, renames: &[(&str, &str)]) -> String {
    let mut out = msg.to_string();
    for (flag, arg) in renames {
        let mut result = String::with_capacity(out.len());
        let mut rest = out.as_str();
        while let Some(i) = rest.find(flag) {
            let after = &rest[i + flag.len()..];
            let whole = !after
                .chars()
                .next()
                .is_some_and(|c| c.is_ascii_alphanumeric() || c == '-');
            result.push_str(&rest[..i]);
            result.push_str(if whole { arg } else { flag });
            rest = after;
        }
        result.push_str(rest);
        out = result;
    }
    out
}

/// Runs `f`, turning a panic into a `HeronError` (a panic is a bug in heron, but it must
/// not take the interpreter down or surface as pyo3's `PanicException`).
pub(crate) fn guard<T>(f: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(r) => r,
        Err(payload) => Err(err(format!(
            "internal error in heron (please report it): {}",
            panic_message(payload.as_ref())
        ))),
    }
}

/// The text of a panic's payload.
pub(crate) fn panic_message(p: &(dyn std::any::Any + Send)) -> String {
    if let Some(s) = p.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = p.downcast_ref::<String>() {
        s.clone()
    } else {
        "a panic".to_string()
    }
}

/// heron: a physically faithful spectral ray tracer for optics research, from Python.
///
/// Scenes are heron's TOML scene files (`load_scene`) or the same schema as a dict
/// (`Scene.from_dict`); `Scene.render` returns numpy arrays (linear sRGB, CIE XYZ,
/// spectral bins) equal bit for bit to the EXR `heron render` writes for the same
/// settings. `trace`, `sky_profile`, `color` and `ior` are the CLI's `heron trace`,
/// `heron sky profile`, `heron color` and the scene files' refractive indices;
/// `compare` is `heron compare`, `lens` is `heron lens`.
/// Bad input raises `HeronError` (a `ValueError`) with the CLI's one-line message.
/// `heron.__version__`: the crate version with the git commit as a PEP 440 local version
/// label (PEP 440, "Local version identifiers"): `0.1.0+g<40 hex>`, `.dirty` appended when
/// the sources differed from the commit, plain `0.1.0` when built outside git.
fn python_version() -> String {
    use heron_core::provenance::{GIT_COMMIT, GIT_STATE, VERSION};
    match (GIT_COMMIT, GIT_STATE) {
        ("unknown", _) => VERSION.to_string(),
        (c, "dirty") => format!("{VERSION}+g{c}.dirty"),
        (c, _) => format!("{VERSION}+g{c}"),
    }
}

#[pymodule]
fn heron(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("HeronError", m.py().get_type::<HeronError>())?;
    m.add("__version__", python_version())?;
    m.add("__commit__", heron_core::provenance::COMMIT)?;
    m.add_class::<scene::Scene>()?;
    m.add_class::<scene::RenderResult>()?;
    m.add_function(wrap_pyfunction!(scene::load_scene, m)?)?;
    m.add_function(wrap_pyfunction!(tools::trace, m)?)?;
    m.add_function(wrap_pyfunction!(tools::sky_profile, m)?)?;
    m.add_function(wrap_pyfunction!(tools::halo_profile, m)?)?;
    m.add_function(wrap_pyfunction!(tools::color, m)?)?;
    m.add_function(wrap_pyfunction!(tools::ior, m)?)?;
    m.add_function(wrap_pyfunction!(compare::compare, m)?)?;
    m.add_function(wrap_pyfunction!(lens::lens, m)?)?;
    Ok(())
}
