//! Shapes: spheres, triangles, planes, quads and meshes (OBJ, PLY, Mitsuba serialized)
//! from the `[[shapes]]` entries, each with its material (named, or one the loader adds)
//! and no light or medium yet (`lights.rs` and `media.rs` give them theirs); the
//! geometric checks (finite, non-degenerate, a finite bounding sphere) and the bounding
//! sphere itself.
use super::errors::{fmt_path, fmt_points, scene_error, Seg};
use super::materials::Materials;
use super::obj;
use crate::error::Result;
use crate::geometry::{Mesh, Shape, ShapeKind, MIN_RELATIVE_RADIUS};
use crate::scene::file::{
    fmt_f32, MeshFile, PlaneFile, QuadFile, ShapeFile, SphereFile, TriangleFile, WavesFile,
};
use glam::{DMat4, Vec2, Vec3};
use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

/// The shapes of the `[[shapes]]` entries, in file order (a mesh entry gives one shape per
/// material it uses), and for each shape the index of the entry it came from. Meshes are
/// read relative to `base_dir` and recorded in `inputs`; errors name `path`, or the mesh
/// file for problems inside it.
pub(super) fn build_shapes(
    path: &Path,
    base_dir: &Path,
    entries: &[ShapeFile],
    materials: &Materials,
    inputs: &mut Vec<String>,
    warnings: &mut Vec<String>,
) -> Result<(Vec<Shape>, Vec<usize>)> {
    let err = |m: String| scene_error(path, m);
    // The material of a simple shape: named, or black for a pure emitter, or the
    // boundary of a medium.
    let resolve = |at: &str, s: &ShapeFile| -> Result<u32> {
        let (material, emission, two_sided) = s.emission();
        if two_sided.is_some() && emission.is_none() {
            return Err(err(format!(
                "{at}.two_sided: applies to emitting shapes, but emission is not given"
            )));
        }
        match (material, emission) {
            (Some(name), _) => materials.lookup(&format!("{at}.material"), name).map_err(err),
            (None, Some(_)) => Ok(materials.black),
            (None, None) if s.medium().is_some() => Ok(materials.boundary),
            (None, None) => Err(err(format!(
                "{at}.material: missing required key (expected the name of a material, or an emission)"
            ))),
        }
    };

    let mut shapes = Vec::with_capacity(entries.len());
    let mut shape_entry: Vec<usize> = Vec::with_capacity(entries.len());
    for (i, s) in entries.iter().enumerate() {
        let at = format!("shapes[{i}]");
        match s {
            ShapeFile::Sphere(sp) => {
                let kind = sphere(&at, sp).map_err(err)?;
                shapes.push(Shape::new(kind, resolve(&at, s)?));
            }
            ShapeFile::Triangle(t) => {
                let material = resolve(&at, s)?;
                shapes.push(Shape::new(triangle(&at, t).map_err(err)?, material));
            }
            ShapeFile::Plane(p) => {
                let material = resolve(&at, s)?;
                shapes.push(Shape::new(plane(&at, p).map_err(err)?, material));
            }
            ShapeFile::Quad(q) => {
                let material = resolve(&at, s)?;
                shapes.push(Shape::new(quad(&at, q).map_err(err)?, material));
            }
            ShapeFile::Waves(wv) => {
                let material = resolve(&at, s)?;
                shapes.push(Shape::new(waves(&at, wv).map_err(err)?, material));
            }
            ShapeFile::Mesh(m) => {
                if m.two_sided.is_some() && m.emission.is_none() {
                    return Err(err(format!(
                        "{at}.two_sided: applies to emitting shapes, but emission is not given"
                    )));
                }
                let fallback = match (&m.emission, &m.medium) {
                    (Some(_), _) => Some(materials.black),
                    (None, Some(_)) => Some(materials.boundary),
                    (None, None) => None,
                };
                let mesh = build_mesh(path, base_dir, &at, m, materials, fallback, warnings)?;
                shapes.extend(mesh);
                if !m.file.is_empty() {
                    inputs.push(m.file.clone());
                }
            }
        }
        shape_entry.resize(shapes.len(), i);
    }
    Ok((shapes, shape_entry))
}

/// A sphere entry at key path `at`.
fn sphere(at: &str, sp: &SphereFile) -> std::result::Result<ShapeKind, String> {
    // Below this a sphere spans a handful of f32 steps at its centre, less than the
    // error bound of its hit points (geometry::spawn): rays would pass through it (heron
    // stress finds leaks from 2e-7 down).
    let reach = sp.center.get().abs().max_element();
    if sp.radius.get() < MIN_RELATIVE_RADIUS * reach {
        return Err(format!(
            "{at}.radius: expected at least {MIN_RELATIVE_RADIUS:e} × the centre's largest coordinate ({}), i.e. {:e}, got {}: a smaller sphere is below float precision where it is",
            fmt_f32(reach),
            MIN_RELATIVE_RADIUS * reach,
            fmt_f32(sp.radius.get())
        ));
    }
    Ok(ShapeKind::Sphere {
        center: sp.center.get(),
        radius: sp.radius.get(),
    })
}

/// A triangle entry at key path `at`: a mesh of one triangle.
fn triangle(at: &str, t: &TriangleFile) -> std::result::Result<ShapeKind, String> {
    let v = [
        t.vertices[0].get(),
        t.vertices[1].get(),
        t.vertices[2].get(),
    ];
    if cross_overflows(v[0], v[1], v[2]) {
        return Err(format!(
            "{at}.vertices: expected a triangle whose edges' cross product is finite in f32 (coordinates within about ±1e19), got {}",
            fmt_points(&v)
        ));
    }
    if is_degenerate(v[0], v[1], v[2]) {
        return Err(format!(
            "{at}.vertices: expected a triangle with non-zero area, got collinear vertices {}",
            fmt_points(&v)
        ));
    }
    Ok(mesh(v.to_vec(), vec![[0, 1, 2]]))
}

/// A plane entry at key path `at`: a square of two triangles.
fn plane(at: &str, p: &PlaneFile) -> std::result::Result<ShapeKind, String> {
    let n = p.normal.unit();
    let size = p.size.map_or(1000.0, |s| s.get());
    // Tangents with t × b = n, so (v1 − v0) × (v2 − v0) points along n.
    let t = n.any_orthogonal_vector().normalize();
    let b = n.cross(t);
    let c = p.point.get();
    let v = vec![
        c - size * t - size * b,
        c + size * t - size * b,
        c + size * t + size * b,
        c - size * t + size * b,
    ];
    if v.iter().any(|x| !x.is_finite()) {
        return Err(format!(
            "{at}.size: expected a size whose square has finite corners, got {size}"
        ));
    }
    // uv = (s, t) at origin + s edge1 + t edge2: Mitsuba 3's rectangle, whose local
    // (−1, −1) corner is uv (0, 0) and the converter's origin.
    let (c0, c1, c2, c3) = (Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::Y);
    Ok(ShapeKind::Mesh(Mesh {
        positions: v,
        indices: vec![[0, 1, 2], [0, 2, 3]],
        uvs: vec![[c0, c1, c2], [c0, c2, c3]],
    }))
}

/// A quad entry at key path `at`: a parallelogram of two triangles.
fn quad(at: &str, q: &QuadFile) -> std::result::Result<ShapeKind, String> {
    let (o, e1, e2) = (q.origin.get(), q.edge1.get(), q.edge2.get());
    let v = vec![o, o + e1, o + e1 + e2, o + e2];
    if v.iter().any(|x| !x.is_finite()) {
        return Err(format!(
            "{at}: expected a quad with finite corners, got origin + edges overflowing f32"
        ));
    }
    if cross_overflows(v[0], v[1], v[3]) {
        return Err(format!(
            "{at}: expected edge1 and edge2 whose cross product is finite in f32 (coordinates within about ±1e19), got {} and {}",
            fmt_points(&[e1]),
            fmt_points(&[e2])
        ));
    }
    if is_degenerate(v[0], v[1], v[3]) {
        return Err(format!(
            "{at}: expected edge1 and edge2 spanning a non-zero area, got parallel edges {} and {}",
            fmt_points(&[e1]),
            fmt_points(&[e2])
        ));
    }
    // uv = (s, t) at origin + s edge1 + t edge2: Mitsuba 3's rectangle, whose local
    // (−1, −1) corner is uv (0, 0) and the converter's origin.
    let (c0, c1, c2, c3) = (Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::Y);
    Ok(ShapeKind::Mesh(Mesh {
        positions: v,
        indices: vec![[0, 1, 2], [0, 2, 3]],
        uvs: vec![[c0, c1, c2], [c0, c2, c3]],
    }))
}

/// The most triangles a `waves` entry may make (2 per cell).
const MAX_WAVE_TRIANGLES: u64 = 1 << 25;

/// A `waves` entry at key path `at`: the quad's grid of cells, displaced along its normal
/// by the sum of the entry's sine waves (`WavesFile`).
fn waves(at: &str, w: &WavesFile) -> std::result::Result<ShapeKind, String> {
    let (o, e1, e2) = (w.origin.get(), w.edge1.get(), w.edge2.get());
    let [nu, nv] = w.resolution.map_or([128, 128], |r| [r[0].0, r[1].0]);
    if nu as u64 * nv as u64 * 2 > MAX_WAVE_TRIANGLES {
        return Err(format!(
            "{at}.resolution: expected at most {} cells (2 triangles each), got [{nu}, {nv}]",
            MAX_WAVE_TRIANGLES / 2
        ));
    }
    // The quad's own checks (finite corners, a non-zero area).
    quad(
        at,
        &QuadFile {
            origin: w.origin,
            edge1: w.edge1,
            edge2: w.edge2,
            material: None,
            emission: None,
            two_sided: None,
            medium: None,
        },
    )?;
    let (u1, u2) = (w.edge1.unit(), w.edge2.unit());
    let normal = e1.cross(e2);
    let normal = (normal / normal.abs().max_element()).normalize();
    let mut terms = Vec::with_capacity(w.waves.len());
    for (i, wave) in w.waves.iter().enumerate() {
        let wat = format!("{at}.waves[{i}]");
        if !(wave.amplitude >= 0.0 && wave.amplitude.is_finite()) {
            return Err(format!(
                "{wat}.amplitude: expected a finite height >= 0, got {}",
                fmt_f32(wave.amplitude)
            ));
        }
        if !wave.phase.is_finite() {
            return Err(format!("{wat}.phase: expected a finite angle in degrees"));
        }
        let [a, b] = wave.direction.get();
        let d = a * u1 + b * u2;
        if !(d.length() > 0.0) || !d.is_finite() {
            return Err(format!(
                "{wat}.direction: expected a non-zero direction [along edge1, along edge2], got [{}, {}]",
                fmt_f32(a),
                fmt_f32(b)
            ));
        }
        let k = std::f64::consts::TAU / wave.wavelength.get() as f64;
        let d = d.normalize().as_dvec3() * k;
        terms.push((wave.amplitude as f64, d, (wave.phase as f64).to_radians()));
    }
    let height = |x: glam::DVec3| -> f64 {
        terms
            .iter()
            .map(|(a, d, phi)| a * (d.dot(x) + phi).sin())
            .sum()
    };
    let mut positions = Vec::with_capacity((nu as usize + 1) * (nv as usize + 1));
    for j in 0..=nv {
        for i in 0..=nu {
            let x = e1.as_dvec3() * (i as f64 / nu as f64) + e2.as_dvec3() * (j as f64 / nv as f64);
            let p = o.as_dvec3() + x + normal.as_dvec3() * height(x);
            positions.push(p.as_vec3());
        }
    }
    if positions.iter().any(|p| !p.is_finite()) {
        return Err(format!(
            "{at}: expected a surface with finite vertices, got waves overflowing f32"
        ));
    }
    let row = nu + 1;
    let mut indices = Vec::with_capacity(2 * nu as usize * nv as usize);
    for j in 0..nv {
        for i in 0..nu {
            let a = j * row + i;
            let (b, c, d) = (a + 1, a + row + 1, a + row);
            // The quad's winding (origin, +edge1, +edge1 + edge2, +edge2), so the
            // normal is edge1 × edge2's side.
            indices.push([a, b, c]);
            indices.push([a, c, d]);
        }
    }
    Ok(mesh(positions, indices))
}

/// Checks that the bounding sphere of `shapes` (the lights at infinity start their paths
/// on it) is finite, naming the first shape that makes it overflow by its entry
/// (`shape_entry`).
pub(super) fn check_bounds(
    shapes: &[Shape],
    shape_entry: &[usize],
) -> std::result::Result<(), String> {
    let mut bbox = EMPTY_BOX;
    for (k, shape) in shapes.iter().enumerate() {
        bbox = grow_box(bbox, shape);
        let b = box_sphere(bbox);
        if !(b.center.is_finite() && b.radius.is_finite()) {
            return Err(format!(
                "shapes[{}]: expected shapes whose bounding sphere is finite in f32 (coordinates within about ±1e19), got shapes reaching from {} to {} with this one",
                shape_entry[k],
                fmt_points(&[bbox.0]),
                fmt_points(&[bbox.1])
            ));
        }
    }
    Ok(())
}

/// The sphere around the shapes' bounding box (a unit sphere at the origin for a scene
/// without shapes).
pub fn scene_bounds(shapes: &[Shape]) -> crate::light::SceneBounds {
    let mut b = EMPTY_BOX;
    for s in shapes {
        b = grow_box(b, s);
    }
    box_sphere(b)
}

/// A bounding box (lo, hi); lo > hi when empty.
pub(super) type Box3 = (Vec3, Vec3);

pub(super) const EMPTY_BOX: Box3 = (Vec3::INFINITY, Vec3::NEG_INFINITY);

/// `b` grown to hold shape `s`.
pub(super) fn grow_box((mut lo, mut hi): Box3, s: &Shape) -> Box3 {
    match &s.kind {
        ShapeKind::Sphere { center, radius } => {
            lo = lo.min(*center - Vec3::splat(*radius));
            hi = hi.max(*center + Vec3::splat(*radius));
        }
        ShapeKind::Mesh(m) => {
            for p in &m.positions {
                lo = lo.min(*p);
                hi = hi.max(*p);
            }
        }
    }
    (lo, hi)
}

/// The sphere around box `b` (a unit sphere at the origin for an empty box).
fn box_sphere((lo, hi): Box3) -> crate::light::SceneBounds {
    if !(lo.x <= hi.x) {
        return crate::light::SceneBounds {
            center: Vec3::ZERO,
            radius: 1.0,
        };
    }
    // Not 0.5 (lo + hi), which overflows for a shape near ±3e38 (the same value
    // elsewhere: halving is exact).
    let center = 0.5 * lo + 0.5 * hi;
    crate::light::SceneBounds {
        center,
        radius: (0.5 * (hi - lo).length()).max(1e-6),
    }
}

/// A triangle mesh.
fn mesh(positions: Vec<Vec3>, indices: Vec<[u32; 3]>) -> ShapeKind {
    ShapeKind::Mesh(Mesh {
        positions,
        indices,
        uvs: Vec::new(),
    })
}

/// Whether the cross product of the edges b − a and c − a (twice the area, and the normal
/// Embree and the lights compute) overflows f32: coordinates beyond about ±1e19.
pub(super) fn cross_overflows(a: Vec3, b: Vec3, c: Vec3) -> bool {
    !(b - a).cross(c - a).is_finite()
}

/// Zero area up to f32 rounding: |e1 × e2| ≤ ε |e1| |e2| (the angle between the edges is
/// below about 1e-7 rad), or a zero-length edge.
pub(crate) fn is_degenerate(a: Vec3, b: Vec3, c: Vec3) -> bool {
    let (e1, e2) = (b - a, c - a);
    let cross = e1.cross(e2).length();
    let limit = f32::EPSILON * e1.length() * e2.length();
    // Not strictly above the limit, NaN included (overflowing edges).
    cross.partial_cmp(&limit) != Some(std::cmp::Ordering::Greater)
}

/// A `type = "mesh"` entry: one shape per material it uses. Mesh-file problems are
/// reported with the mesh file as `file` and the scene's key path in the message.
fn build_mesh(
    scene_path: &Path,
    base_dir: &Path,
    at: &str,
    m: &MeshFile,
    materials: &Materials,
    emitter_material: Option<u32>,
    warnings: &mut Vec<String>,
) -> Result<Vec<Shape>> {
    let lookup = |at: String, name: &str| {
        materials
            .lookup(&at, name)
            .map_err(|m| scene_error(scene_path, m))
    };
    // Scene-file checks first: the material names.
    let default_material = match &m.material {
        Some(name) => Some(lookup(format!("{at}.material"), name)?),
        None => emitter_material,
    };
    let mut group_material = BTreeMap::new();
    for (group, name) in &m.groups {
        let gk = fmt_path(&[Seg::Key("groups".into()), Seg::Key(group.clone())]);
        group_material.insert(group.as_str(), lookup(format!("{at}.{gk}"), name)?);
    }
    if let Some(groups) = inline_mesh(at, m).map_err(|msg| scene_error(scene_path, msg))? {
        return shapes_of_groups(
            groups,
            scene_path,
            scene_path,
            at,
            m,
            &group_material,
            default_material,
            warnings,
        );
    }
    if m.file.trim().is_empty() {
        return Err(scene_error(
            scene_path,
            format!("{at}.file: expected the path of a mesh file (.obj, .ply or .serialized), got an empty string"),
        ));
    }

    let mesh_path: PathBuf = base_dir.join(&m.file);
    let format = MeshFormat::of(&mesh_path);
    if let (Some(k), false) = (m.shape_index, format == MeshFormat::Serialized) {
        return Err(scene_error(
            scene_path,
            format!(
                "{at}.shape_index: applies to Mitsuba serialized meshes (a file ending in .serialized) only, got shape_index = {k} for {:?}",
                m.file
            ),
        ));
    }
    let read_error = |e: std::io::Error| {
        scene_error(
            &mesh_path,
            format!("{at}.file: cannot read the mesh file: {e}"),
        )
    };
    if format != MeshFormat::Obj {
        let bytes = std::fs::read(&mesh_path).map_err(read_error)?;
        let stem = mesh_path
            .file_stem()
            .map_or(String::new(), |s| s.to_string_lossy().into_owned());
        let groups = match format {
            MeshFormat::Ply => super::ply::parse_ply(&bytes, &stem),
            _ => super::serialized::parse_serialized(&bytes, m.shape_index.unwrap_or(0), &stem),
        }
        .map_err(|msg| scene_error(&mesh_path, format!("{at}.file: {msg}")))?;
        return shapes_of_groups(
            groups,
            scene_path,
            &mesh_path,
            at,
            m,
            &group_material,
            default_material,
            warnings,
        );
    }
    let text = std::fs::read_to_string(&mesh_path).map_err(read_error)?;
    mesh_shapes(
        &text,
        scene_path,
        &mesh_path,
        at,
        m,
        &group_material,
        default_material,
        warnings,
    )
}

/// The one group of a mesh written in the scene (`vertices` and `triangles`), checked,
/// or None for a mesh file.
fn inline_mesh(at: &str, m: &MeshFile) -> std::result::Result<Option<Vec<obj::ObjGroup>>, String> {
    let (vertices, triangles) = match (&m.vertices, &m.triangles) {
        (None, None) if m.uv.is_some() => {
            return Err(format!(
                "{at}.uv: applies to a mesh written in the scene (vertices and triangles); a mesh file's texture coordinates come from the file"
            ))
        }
        (None, None) => return Ok(None),
        (Some(v), Some(t)) => (v, t),
        (Some(_), None) => {
            return Err(format!(
                "{at}.triangles: missing required key (vertices are given: expected the triangles' vertex indices)"
            ))
        }
        (None, Some(_)) => {
            return Err(format!(
                "{at}.vertices: missing required key (triangles are given: expected the vertex positions)"
            ))
        }
    };
    if !m.file.is_empty() {
        return Err(format!(
            "{at}: expected either file or vertices and triangles, got both"
        ));
    }
    if let Some(k) = m.shape_index {
        return Err(format!(
            "{at}.shape_index: applies to Mitsuba serialized meshes, got shape_index = {k} for a mesh written in the scene"
        ));
    }
    if let Some(g) = m.groups.keys().next() {
        return Err(format!(
            "{at}.groups: a mesh written in the scene has one group; got a group {g:?} (give material instead)"
        ));
    }
    for (i, t) in triangles.iter().enumerate() {
        if let Some(k) = t.iter().find(|&&k| k as usize >= vertices.len()) {
            return Err(format!(
                "{at}.triangles[{i}]: expected vertex indices below {} (the number of vertices), got {k}",
                vertices.len()
            ));
        }
    }
    let uvs = match &m.uv {
        None => Vec::new(),
        Some(uv) if uv.len() == vertices.len() && uv.iter().flatten().all(|x| x.is_finite()) => {
            let at = |k: u32| {
                let [u, v] = uv[k as usize];
                Vec2::new(u as f32, v as f32)
            };
            triangles.iter().map(|t| t.map(at)).collect()
        }
        Some(uv) => {
            return Err(format!(
                "{at}.uv: expected one finite [u, v] per vertex ({}), got {} pairs",
                vertices.len(),
                uv.len()
            ))
        }
    };
    Ok(Some(vec![obj::ObjGroup {
        name: String::new(),
        positions: vertices.iter().map(|p| p.get()).collect(),
        indices: triangles.clone(),
        uvs,
    }]))
}

/// A mesh file's format, by its extension (in any case): `.ply`, `.serialized`, else OBJ.
#[derive(Clone, Copy, PartialEq, Eq)]
enum MeshFormat {
    Obj,
    Ply,
    Serialized,
}

impl MeshFormat {
    fn of(path: &Path) -> MeshFormat {
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
        if ext.eq_ignore_ascii_case("ply") {
            MeshFormat::Ply
        } else if ext.eq_ignore_ascii_case("serialized") {
            MeshFormat::Serialized
        } else {
            MeshFormat::Obj
        }
    }
}

/// A mesh entry's `transform`: four rows of four finite numbers, the last `[0, 0, 0,
/// 1]`, invertible.
fn mesh_transform(
    at: &str,
    t: &Option<Vec<Vec<f64>>>,
) -> std::result::Result<Option<DMat4>, String> {
    let Some(rows) = t else {
        return Ok(None);
    };
    let bad = || {
        format!("{at}.transform: expected four rows of four finite numbers, the last [0, 0, 0, 1] (an affine matrix), got {rows:?}")
    };
    if rows.len() != 4
        || rows
            .iter()
            .any(|r| r.len() != 4 || r.iter().any(|x| !x.is_finite()))
    {
        return Err(bad());
    }
    if rows[3] != [0.0, 0.0, 0.0, 1.0] {
        return Err(bad());
    }
    let m = DMat4::from_cols_array_2d(&[
        [rows[0][0], rows[1][0], rows[2][0], 0.0],
        [rows[0][1], rows[1][1], rows[2][1], 0.0],
        [rows[0][2], rows[1][2], rows[2][2], 0.0],
        [rows[0][3], rows[1][3], rows[2][3], 1.0],
    ]);
    if m.determinant() == 0.0 || !m.determinant().is_finite() {
        return Err(format!(
            "{at}.transform: expected an invertible matrix, got determinant 0"
        ));
    }
    Ok(Some(m))
}

/// The shapes of mesh entry `m` (at key path `at`) from the text of its OBJ file
/// `mesh_path`, with the materials of its groups already looked up.
#[allow(clippy::too_many_arguments)]
pub(crate) fn mesh_shapes(
    text: &str,
    scene_path: &Path,
    mesh_path: &Path,
    at: &str,
    m: &MeshFile,
    group_material: &BTreeMap<&str, u32>,
    default_material: Option<u32>,
    warnings: &mut Vec<String>,
) -> Result<Vec<Shape>> {
    let merr = |msg: String| scene_error(mesh_path, format!("{at}.file: {msg}"));
    let groups = obj::parse_obj(text).map_err(merr)?;
    shapes_of_groups(
        groups,
        scene_path,
        mesh_path,
        at,
        m,
        group_material,
        default_material,
        warnings,
    )
}

/// The shapes of mesh entry `m` from its file's groups (OBJ objects and groups, or the
/// one group of a PLY file or of a serialized file's shape). Triangles of zero area
/// (never hit, and no area to emit from) are dropped with one warning per entry in
/// `warnings`; a mesh left with none is dropped (no shapes) with a warning, as pbrt-v4
/// and Mitsuba 3 load such files (issue 38: one degenerate mesh among hundreds once
/// rejected the whole scene).
#[allow(clippy::too_many_arguments)]
pub(crate) fn shapes_of_groups(
    groups: Vec<obj::ObjGroup>,
    scene_path: &Path,
    mesh_path: &Path,
    at: &str,
    m: &MeshFile,
    group_material: &BTreeMap<&str, u32>,
    default_material: Option<u32>,
    warnings: &mut Vec<String>,
) -> Result<Vec<Shape>> {
    let merr = |msg: String| scene_error(mesh_path, format!("{at}.file: {msg}"));
    let transform = mesh_transform(at, &m.transform).map_err(|msg| scene_error(scene_path, msg))?;
    check_group_names(&groups, mesh_path, at, m)?;
    let placement = Placement {
        scale: m.scale.map_or(1.0, |s| s.get()),
        translate: m.translate.map_or(Vec3::ZERO, |t| t.get()),
        transform,
    };
    // Mitsuba 3's readers: an OBJ's v is flipped (its images start at the bottom row,
    // heron's uv at the top), a PLY's and a serialized mesh's are not (`flip_tex_coords`,
    // src/shapes/obj.cpp and ply.cpp; serialized.cpp has no flip).
    // A mesh written in the scene (no file) keeps its uv as given.
    let flip = m
        .flip_tex_coords
        .unwrap_or(!m.file.is_empty() && MeshFormat::of(mesh_path) == MeshFormat::Obj);
    // The triangles per material, in the order the materials first appear.
    let mut parts: Vec<Part> = Vec::new();
    let (mut kept, mut dropped) = (0usize, 0usize);
    for g in &groups {
        if g.indices.is_empty() {
            continue;
        }
        let material = match group_material.get(g.name.as_str()).copied().or(default_material) {
            Some(mat) => mat,
            None => {
                return Err(scene_error(
                    scene_path,
                    format!(
                        "{at}.material: missing required key (expected the name of a material for the mesh's object {:?}, which groups does not list)",
                        g.name
                    ),
                ))
            }
        };
        let part = match parts.iter().position(|p| p.material == material) {
            Some(k) => &mut parts[k],
            None => {
                parts.push(Part::new(material));
                parts.last_mut().expect("just pushed")
            }
        };
        part.textured &= !g.uvs.is_empty();
        for (k, tri) in g.indices.iter().enumerate() {
            let p = placement
                .place(&g.name, tri.map(|i| g.positions[i as usize]))
                .map_err(merr)?;
            // Zero-area triangles are never hit; they are dropped.
            if is_degenerate(p[0], p[1], p[2]) {
                dropped += 1;
                continue;
            }
            kept += 1;
            let uv = part.textured.then(|| {
                let t = g.uvs[k];
                if flip {
                    t.map(|c| Vec2::new(c.x, 1.0 - c.y))
                } else {
                    t
                }
            });
            part.push(p, uv);
        }
    }
    if kept + dropped == 0 {
        return Err(merr(
            "expected a mesh with at least one triangle, got none".into(),
        ));
    }
    if dropped > 0 {
        let what = if kept == 0 {
            "no triangle is left, the mesh is dropped".to_string()
        } else {
            format!("{kept} kept")
        };
        warnings.push(format!(
            "{}: {at}: {dropped} triangle(s) of zero area dropped ({what})",
            mesh_path.display()
        ));
    }
    Ok(parts
        .into_iter()
        .filter(|p| !p.indices.is_empty())
        .map(Part::into_shape)
        .collect())
}

/// Every group `m.groups` names is in the mesh.
fn check_group_names(
    groups: &[obj::ObjGroup],
    mesh_path: &Path,
    at: &str,
    m: &MeshFile,
) -> Result<()> {
    for g in m.groups.keys() {
        if !groups.iter().any(|x| &x.name == g) {
            let mut names: Vec<&str> = groups
                .iter()
                .filter(|x| !x.indices.is_empty())
                .map(|x| x.name.as_str())
                .collect();
            names.dedup();
            let gk = fmt_path(&[Seg::Key("groups".into()), Seg::Key(g.clone())]);
            return Err(scene_error(
                mesh_path,
                format!(
                    "{at}.{gk}: no object or group named {g:?} in the mesh (it has: {})",
                    names.join(", ")
                ),
            ));
        }
    }
    Ok(())
}

/// Where a mesh entry puts its file's vertices: scaled, translated, then transformed.
struct Placement {
    scale: f32,
    translate: Vec3,
    transform: Option<DMat4>,
}

impl Placement {
    /// A triangle of object `name` placed, or why it cannot be (not finite, or too large
    /// for its edges' cross product in f32).
    fn place(&self, name: &str, tri: [Vec3; 3]) -> std::result::Result<[Vec3; 3], String> {
        let (scale, translate) = (self.scale, self.translate);
        let mut p = tri.map(|v| v * scale + translate);
        if let Some(t) = &self.transform {
            p = p.map(|v| t.transform_point3(v.as_dvec3()).as_vec3());
        }
        if p.iter().any(|x| !x.is_finite()) {
            return Err(format!(
                "a vertex of object {name:?} is not finite after scale {} and translate {}",
                fmt_f32(scale),
                fmt_points(&[translate])
            ));
        }
        if cross_overflows(p[0], p[1], p[2]) {
            return Err(format!(
                "a triangle of object {name:?} is too large for f32 after scale {} and translate {}: expected its edges' cross product to be finite (coordinates within about ±1e19), got {}",
                fmt_f32(scale),
                fmt_points(&[translate]),
                fmt_points(&p)
            ));
        }
        Ok(p)
    }
}

/// The triangles of one material of a mesh entry.
struct Part {
    material: u32,
    positions: Vec<Vec3>,
    indices: Vec<[u32; 3]>,
    /// Vertex index by position: OBJ groups come with their own vertex arrays, so
    /// vertices are shared within a shape by their (exact) coordinates.
    remap: HashMap<[u32; 3], u32>,
    /// Texture coordinates per kept triangle, while every group has them.
    uvs: Vec<[Vec2; 3]>,
    textured: bool,
}

impl Part {
    fn new(material: u32) -> Part {
        Part {
            material,
            positions: Vec::new(),
            indices: Vec::new(),
            remap: HashMap::new(),
            uvs: Vec::new(),
            textured: true,
        }
    }

    /// A placed triangle, its vertices shared with the part's by their coordinates.
    fn push(&mut self, p: [Vec3; 3], uv: Option<[Vec2; 3]>) {
        let mut out = [0u32; 3];
        for (o, v) in out.iter_mut().zip(p) {
            let next = self.positions.len() as u32;
            // + 0.0 turns −0 into +0, so the two zeros share a vertex.
            let bits = (v + Vec3::ZERO).to_array().map(f32::to_bits);
            let positions = &mut self.positions;
            *o = *self.remap.entry(bits).or_insert_with(|| {
                positions.push(v);
                next
            });
        }
        self.indices.push(out);
        if let Some(uv) = uv {
            self.uvs.push(uv);
        }
    }

    fn into_shape(self) -> Shape {
        let uvs = if self.textured { self.uvs } else { Vec::new() };
        Shape::new(
            ShapeKind::Mesh(Mesh {
                positions: self.positions,
                indices: self.indices,
                uvs,
            }),
            self.material,
        )
    }
}
