//! Lights: each `[[lights]]` entry to its [`Light`] (point, directional, sun with an
//! optional portal, spot), and one area light per emitting shape after them.
use super::errors::fmt_points;
use super::shapes::{cross_overflows, is_degenerate};
use super::textures::Textures;
use crate::geometry::{Shape, ShapeKind};
use crate::light::{
    AreaLight, AreaShape, DirectionalLight, Light, LightPolarization, PointLight, Portal,
    SpotLight, SunLight,
};
use crate::scene::file::{
    fmt_f32, LightFile, LightPolarizationFile, ShapeEmission, ShapeFile, SpotLightFile,
    SunLightFile,
};
use crate::spectrum::DenseSpectrum;

/// The file's lights, in file order.
pub(super) fn build_lights(entries: &[LightFile]) -> Result<Vec<Light>, String> {
    entries
        .iter()
        .enumerate()
        .map(|(i, l)| match l {
            LightFile::Point(p) => Ok(Light::Point(PointLight {
                position: p.position.get(),
                intensity: p.intensity.spectrum(),
            })),
            LightFile::Directional(d) => Ok(Light::Directional(DirectionalLight {
                direction: d.direction.unit(),
                radiance: d.radiance.spectrum(),
            })),
            LightFile::Sun(s) => sun(&format!("lights[{i}]"), s).map(Light::Sun),
            LightFile::Spot(s) => spot(&format!("lights[{i}]"), s).map(Light::Spot),
        })
        .collect()
}

/// The polarisation of each `[[lights]]` entry, in file order (`light::polarization`).
pub(super) fn build_light_polarization(
    entries: &[LightFile],
) -> Result<Vec<Option<LightPolarization>>, String> {
    entries
        .iter()
        .enumerate()
        .map(|(i, l)| {
            let p = match l {
                LightFile::Point(p) => &p.polarization,
                LightFile::Directional(d) => &d.polarization,
                LightFile::Spot(s) => &s.polarization,
                LightFile::Sun(_) => &None,
            };
            p.as_ref()
                .map(|p| polarization(&format!("lights[{i}].polarization"), p))
                .transpose()
        })
        .collect()
}

/// A light's `polarization` table at key path `at`.
fn polarization(at: &str, p: &LightPolarizationFile) -> Result<LightPolarization, String> {
    let circular = p.circular.unwrap_or(0.0);
    let linear = p
        .linear
        .unwrap_or(if p.circular.is_some() { 0.0 } else { 1.0 });
    for (key, v) in [("linear", linear), ("circular", circular)] {
        if !(v.is_finite() && (-1.0..=1.0).contains(&v)) {
            return Err(format!("{at}.{key}: expected a number in [-1, 1], got {v}"));
        }
    }
    if linear * linear + circular * circular > 1.0 + 1e-6 {
        return Err(format!(
            "{at}: expected a degree of polarisation sqrt(linear^2 + circular^2) of at most 1, got linear = {linear} and circular = {circular}"
        ));
    }
    Ok(LightPolarization {
        axis: p.axis.unit(),
        linear,
        circular,
    })
}

/// A sun entry at key path `at`.
fn sun(at: &str, s: &SunLightFile) -> Result<SunLight, String> {
    let deg = s
        .angular_radius
        .map_or(crate::light::sun::SUN_ANGULAR_RADIUS_DEG, |a| a.get());
    if deg >= 90.0 {
        return Err(format!(
            "{at}.angular_radius: expected degrees in (0, 90), got {deg}"
        ));
    }
    let mut sun = SunLight::new(
        s.direction.unit(),
        s.irradiance.spectrum(),
        deg.to_radians(),
    );
    if !sun.radiance.values().iter().all(|v| v.is_finite()) {
        return Err(format!(
            "{at}: the sun's radiance (irradiance / solid angle of the disk) overflows f32 with angular_radius = {} degrees and irradiance up to {}; expected a larger angular_radius or a smaller irradiance",
            fmt_f32(deg),
            fmt_f32(sun.irradiance.max_value())
        ));
    }
    if let Some(p) = &s.portal {
        let (o, e1, e2) = (p.origin.get(), p.edge1.get(), p.edge2.get());
        if cross_overflows(o, o + e1, o + e2) || !(o + e1 + e2).is_finite() {
            return Err(format!(
                "{at}.portal: expected a portal whose corners and edges' cross product are finite in f32 (coordinates within about ±1e19), got origin {} and edges {} and {}",
                fmt_points(&[o]),
                fmt_points(&[e1]),
                fmt_points(&[e2])
            ));
        }
        if is_degenerate(o, o + e1, o + e2) {
            return Err(format!(
                "{at}.portal: expected edge1 and edge2 spanning a non-zero area, got {} and {}",
                fmt_points(&[e1]),
                fmt_points(&[e2])
            ));
        }
        sun.portal = Some(Portal::new(o, e1, e2));
    }
    Ok(sun)
}

/// A spot entry at key path `at`.
fn spot(at: &str, s: &SpotLightFile) -> Result<SpotLight, String> {
    let angle = s.cone_angle.map_or(30.0, |a| a.get());
    let delta = s.cone_delta.map_or(5.0, |a| a.get());
    if angle > 90.0 {
        return Err(format!(
            "{at}.cone_angle: expected degrees in (0, 90], got {angle}"
        ));
    }
    if delta > angle {
        return Err(format!(
            "{at}.cone_delta: expected degrees in [0, cone_angle = {angle}], got {delta}"
        ));
    }
    Ok(SpotLight {
        position: s.position.get(),
        direction: s.direction.unit(),
        intensity: s.intensity.spectrum(),
        cos_falloff_start: (angle - delta).to_radians().cos(),
        cos_falloff_end: angle.to_radians().cos(),
    })
}

/// Appends one area light per emitting shape (emission above zero somewhere) to `lights`
/// and gives the shape its index. `shape_entry` is each shape's entry in `entries`. A
/// textured emission (`{ texture = "NAME", scale = S }`) is the named tree from
/// `textures` times D65 at Y = 1 times S ([`crate::scene::file::ShapeEmission`]); its
/// shape then computes uv at its hits.
pub(super) fn add_area_lights(
    entries: &[ShapeFile],
    shape_entry: &[usize],
    shapes: &mut [Shape],
    lights: &mut Vec<Light>,
    textures: &mut Textures,
    inputs: &mut Vec<String>,
) -> Result<(), String> {
    for (k, shape) in shapes.iter_mut().enumerate() {
        let (_, emission, two_sided) = entries[shape_entry[k]].emission();
        let (spectrum, texture) = match emission {
            None => continue,
            Some(ShapeEmission::Colour(e)) => {
                if e.0.max_value() <= 0.0 {
                    continue;
                }
                (e.spectrum(), None)
            }
            Some(ShapeEmission::Texture { texture, scale }) => {
                let at = format!("shapes[{}].emission", shape_entry[k]);
                let tree = textures.tree(&at, texture, inputs)?;
                if *scale <= 0.0 {
                    continue;
                }
                (
                    crate::spectrum::uplift::named("D65")
                        .unwrap_or_else(|| DenseSpectrum::constant(1.0))
                        .scaled(*scale as f32),
                    Some(tree),
                )
            }
        };
        let two_sided = two_sided.unwrap_or(false);
        let area = match &shape.kind {
            ShapeKind::Sphere { center, radius } => AreaLight::new(
                k as u32,
                spectrum,
                two_sided,
                AreaShape::Sphere {
                    center: *center,
                    radius: *radius,
                },
            ),
            ShapeKind::Mesh(m) => AreaLight::triangles(
                k as u32,
                spectrum,
                two_sided,
                m.indices
                    .iter()
                    .map(|t| t.map(|v| m.positions[v as usize]))
                    .collect(),
            ),
        };
        let area = match texture {
            None => area,
            Some(tree) => {
                shape.textured_emission = true;
                let uvs = match &shape.kind {
                    ShapeKind::Mesh(m) => m.uvs.clone(),
                    ShapeKind::Sphere { .. } => Vec::new(),
                };
                area.with_texture(tree, uvs)
            }
        };
        shape.light = lights.len() as u32;
        lights.push(Light::Area(area));
    }
    Ok(())
}
