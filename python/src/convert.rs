//! Values between Python and heron: dicts to TOML (for `Scene.from_dict` and `ior`),
//! JSON values to Python objects (the CLI's JSON reports), numbers and number lists.
use crate::err;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};

/// A Python value as TOML: bool, int, float, str, list/tuple (arrays) and dict with str
/// keys (tables); numpy scalars and arrays go through `.item()` / `.tolist()`. `at` is the
/// key path for the error message, which names the value's type.
pub fn to_toml(v: &Bound<'_, PyAny>, at: &str) -> PyResult<toml::Value> {
    // bool before int: Python's bool is an int subclass.
    if v.is_instance_of::<PyBool>() {
        return Ok(toml::Value::Boolean(v.extract()?));
    }
    if v.is_instance_of::<PyInt>() {
        return match v.extract::<i64>() {
            Ok(i) => Ok(toml::Value::Integer(i)),
            Err(_) => Err(err(format!(
                "{at}: expected an integer within 64 bits, got {}",
                v.str()?
            ))),
        };
    }
    if v.is_instance_of::<PyFloat>() {
        return Ok(toml::Value::Float(v.extract()?));
    }
    if v.is_instance_of::<PyString>() {
        return Ok(toml::Value::String(v.extract()?));
    }
    if let Ok(d) = v.cast::<PyDict>() {
        let mut t = toml::Table::new();
        for (k, x) in d.iter() {
            let Ok(key) = k.extract::<String>() else {
                return Err(err(format!(
                    "{at}: expected string keys, got {} ({})",
                    k.repr()?,
                    k.get_type().name()?
                )));
            };
            let path = if at.is_empty() {
                key.clone()
            } else {
                format!("{at}.{key}")
            };
            t.insert(key, to_toml(&x, &path)?);
        }
        return Ok(toml::Value::Table(t));
    }
    if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        let mut a = Vec::new();
        for (i, x) in v.try_iter()?.enumerate() {
            a.push(to_toml(&x?, &format!("{at}[{i}]"))?);
        }
        return Ok(toml::Value::Array(a));
    }
    // numpy arrays and scalars (and anything else with tolist/item) as their Python
    // equivalents.
    for method in ["tolist", "item"] {
        if v.hasattr(method)? && !v.is_none() {
            let plain = v.call_method0(method)?;
            if !plain.is(v) {
                return to_toml(&plain, at);
            }
        }
    }
    Err(err(format!(
        "{at}: expected a bool, int, float, str, list or dict (a TOML value), got {} ({})",
        v.repr()?,
        v.get_type().name()?
    )))
}

/// A JSON value (one of the CLI's reports) as Python: objects as dicts, arrays as lists,
/// null as None.
pub fn json_to_py<'py>(py: Python<'py>, v: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    use serde_json::Value;
    Ok(match v {
        Value::Null => py.None().into_bound(py),
        Value::Bool(b) => PyBool::new(py, *b).to_owned().into_any(),
        Value::Number(n) => {
            if let Some(i) = n.as_i64() {
                i.into_pyobject(py)?.into_any()
            } else {
                n.as_f64().unwrap_or(f64::NAN).into_pyobject(py)?.into_any()
            }
        }
        Value::String(s) => PyString::new(py, s).into_any(),
        Value::Array(a) => {
            let l = PyList::empty(py);
            for x in a {
                l.append(json_to_py(py, x)?)?;
            }
            l.into_any()
        }
        Value::Object(o) => {
            let d = PyDict::new(py);
            for (k, x) in o {
                d.set_item(k, json_to_py(py, x)?)?;
            }
            d.into_any()
        }
    })
}

/// A number or a one-dimensional sequence of numbers (list, tuple, numpy array) as
/// f64 values; `name` is the argument for the error message.
pub fn numbers(v: &Bound<'_, PyAny>, name: &str) -> PyResult<Vec<f64>> {
    if let Ok(x) = v.extract::<f64>() {
        return Ok(vec![x]);
    }
    if v.is_instance_of::<PyString>() {
        return Err(err(format!(
            "{name}: expected a number or a sequence of numbers, got {}",
            v.repr()?
        )));
    }
    let mut out = Vec::new();
    let iter = v.try_iter().map_err(|_| {
        err(format!(
            "{name}: expected a number or a sequence of numbers, got {} ({})",
            v.repr().map(|r| r.to_string()).unwrap_or_default(),
            v.get_type()
                .name()
                .map(|n| n.to_string())
                .unwrap_or_default()
        ))
    })?;
    for (i, x) in iter.enumerate() {
        let x = x?;
        out.push(x.extract::<f64>().map_err(|_| {
            err(format!(
                "{name}[{i}]: expected a number, got {}",
                x.repr().map(|r| r.to_string()).unwrap_or_default()
            ))
        })?);
    }
    Ok(out)
}

/// Three numbers (a point or direction), finite in f32; `name` is the argument.
pub fn vec3(v: &Bound<'_, PyAny>, name: &str) -> PyResult<glam::Vec3> {
    let x = numbers(v, name)?;
    if x.len() != 3 {
        return Err(err(format!(
            "{name}: expected X,Y,Z (three numbers), got {} number{}",
            x.len(),
            if x.len() == 1 { "" } else { "s" }
        )));
    }
    Ok(glam::Vec3::new(x[0] as f32, x[1] as f32, x[2] as f32))
}
