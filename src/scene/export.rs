//! The spectra a loaded scene uses, as JSON on heron's 1 nm grid (`heron spectra`, a
//! hidden command): reflectances and emissions after RGB uplift, metals' n and k,
//! dielectrics' indices, the background, point lights' intensities, and the triangles
//! of mesh shapes. tests/python/test_mitsuba.py gives these same
//! spectra to Mitsuba 3, so that a comparison of the two renderers does not also
//! compare their RGB uplifts.
use super::Scene;
use crate::bsdf::Material;
use crate::light::Light;
use crate::spectrum::{DenseSpectrum, LAMBDA_MIN};
use serde_json::{json, Value};

fn values(s: &DenseSpectrum) -> Value {
    json!(s.values().to_vec())
}

fn ior_values(ior: &crate::spectrum::ior::Ior) -> Value {
    values(&DenseSpectrum::from_fn(|l| ior.eval(l)))
}

/// The scene's spectra; `shapes[i]` is Embree geometry i.
pub fn spectra_json(scene: &Scene) -> Value {
    let lambda: Vec<f32> = (0..crate::spectrum::DENSE_LEN)
        .map(|i| LAMBDA_MIN + i as f32)
        .collect();
    let mut materials = serde_json::Map::new();
    for (name, m) in scene.material_names.iter().zip(&scene.materials) {
        let v = match m {
            Material::Lambertian(l) => json!({"type": "lambertian", "rho_d": values(&l.rho_d)}),
            Material::TexturedDiffuse(t) => {
                json!({"type": "lambertian", "texture": {"nodes": t.texture().nodes().len()}})
            }
            Material::Mirror(l) => json!({"type": "mirror", "rho_s": values(&l.rho_s)}),
            Material::Dielectric(d) => json!({"type": "dielectric", "ior": ior_values(&d.ior),
                "outside_ior": ior_values(&d.outside), "fresnel": d.fresnel, "alpha": 0.0}),
            Material::RoughDielectric(d) => json!({"type": "dielectric",
                "ior": ior_values(&d.interface.ior), "outside_ior": ior_values(&d.interface.outside),
                "fresnel": true, "alpha": d.distribution.alpha}),
            Material::Conductor(c) => json!({"type": "conductor", "n": values(&c.ior.n),
                "k": values(&c.ior.k), "alpha": 0.0}),
            Material::RoughConductor(c) => json!({"type": "conductor", "n": values(&c.ior.n),
                "k": values(&c.ior.k), "alpha": c.distribution.alpha}),
            Material::Glossy(g) => json!({"type": "glossy", "rho_d": values(&g.rho_d),
                "rho_s": g.rho_s, "shininess": g.shininess}),
            Material::CoatedDiffuse(c) => json!({"type": "coated", "reflectance": values(&c.rho),
                "ior": ior_values(&c.ior),
                "alpha": c.distribution.map_or(0.0, |d| d.alpha),
                "thickness": c.thickness, "linear": c.linear}),
            Material::Polarizer(p) => json!({"type": "polarizer",
                "axis": [p.axis.x, p.axis.y, p.axis.z], "angle": p.angle,
                "t_x": p.t_x, "t_y": p.t_y}),
            Material::Retarder(r) => json!({"type": "retarder",
                "axis": [r.axis.x, r.axis.y, r.axis.z], "angle": r.angle,
                "retardance": r.retardance}),
            Material::ThinDielectric(d) => json!({"type": "thin-dielectric",
                "ior": ior_values(&d.ior), "outside_ior": ior_values(&d.outside)}),
            Material::DiffuseTransmission(d) => json!({"type": "diffuse-transmission",
                "reflectance": values(&d.reflectance), "transmittance": values(&d.transmittance)}),
        };
        materials.insert(name.clone(), v);
    }
    let shapes: Vec<Value> = scene
        .shapes
        .iter()
        .map(|s| {
            let (emission, two_sided) = match scene.lights.get(s.light as usize) {
                Some(Light::Area(a)) => (values(&a.emission), a.two_sided),
                _ => (Value::Null, false),
            };
            // Triangle meshes (planes, triangles, quads and OBJ meshes after loading)
            // with their vertices, so another renderer can be given the same geometry.
            let mesh = match &s.kind {
                crate::geometry::ShapeKind::Mesh(m) => json!({
                    "positions": m.positions.iter().map(|p| [p.x, p.y, p.z]).collect::<Vec<_>>(),
                    "indices": m.indices,
                }),
                crate::geometry::ShapeKind::Sphere { .. } => Value::Null,
            };
            json!({
                "material": scene.material_names[s.material as usize],
                "emission": emission,
                "two_sided": two_sided,
                "mesh": mesh,
            })
        })
        .collect();
    let point_lights: Vec<Value> = scene
        .lights
        .iter()
        .filter_map(|l| match l {
            Light::Point(p) => Some(json!({
                "position": [p.position.x, p.position.y, p.position.z],
                "intensity": values(&p.intensity),
            })),
            _ => None,
        })
        .collect();
    json!({
        "lambda_nm": lambda,
        "materials": materials,
        "shapes": shapes,
        "point_lights": point_lights,
        "background": values(&scene.background),
    })
}
