//! Lens prescriptions from files: heron's TOML (`[[surface]]` tables, or the
//! `[[camera.surface]]` of a scene) and pbrt-v4's lens files (`*.dat`: rows of radius,
//! thickness, index and aperture diameter in mm, object side first, index 0 for the
//! stop; heron reads an optional fifth column naming a catalogue glass). Errors name the
//! file, and the surface from 1 (pbrt's rows are surfaces too), or the line.
use crate::camera::lens::{LensSystem, Surface};
use crate::spectrum::ior::Ior;
use serde::Deserialize;
use std::path::Path;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PrescriptionFile {
    name: String,
    #[allow(dead_code)]
    source: String,
    #[serde(default)]
    reference_wavelength: Option<f64>,
    surface: Vec<toml::Value>,
}

/// One `[[surface]]`: lengths in mm.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SurfaceFile {
    radius: f64,
    thickness: f64,
    #[serde(default)]
    medium: Option<toml::Value>,
    semi_aperture: f64,
    #[serde(default)]
    stop: bool,
}

/// The prescription in the file at `path`: a pbrt-v4 lens file when its name ends in
/// `.dat`, else heron's TOML. Errors start with the path.
pub fn read_prescription(path: &Path) -> Result<LensSystem, String> {
    let at = path.display();
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("{at}: cannot read the lens prescription: {e}"))?;
    let name = path
        .file_stem()
        .map_or_else(|| "lens".to_string(), |s| s.to_string_lossy().into_owned());
    let base = path.parent().unwrap_or(Path::new(""));
    let sys = if path.extension().is_some_and(|e| e == "dat") {
        parse_pbrt_lens(&text, &name)
    } else {
        parse_prescription(&text, base)
    };
    sys.map_err(|e| format!("{at}: {e}"))
}

/// heron's TOML prescription (`name`, `source`, optional `reference_wavelength`,
/// `[[surface]]`s); a glass table file is read relative to `base_dir`. A surface's
/// `medium` accepts what a dielectric's `ior` does, and "air" (n = 1, the default).
pub fn parse_prescription(text: &str, base_dir: &Path) -> Result<LensSystem, String> {
    let table: toml::Table = text
        .parse()
        .map_err(|e: toml::de::Error| super::errors::toml_syntax(text, &e))?;
    let file = PrescriptionFile::deserialize(toml::Value::Table(table))
        .map_err(|e| e.message().to_string())?;
    let mut sys = surfaces_from_values("", &file.name, &file.surface, base_dir)?;
    if let Some(l) = file.reference_wavelength {
        if !(360.0..=830.0).contains(&l) {
            return Err(format!(
                "reference_wavelength: expected a wavelength in 360–830 nm, got {l}"
            ));
        }
        sys.reference_wavelength = l;
    }
    Ok(sys)
}

/// The surfaces of `[[surface]]` tables (`prefix` goes before "surface N" in errors:
/// "camera." for a scene's inline prescription).
pub fn surfaces_from_values(
    prefix: &str,
    name: &str,
    values: &[toml::Value],
    base_dir: &Path,
) -> Result<LensSystem, String> {
    let mut surfaces = Vec::with_capacity(values.len());
    for (i, v) in values.iter().enumerate() {
        let at = format!("{prefix}surface {}", i + 1);
        let s =
            SurfaceFile::deserialize(v.clone()).map_err(|e| format!("{at}: {}", e.message()))?;
        let medium = match &s.medium {
            None => Ior::Constant(1.0),
            Some(toml::Value::String(a)) if a == "air" => Ior::Constant(1.0),
            Some(m) => {
                super::materials::ior_from_value(&format!("{at}: medium"), m.clone(), base_dir)?
            }
        };
        surfaces.push(Surface {
            radius: s.radius,
            thickness: s.thickness,
            medium,
            semi_aperture: s.semi_aperture,
            stop: s.stop,
        });
    }
    LensSystem::new(name, surfaces).map_err(|e| {
        if prefix.is_empty() {
            e
        } else {
            format!("{prefix}{e}")
        }
    })
}

/// A pbrt-v4 lens file (pbrt-v4 `RealisticCamera`; its lenses/*.dat): per row the
/// radius, the thickness to the next surface, the index behind the surface (0: the
/// aperture stop, in air) and the aperture's diameter, in mm, from the object side.
/// A fifth column, heron's, names a catalogue glass that replaces the index. `#`
/// starts a comment.
pub fn parse_pbrt_lens(text: &str, name: &str) -> Result<LensSystem, String> {
    let mut surfaces = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line_no = i + 1;
        let body = line.split('#').next().unwrap_or("").trim();
        if body.is_empty() {
            continue;
        }
        let cols: Vec<&str> = body.split_whitespace().collect();
        if !(4..=5).contains(&cols.len()) {
            return Err(format!(
                "line {line_no}: expected 4 numbers (radius, thickness, index, aperture diameter in mm) and an optional glass name, got {} fields",
                cols.len()
            ));
        }
        let num = |k: usize, what: &str| -> Result<f64, String> {
            cols[k]
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| {
                    format!(
                        "line {line_no}: expected a number for the {what}, got {:?}",
                        cols[k]
                    )
                })
        };
        let radius = num(0, "radius")?;
        let thickness = num(1, "thickness")?;
        let eta = num(2, "index")?;
        let diameter = num(3, "aperture diameter")?;
        let stop = eta == 0.0;
        let medium = match cols.get(4) {
            Some(glass) => crate::spectrum::ior::named(glass).ok_or_else(|| {
                format!(
                    "line {line_no} (surface {}): unknown glass {glass:?}; expected a name from spectra/ior_catalogue.toml",
                    surfaces.len() + 1
                )
            })?,
            None if stop => Ior::Constant(1.0),
            None if eta >= 1.0 => Ior::Constant(eta as f32),
            None => {
                return Err(format!(
                    "line {line_no} (surface {}): expected an index ≥ 1 (or 0 for the stop), got {eta}",
                    surfaces.len() + 1
                ))
            }
        };
        surfaces.push(Surface {
            radius,
            thickness,
            medium,
            semi_aperture: 0.5 * diameter,
            stop,
        });
    }
    LensSystem::new(name, surfaces)
}

#[cfg(test)]
mod tests {
    use super::*;

    const DGAUSS: &str = "# D-GAUSS F/2 22deg HFOV
#    radius	 axpos	N	aperture
29.475	3.76	1.67	25.2
84.83	0.12	1	25.2
19.275	4.025	1.67	23
40.77	3.275	1.699	23
12.75	5.705	1	18
0	4.5	0	17.1
-14.495	1.18	1.603	17
40.77	6.065	1.658	20
-20.385	0.19	1	20
437.065	3.22	1.717	20
-39.73	0	1	20
";

    #[test]
    fn pbrt_lens_files_load() {
        let s = parse_pbrt_lens(DGAUSS, "dgauss").unwrap();
        assert_eq!(s.surfaces.len(), 11);
        assert_eq!(s.stop, 5);
        assert_eq!(s.surfaces[0].semi_aperture, 12.6);
        assert!(!s.is_dispersive());
        // With glasses.
        let g = DGAUSS.replace(
            "29.475\t3.76\t1.67\t25.2",
            "29.475\t3.76\t1.67\t25.2\tN-BAF10",
        );
        assert!(parse_pbrt_lens(&g, "dgauss").unwrap().is_dispersive());
        let e = parse_pbrt_lens(&DGAUSS.replace("1.699", "N-SF5x"), "x").unwrap_err();
        assert!(
            e.starts_with("line 6: expected a number for the index"),
            "{e}"
        );
        let e = parse_pbrt_lens(&g.replace("N-BAF10", "N-BAF11x"), "x").unwrap_err();
        assert!(e.starts_with("line 3 (surface 1): unknown glass"), "{e}");
    }

    #[test]
    fn toml_prescriptions_name_the_surface() {
        let text = r#"
name = "singlet"
source = "a test"
[[surface]]
radius = 0
thickness = 1
stop = true
semi_aperture = 4
[[surface]]
radius = 25.84
thickness = 5
medium = "N-BK7"
semi_aperture = 12.7
[[surface]]
radius = 0
thickness = 46.7
semi_aperture = 12.7
"#;
        let s = parse_prescription(text, Path::new(".")).unwrap();
        assert!(s.is_dispersive());
        assert_eq!(s.reference_wavelength, 587.5618);
        let e = parse_prescription(&text.replace("N-BK7", "N-BK8"), Path::new(".")).unwrap_err();
        assert!(
            e.starts_with("surface 2: medium: unknown refractive-index model"),
            "{e}"
        );
        let e = parse_prescription(
            &text.replace("radius = 25.84", "radius = 10"),
            Path::new("."),
        )
        .unwrap_err();
        assert!(
            e.starts_with("surface 2: semi-aperture 12.7 mm is larger"),
            "{e}"
        );
        let e = parse_prescription(
            &text.replace("thickness = 5", "thickness = \"5\""),
            Path::new("."),
        )
        .unwrap_err();
        assert!(e.starts_with("surface 2: invalid type"), "{e}");
        let e = parse_prescription(
            &text.replace("thickness = 1\n", "thickness = 1\ncolour = 2\n"),
            Path::new("."),
        )
        .unwrap_err();
        assert!(e.starts_with("surface 1: unknown field `colour`"), "{e}");
    }
}
