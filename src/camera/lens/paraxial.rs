//! First-order (paraxial) optics of a [`LensSystem`] at one wavelength: the y–nu ray
//! trace (Smith, "Modern Optical Engineering", 4th ed., §3.1; Kingslake & Johnson,
//! "Lens Design Fundamentals", 2nd ed., §3.3). At a surface of curvature c between
//! indices n and n′ a ray of height y and slope u leaves with n′u′ = nu − y c (n′ − n);
//! over a thickness t the height becomes y + t u′.
//!
//! From it: the effective focal length (EFL = −y₁/u′ₖ for a ray entering parallel to the
//! axis, image space in air), the back focal distance (the last vertex to the paraxial
//! focus, −yₖ/u′ₖ), the entrance and exit pupils (the stop imaged through the surfaces
//! in front of it and behind it; their sizes from the Lagrange invariant n u y, §2.8),
//! the f-number EFL/EPD and the image distance of an object at a finite distance.
use super::system::LensSystem;

/// First-order properties at one wavelength. Lengths in mm.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Paraxial {
    pub wavelength_nm: f64,
    /// Effective focal length.
    pub efl: f64,
    /// Back focal distance: from the last vertex to the paraxial focus.
    pub bfl: f64,
    /// Entrance pupil: position from the first vertex (+ toward the image), diameter.
    pub entrance_pupil_z: f64,
    pub entrance_pupil_diameter: f64,
    /// Exit pupil: position from the last vertex (+ toward the image), diameter.
    pub exit_pupil_z: f64,
    pub exit_pupil_diameter: f64,
    /// EFL / entrance pupil diameter (object at infinity).
    pub f_number: f64,
}

/// A paraxial ray: height y and reduced slope ω = n u in the medium of index n.
#[derive(Clone, Copy, Debug)]
struct YNu {
    y: f64,
    nu: f64,
}

/// Traces `r`, given just in front of surface `from` (in the medium before it), through
/// surfaces `from..=to` in order, and returns it just behind surface `to`.
fn forward(sys: &LensSystem, lambda: f64, from: usize, to: usize, mut r: YNu) -> YNu {
    for i in from..=to {
        let s = &sys.surfaces[i];
        let (n, n2) = (sys.n_before(i, lambda), sys.n_after(i, lambda));
        r.nu -= r.y * s.curvature() * (n2 - n);
        if i < to {
            r.y += s.thickness * r.nu / n2;
        }
    }
    r
}

/// Traces `r`, given just behind surface `from` (in the medium behind it) and going
/// toward the object, through surfaces `from` down to `to`, in the mirrored system
/// (z → −z, so curvatures change sign and each surface's media swap); returns it just
/// in front of surface `to`, as slope in the mirrored frame.
fn backward(sys: &LensSystem, lambda: f64, from: usize, to: usize, mut r: YNu) -> YNu {
    let mut i = from;
    loop {
        let s = &sys.surfaces[i];
        let (n, n2) = (sys.n_after(i, lambda), sys.n_before(i, lambda));
        r.nu -= r.y * (-s.curvature()) * (n2 - n);
        if i == to {
            return r;
        }
        r.y += sys.surfaces[i - 1].thickness * r.nu / n2;
        i -= 1;
    }
}

/// First-order properties of `sys` at `lambda_nm` (object at infinity).
pub fn paraxial(sys: &LensSystem, lambda_nm: f64) -> Paraxial {
    let last = sys.surfaces.len() - 1;
    // A ray of height 1 parallel to the axis.
    let m = forward(sys, lambda_nm, 0, last, YNu { y: 1.0, nu: 0.0 });
    let efl = -1.0 / m.nu;
    let bfl = -m.y / m.nu;
    let stop = sys.stop;
    let sa = sys.surfaces[stop].semi_aperture;
    let u0 = 0.1;
    // The entrance pupil: a ray from the stop's centre toward the object.
    let (ep_z, epd) = if stop == 0 {
        (0.0, 2.0 * sa)
    } else {
        let n_s = sys.n_before(stop, lambda_nm);
        let start = YNu {
            y: sys.surfaces[stop - 1].thickness * u0,
            nu: n_s * u0,
        };
        let r = backward(sys, lambda_nm, stop - 1, 0, start);
        // In the mirrored frame it crosses the axis at z′ = −y/u from the first vertex,
        // which is z = y/u in the lens's frame (object space is air).
        let u = r.nu;
        (r.y / u, 2.0 * sa * (n_s * u0 / u).abs())
    };
    // The exit pupil: a ray from the stop's centre toward the image.
    let (xp_z, xpd) = if stop == last {
        (0.0, 2.0 * sa)
    } else {
        let n_s = sys.n_after(stop, lambda_nm);
        let start = YNu {
            y: sys.surfaces[stop].thickness * u0,
            nu: n_s * u0,
        };
        let r = forward(sys, lambda_nm, stop + 1, last, start);
        (-r.y / r.nu, 2.0 * sa * (n_s * u0 / r.nu).abs())
    };
    Paraxial {
        wavelength_nm: lambda_nm,
        efl,
        bfl,
        entrance_pupil_z: ep_z,
        entrance_pupil_diameter: epd,
        exit_pupil_z: xp_z,
        exit_pupil_diameter: xpd,
        f_number: efl / epd,
    }
}

/// Distance from the last vertex to the paraxial image of an axial object point
/// `object_mm` in front of the first vertex (positive: a real image behind the lens).
pub fn image_distance(sys: &LensSystem, lambda_nm: f64, object_mm: f64) -> f64 {
    let last = sys.surfaces.len() - 1;
    let u = 1e-3;
    let r = forward(
        sys,
        lambda_nm,
        0,
        last,
        YNu {
            y: object_mm * u,
            nu: u,
        },
    );
    -r.y / r.nu
}

#[cfg(test)]
mod tests {
    use super::super::system::Surface;
    use super::*;

    /// A thick singlet against the thick-lens formula 1/f = (n−1)(1/R₁ − 1/R₂ +
    /// (n−1)t/(n R₁R₂)) and its back focal distance f(1 − (n−1)t/(n R₁)) (Hecht,
    /// "Optics", 5th ed., eqs. 6.2 and 6.3).
    #[test]
    fn thick_singlet_matches_the_thick_lens_formula() {
        let (r1, r2, t, n) = (40.0, -60.0, 6.0, 1.6f32);
        let sys = LensSystem::new(
            "singlet",
            vec![
                Surface::constant(0.0, 0.0, 1.0, 10.0, true),
                Surface::constant(r1, t, n, 12.0, false),
                Surface::constant(r2, 50.0, 1.0, 12.0, false),
            ],
        )
        .unwrap();
        let p = paraxial(&sys, 550.0);
        let n = n as f64;
        let f = 1.0 / ((n - 1.0) * (1.0 / r1 - 1.0 / r2 + (n - 1.0) * t / (n * r1 * r2)));
        let bfl = f * (1.0 - (n - 1.0) * t / (n * r1));
        assert!((p.efl - f).abs() < 1e-9 * f, "{} {f}", p.efl);
        assert!((p.bfl - bfl).abs() < 1e-9 * f, "{} {bfl}", p.bfl);
        // The stop at the first vertex is the entrance pupil.
        assert_eq!((p.entrance_pupil_z, p.entrance_pupil_diameter), (0.0, 20.0));
        assert!((p.f_number - f / 20.0).abs() < 1e-12);
        // An object at infinity images at the focus; a near one farther back, by
        // Newton's x x′ = −f² (distances from the focal points).
        assert!((image_distance(&sys, 550.0, 1e12) - bfl).abs() < 1e-6);
        let front_focus = f * (1.0 + (n - 1.0) * t / (n * r2)); // FFD, Hecht eq. 6.4
        let x = 500.0 - front_focus;
        assert!((image_distance(&sys, 550.0, 500.0) - (bfl + f * f / x)).abs() < 1e-9 * f);
    }

    /// A stop behind a thin lens of focal length f at distance d: the entrance pupil
    /// is its virtual image at d/(1 − d/f) behind the lens, magnified 1/(1 − d/f).
    #[test]
    fn entrance_pupil_is_the_stop_seen_through_the_front() {
        // A thin lens: a plano-convex 1e-4 mm thick (paraxial optics needs no
        // aperture, so its rim can be small enough for that).
        let (r, n) = (25.0, 1.5f32);
        let f = r / 0.5;
        let d = 10.0;
        let sys = LensSystem::new(
            "front",
            vec![
                Surface::constant(r, 1e-4, n, 0.05, false),
                Surface::constant(0.0, d, 1.0, 0.05, false),
                Surface::constant(0.0, 40.0, 1.0, 4.0, true),
            ],
        )
        .unwrap();
        let p = paraxial(&sys, 550.0);
        let m = 1.0 / (1.0 - d / f);
        assert!((p.entrance_pupil_z - d * m).abs() < 1e-5 * d * m, "{p:?}");
        assert!(
            (p.entrance_pupil_diameter - 8.0 * m).abs() < 1e-5 * 8.0 * m,
            "{p:?}"
        );
        // Behind the stop there is nothing: the exit pupil is the stop.
        assert_eq!((p.exit_pupil_z, p.exit_pupil_diameter), (0.0, 8.0));
    }
}
