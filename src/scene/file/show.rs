//! How values appear in messages: TOML values written back as the user wrote them, and
//! numbers with the digits that tell them apart.
use super::*;

/// A TOML value written back on one line for an error message, shortened when long.
pub fn show(v: &toml::Value) -> String {
    let mut s = String::new();
    show_into(v, &mut s);
    if s.chars().count() > 80 {
        let cut: String = s.chars().take(77).collect();
        format!("{cut}...")
    } else {
        s
    }
}

pub(super) fn show_into(v: &toml::Value, s: &mut String) {
    match v {
        toml::Value::String(x) => {
            let _ = write!(s, "{x:?}");
        }
        toml::Value::Integer(x) => {
            let _ = write!(s, "{x}");
        }
        toml::Value::Float(x) => {
            let _ = write!(s, "{}", fmt_f64(*x));
        }
        toml::Value::Boolean(x) => {
            let _ = write!(s, "{x}");
        }
        toml::Value::Datetime(x) => {
            let _ = write!(s, "{x}");
        }
        toml::Value::Array(a) => {
            s.push('[');
            for (i, x) in a.iter().enumerate() {
                if i > 0 {
                    s.push_str(", ");
                }
                show_into(x, s);
            }
            s.push(']');
        }
        toml::Value::Table(t) => {
            if t.is_empty() {
                s.push_str("{}");
                return;
            }
            s.push_str("{ ");
            for (i, (k, x)) in t.iter().enumerate() {
                if i > 0 {
                    s.push_str(", ");
                }
                let _ = write!(s, "{k} = ");
                show_into(x, s);
            }
            s.push_str(" }");
        }
    }
}

/// [`fmt_f64`] of an f32, in its own shortest form (`1e-30`, not `1.0000000031710769e-30`).
pub(crate) fn fmt_f32(x: f32) -> String {
    if x.is_finite() && x != 0.0 && !(1e-5..1e16).contains(&x.abs()) {
        format!("{x:e}")
    } else if x.is_finite() {
        format!("{x}")
    } else {
        fmt_f64(x as f64)
    }
}

/// TOML's spelling of a float (`nan`, `inf`, `-inf`, else Rust's shortest form, with an
/// exponent when very large or small: `3e38`, not 39 digits).
pub(crate) fn fmt_f64(x: f64) -> String {
    if x.is_nan() {
        "nan".into()
    } else if x.is_infinite() {
        if x > 0.0 { "inf" } else { "-inf" }.into()
    } else if x != 0.0 && !(1e-5..1e16).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}
