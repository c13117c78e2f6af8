//! The `[camera]` table to the seed's pinhole [`Camera`], to a film behind a lens
//! prescription ([`crate::camera::lens`]), or to an orthographic camera
//! ([`crate::camera::Projection`]).
use super::errors::fmt_points;
use crate::camera::lens::{paraxial, Focus, LensCamera, LensSettings, LensSystem, PupilSampling};
use crate::camera::{Camera, D_MAX, D_MIN};
use crate::scene::file::{fmt_f32, CameraFile};
use glam::Vec3;
use std::path::Path;

/// The film diagonal of 35 mm film (36 × 24 mm), the default.
pub const FILM_DIAGONAL_35MM: f64 = 43.266615305567875;

/// The camera of the `[camera]` table `c`; a lens file is read relative to `base_dir`
/// and recorded in `inputs`.
pub(super) fn build_camera(
    c: &CameraFile,
    base_dir: &Path,
    inputs: &mut Vec<String>,
) -> Result<Camera, String> {
    if !(c.look_at.get() - c.eye.get()).length().is_finite() {
        return Err(format!(
            "camera: expected eye and look_at at a distance finite in f32, got eye = {} and look_at = {}",
            fmt_points(&[c.eye.get()]),
            fmt_points(&[c.look_at.get()])
        ));
    }
    let orthographic = c.kind.as_deref() == Some("orthographic");
    if let (false, Some(_)) = (orthographic, c.height) {
        return Err(
            "camera.height: the orthographic camera's image plane height; set camera.type = \"orthographic\" to use it".into(),
        );
    }
    let lens = match c.kind.as_deref() {
        None | Some("pinhole") | Some("orthographic") => {
            let lens_keys = [
                ("lens", c.lens.is_some()),
                ("surface", c.surface.is_some()),
                ("film_diagonal", c.film_diagonal.is_some()),
                ("film_distance", c.film_distance.is_some()),
                ("focus_distance", c.focus_distance.is_some()),
                ("focus_wavelength", c.focus_wavelength.is_some()),
                ("mm_per_unit", c.mm_per_unit.is_some()),
                ("f_number", c.f_number.is_some()),
                ("pupil", c.pupil.is_some()),
                ("film_offset", c.film_offset.is_some()),
            ];
            if let Some((k, _)) = lens_keys.iter().find(|(_, set)| *set) {
                return Err(format!(
                    "camera.{k}: a key of the lens camera; set camera.type = \"lens\" to use it"
                ));
            }
            None
        }
        Some("lens") => Some(build_lens(c, base_dir, inputs)?),
        Some(other) => {
            return Err(format!(
                "camera.type: expected \"pinhole\", \"lens\" or \"orthographic\", got {other:?}"
            ))
        }
    };
    let height = match (orthographic, c.height, c.d) {
        (true, _, Some(_)) => {
            return Err(
                "camera.d: the pinhole's camera constant; an orthographic camera's view is set by camera.height (the image plane's height in scene units)".into(),
            )
        }
        (true, None, _) => {
            return Err(
                "camera.height: an orthographic camera needs its image plane's height in scene units (a positive number)".into(),
            )
        }
        (_, h, _) => h.map(|h| h.get()),
    };
    let d = match (&lens, c.d) {
        (Some(_), Some(_)) => {
            return Err(
                "camera.d: the pinhole's camera constant; a lens camera's field of view follows from its focal length and film_diagonal".into(),
            )
        }
        // The pinhole of the same field of view, for what asks a camera for its d.
        (Some(l), None) => {
            let (_, fh) = l.film_size(c.resolution.width, c.resolution.height);
            let f = paraxial::paraxial(&l.system, l.settings.focus_wavelength).efl;
            ((f / fh) as f32).clamp(D_MIN, D_MAX)
        }
        (None, d) => d.map_or(1.0, |d| d.get()),
    };
    if !(D_MIN..=D_MAX).contains(&d) {
        return Err(format!(
            "camera.d: expected a camera constant in [{D_MIN:e}, {D_MAX:e}] (a vertical field of view from about 180° down to 1e-6 rad), got {}",
            fmt_f32(d)
        ));
    }
    let cam = Camera::new(
        c.eye.get(),
        c.look_at.get(),
        c.up.map_or(Vec3::Y, |u| u.unit()),
        d,
        c.resolution.width,
        c.resolution.height,
    )
    .map_err(|e| format!("camera: {e}"))?;
    let mut cam = cam;
    cam.polarizer = match c.polarizer {
        None => None,
        Some(a) if a.is_finite() => Some(a.to_radians()),
        Some(a) => {
            return Err(format!(
                "camera.polarizer: expected the analyser's angle in degrees from the image's horizontal, got {a}"
            ))
        }
    };
    Ok(match (lens, height) {
        (Some(l), _) => cam.with_lens(l),
        (None, Some(h)) => cam.orthographic(h),
        (None, None) => cam,
    })
}

/// The lens of a `type = "lens"` camera.
fn build_lens(
    c: &CameraFile,
    base_dir: &Path,
    inputs: &mut Vec<String>,
) -> Result<LensCamera, String> {
    let system: LensSystem = match (&c.lens, &c.surface) {
        (Some(file), None) => {
            let sys = super::lens::read_prescription(&base_dir.join(file))
                .map_err(|e| format!("camera.lens: {e}"))?;
            inputs.push(file.clone());
            sys
        }
        (None, Some(values)) => {
            super::lens::surfaces_from_values("camera.", "inline", values, base_dir)?
        }
        (Some(_), Some(_)) => {
            return Err(
                "camera.lens: give the prescription once: a file (lens = \"…\") or [[camera.surface]] tables, not both".into(),
            )
        }
        (None, None) => {
            return Err(
                "camera.lens: a lens camera needs a prescription: lens = \"file.toml\" (or a pbrt-v4 .dat file) or [[camera.surface]] tables".into(),
            )
        }
    };
    let focus_wavelength = c
        .focus_wavelength
        .map_or(system.reference_wavelength, |w| w.get() as f64);
    if !(360.0..=830.0).contains(&focus_wavelength) {
        return Err(format!(
            "camera.focus_wavelength: expected a wavelength in 360–830 nm, got {focus_wavelength}"
        ));
    }
    let mm_per_unit = c.mm_per_unit.map_or(1000.0, |x| x.get() as f64);
    let focus = match (c.film_distance, c.focus_distance) {
        (Some(_), Some(_)) => {
            return Err(
                "camera.focus_distance: give the focus once: film_distance (mm behind the last vertex) or focus_distance (scene units in front of the film), not both".into(),
            )
        }
        (Some(d), None) => Focus::FilmDistance(d.get() as f64),
        (None, Some(d)) => Focus::ObjectDistance(d.get() as f64 * mm_per_unit),
        (None, None) => Focus::Prescription,
    };
    let pupil = match c.pupil.as_deref() {
        None => PupilSampling::Bounds,
        Some(p) => PupilSampling::parse(p).ok_or_else(|| {
            format!(
                "camera.pupil: expected one of {}, got {p:?}",
                PupilSampling::NAMES.join(", ")
            )
        })?,
    };
    let system = match c.f_number {
        Some(n) => {
            let p = paraxial::paraxial(&system, focus_wavelength);
            system.with_stop_scaled(p.f_number / n.get() as f64)
        }
        None => system,
    };
    let settings = LensSettings {
        film_diagonal: c
            .film_diagonal
            .map_or(FILM_DIAGONAL_35MM, |x| x.get() as f64),
        focus,
        focus_wavelength,
        pupil,
        mm_per_unit,
        film_offset: c
            .film_offset
            .map_or((0.0, 0.0), |p| (p.get()[0] as f64, p.get()[1] as f64)),
    };
    LensCamera::new(system, settings).map_err(|e| format!("camera.{e}"))
}
