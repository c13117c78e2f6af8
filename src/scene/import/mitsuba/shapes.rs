//! Mitsuba 3's shapes (with their area emitters) and emitters as heron's shapes and
//! lights.
use super::*;
use crate::scene::file::{DirectionalLightFile, PointLightFile, ShapeEmission, SpotLightFile};

impl<'a> Converter<'a> {
    pub(super) fn shape(&mut self, n: &'a Node) -> Result<(), Diagnostic> {
        let kind = Self::plugin(n)?;
        match kind {
            "instance" => return self.instance(n),
            "shapegroup" if self.placing.is_some() => {
                return Err(n.diag("a shapegroup inside a shapegroup (Mitsuba forbids nesting)"))
            }
            "shapegroup" => return Err(n.diag("a shapegroup needs an id; it renders through <shape type=\"instance\"> referencing it")),
            _ => {}
        }
        let p = self.props(n);
        let to_world = self.placing.unwrap_or(DMat4::IDENTITY)
            * p.transform("to_world")?.unwrap_or(DMat4::IDENTITY);
        let flip = p.boolean("flip_normals")?.unwrap_or(false);
        // The BSDF, an area emitter and the interior medium.
        let mut material = None;
        let mut emission = None;
        let mut null_bsdf = false;
        let mut medium = None;
        for o in p.objects(&["bsdf", "emitter", "medium"]) {
            // A medium's role is the name on the element naming it (a `ref` too).
            let role = o.attr("name");
            let o = self.resolve(o)?;
            match o.tag.as_str() {
                "bsdf" if o.attr("type") == Some("null") => {
                    null_bsdf = true;
                    self.finish(&self.props(o))?;
                }
                "bsdf" => material = Some(self.bsdf(o)?),
                "emitter" => emission = self.emitter(o, Some(n))?,
                "medium" => match role {
                    Some("interior") => medium = self.medium(o)?,
                    Some("exterior") => self.warn(o.diag(
                        "an exterior medium is not supported (heron's media fill closed shapes and the camera is outside every medium), ignored",
                    ))?,
                    _ => {
                        return Err(o.diag(
                            "a shape's medium: expected name=\"interior\" or name=\"exterior\"",
                        ))
                    }
                },
                _ => return Err(o.diag("expected a bsdf, an emitter or a medium inside a shape")),
            }
        }
        let Some(material) = self.surface(n, kind, material, null_bsdf, &emission, &mut medium)?
        else {
            // A null surface around no medium is invisible: nothing to render, and
            // nothing of it to warn about.
            for c in &n.children {
                if let Some(name) = c.attr("name") {
                    p.get(name);
                }
            }
            return self.finish(&p);
        };
        let mut entries: Vec<ShapeFile> = Vec::new();
        match kind {
            "rectangle" => {
                let mut q = quad(
                    &to_world,
                    [-1.0, -1.0, 0.0],
                    [2.0, 0.0, 0.0],
                    [0.0, 2.0, 0.0],
                );
                if flip {
                    q.reverse_edges();
                }
                entries.push(q.shape());
            }
            "cube" if medium.is_some() => {
                // A medium needs one closed mesh, not six quads.
                entries.push(schema::triangle_mesh(&cube_triangles(&to_world, flip)));
            }
            "cube" => {
                for (o, e1, e2) in CUBE_FACES {
                    let mut q = quad(&to_world, o, e1, e2);
                    if flip {
                        q.reverse_edges();
                    }
                    entries.push(q.shape());
                }
            }
            "disk" => {
                let swap = flip ^ (to_world.determinant() < 0.0);
                let tau = std::f64::consts::TAU;
                entries.extend(schema::disk(
                    &to_world,
                    1.0,
                    0.0,
                    0.0,
                    tau,
                    swap,
                    DISK_SEGMENTS,
                ));
            }
            "cylinder" => entries.push(self.cylinder(n, &p, &to_world, flip)?),
            "sphere" => {
                let center = p.point("center")?.unwrap_or(DVec3::ZERO);
                let radius = p.float("radius")?.unwrap_or(1.0);
                let m3 = glam::DMat3::from_mat4(to_world);
                let s = [m3.x_axis.length(), m3.y_axis.length(), m3.z_axis.length()];
                if (s[0] - s[1]).abs() > 1e-6 * s[0] || (s[0] - s[2]).abs() > 1e-6 * s[0] {
                    return Err(n.diag(format!(
                        "to_world scales the sphere by {:.6}, {:.6}, {:.6}: heron's spheres take a uniform scale only",
                        s[0], s[1], s[2]
                    )));
                }
                if flip {
                    self.warn(n.diag("flip_normals on a sphere is not supported, ignored"))?;
                }
                entries.push(schema::sphere(
                    to_world.transform_point3(center),
                    radius * s[0],
                ));
            }
            "obj" | "ply" | "serialized" => {
                entries.push(self.mesh_file(n, &p, kind, to_world, flip)?)
            }
            other => {
                self.warn(n.diag(format!(
                    "shape {other:?} is not supported (rectangle, cube, disk, cylinder, sphere, obj, ply, serialized are), ignored"
                )))?;
                return self.finish(&p);
            }
        }
        for mut e in entries {
            let (m, em, _) = e.surface_mut();
            *m = material.clone();
            *em = emission.clone();
            *e.medium_mut() = medium.clone();
            self.shapes.push(e);
        }
        self.finish(&p)
    }

    /// An `obj`, `ply` or `serialized` shape: a mesh entry of its file, looked up as
    /// Mitsuba does, placed by `to_world`.
    fn mesh_file(
        &mut self,
        n: &Node,
        p: &Props<'a>,
        kind: &str,
        to_world: DMat4,
        flip: bool,
    ) -> Result<ShapeFile, Diagnostic> {
        let Some(file) = p.string("filename")? else {
            return Err(n.diag("expected <string name=\"filename\" value=\"…\"/>"));
        };
        // heron tells a mesh file's format by its extension (Mitsuba by the shape's
        // type), so a serialized file of another name would be read as OBJ.
        let ext = Path::new(file).extension().and_then(|e| e.to_str());
        if kind == "serialized" && !ext.is_some_and(|e| e.eq_ignore_ascii_case("serialized")) {
            return Err(n.diag(format!(
                "filename: expected a file ending in .serialized (heron tells mesh formats by their extension), got {file:?}"
            )));
        }
        let rel = relative_to(&self.find(n, file), &self.base);
        let file = rel.to_string_lossy().replace('\\', "/");
        if flip {
            self.warn(n.diag("flip_normals on a mesh is not supported, ignored"))?;
        }
        // heron shades every mesh by its face normals (docs/import.md, "Mitsuba 3 scenes").
        p.get("face_normals");
        if kind == "serialized" {
            let index = match p.integer("shape_index")? {
                None => None,
                Some(k) => Some(u32::try_from(k).map_err(|_| {
                    n.diag(format!("shape_index: expected an integer ≥ 0, got {k}"))
                })?),
            };
            return Ok(schema::serialized_mesh(file, to_world, index));
        }
        // heron's defaults are Mitsuba's (true for OBJ, false for PLY).
        let flip_uv = p.boolean("flip_tex_coords")?;
        Ok(schema::mesh(file, to_world, flip_uv))
    }

    /// Mitsuba's `instance` of a `shapegroup` (src/shapes/instance.cpp), flattened: a
    /// copy of each of the group's shapes with the instance's `to_world` applied after
    /// the shape's own, as pbrt's object instances are. As in Mitsuba, a group holds no
    /// emitters, no nested group and no instance.
    fn instance(&mut self, n: &'a Node) -> Result<(), Diagnostic> {
        if self.placing.is_some() {
            return Err(n.diag("an instance inside a shapegroup (Mitsuba forbids nesting)"));
        }
        let p = self.props(n);
        let to_world = p.transform("to_world")?.unwrap_or(DMat4::IDENTITY);
        let groups: Vec<&'a Node> = p.objects(&["shape"]);
        let group = match groups.as_slice() {
            [g] => self.resolve(g)?,
            _ => {
                return Err(
                    n.diag("an instance: expected exactly one shapegroup (a <ref id=…/> to it)")
                )
            }
        };
        if group.tag != "shape" || group.attr("type") != Some("shapegroup") {
            return Err(n.diag(format!(
                "an instance: expected a reference to a shapegroup, got {}",
                group.describe()
            )));
        }
        self.placing = Some(to_world);
        let mut out = Ok(());
        for c in &group.children {
            let c = match self.resolve(c) {
                Ok(c) => c,
                Err(e) => {
                    out = Err(e);
                    break;
                }
            };
            if c.tag != "shape" {
                out = Err(c.diag("a shapegroup holds shapes only"));
                break;
            }
            let has_emitter = c.children.iter().any(|e| {
                e.tag == "emitter"
                    || (e.tag == "ref"
                        && e.attr("id")
                            .and_then(|id| self.ids.get(id))
                            .is_some_and(|t| t.tag == "emitter"))
            });
            if has_emitter {
                out = Err(c.diag("a shape with an emitter in a shapegroup (Mitsuba: instancing of emitters is not supported)"));
                break;
            }
            if let Err(e) = self.shape(c) {
                out = Err(e);
                break;
            }
        }
        self.placing = None;
        out?;
        self.finish(&p)
    }

    // ---- emitters ---------------------------------------------------------------

    /// An area emitter's `radiance` given as a texture: a `bitmap` or `checkerboard`
    /// (nested or by `ref`; a `d65` texture around one, with its `scale`) becomes the
    /// shape's `{ texture = "NAME", scale = S }`, which heron emits times D65 at Y = 1.
    /// That is Mitsuba's `d65` around the texture, and its RGB variants' reading of a
    /// bare one (a texel of 1 is sRGB white); its spectral variants emit a bare
    /// texture's reflectance spectrum unlit, white being equal energy, so a bare one
    /// warns. Another texture warns and emits the default radiance 1.
    fn radiance_texture(&mut self, t: &'a Node) -> Result<ShapeEmission, Diagnostic> {
        let (inner, scale) = if t.attr("type") == Some("d65") {
            let tp = self.props(t);
            let scale = tp.float("scale")?.unwrap_or(1.0);
            let nested = tp.objects(&["texture"]);
            let Some(inner) = nested.first() else {
                return Err(t.diag("d65: expected a nested <texture> (heron's textured emission is a texture times D65)"));
            };
            let inner = self.resolve(inner)?;
            self.finish(&tp)?;
            if !(scale >= 0.0 && (scale as f32).is_finite()) {
                return Err(t.diag(format!(
                    "d65: scale: expected a finite number ≥ 0, got {scale}"
                )));
            }
            (inner, scale)
        } else {
            (t, 1.0)
        };
        let Some(name) = self.texture(inner)? else {
            return Ok(ColourValue::Grey(1.0).emission().into());
        };
        if !std::ptr::eq(inner, t) {
            return Ok(ShapeEmission::Texture {
                texture: name,
                scale,
            });
        }
        self.warn(t.diag(
            "area radiance texture: emitted times D65 (a texel of 1 is sRGB white, as in Mitsuba's RGB variants and under a <texture type=\"d65\">); Mitsuba's spectral variants emit a bare texture's spectrum without an illuminant",
        ))?;
        Ok(ShapeEmission::Texture {
            texture: name,
            scale: 1.0,
        })
    }

    /// Converts an emitter; inside a shape (`shape` given) it returns the area light's
    /// radiance for the shape's `emission`.
    pub(super) fn emitter(
        &mut self,
        n: &'a Node,
        shape: Option<&Node>,
    ) -> Result<Option<ShapeEmission>, Diagnostic> {
        let kind = Self::plugin(n)?;
        let p = self.props(n);
        let out = match (kind, shape) {
            ("area", Some(_)) => match self.texture_node(&p, "radiance")? {
                Some(t) => Some(self.radiance_texture(t)?),
                None => {
                    let l = self.colour(&p, "radiance", ColourValue::Grey(1.0))?;
                    Some(l.emission().into())
                }
            },
            ("area", None) => return Err(n.diag("an area emitter must be inside a <shape>")),
            (_, Some(s)) => {
                return Err(n.diag(format!(
                    "expected an area emitter inside {}, got {kind:?}",
                    s.describe()
                )))
            }
            ("point", None) => {
                let pos = match (p.point("position")?, p.transform("to_world")?) {
                    (Some(x), _) => x,
                    (None, Some(m)) => m.transform_point3(DVec3::ZERO),
                    (None, None) => DVec3::ZERO,
                };
                let i = self.colour(&p, "intensity", ColourValue::Grey(1.0))?;
                self.lights.push(LightFile::Point(PointLightFile {
                    position: schema::point(pos),
                    intensity: i.emission(),
                    polarization: None,
                }));
                None
            }
            ("spot", None) => {
                let m = p.transform("to_world")?.unwrap_or(DMat4::IDENTITY);
                let cutoff = p.float("cutoff_angle")?.unwrap_or(20.0);
                let beam = p.float("beam_width")?.unwrap_or(cutoff * 0.75);
                if !(cutoff > 0.0 && cutoff <= 90.0 && beam >= 0.0 && beam <= cutoff) {
                    return Err(n.diag(format!(
                        "expected 0 < cutoff_angle ≤ 90 and 0 ≤ beam_width ≤ cutoff_angle, got {cutoff} and {beam}"
                    )));
                }
                let i = self.colour(&p, "intensity", ColourValue::Grey(1.0))?;
                self.warn(n.diag(
                    "spot: heron's falloff between beam_width and cutoff_angle is pbrt's smoothstep, Mitsuba's is linear in angle",
                ))?;
                self.lights.push(LightFile::Spot(SpotLightFile {
                    position: schema::point(m.transform_point3(DVec3::ZERO)),
                    direction: schema::direction(m.transform_vector3(DVec3::Z)),
                    intensity: i.emission(),
                    cone_angle: Some(schema::positive(cutoff)),
                    cone_delta: Some(schema::non_negative(cutoff - beam)),
                    polarization: None,
                }));
                None
            }
            ("directional", None) => {
                let dir = match (p.point("direction")?, p.transform("to_world")?) {
                    (Some(d), _) => d,
                    (None, Some(m)) => m.transform_vector3(DVec3::Z),
                    (None, None) => DVec3::Z,
                };
                if dir.length() == 0.0 {
                    return Err(n.diag("direction: expected a non-zero vector"));
                }
                let e = self.colour(&p, "irradiance", ColourValue::Grey(1.0))?;
                self.lights
                    .push(LightFile::Directional(DirectionalLightFile {
                        direction: schema::direction(dir),
                        radiance: e.emission(),
                        polarization: None,
                    }));
                None
            }
            ("constant", None) => {
                let l = self.colour(&p, "radiance", ColourValue::Grey(1.0))?;
                if self.background.is_some() || self.environment.is_some() {
                    self.warn(n.diag(
                        "a second environment emitter (constant or envmap); heron's environment is the first, ignored",
                    ))?;
                } else {
                    self.background = Some(l.emission());
                }
                None
            }
            ("envmap", None) => {
                let Some(file) = p.string("filename")? else {
                    return Err(n.diag("expected <string name=\"filename\" value=\"…\"/>"));
                };
                let rel = relative_to(&self.find(n, file), &self.base);
                let scale = p.float("scale")?.unwrap_or(1.0);
                if !(scale >= 0.0) {
                    return Err(n.diag(format!("scale: expected a number ≥ 0, got {scale}")));
                }
                let to_world = p.transform("to_world")?.unwrap_or(DMat4::IDENTITY);
                // Only how the map is sampled, not what it shows: heron's own sampling.
                p.get("mis_compensation");
                let transform = (to_world != DMat4::IDENTITY).then(|| {
                    // The map is at infinity: its translation does not matter.
                    let mut m = to_world;
                    m.w_axis = glam::DVec4::W;
                    schema::rows(m)
                });
                let t = EnvironmentFile {
                    map: rel.to_string_lossy().replace('\\', "/"),
                    mapping: None,
                    scale: Some(schema::non_negative(scale)),
                    transform,
                };
                if self.environment.is_some() || self.background.is_some() {
                    self.warn(n.diag(
                        "a second environment emitter (envmap or constant); heron's environment is the first, ignored",
                    ))?;
                } else {
                    self.environment = Some(t);
                }
                None
            }
            (other, None) => {
                self.warn(n.diag(format!(
                    "emitter {other:?} is not supported yet (area, point, spot, directional, constant, envmap are), ignored: the image lacks its light"
                )))?;
                return Ok(None);
            }
        };
        self.finish(&p)?;
        Ok(out)
    }
}

/// A parallelogram after a transform: origin and edges in world space.
pub(super) struct Quad {
    origin: DVec3,
    edge1: DVec3,
    edge2: DVec3,
}

impl Quad {
    fn reverse_edges(&mut self) {
        std::mem::swap(&mut self.edge1, &mut self.edge2);
    }

    fn shape(&self) -> ShapeFile {
        schema::quad(self.origin, self.edge1, self.edge2)
    }
}

/// The six faces of Mitsuba's cube, [-1, 1]³, each (origin, edge1, edge2) with
/// edge1 × edge2 outward.
pub(super) const CUBE_FACES: [([f64; 3], [f64; 3], [f64; 3]); 6] = [
    ([1.0, -1.0, -1.0], [0.0, 2.0, 0.0], [0.0, 0.0, 2.0]),
    ([-1.0, -1.0, -1.0], [0.0, 0.0, 2.0], [0.0, 2.0, 0.0]),
    ([-1.0, 1.0, -1.0], [0.0, 0.0, 2.0], [2.0, 0.0, 0.0]),
    ([-1.0, -1.0, -1.0], [2.0, 0.0, 0.0], [0.0, 0.0, 2.0]),
    ([-1.0, -1.0, 1.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]),
    ([-1.0, -1.0, -1.0], [0.0, 2.0, 0.0], [2.0, 0.0, 0.0]),
];

pub(super) fn quad(m: &DMat4, o: [f64; 3], e1: [f64; 3], e2: [f64; 3]) -> Quad {
    let o = DVec3::from_array(o);
    let (e1, e2) = (DVec3::from_array(e1), DVec3::from_array(e2));
    let origin = m.transform_point3(o);
    let mut q = Quad {
        origin,
        edge1: m.transform_point3(o + e1) - origin,
        edge2: m.transform_point3(o + e2) - origin,
    };
    // A mirroring transform turns the normal inward; Mitsuba's normal follows the
    // transformed geometry's orientation, so the edges are swapped back.
    if m.determinant() < 0.0 {
        q.reverse_edges();
    }
    q
}

/// Mitsuba's cube placed by `to_world` as twelve outward-facing triangles (inward with
/// `flip_normals`), corners shared, so that it is closed around a medium.
pub(super) fn cube_triangles(to_world: &DMat4, flip: bool) -> Vec<[DVec3; 3]> {
    let mirror = to_world.determinant() < 0.0;
    let mut out = Vec::with_capacity(12);
    for (o, e1, e2) in CUBE_FACES {
        let (o, e1, e2) = (
            DVec3::from_array(o),
            DVec3::from_array(e1),
            DVec3::from_array(e2),
        );
        // Corners from exact local coordinates, so that faces share them exactly.
        let at = |p: DVec3| to_world.transform_point3(p);
        for t in [[o, o + e1, o + e1 + e2], [o, o + e1 + e2, o + e2]] {
            let t = t.map(at);
            out.push(if flip ^ mirror { [t[0], t[2], t[1]] } else { t });
        }
    }
    out
}

impl Converter<'_> {
    /// Mitsuba 3's `cylinder` (src/shapes/cylinder.cpp): the open side of radius
    /// `radius` (default 1) from `p0` (default the origin) to `p1` (default +z), placed
    /// as `to_world` · translate(p0) · to_frame(Frame(p1 − p0)) · scale(r, r, |p1 − p0|),
    /// the unit cylinder's uv (φ/2π, z) kept. Its normals point outward, inward under
    /// `flip_normals`, whatever the handedness of `to_world` (Mitsuba flips them back
    /// for a mirroring one).
    fn cylinder(
        &mut self,
        n: &Node,
        p: &Props,
        to_world: &DMat4,
        flip: bool,
    ) -> Result<ShapeFile, Diagnostic> {
        let radius = p.float("radius")?.unwrap_or(1.0);
        let p0 = p.point("p0")?.unwrap_or(DVec3::ZERO);
        let p1 = p.point("p1")?.unwrap_or(DVec3::Z);
        let d = p1 - p0;
        let len = d.length();
        if !(radius > 0.0 && radius.is_finite() && len > 0.0 && len.is_finite()) {
            return Err(n.diag(format!(
                "cylinder: expected a positive finite radius and distinct finite p0 and p1, got radius {radius}, p0 {p0}, p1 {p1}"
            )));
        }
        let axis = d / len;
        let (s, t) = schema::coordinate_system(axis);
        let frame = DMat4::from_cols(
            s.extend(0.0),
            t.extend(0.0),
            axis.extend(0.0),
            DVec3::ZERO.extend(1.0),
        );
        let m = *to_world
            * DMat4::from_translation(p0)
            * frame
            * DMat4::from_scale(DVec3::new(radius, radius, len));
        let swap = flip ^ (m.determinant() < 0.0);
        Ok(schema::cylinder(
            &m,
            1.0,
            (0.0, 1.0),
            std::f64::consts::TAU,
            swap,
            DISK_SEGMENTS,
        ))
    }
}
