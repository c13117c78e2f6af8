//! Materials: each `[materials.NAME]` table to its [`Material`] (refractive indices and
//! metals' complex indices read from the catalogue, formulas or tables), the two materials
//! the loader adds for shapes that name none, and the lookup of a material by name.
use super::errors::key;
use super::textures::Textures;
use crate::bsdf::microfacet::{TrowbridgeReitz, MIN_ALPHA};
use crate::bsdf::{
    CoatedDiffuse, Conductor, Dielectric, DiffuseTransmission, Glossy, GlossyTextures, Lambertian,
    Material, Mirror, Polarizer, Retarder, RoughConductor, RoughDielectric, TexturedDiffuse,
    ThinDielectric,
};
use crate::scene::file::{
    DiffuseTransmissionFile, GlossyFile, IorSpec, MaterialFile, MetalSpec, SceneFile, Textured,
    UnitNumber,
};
use crate::spectrum::ior::Ior;
use crate::spectrum::metals::ComplexIor;
use crate::spectrum::DenseSpectrum;
use crate::texture::Texture;
use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

/// The scene's materials: the file's, sorted by name (a TOML table keeps no order), then
/// the ones the loader adds.
pub(super) struct Materials {
    pub list: Vec<Material>,
    pub names: Vec<String>,
    /// The black Lambertian of a shape that emits and names no material (a pure
    /// emitter); its index even when no shape needs it.
    pub black: u32,
    /// The index-matched boundary of a shape with a medium and no material: a dielectric
    /// of index 1 (Fresnel 0, straight through), so every integrator and `heron stress`
    /// see a valid material, and the path tracer passes it without a bounce.
    pub boundary: u32,
    index: HashMap<String, u32>,
}

impl Materials {
    /// Builds the file's materials (tables read relative to `base_dir`, recorded in
    /// `inputs`), and adds the black emitter and the medium boundary after them, when a
    /// shape needs one, so the named materials' indices do not move.
    pub fn build(
        file: &SceneFile,
        base_dir: &Path,
        inputs: &mut Vec<String>,
    ) -> Result<Materials, String> {
        let mut list = Vec::with_capacity(file.materials.len());
        let mut names = Vec::with_capacity(file.materials.len());
        let mut textures = Textures::new(&file.textures, base_dir);
        for (name, m) in &file.materials {
            list.push(build_material(
                &key("materials", name),
                m,
                base_dir,
                &mut textures,
                inputs,
            )?);
            names.push(name.clone());
        }
        let black = list.len() as u32;
        if file.shapes.iter().any(|s| {
            let (m, e, _) = s.emission();
            m.is_none() && e.is_some()
        }) {
            list.push(Material::Lambertian(Lambertian {
                rho_d: DenseSpectrum::constant(0.0),
            }));
            names.push("(black emitter)".into());
        }
        let boundary = list.len() as u32;
        if file.shapes.iter().any(|s| {
            let (m, e, _) = s.emission();
            m.is_none() && e.is_none() && s.medium().is_some()
        }) {
            list.push(Material::Dielectric(Dielectric::new(
                Ior::Constant(1.0),
                true,
            )));
            names.push("(medium boundary)".into());
        }
        let index = names
            .iter()
            .enumerate()
            .map(|(i, n)| (n.clone(), i as u32))
            .collect();
        Ok(Materials {
            list,
            names,
            black,
            boundary,
            index,
        })
    }

    /// The index of the material `name` that key path `at` names.
    pub fn lookup(&self, at: &str, name: &str) -> Result<u32, String> {
        self.index.get(name).copied().ok_or_else(|| {
            let defined = if self.names.is_empty() {
                "no materials are defined".to_string()
            } else {
                format!("defined: {}", self.names.join(", "))
            };
            format!("{at}: no material named {name:?} ({defined})")
        })
    }
}

/// The refractive-index model a scene file's `ior` value describes (a number, a catalogue
/// name, `{ sellmeier = .. }`, `{ cauchy = .. }` or `{ table = "file.csv" }`, read
/// relative to `base_dir`), checked as the loader checks it; the error is the loader's
/// message after `at` (the key path it names). For the Python module's `heron.ior`.
pub fn ior_from_value(
    at: &str,
    value: toml::Value,
    base_dir: &Path,
) -> std::result::Result<Ior, String> {
    use serde::Deserialize as _;
    let spec = IorSpec::deserialize(value).map_err(|e| format!("{at}: {}", e.message()))?;
    build_ior(at, &spec, base_dir, &mut Vec::new())
}

/// The refractive-index model of `spec`; a table file is read relative to `base_dir`.
fn build_ior(
    at: &str,
    spec: &IorSpec,
    base_dir: &Path,
    inputs: &mut Vec<String>,
) -> std::result::Result<Ior, String> {
    let ior = match spec {
        IorSpec::Constant(n) => Ior::Constant(*n as f32),
        IorSpec::Named(name) => crate::spectrum::ior::named(name)
            .ok_or_else(|| format!("{at}: unknown refractive-index model {name:?}"))?,
        IorSpec::Sellmeier { b, c } => {
            let f32s = |v: &[f64]| v.iter().map(|&x| x as f32).collect::<Vec<_>>();
            Ior::sellmeier(&f32s(b), &f32s(c)).map_err(|e| format!("{at}: {e}"))?
        }
        IorSpec::Cauchy([a, b, c]) => Ior::Cauchy {
            a: *a as f32,
            b: *b as f32,
            c: *c as f32,
        },
        IorSpec::Abbe { n_d, v_d } => Ior::abbe(*n_d as f32, *v_d as f32),
        IorSpec::Table(file) => {
            let p = base_dir.join(file);
            let csv =
                crate::spectrum::csv::SpectrumCsv::read(&p).map_err(|e| format!("{at}: {e}"))?;
            inputs.push(file.clone());
            Ior::Table(csv.to_dense())
        }
    };
    ior.validate().map_err(|e| format!("{at}: {e}"))?;
    Ok(ior)
}

/// The complex index of `spec`; a table is read relative to `base_dir`.
fn build_metal(
    at: &str,
    spec: &MetalSpec,
    base_dir: &Path,
    inputs: &mut Vec<String>,
) -> std::result::Result<ComplexIor, String> {
    let at = format!("{at}.metal");
    match spec {
        MetalSpec::Named(name) => crate::spectrum::metals::named(name)
            .ok_or_else(|| format!("{at}: unknown metal {name:?}")),
        MetalSpec::Table(file) => {
            inputs.push(file.clone());
            crate::spectrum::metals::read_nk(&base_dir.join(file)).map_err(|e| format!("{at}: {e}"))
        }
        MetalSpec::Constant { n, k } => Ok(ComplexIor {
            n: DenseSpectrum::constant(*n as f32),
            k: DenseSpectrum::constant(*k as f32),
        }),
        MetalSpec::Curves { n, k } => {
            // Imported scenes arrive as SceneFile without the TOML reader's checks.
            n.check_index(true).map_err(|e| format!("{at}.n: {e}"))?;
            k.check_index(false).map_err(|e| format!("{at}.k: {e}"))?;
            Ok(ComplexIor {
                n: n.index_spectrum(),
                k: k.index_spectrum(),
            })
        }
    }
}

/// The material of the table `m` at key path `at` (`materials.NAME`).
fn build_material(
    at: &str,
    m: &MaterialFile,
    base_dir: &Path,
    textures: &mut Textures,
    inputs: &mut Vec<String>,
) -> std::result::Result<Material, String> {
    Ok(match m {
        MaterialFile::Lambertian(l) => match (&l.rho_d, &l.texture) {
            (Some(Textured::Value(rho)), None) => Material::Lambertian(Lambertian {
                rho_d: rho.spectrum(),
            }),
            (Some(Textured::Texture(name)), None) => Material::TexturedDiffuse(
                TexturedDiffuse::new(textures.tree(&format!("{at}.rho_d"), name, inputs)?),
            ),
            // `texture` names a [textures] table, or else (as before tables) a file.
            (None, Some(t)) => Material::TexturedDiffuse(TexturedDiffuse::new(
                if textures.has(t) {
                    textures.tree(&format!("{at}.texture"), t, inputs)?
                } else {
                    textures.image_file(&format!("{at}.texture"), t, inputs)?
                },
            )),
            (Some(_), Some(_)) => {
                return Err(format!(
                    "{at}: expected rho_d or texture, not both (the texture is the reflectance)"
                ))
            }
            (None, None) => {
                return Err(format!(
                    "{at}: expected rho_d (a reflectance or {{ texture = \"NAME\" }}) or texture (a [textures] table or an image file)"
                ))
            }
        },
        MaterialFile::Mirror(mi) => Material::Mirror(match &mi.rho_s {
            // Left out: the lecture's ideal mirror, exactly 1 at every wavelength.
            None => Mirror {
                rho_s: DenseSpectrum::constant(1.0),
                texture: None,
            },
            Some(Textured::Value(r)) => Mirror {
                rho_s: r.spectrum(),
                texture: None,
            },
            Some(Textured::Texture(name)) => Mirror {
                rho_s: DenseSpectrum::constant(1.0),
                texture: Some(textures.tree(&format!("{at}.rho_s"), name, inputs)?),
            },
        }),
        MaterialFile::Dielectric(d) => {
            let mut interface = Dielectric::new(
                build_ior(&format!("{at}.ior"), &d.ior, base_dir, inputs)?,
                d.fresnel.unwrap_or(true),
            );
            if let Some(o) = &d.outside_ior {
                interface.outside = build_ior(&format!("{at}.outside_ior"), o, base_dir, inputs)?;
            }
            let (alpha, alpha_texture) =
                roughness(at, d.roughness.as_ref(), textures, inputs)?;
            if alpha < MIN_ALPHA && alpha_texture.is_none() {
                Material::Dielectric(interface)
            } else {
                if d.fresnel == Some(false) {
                    let r = describe_roughness(d.roughness.as_ref());
                    return Err(format!(
                        "{at}.fresnel: false applies to the smooth interface (the lecture's pure refraction), not with roughness = {r}"
                    ));
                }
                Material::RoughDielectric(RoughDielectric {
                    interface,
                    distribution: TrowbridgeReitz { alpha },
                    alpha_texture,
                })
            }
        }
        MaterialFile::Conductor(c) => {
            let ior = build_metal(at, &c.metal, base_dir, inputs)?;
            let (alpha, alpha_texture) =
                roughness(at, c.roughness.as_ref(), textures, inputs)?;
            if alpha < MIN_ALPHA && alpha_texture.is_none() {
                Material::Conductor(Conductor { ior })
            } else {
                Material::RoughConductor(RoughConductor {
                    ior,
                    distribution: TrowbridgeReitz { alpha },
                    alpha_texture,
                })
            }
        }
        MaterialFile::Coated(c) => {
            let ior = match &c.ior {
                Some(spec) => build_ior(&format!("{at}.ior"), spec, base_dir, inputs)?,
                None => Ior::Constant(1.5),
            };
            let thickness = c.thickness.unwrap_or(0.0);
            if !(thickness >= 0.0 && (thickness as f32).is_finite()) {
                return Err(format!(
                    "{at}.thickness: expected a finite optical depth >= 0, got {thickness}"
                ));
            }
            let (alpha, alpha_texture) =
                roughness(at, c.roughness.as_ref(), textures, inputs)?;
            let (rho, rho_texture) = match &c.reflectance {
                Textured::Value(r) => (r.spectrum(), None),
                Textured::Texture(name) => (
                    DenseSpectrum::constant(0.0),
                    Some(textures.tree(&format!("{at}.reflectance"), name, inputs)?),
                ),
            };
            let (thickness, linear) = (thickness as f32, !c.nonlinear.unwrap_or(true));
            let coat = match alpha_texture {
                None => CoatedDiffuse::new(
                    rho,
                    ior,
                    (alpha >= MIN_ALPHA).then_some(TrowbridgeReitz { alpha }),
                    thickness,
                    linear,
                ),
                Some(t) => CoatedDiffuse::textured_alpha(rho, ior, t, thickness, linear),
            };
            Material::CoatedDiffuse(match rho_texture {
                None => coat,
                Some(t) => coat.with_rho_texture(t),
            })
        }
        MaterialFile::Glossy(g) => {
            if g.fresnel.is_some() && g.ior.is_none() {
                return Err(format!(
                    "{at}.fresnel: expected only together with ior (fresnel weights the refractive base), but ior is not given"
                ));
            }
            let (rho_d, rho_s, textures) = glossy_params(at, g, textures, inputs)?;
            Material::Glossy(Glossy {
                rho_d,
                rho_s,
                textures,
                shininess: g.shininess.get(),
                base: match &g.ior {
                    Some(spec) => Some(Dielectric::new(
                        build_ior(&format!("{at}.ior"), spec, base_dir, inputs)?,
                        g.fresnel.unwrap_or(true),
                    )),
                    None => None,
                },
            })
        }
        MaterialFile::Polarizer(p) => {
            let t_x = p.transmittance.unwrap_or(1.0);
            if !(t_x > 0.0 && t_x <= 1.0) {
                return Err(format!(
                    "{at}.transmittance: expected a number in (0, 1], got {t_x}"
                ));
            }
            let t_y = match p.extinction_ratio {
                None => 0.0,
                Some(r) if r >= 1.0 && r.is_finite() => t_x / r,
                Some(r) => {
                    return Err(format!(
                        "{at}.extinction_ratio: expected a finite number of at least 1 (t along the axis / t across it), got {r}"
                    ))
                }
            };
            Material::Polarizer(Polarizer {
                axis: p.axis.map_or(glam::Vec3::Y, |a| a.unit()),
                angle: sheet_angle(at, p.angle)?,
                t_x,
                t_y,
            })
        }
        MaterialFile::Retarder(r) => {
            let waves = r.retardance.unwrap_or(0.25);
            if !waves.is_finite() {
                return Err(format!(
                    "{at}.retardance: expected a finite number of waves (0.25 for a quarter-wave plate), got {waves}"
                ));
            }
            Material::Retarder(Retarder {
                axis: r.axis.map_or(glam::Vec3::Y, |a| a.unit()),
                angle: sheet_angle(at, r.angle)?,
                retardance: waves * std::f32::consts::TAU,
            })
        }
        MaterialFile::ThinDielectric(d) => {
            let mut sheet =
                ThinDielectric::new(build_ior(&format!("{at}.ior"), &d.ior, base_dir, inputs)?);
            if let Some(o) = &d.outside_ior {
                sheet.outside = build_ior(&format!("{at}.outside_ior"), o, base_dir, inputs)?;
            }
            Material::ThinDielectric(sheet)
        }
        MaterialFile::DiffuseTransmission(d) => diffuse_transmission(at, d)?,
    })
}

/// A roughness key (`roughness`): the constant α (0 when absent or textured) and the
/// texture, if it names one.
fn roughness(
    at: &str,
    r: Option<&Textured<UnitNumber>>,
    textures: &mut Textures,
    inputs: &mut Vec<String>,
) -> std::result::Result<(f32, Option<Arc<Texture>>), String> {
    Ok(match r {
        None => (0.0, None),
        Some(Textured::Value(a)) => (a.get(), None),
        Some(Textured::Texture(name)) => (
            0.0,
            Some(textures.tree(&format!("{at}.roughness"), name, inputs)?),
        ),
    })
}

/// A roughness key as written, for a message.
fn describe_roughness(r: Option<&Textured<UnitNumber>>) -> String {
    match r {
        Some(Textured::Value(a)) => a.get().to_string(),
        Some(Textured::Texture(name)) => format!("{{ texture = {name:?} }}"),
        None => "0".into(),
    }
}

/// The glossy model's ρd, ρs and textures. Constants keep the seed's check ρd + ρs ≤ 1
/// ("Glossy materials", energy conservation) and are refused past it; a texture on
/// either key is clamped at the hit instead (src/bsdf/phong.rs), as a texture's maximum
/// is one texel's and should not refuse the whole image.
type GlossyParams = (DenseSpectrum, f32, Option<Box<GlossyTextures>>);
fn glossy_params(
    at: &str,
    g: &GlossyFile,
    textures: &mut Textures,
    inputs: &mut Vec<String>,
) -> std::result::Result<GlossyParams, String> {
    let (rho_d, rho_s) = match (&g.rho_d, &g.rho_s) {
        (Textured::Value(rho_d), Textured::Value(rho_s)) => {
            let rho_s = rho_s.get();
            let sum_max = match rho_d.0.rgb() {
                Some(rgb) => rgb.iter().fold(f32::MIN, |a, &c| a.max(c + rho_s)),
                None => rho_d.0.max_value() + rho_s,
            };
            if sum_max > 1.0 + 1e-6 {
                let rho_d = rho_d.0.describe();
                return Err(format!(
                    "{at}: expected rho_d + rho_s <= 1 in every channel (energy conservation), got rho_d = {rho_d} and rho_s = {rho_s} (sum up to {sum_max})"
                ));
            }
            return Ok((rho_d.spectrum(), rho_s, None));
        }
        pair => pair,
    };
    let mut t = GlossyTextures::default();
    let rho_d = match rho_d {
        Textured::Value(r) => r.spectrum(),
        Textured::Texture(name) => {
            t.rho_d = Some(textures.tree(&format!("{at}.rho_d"), name, inputs)?);
            DenseSpectrum::constant(0.0)
        }
    };
    let rho_s = match rho_s {
        Textured::Value(r) => r.get(),
        Textured::Texture(name) => {
            t.rho_s = Some(textures.tree(&format!("{at}.rho_s"), name, inputs)?);
            0.0
        }
    };
    Ok((rho_d, rho_s, Some(Box::new(t))))
}

/// Diffuse transmission, with ρ_r + τ ≤ 1 (energy conservation) checked per RGB channel
/// when both are given as RGB (or numbers), else per wavelength. Two RGB colours whose
/// channels sum to at most 1 can have uplifted spectra summing to a little more at some
/// wavelengths (the uplift is not linear); there both are scaled down to sum to 1.
fn diffuse_transmission(
    at: &str,
    d: &DiffuseTransmissionFile,
) -> std::result::Result<Material, String> {
    let (r, t) = (&d.reflectance.0, &d.transmittance.0);
    let (mut rs, mut ts) = (d.reflectance.spectrum(), d.transmittance.spectrum());
    let sum_max = match (r.rgb(), t.rgb()) {
        (Some(a), Some(b)) => (0..3).fold(f32::MIN, |m, i| m.max(a[i] + b[i])),
        _ => rs
            .values()
            .iter()
            .zip(ts.values())
            .fold(f32::MIN, |m, (a, b)| m.max(a + b)),
    };
    if sum_max > 1.0 + 1e-6 {
        return Err(format!(
            "{at}: expected reflectance + transmittance <= 1 at every wavelength (energy conservation), got reflectance = {} and transmittance = {} (sum up to {sum_max})",
            r.describe(),
            t.describe()
        ));
    }
    let sum = DenseSpectrum::from_fn(|l| rs.eval(l) + ts.eval(l));
    if sum.max_value() > 1.0 {
        let scale = DenseSpectrum::from_fn(|l| 1.0 / sum.eval(l).max(1.0));
        (rs, ts) = (rs.mul(&scale), ts.mul(&scale));
    }
    Ok(Material::DiffuseTransmission(DiffuseTransmission {
        reflectance: rs,
        transmittance: ts,
    }))
}

/// A sheet's `angle` in degrees, as radians (default 0).
fn sheet_angle(at: &str, angle: Option<f32>) -> std::result::Result<f32, String> {
    match angle {
        None => Ok(0.0),
        Some(a) if a.is_finite() => Ok(a.to_radians()),
        Some(a) => Err(format!(
            "{at}.angle: expected a finite angle in degrees, got {a}"
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ior_from_value_reads_a_scene_files_ior() {
        let eval = |v: toml::Value| ior_from_value("ior", v, Path::new("")).map(|i| i.eval(500.0));
        assert_eq!(eval(toml::Value::Float(1.5)), Ok(1.5));
        let named = crate::spectrum::ior::named("N-BK7").unwrap().eval(500.0);
        assert_eq!(eval(toml::Value::String("N-BK7".into())), Ok(named));
        let cauchy: toml::Value = toml::from_str::<toml::Table>("cauchy = [1.5, 0.0042]")
            .unwrap()
            .into();
        let n = eval(cauchy).unwrap();
        assert!((n - (1.5 + 0.0042 / 0.25)).abs() < 1e-6, "{n}");
        // The loader's messages, after the key path given.
        let e = eval(toml::Value::String("BK7".into())).unwrap_err();
        assert!(
            e.starts_with("ior: unknown refractive-index model \"BK7\", expected one of"),
            "{e}"
        );
        let e = eval(toml::Value::Float(-1.0)).unwrap_err();
        assert_eq!(e, "ior: expected a positive finite number, got -1");
        // A Cauchy model below 1 in the visible is refused as in a scene.
        let low: toml::Value = toml::from_str::<toml::Table>("cauchy = [0.5, 0.0]")
            .unwrap()
            .into();
        assert!(eval(low)
            .unwrap_err()
            .starts_with("ior: expected a refractive index ≥ 1"));
    }
}
