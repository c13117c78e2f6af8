//! Real rays through a [`LensSystem`], in f64 and in the lens's frame (mm, the first
//! vertex at z = 0, +z toward the image): exact intersection with each sphere, Snell's
//! law in vector form (Glassner, "An Introduction to Ray Tracing", 1989, §5.2; the seed
//! lecture's refraction), and the rim of each surface, where a ray is stopped. Total
//! internal reflection inside a lens also ends the ray (its light would leave at a
//! stray angle: a lens's flare, which a camera model leaves out, as pbrt-v4's
//! `RealisticCamera` does).
use super::system::LensSystem;
use glam::DVec3;

/// A ray in the lens's frame: origin and unit direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LensRay {
    pub o: DVec3,
    pub d: DVec3,
}

/// Why a ray did not get through (surfaces numbered from 0 here).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Blocked {
    /// It missed the surface's sphere or passed outside its semi-aperture (for the stop:
    /// outside the stop's opening).
    Rim(usize),
    /// Total internal reflection at the surface.
    Tir(usize),
}

/// Whether to stop rays at the rims (the camera) or let them through (the spot diagrams
/// of design programs, which fill the pupil whatever the rims do, and count the
/// vignetted rays separately).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rims {
    Stop,
    /// Through every rim, and to each surface even where it lies behind the last.
    Ignore,
}

/// The point where `r` meets surface `i`, or None when it misses the sphere (or meets
/// it behind its origin, unless `behind`). Of the sphere's two points, the one on the
/// vertex's side.
#[inline]
fn intersect(sys: &LensSystem, i: usize, r: &LensRay, behind: bool) -> Option<(f64, DVec3)> {
    let s = &sys.surfaces[i];
    let zv = sys.vertex_z(i);
    let t = if s.radius == 0.0 {
        (zv - r.o.z) / r.d.z
    } else {
        let c = DVec3::new(0.0, 0.0, zv + s.radius);
        let oc = r.o - c;
        let b = oc.dot(r.d);
        let cc = oc.length_squared() - s.radius * s.radius;
        let disc = b * b - cc;
        if disc < 0.0 {
            return None;
        }
        let q = disc.sqrt();
        // For R > 0 the vertex is the sphere's point of smallest z, met first by a
        // ray going +z; for R < 0 the one of largest z.
        if (r.d.z > 0.0) == (s.radius > 0.0) {
            -b - q
        } else {
            -b + q
        }
    };
    (t.is_finite() && (behind || t >= 0.0)).then(|| (t, r.o + t * r.d))
}

/// Unit normal of surface i at p, pointing toward −z (the object side) near the axis.
#[inline]
fn normal(sys: &LensSystem, i: usize, p: DVec3) -> DVec3 {
    let s = &sys.surfaces[i];
    if s.radius == 0.0 {
        DVec3::NEG_Z
    } else {
        let c = DVec3::new(0.0, 0.0, sys.vertex_z(i) + s.radius);
        (p - c) / s.radius
    }
}

/// Refracts the unit direction `d` at a surface with unit normal `n` (either side) from
/// index `n1` into `n2`; None on total internal reflection.
#[inline]
pub fn refract(d: DVec3, n: DVec3, n1: f64, n2: f64) -> Option<DVec3> {
    let n = if n.dot(d) > 0.0 { -n } else { n };
    let eta = n1 / n2;
    let cos_i = -n.dot(d);
    let k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
    if k < 0.0 {
        return None;
    }
    Some((eta * d + (eta * cos_i - k.sqrt()) * n).normalize())
}

/// One surface crossing of `r` at surface `i`, from index n1 into n2.
#[inline]
fn cross(
    sys: &LensSystem,
    i: usize,
    r: &LensRay,
    n1: f64,
    n2: f64,
    rims: Rims,
) -> Result<LensRay, Blocked> {
    // Without the rims, a ray far outside them may meet the next sphere where it lies
    // behind the last (the spheres cross beyond the rims): it is carried back to it,
    // as design programs carry such rays (they are vignetted in the real lens).
    let (_, p) = intersect(sys, i, r, rims == Rims::Ignore).ok_or(Blocked::Rim(i))?;
    let s = &sys.surfaces[i];
    if rims == Rims::Stop && p.x * p.x + p.y * p.y > s.semi_aperture * s.semi_aperture {
        return Err(Blocked::Rim(i));
    }
    if n1 == n2 {
        return Ok(LensRay { o: p, d: r.d });
    }
    let d = refract(r.d, normal(sys, i, p), n1, n2).ok_or(Blocked::Tir(i))?;
    Ok(LensRay { o: p, d })
}

/// Traces `r` (in object space, heading +z) through every surface at `lambda_nm`;
/// returns it in image space, leaving the last surface.
pub fn trace_forward(
    sys: &LensSystem,
    mut r: LensRay,
    lambda_nm: f64,
    rims: Rims,
) -> Result<LensRay, Blocked> {
    // Each medium's index is evaluated once and carried to the next surface (a
    // Sellmeier index costs four divisions and a square root).
    let mut n1 = 1.0;
    for i in 0..sys.surfaces.len() {
        let n2 = sys.n_after(i, lambda_nm);
        r = cross(sys, i, &r, n1, n2, rims)?;
        n1 = n2;
    }
    Ok(r)
}

/// Traces `r` (in image space, heading −z: a camera ray from the film) through every
/// surface from the last to the first at `lambda_nm`; returns it in object space,
/// leaving the first surface. Rays are stopped at the rims.
#[inline]
pub fn trace_backward(
    sys: &LensSystem,
    mut r: LensRay,
    lambda_nm: f64,
) -> Result<LensRay, Blocked> {
    let last = sys.surfaces.len() - 1;
    let mut n1 = sys.n_after(last, lambda_nm);
    for i in (0..=last).rev() {
        let n2 = sys.n_before(i, lambda_nm);
        r = cross(sys, i, &r, n1, n2, Rims::Stop)?;
        n1 = n2;
    }
    Ok(r)
}

#[cfg(test)]
mod tests {
    use super::super::paraxial::paraxial;
    use super::super::system::Surface;
    use super::*;

    fn singlet() -> LensSystem {
        let surf = Surface::constant;
        LensSystem::new(
            "singlet",
            vec![
                surf(0.0, 0.0, 1.0, 5.0, true),
                surf(50.0, 5.0, 1.5, 12.0, false),
                surf(-50.0, 50.0, 1.0, 12.0, false),
            ],
        )
        .unwrap()
    }

    /// Snell's law n₁ sin θ₁ = n₂ sin θ₂, in the plane of incidence, and total internal
    /// reflection beyond the critical angle.
    #[test]
    fn refraction_obeys_snell() {
        let n = DVec3::new(0.0, 0.0, -1.0);
        for deg in [0.0f64, 10.0, 30.0, 60.0, 85.0] {
            let t = deg.to_radians();
            let d = DVec3::new(t.sin(), 0.0, t.cos());
            let o = refract(d, n, 1.0, 1.5).unwrap();
            assert!((1.0 * t.sin() - 1.5 * o.x).abs() < 1e-12 && o.y == 0.0);
            assert!(o.z > 0.0);
        }
        let crit = (1.0f64 / 1.5).asin();
        let d = |t: f64| DVec3::new(t.sin(), 0.0, t.cos());
        assert!(refract(d(crit - 1e-6), n, 1.5, 1.0).is_some());
        assert!(refract(d(crit + 1e-6), n, 1.5, 1.0).is_none());
    }

    /// Real rays close to the axis meet it at the paraxial focus; marginal rays of a
    /// biconvex singlet fall short of it (undercorrected spherical aberration).
    #[test]
    fn near_axis_rays_meet_at_the_paraxial_focus() {
        let sys = singlet();
        let p = paraxial(&sys, 550.0);
        let axis_crossing = |h: f64| {
            let r = LensRay {
                o: DVec3::new(0.0, h, -10.0),
                d: DVec3::Z,
            };
            let out = trace_forward(&sys, r, 550.0, Rims::Stop).unwrap();
            out.o.z - out.o.y / out.d.y * out.d.z - sys.length()
        };
        let near = axis_crossing(1e-3);
        assert!((near - p.bfl).abs() < 1e-5 * p.bfl, "{near} vs {}", p.bfl);
        assert!(axis_crossing(4.5) < p.bfl - 0.1);
        // Beyond the stop: stopped there (surface 0).
        let r = LensRay {
            o: DVec3::new(0.0, 6.0, -10.0),
            d: DVec3::Z,
        };
        assert_eq!(
            trace_forward(&sys, r, 550.0, Rims::Stop),
            Err(Blocked::Rim(0))
        );
        assert!(trace_forward(&sys, r, 550.0, Rims::Ignore).is_ok());
    }

    /// A ray traced backward retraces the forward ray (reversibility).
    #[test]
    fn backward_retraces_forward() {
        let sys = singlet();
        let r = LensRay {
            o: DVec3::new(0.3, 2.0, -10.0),
            d: DVec3::new(0.02, -0.05, 1.0).normalize(),
        };
        let out = trace_forward(&sys, r, 486.0, Rims::Stop).unwrap();
        let back = trace_backward(
            &sys,
            LensRay {
                o: out.o + 20.0 * out.d,
                d: -out.d,
            },
            486.0,
        )
        .unwrap();
        // Back on the incoming line, going the other way.
        assert!((back.d + r.d).length() < 1e-12);
        let k = (back.o - r.o).cross(r.d).length();
        assert!(k < 1e-9, "{k}");
    }
}
