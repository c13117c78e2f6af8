//! `[environment]`: the environment map ([`crate::light::EnvMap`]) from its image file.
use super::image::read_rgb;
use crate::light::{EnvMap, EnvMapping};
use crate::scene::file::EnvironmentFile;
use glam::{DMat3, Mat3};
use std::path::Path;
use std::sync::Arc;

/// The map of `env`, its image read relative to `base_dir` (and listed in `inputs`).
pub(super) fn build_envmap(
    env: &EnvironmentFile,
    base_dir: &Path,
    inputs: &mut Vec<String>,
) -> Result<Arc<EnvMap>, String> {
    let mapping = match &env.mapping {
        None => EnvMapping::LatLong,
        Some(m) => EnvMapping::from_name(m).ok_or_else(|| {
            format!(
                "environment.mapping: expected one of {}, got {m:?}",
                EnvMapping::NAMES.join(", ")
            )
        })?,
    };
    let to_world = orientation(&env.transform)?;
    let img = read_rgb(&base_dir.join(&env.map)).map_err(|e| format!("environment.map: {e}"))?;
    match mapping {
        EnvMapping::LatLong if img.height < 2 => {
            return Err(format!(
                "environment.map: a latlong map needs at least 2 rows (its first and last are the poles), {} has {}",
                env.map, img.height
            ))
        }
        EnvMapping::EqualArea if img.width != img.height => {
            return Err(format!(
                "environment.map: an equal-area map is square, {} is {} × {}",
                env.map, img.width, img.height
            ))
        }
        _ => {}
    }
    inputs.push(env.map.clone());
    let scale = env.scale.map_or(1.0, |s| s.get());
    Ok(Arc::new(EnvMap::new(
        mapping,
        img.width,
        img.height,
        &img.pixels,
        scale,
        to_world,
    )))
}

/// The 3 × 3 part of `environment.transform`, checked to be orthogonal (to 1e-4): the
/// map is sampled by solid angle, which only rotations and mirrors keep.
fn orientation(t: &Option<Vec<Vec<f64>>>) -> Result<Mat3, String> {
    let Some(rows) = t else {
        return Ok(Mat3::IDENTITY);
    };
    let well_formed = rows.len() == 4
        && rows
            .iter()
            .all(|r| r.len() == 4 && r.iter().all(|x| x.is_finite()))
        && rows[3] == [0.0, 0.0, 0.0, 1.0];
    if !well_formed {
        return Err(format!(
            "environment.transform: expected four rows of four finite numbers, the last [0, 0, 0, 1] (an affine matrix), got {rows:?}"
        ));
    }
    let m = DMat3::from_cols_array_2d(&[
        [rows[0][0], rows[1][0], rows[2][0]],
        [rows[0][1], rows[1][1], rows[2][1]],
        [rows[0][2], rows[1][2], rows[2][2]],
    ]);
    let e = (m.transpose() * m - DMat3::IDENTITY).to_cols_array();
    let worst = e.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    if !(worst <= 1e-4) {
        return Err(format!(
            "environment.transform: expected a rotation (an orthogonal 3 × 3 part), got {rows:?}, whose MᵀM is off the identity by {worst:.3e}"
        ));
    }
    Ok(m.as_mat3())
}
