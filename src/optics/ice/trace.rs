//! One ray through one crystal, by geometric optics: Fresnel reflection or refraction
//! at every face it meets, chosen at random by the reflected and transmitted powers, so
//! each ray keeps its whole power and leaves along one direction (the Monte Carlo of
//! halo simulators: Pattloch & Tränkle 1984, J. Opt. Soc. Am. A 1, 520; Tape 1994,
//! "Atmospheric Halos", appendix; HaloSim). Total internal reflection is certain
//! reflection. Ice is taken as non-absorbing and isotropic: its absorption index k is
//! below 3e-8 up to 700 nm and 1.5e-7 at 830 nm (Warren & Brandt 2008), an absorption
//! coefficient 4πk/λ of at most 2.2 m⁻¹, so a path of a few mm (the largest crystals the
//! halo spec allows: a ≤ 1 mm, c ≤ 2 mm) loses under 1% of the light at 830 nm and
//! under 0.1% below 700 nm; its birefringence
//! (n_e − n_o ≈ 0.0014) splits a halo's edge by 0.1° for the two polarisations
//! (Können 1983, J. Opt. Soc. Am. 73, 1629), which this model does not resolve.
//!
//! Polarisation: with `polarised`, the ray carries a Stokes vector through the Mueller
//! matrices of [`crate::optics::mueller`] (Collett's convention; the frame's x̂ is
//! turned onto each interface's s direction, d × n, before its matrix acts), and the
//! choice between reflection and transmission is made with the powers of the actual
//! state, (M_R S)₀ and (M_T S)₀, which add to S₀; the state is then divided by the chosen
//! power, so S₀ stays 1 and the estimator stays unbiased for every Stokes component.
use super::crystal::{HexPrism, FACES};
use crate::optics::mueller::{self, Mueller, Stokes};
use glam::DVec3;
use num_complex::Complex64;

/// Interactions after which a ray trapped inside is abandoned (and counted lost): with
/// n ≈ 1.31 a ray meets a reflection of probability ≤ 0.5 at each face it is not totally
/// reflected by, and skew rays are seldom trapped for long; tests count the loss.
pub const MAX_EVENTS: u32 = 200;

/// A ray as it leaves the crystal.
#[derive(Clone, Copy, Debug)]
pub struct Exit {
    /// Direction of travel, in the crystal's frame.
    pub dir: DVec3,
    /// The face it entered by (or was reflected by, outside).
    pub entry: usize,
    /// The face it left by (the entry face for an external reflection).
    pub exit: usize,
    /// Internal reflections between entry and exit (total or partial).
    pub reflections: u32,
    /// True for the external reflection at the entry face.
    pub external: bool,
    /// Stokes vector, S₀ = 1, in the frame (x̂, dir × x̂), when traced polarised.
    pub stokes: Stokes,
    pub frame_x: DVec3,
}

/// Fresnel reflectances (R_s, R_p) at `cos_i` onto a relative index `eta` = n_t / n_i,
/// both 1 under total internal reflection.
#[inline]
pub fn fresnel_rs_rp(cos_i: f64, eta: f64) -> (f64, f64) {
    let sin2 = 1.0 - cos_i * cos_i;
    let k = eta * eta - sin2;
    if k <= 0.0 {
        return (1.0, 1.0);
    }
    let ect = k.sqrt(); // η cos θt
    let rs = (cos_i - ect) / (cos_i + ect);
    let rp = (eta * eta * cos_i - ect) / (eta * eta * cos_i + ect);
    (rs * rs, rp * rp)
}

/// The direction refracted from `d` through a surface of unit normal `nn` facing the
/// incoming side (nn·d < 0), into relative index `eta` = n_t / n_i; None under total
/// internal reflection.
#[inline]
pub fn refract(d: DVec3, nn: DVec3, eta: f64) -> Option<DVec3> {
    let cos_i = -d.dot(nn);
    let r = 1.0 / eta;
    let k = 1.0 - r * r * (1.0 - cos_i * cos_i);
    if k <= 0.0 {
        return None;
    }
    Some((d * r + nn * (r * cos_i - k.sqrt())).normalize())
}

#[inline]
fn reflect(d: DVec3, n: DVec3) -> DVec3 {
    d - n * (2.0 * d.dot(n))
}

/// The state `s` in the frame x̂ = `x` re-expressed with x̂ turned onto the unit `to`
/// (both perpendicular to `dir`).
fn rotate_frame(s: &Stokes, dir: DVec3, x: DVec3, to: DVec3) -> Stokes {
    let y = dir.cross(x);
    let theta = to.dot(y).atan2(to.dot(x));
    Mueller::rotator(theta).apply(s)
}

/// A unit vector perpendicular to the unit `d`.
fn perpendicular(d: DVec3) -> DVec3 {
    let a = if d.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
    d.cross(a).normalize()
}

/// The interface's s direction (perpendicular to the plane of incidence), or `x` at
/// normal incidence.
fn s_axis(d: DVec3, n: DVec3, x: DVec3) -> DVec3 {
    let s = d.cross(n);
    let l = s.length();
    if l > 1e-12 {
        s / l
    } else {
        x
    }
}

/// One interface: the ray along `d` meets the face of outward normal `n_out` from the
/// side of index ratio `eta` = n_t / n_i. Returns whether it reflects, and updates the
/// polarisation state (`stokes`, `x`) to the outgoing ray's frame when `polarised`.
fn interface(
    d: DVec3,
    n_out: DVec3,
    eta: f64,
    polarised: bool,
    stokes: &mut Stokes,
    x: &mut DVec3,
    u: &mut impl FnMut() -> f64,
) -> bool {
    let cos_i = d.dot(n_out).abs();
    if !polarised {
        let (rs, rp) = fresnel_rs_rp(cos_i, eta);
        return u() < 0.5 * (rs + rp);
    }
    let s_dir = s_axis(d, n_out, *x);
    let s = rotate_frame(stokes, d, *x, s_dir);
    let m_r = mueller::reflection(cos_i, Complex64::new(eta, 0.0));
    let m_t = mueller::transmission(cos_i, eta);
    let (sr, st) = (m_r.apply(&s), m_t.apply(&s));
    let total = sr[0] + st[0];
    let reflects = u() * total < sr[0];
    let chosen = if reflects { sr } else { st };
    *stokes = chosen.map(|v| v / chosen[0]);
    *x = s_dir;
    reflects
}

/// Traces a ray travelling along the unit `dir` (crystal frame) into `prism` of index
/// `n`, entering at a point uniform over the projected area. None if it is still
/// inside after [`MAX_EVENTS`] interactions.
pub fn trace(
    prism: &HexPrism,
    dir: DVec3,
    n: f64,
    polarised: bool,
    u: &mut impl FnMut() -> f64,
) -> Option<Exit> {
    let (mut p, entry) = prism.sample_entry(dir, u);
    let mut stokes: Stokes = [1.0, 0.0, 0.0, 0.0];
    let mut x = perpendicular(dir);
    let nf = prism.normal(entry);
    if interface(dir, nf, n, polarised, &mut stokes, &mut x, u) {
        return Some(Exit {
            dir: reflect(dir, nf),
            entry,
            exit: entry,
            reflections: 0,
            external: true,
            stokes,
            frame_x: x,
        });
    }
    let mut d = refract(dir, nf, n)?;
    let mut face = entry;
    for reflections in 0..MAX_EVENTS {
        let (k, t) = prism.exit(p, d, face);
        if k >= FACES || !t.is_finite() {
            return None;
        }
        p += d * t;
        face = k;
        let nk = prism.normal(k);
        if interface(d, nk, 1.0 / n, polarised, &mut stokes, &mut x, u) {
            d = reflect(d, nk);
            continue;
        }
        // Not totally reflected (the interface reflects with certainty then).
        let out = refract(d, -nk, 1.0 / n)?;
        return Some(Exit {
            dir: out,
            entry,
            exit: k,
            reflections,
            external: false,
            stokes,
            frame_x: x,
        });
    }
    None
}

/// S1/S0 and S2/S0 of `exit` in the frame whose x̂ is perpendicular to the scattering
/// plane (the plane of `incident` and the exit direction, both in one frame): S1 > 0 is
/// light polarised perpendicular to that plane (tangential around the sun, for a halo),
/// S1 < 0 parallel to it (radial). (0, 0) for forward or backward scattering, where the
/// plane is undefined.
pub fn scattering_plane_stokes(exit: &Exit, incident: DVec3) -> (f64, f64) {
    let perp = incident.cross(exit.dir);
    if perp.length_squared() < 1e-20 {
        return (0.0, 0.0);
    }
    let s = rotate_frame(&exit.stokes, exit.dir, exit.frame_x, perp.normalize());
    (s[1], s[2])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fresnel_reflectances_match_the_mueller_matrices() {
        for &(c, eta) in &[
            (0.9, 1.31),
            (0.3, 1.31),
            (0.99, 1.0 / 1.31),
            (0.7, 1.0 / 1.31),
        ] {
            let (rs, rp) = fresnel_rs_rp(c, eta);
            let m = mueller::reflection(c, Complex64::new(eta, 0.0));
            let t = mueller::transmission(c, eta);
            assert!((0.5 * (rs + rp) - m.0[0][0]).abs() < 1e-12);
            assert!((0.5 * (rs - rp) - m.0[0][1]).abs() < 1e-12);
            // R + T = 1.
            assert!((m.0[0][0] + t.0[0][0] - 1.0).abs() < 1e-12);
        }
        // Total internal reflection past the critical angle of ice.
        let c = (1.0f64 - (1.0 / 1.31f64).powi(2)).sqrt() - 1e-6;
        assert_eq!(fresnel_rs_rp(c, 1.0 / 1.31), (1.0, 1.0));
    }

    #[test]
    fn refraction_obeys_snells_law() {
        let n = DVec3::Z;
        for deg in [0.0f64, 10.0, 40.0, 70.0, 89.0] {
            let a = deg.to_radians();
            let d = DVec3::new(a.sin(), 0.0, -a.cos());
            let t = refract(d, n, 1.31).unwrap();
            let sin_t = t.x.hypot(t.y);
            assert!((a.sin() - 1.31 * sin_t).abs() < 1e-12, "{deg}°");
            assert!(t.z < 0.0 && t.y.abs() < 1e-15);
        }
        // From inside past the critical angle: none.
        let d = DVec3::new(0.8, 0.0, -0.6);
        assert!(refract(d, n, 1.0 / 1.31).is_none());
    }
}
