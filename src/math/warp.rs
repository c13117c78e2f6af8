//! Warps from the unit square to directions and points, each with its density. The
//! formulas are the standard ones collected in pbrt-v4 (Pharr, Jakob & Humphreys 2023,
//! "Physically Based Rendering", 4th ed.) §A.5; Shirley & Chiu 1997 for the concentric
//! disk map. Every warp here has a chi-square test in `tests/sampling.rs`.
use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, FRAC_PI_2, FRAC_PI_4, PI};

/// Concentric map of [0,1)² onto the unit disk (Shirley & Chiu 1997): area-preserving
/// and continuous, so stratification survives.
#[inline]
pub fn concentric_disk(u: Vec2) -> Vec2 {
    let o = 2.0 * u - Vec2::ONE;
    if o.x == 0.0 && o.y == 0.0 {
        return Vec2::ZERO;
    }
    let (r, theta) = if o.x.abs() > o.y.abs() {
        (o.x, FRAC_PI_4 * (o.y / o.x))
    } else {
        (o.y, FRAC_PI_2 - FRAC_PI_4 * (o.x / o.y))
    };
    r * Vec2::new(theta.cos(), theta.sin())
}

/// Cosine-weighted direction on the hemisphere z > 0 (Malley's method), pdf cos θ/π.
#[inline]
pub fn cosine_hemisphere(u: Vec2) -> Vec3 {
    let d = concentric_disk(u);
    let z = (1.0 - d.length_squared()).max(0.0).sqrt();
    Vec3::new(d.x, d.y, z)
}

#[inline]
pub fn cosine_hemisphere_pdf(cos_theta: f32) -> f32 {
    cos_theta.max(0.0) * FRAC_1_PI
}

/// Uniform direction on the unit sphere, pdf 1/(4π).
#[inline]
pub fn uniform_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

pub const UNIFORM_SPHERE_PDF: f32 = 1.0 / (4.0 * PI);

/// Uniform direction in the cone of half-angle θmax about +z, given 1 − cos θmax (kept
/// as such so that tiny cones such as the sun's keep their digits); pdf
/// 1/(2π(1 − cos θmax)).
#[inline]
pub fn uniform_cone(u: Vec2, one_minus_cos_max: f32) -> Vec3 {
    // 1 − cos θ = u · (1 − cos θmax); sin θ = √((1 − cos θ)(1 + cos θ)).
    let omc = u.x * one_minus_cos_max;
    let cos = 1.0 - omc;
    let sin = (omc * (2.0 - omc)).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    Vec3::new(sin * phi.cos(), sin * phi.sin(), cos)
}

#[inline]
pub fn uniform_cone_pdf(one_minus_cos_max: f32) -> f32 {
    1.0 / (2.0 * PI * one_minus_cos_max)
}

/// Uniform barycentric coordinates (b0, b1, b2) on a triangle (pbrt-v4's
/// `SampleUniformTriangle`, after Heitz 2019, "A Low-Distortion Map Between Triangle
/// and Square").
#[inline]
pub fn uniform_triangle(u: Vec2) -> [f32; 3] {
    let (b0, b1);
    if u.x < u.y {
        b0 = u.x / 2.0;
        b1 = u.y - b0;
    } else {
        b1 = u.y / 2.0;
        b0 = u.x - b1;
    }
    [b0, b1, 1.0 - b0 - b1]
}

/// The power heuristic with β = 2 (Veach 1997, §9.2.4), for one sample of each
/// strategy: w = p_f² / (p_f² + p_g²).
#[inline]
pub fn power_heuristic(pf: f32, pg: f32) -> f32 {
    if pf.is_infinite() {
        return 1.0;
    }
    // Squared in f64: in f32 the squares overflow above 1.8e19 and vanish below 4e-23.
    let (f, g) = ((pf as f64) * (pf as f64), (pg as f64) * (pg as f64));
    if f + g == 0.0 {
        return 0.0;
    }
    (f / (f + g)) as f32
}

/// The equal-area octahedral map of [0, 1]² onto the unit sphere (Clarberg 2008, "Fast
/// Equal-Area Mapping of the (Hemi)Sphere using SIMD", J. Graphics Tools 13(3); pbrt-v4's
/// `EqualAreaSquareToSphere`, the layout of its image environment maps): the square's
/// centre is +z, its corners −z, and every cell of the square covers the same solid
/// angle, so the density is 1/(4π) per unit area of the square.
#[inline]
pub fn equal_area_square_to_sphere(p: Vec2) -> Vec3 {
    let (u, v) = (2.0 * p.x - 1.0, 2.0 * p.y - 1.0);
    let (up, vp) = (u.abs(), v.abs());
    // The signed distance from the diagonal |u| + |v| = 1 (the equator) sets the radius.
    let signed = 1.0 - (up + vp);
    let r = 1.0 - signed.abs();
    let phi = if r == 0.0 { 1.0 } else { (vp - up) / r + 1.0 } * FRAC_PI_4;
    let z = (1.0 - r * r).copysign(signed);
    let s = r * (2.0 - r * r).max(0.0).sqrt();
    Vec3::new(phi.cos().copysign(u) * s, phi.sin().copysign(v) * s, z)
}

/// The inverse of [`equal_area_square_to_sphere`] for a unit vector (with the exact
/// arctangent where pbrt-v4 uses a polynomial fit of it, 1e-5 away).
#[inline]
pub fn equal_area_sphere_to_square(d: Vec3) -> Vec2 {
    let (x, y, z) = (d.x.abs(), d.y.abs(), d.z.abs());
    let r = (1.0 - z).max(0.0).sqrt();
    let (a, b) = (x.max(y), x.min(y));
    let b = if a == 0.0 { 0.0 } else { b / a };
    let mut phi = b.atan() * 2.0 * FRAC_1_PI;
    if x < y {
        phi = 1.0 - phi;
    }
    let mut v = phi * r;
    let mut u = r - v;
    if d.z < 0.0 {
        // The southern hemisphere folds onto the square's corners.
        std::mem::swap(&mut u, &mut v);
        u = 1.0 - u;
        v = 1.0 - v;
    }
    Vec2::new(0.5 * (u.copysign(d.x) + 1.0), 0.5 * (v.copysign(d.y) + 1.0))
}
