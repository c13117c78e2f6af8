//! Mitsuba 3's `<transform>` element as an affine matrix: its children (`translate`,
//! `rotate`, `scale`, `matrix`, `lookat`) each multiply from the left, so they apply in
//! the order written (Mitsuba 3, "Scene XML file format", Transformations). `lookat`
//! is Mitsuba's `Transform4f::look_at`: columns left, up, forward and the origin, so a
//! sensor looks along its local +z.
use super::xml::{Diagnostic, Node};
use glam::{DMat4, DVec3, DVec4};

/// Numbers separated by commas and/or white space, as Mitsuba writes lists.
pub fn numbers(text: &str) -> Option<Vec<f64>> {
    text.split(|c: char| c == ',' || c.is_whitespace())
        .filter(|s| !s.is_empty())
        .map(|s| s.parse::<f64>().ok().filter(|v| v.is_finite()))
        .collect()
}

/// A vector from `value="x, y, z"` or from `x`, `y`, `z` attributes (each defaulting to
/// `default`).
pub fn vector_attrs(n: &Node, default: f64) -> Result<DVec3, Diagnostic> {
    if let Some(v) = n.attr("value") {
        return match numbers(v).as_deref() {
            Some([x, y, z]) => Ok(DVec3::new(*x, *y, *z)),
            Some([s]) => Ok(DVec3::splat(*s)),
            _ => Err(n.diag(format!(
                "value: expected three numbers \"x, y, z\", got {v:?}"
            ))),
        };
    }
    let mut out = [default; 3];
    for (o, key) in out.iter_mut().zip(["x", "y", "z"]) {
        if let Some(v) = n.attr(key) {
            *o = number(n, key, v)?;
        }
    }
    Ok(DVec3::from_array(out))
}

/// One number in attribute `key` of `n`.
pub fn number(n: &Node, key: &str, v: &str) -> Result<f64, Diagnostic> {
    match numbers(v).as_deref() {
        Some([x]) => Ok(*x),
        _ => Err(n.diag(format!("{key}: expected a finite number, got {v:?}"))),
    }
}

fn point(n: &Node, key: &str) -> Result<DVec3, Diagnostic> {
    let Some(v) = n.attr(key) else {
        return Err(n.diag(format!("expected the attribute {key}=\"x, y, z\"")));
    };
    match numbers(v).as_deref() {
        Some([x, y, z]) => Ok(DVec3::new(*x, *y, *z)),
        _ => Err(n.diag(format!(
            "{key}: expected three numbers \"x, y, z\", got {v:?}"
        ))),
    }
}

/// The matrix of a `<transform>` element.
pub fn parse_transform(t: &Node) -> Result<DMat4, Diagnostic> {
    let mut m = DMat4::IDENTITY;
    for op in &t.children {
        let step = match op.tag.as_str() {
            "translate" => DMat4::from_translation(vector_attrs(op, 0.0)?),
            "scale" => DMat4::from_scale(vector_attrs(op, 1.0)?),
            "rotate" => {
                let axis = vector_attrs(op, 0.0)?;
                let angle = match op.attr("angle") {
                    Some(a) => number(op, "angle", a)?,
                    None => return Err(op.diag("expected the attribute angle (degrees)")),
                };
                if axis.length() == 0.0 {
                    return Err(op.diag("expected a non-zero axis x, y, z"));
                }
                DMat4::from_axis_angle(axis.normalize(), angle.to_radians())
            }
            "matrix" => {
                let v = op.attr("value").unwrap_or("");
                match numbers(v) {
                    // Mitsuba writes the matrix row by row.
                    Some(x) if x.len() == 16 => DMat4::from_cols_array(&[
                        x[0], x[4], x[8], x[12], x[1], x[5], x[9], x[13], x[2], x[6], x[10],
                        x[14], x[3], x[7], x[11], x[15],
                    ]),
                    Some(x) if x.len() == 9 => DMat4::from_cols_array(&[
                        x[0], x[3], x[6], 0.0, x[1], x[4], x[7], 0.0, x[2], x[5], x[8], 0.0,
                        0.0, 0.0, 0.0, 1.0,
                    ]),
                    _ => {
                        return Err(op.diag(format!(
                            "value: expected 16 (4×4) or 9 (3×3) numbers, row by row, got {v:?}"
                        )))
                    }
                }
            }
            "lookat" => {
                let origin = point(op, "origin")?;
                let target = point(op, "target")?;
                let up = match op.attr("up") {
                    Some(_) => point(op, "up")?,
                    None => DVec3::Y,
                };
                look_at(origin, target, up).map_err(|m| op.diag(m))?
            }
            other => {
                return Err(op.diag(format!(
                    "expected translate, rotate, scale, matrix or lookat inside <transform>, got <{other}>"
                )))
            }
        };
        m = step * m;
    }
    if !m.is_finite() {
        return Err(t.diag("the transform is not finite"));
    }
    if m.row(3) != DVec4::new(0.0, 0.0, 0.0, 1.0) {
        return Err(t.diag(
            "expected an affine transform (last row 0 0 0 1); projective transforms are not supported",
        ));
    }
    Ok(m)
}

/// Mitsuba's `look_at`: local +z toward the target, +y toward `up`, +x to the left.
pub fn look_at(origin: DVec3, target: DVec3, up: DVec3) -> Result<DMat4, String> {
    let dir = (target - origin).normalize_or_zero();
    if dir == DVec3::ZERO {
        return Err("lookat: expected a target different from the origin".into());
    }
    let left = up.cross(dir).normalize_or_zero();
    if left == DVec3::ZERO {
        return Err("lookat: expected an up vector not parallel to the view direction".into());
    }
    let new_up = dir.cross(left);
    Ok(DMat4::from_cols(
        left.extend(0.0),
        new_up.extend(0.0),
        dir.extend(0.0),
        origin.extend(1.0),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn look_at_sends_local_z_to_the_target_and_y_to_up() {
        let m = look_at(DVec3::new(0.0, 0.0, 5.0), DVec3::ZERO, DVec3::Y).unwrap();
        let o = m.transform_point3(DVec3::ZERO);
        let f = m.transform_vector3(DVec3::Z);
        let u = m.transform_vector3(DVec3::Y);
        assert!((o - DVec3::new(0.0, 0.0, 5.0)).length() < 1e-12);
        assert!((f - DVec3::new(0.0, 0.0, -1.0)).length() < 1e-12);
        assert!((u - DVec3::Y).length() < 1e-12);
    }

    #[test]
    fn numbers_take_commas_and_spaces() {
        assert_eq!(numbers("1, 2 3,4").unwrap(), vec![1.0, 2.0, 3.0, 4.0]);
        assert!(numbers("1, x").is_none());
        assert!(numbers("nan").is_none());
    }
}
