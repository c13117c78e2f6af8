//! The scene schema's values ([`crate::scene::file`]) as both converters build them from
//! their f64 arithmetic: numbers tidied to 12 significant digits ([`tidy`]), the shapes
//! and the pinhole camera the two formats share. The schema's leaves keep these f64
//! numbers as they are (and heron reads them in f32), so `heron convert` writes the
//! digits computed here; the ranges are checked when the scene is read, as a file's.
use crate::scene::file::{
    CameraFile, Direction3, MeshFile, NonNegativeNumber, Point3, PositiveCount, PositiveNumber,
    QuadFile, Resolution, ShapeFile, SphereFile, TriangleFile, UnitNumber,
};
use glam::{DMat4, DVec3};
use std::collections::BTreeMap;

/// `v` to 12 significant digits (far beyond f32's 7), so that a rotation by 90° writes
/// 0 and 1 rather than 6e-17 and 0.9999999999999999.
pub fn tidy(v: f64) -> f64 {
    if v.abs() < 1e-12 {
        return 0.0;
    }
    format!("{v:.11e}").parse().unwrap_or(v)
}

pub fn point(v: DVec3) -> Point3 {
    Point3(v.to_array().map(tidy).into())
}

pub fn direction(v: DVec3) -> Direction3 {
    Direction3(v.to_array().map(tidy).into())
}

pub fn positive(x: f64) -> PositiveNumber {
    PositiveNumber(tidy(x))
}

pub fn unit(x: f64) -> UnitNumber {
    UnitNumber(tidy(x))
}

pub fn non_negative(x: f64) -> NonNegativeNumber {
    NonNegativeNumber(tidy(x))
}

/// An affine matrix as the schema's `transform` (rows).
pub fn rows(m: DMat4) -> Vec<Vec<f64>> {
    (0..4)
        .map(|r| m.row(r).to_array().map(tidy).to_vec())
        .collect()
}

/// A count x ≥ 0 as the schema's u32 (image sizes, samples, depths), or the message for
/// one beyond it (a scene file's TOML integer could say it, the schema cannot).
pub fn count(what: &str, x: i64) -> Result<u32, String> {
    u32::try_from(x).map_err(|_| format!("{what}: expected at most {}, got {x}", u32::MAX))
}

/// A count ≥ 1 as the schema's [`PositiveCount`] (see [`count`]).
pub fn positive_count(what: &str, x: i64) -> Result<PositiveCount, String> {
    count(what, x).map(PositiveCount)
}

/// The pinhole camera both formats convert to: heron's image plane of height 1 at `d`.
pub fn pinhole(
    eye: DVec3,
    look_at: DVec3,
    up: DVec3,
    d: f64,
    (width, height): (u32, u32),
) -> CameraFile {
    CameraFile {
        eye: point(eye),
        look_at: point(look_at),
        up: Some(direction(up)),
        d: Some(positive(d)),
        resolution: Resolution { width, height },
        kind: None,
        height: None,
        lens: None,
        surface: None,
        film_diagonal: None,
        film_distance: None,
        focus_distance: None,
        focus_wavelength: None,
        mm_per_unit: None,
        f_number: None,
        polarizer: None,
        pupil: None,
        film_offset: None,
    }
}

// The shapes with no surface yet: the converters give each the surface of the element
// it came from (`ShapeFile::surface_mut`).

pub fn sphere(center: DVec3, radius: f64) -> ShapeFile {
    ShapeFile::Sphere(SphereFile {
        center: point(center),
        radius: positive(radius),
        material: None,
        emission: None,
        two_sided: None,
        medium: None,
    })
}

pub fn triangle(vertices: [DVec3; 3]) -> ShapeFile {
    ShapeFile::Triangle(TriangleFile {
        vertices: vertices.map(point),
        material: None,
        emission: None,
        two_sided: None,
        medium: None,
    })
}

/// A disk as triangles: `segments` per full turn (fewer for a partial disk of
/// `phi_max` radians), a fan about the centre or, with `inner` > 0, a ring of quads
/// split in two. The disk lies at z = `height` of the object space `m` maps to the
/// world, facing +z (Mitsuba's and pbrt-v4's `disk`); `swap` turns it to face −z (a
/// flipped normal, or a mirroring `m`). A fan of 128 has 0.9996 of the disk's area.
pub fn disk(
    m: &DMat4,
    radius: f64,
    inner: f64,
    height: f64,
    phi_max: f64,
    swap: bool,
    segments: usize,
) -> Vec<ShapeFile> {
    let n = ((segments as f64 * phi_max / std::f64::consts::TAU).ceil() as usize).max(1);
    let at = |r: f64, i: usize| {
        let a = phi_max * i as f64 / n as f64;
        m.transform_point3(DVec3::new(r * a.cos(), r * a.sin(), height))
    };
    let mut out = Vec::with_capacity(2 * n);
    let mut push = |v: [DVec3; 3]| out.push(triangle(if swap { [v[0], v[2], v[1]] } else { v }));
    for i in 0..n {
        let (o0, o1) = (at(radius, i), at(radius, i + 1));
        if inner > 0.0 {
            let (i0, i1) = (at(inner, i), at(inner, i + 1));
            push([i0, o0, o1]);
            push([i0, o1, i1]);
        } else {
            push([m.transform_point3(DVec3::new(0.0, 0.0, height)), o0, o1]);
        }
    }
    out
}

/// The side of a cylinder (open: no caps) as one mesh entry of `segments` quads per
/// full turn (fewer for a partial one of `phi_max` radians), each split in two: the
/// surface (r cos φ, r sin φ, z), z from `z0` to `z1`, of the object space `m` maps to
/// the world (pbrt-v4's and Mitsuba 3's `cylinder`). Its uv is (φ/φmax, (z − z0)/(z1 −
/// z0)), the parametrisation both formats give their cylinders (pbrt-v4 `Cylinder`,
/// Mitsuba 3 src/shapes/cylinder.cpp); the seam's vertices are doubled so u runs to 1.
/// The triangles face outward (the formats' normal); `swap` turns them inward (a
/// flipped normal, or a mirroring `m`). 128 segments have 0.9999 of the side's area
/// (128 sin(π/128)/π).
pub fn cylinder(
    m: &DMat4,
    radius: f64,
    (z0, z1): (f64, f64),
    phi_max: f64,
    swap: bool,
    segments: usize,
) -> ShapeFile {
    let n = ((segments as f64 * phi_max / std::f64::consts::TAU).ceil() as usize).max(1);
    let mut vertices = Vec::with_capacity(2 * (n + 1));
    let mut uv = Vec::with_capacity(2 * (n + 1));
    for i in 0..=n {
        let u = i as f64 / n as f64;
        let (sin, cos) = (phi_max * u).sin_cos();
        for (z, v) in [(z0, 0.0), (z1, 1.0)] {
            vertices.push(point(m.transform_point3(DVec3::new(
                radius * cos,
                radius * sin,
                z,
            ))));
            uv.push([tidy(u), v]);
        }
    }
    let mut triangles = Vec::with_capacity(2 * n);
    for i in 0..n as u32 {
        // a, b at z0 and d, c at z1: (b − a) × (c − a) points away from the axis.
        let (a, d, b, c) = (2 * i, 2 * i + 1, 2 * i + 2, 2 * i + 3);
        for t in [[a, b, c], [a, c, d]] {
            triangles.push(if swap { [t[0], t[2], t[1]] } else { t });
        }
    }
    let mut shape = mesh(String::new(), DMat4::IDENTITY, None);
    if let ShapeFile::Mesh(mf) = &mut shape {
        mf.vertices = Some(vertices);
        mf.triangles = Some(triangles);
        mf.uv = Some(uv);
    }
    shape
}

/// Mitsuba 3's `coordinate_system` (include/mitsuba/core/vector.h; Duff et al. 2017,
/// "Building an orthonormal basis, revisited"): the frame's s and t about unit `n`,
/// which a `cylinder`'s `p0`/`p1` turn its local x and y into.
pub fn coordinate_system(n: DVec3) -> (DVec3, DVec3) {
    let sign = 1f64.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        DVec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}

pub fn quad(origin: DVec3, edge1: DVec3, edge2: DVec3) -> ShapeFile {
    ShapeFile::Quad(QuadFile {
        origin: point(origin),
        edge1: direction(edge1),
        edge2: direction(edge2),
        material: None,
        emission: None,
        two_sided: None,
        medium: None,
    })
}

/// A mesh file (relative to the scene's folder), placed by `transform` unless it is the
/// identity.
pub fn mesh(file: String, transform: DMat4, flip_tex_coords: Option<bool>) -> ShapeFile {
    ShapeFile::Mesh(MeshFile {
        file,
        vertices: None,
        triangles: None,
        shape_index: None,
        material: None,
        groups: BTreeMap::new(),
        scale: None,
        translate: None,
        transform: (transform != DMat4::IDENTITY).then(|| rows(transform)),
        uv: None,
        flip_tex_coords,
        emission: None,
        two_sided: None,
        medium: None,
    })
}

/// Shape `shape_index` of a Mitsuba serialized file (relative to the scene's folder),
/// placed by `transform` unless it is the identity. Its texture coordinates are read as
/// they are, as Mitsuba reads them.
pub fn serialized_mesh(file: String, transform: DMat4, shape_index: Option<u32>) -> ShapeFile {
    let mut shape = mesh(file, transform, None);
    if let ShapeFile::Mesh(m) = &mut shape {
        m.shape_index = shape_index;
    }
    shape
}

/// Triangles written in the scene as one mesh entry (`vertices` and `triangles`),
/// corners that are equal in f64 sharing a vertex: the form a closed shape around a
/// medium takes (a triangle (a, b, c) faces (b − a) × (c − a)).
pub fn triangle_mesh(tris: &[[DVec3; 3]]) -> ShapeFile {
    let mut vertices: Vec<Point3> = Vec::new();
    let mut index: BTreeMap<[u64; 3], u32> = BTreeMap::new();
    let mut triangles = Vec::with_capacity(tris.len());
    for t in tris {
        triangles.push(t.map(|v| {
            let p = point(v);
            let key = p.0.to_array().map(|x| (x + 0.0).to_bits());
            *index.entry(key).or_insert_with(|| {
                vertices.push(p);
                vertices.len() as u32 - 1
            })
        }));
    }
    let mut shape = mesh(String::new(), DMat4::IDENTITY, None);
    if let ShapeFile::Mesh(m) = &mut shape {
        m.vertices = Some(vertices);
        m.triangles = Some(triangles);
    }
    shape
}

/// heron's light tracing and BDPT refuse a filter other than the default box
/// (`integrator::capabilities::check_filter`): an imported scene that asks for one of
/// them keeps the box filter. Returns the warning to give when a filter was dropped.
pub fn box_for_light_paths(render: &mut Option<crate::scene::file::RenderFile>) -> Option<String> {
    let r = render.as_mut()?;
    let light_paths = matches!(r.integrator.as_deref(), Some("lighttrace" | "bdpt"));
    let filter = r.filter.clone()?;
    if !light_paths || filter == "box" && r.filter_radius.map_or(true, |x| x == 0.5) {
        return None;
    }
    (
        r.filter,
        r.filter_radius,
        r.filter_stddev,
        r.filter_b,
        r.filter_c,
    ) = (None, None, None, None, None);
    Some(format!(
        "the {filter} pixel filter is read as heron's box: heron's {} reaches the film at one point per light path and has no other filter",
        r.integrator.as_deref().unwrap_or_default()
    ))
}

/// A Henyey–Greenstein medium of coefficients σ_a, σ_s (per scene unit) and mean
/// cosine g: what both importers make of a homogeneous medium.
pub fn hg_medium(
    sigma_a: crate::scene::file::Coefficient,
    sigma_s: crate::scene::file::Coefficient,
    g: f64,
) -> crate::scene::file::MediumFile {
    crate::scene::file::MediumFile {
        kind: "henyey-greenstein".into(),
        radius_mm: None,
        drops: None,
        number_density: None,
        liquid_water_content: None,
        absorption: None,
        lambda_step: None,
        forward_cutoff: None,
        sigma_a: Some(sigma_a),
        sigma_s: Some(sigma_s),
        g: Some(g as f32),
        crystals: None,
        rays: None,
        seed: None,
        density: None,
        aloft: None,
    }
}

/// The box [lo, hi] under the affine map `m` as heron's axis-aligned grids hold it: the
/// box around its image (`min`, `max`, tidied), and whether the map keeps it
/// axis-aligned (a positive scale and a translation; else the importer warns).
pub fn grid_box(
    m: glam::DMat4,
    lo: glam::DVec3,
    hi: glam::DVec3,
) -> (crate::scene::file::Point3, crate::scene::file::Point3, bool) {
    use glam::DVec3;
    let c = m.to_cols_array_2d();
    let axis_aligned = (0..3).all(|j| (0..3).all(|r| (r == j) == (c[j][r] != 0.0)))
        && (0..3).all(|i| c[i][i] > 0.0);
    let (mut a, mut b) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    for i in 0..8 {
        let corner = DVec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        );
        let w = m.transform_point3(corner);
        a = a.min(w);
        b = b.max(w);
    }
    let tidy = |v: DVec3| crate::scene::file::Point3(DVec3::new(tidy(v.x), tidy(v.y), tidy(v.z)));
    (tidy(a), tidy(b), axis_aligned)
}
