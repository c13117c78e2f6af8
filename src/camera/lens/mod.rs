//! A camera made of real glass: a lens prescription ([`LensSystem`]) in front of a
//! film, camera rays traced from the film through every element per wavelength
//! (pbrt-v4's `RealisticCamera`, Pharr et al. 2023 §5.4, with a dispersive index per
//! element, which pbrt's single `eta` per element cannot have).
//!
//! **Frame.** The lens's frame is in millimetres with the first vertex at z = 0 and +z
//! toward the film; the film is at z = `length + film_distance`. In the scene the film's
//! centre is the camera's `eye` and +z of the lens is the camera's backward direction;
//! `mm_per_unit` scales the lens to scene units (1000: the scene is in metres).
//!
//! **Film window.** The film's centre is on the optical axis, or `film_offset` away from
//! it in the image plane (a small detector anywhere in the field: with a small
//! `film_diagonal`, it resolves an off-axis spot without rendering the whole frame).
//! The offset is given in the orientation of the output image (+x toward its right, +y
//! toward its top); the lens inverts the image, so in the lens's frame the window's
//! centre is at −offset ([`crate::camera::Camera::ray`]).
//!
//! **Measurement.** A pixel's value is the film irradiance over it,
//! E(x) = ∫ L cos⁴θ / z² dA over the plane of the rear vertex (z the film's distance from
//! that plane; pbrt-v4 eq. 5.3), divided by E₀, the irradiance a uniform radiance of 1
//! gives on the optical axis (the film's centre, without an offset) at the focus
//! wavelength. So a uniformly bright scene has the value 1 at the image's centre, as with
//! the pinhole camera, and the fall-off toward the corners (cos⁴, vignetting by the rims)
//! is the lens's own; a window off the axis keeps the same E₀, so its values compare with
//! the full frame's and with other windows'.
//!
//! **Sampling.** A film point's rays are aimed at points drawn uniformly in a
//! rectangle of the rear plane that holds every ray that gets through (the exit
//! pupil's bounds, per ring of film radius, found once by tracing a grid; pbrt-v4
//! §5.4.4), or in the whole square around the rear element ([`PupilSampling`]). Each
//! camera ray is traced at the hero wavelength; when any glass disperses the companions
//! end at the lens ([`CameraRay::hero_only`]), as they do at the first dispersive
//! surface in the scene.
pub mod paraxial;
pub mod system;
pub mod trace;

use glam::DVec3;
use rayon::prelude::*;
pub use system::{LensSystem, Surface};
use trace::{trace_backward, LensRay};

/// Where the rays from a film point are aimed on the rear plane.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PupilSampling {
    /// The exit pupil's bounds for the film point's ring of radius (the default).
    Bounds,
    /// The whole square of side 4 × the rear semi-aperture around the axis (the check
    /// that the bounds lose no rays; many rays are then stopped).
    RearElement,
}

impl PupilSampling {
    pub const NAMES: &'static [&'static str] = &["bounds", "rear-element"];

    pub fn parse(s: &str) -> Option<PupilSampling> {
        match s {
            "bounds" => Some(PupilSampling::Bounds),
            "rear-element" => Some(PupilSampling::RearElement),
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            PupilSampling::Bounds => "bounds",
            PupilSampling::RearElement => "rear-element",
        }
    }
}

/// Where the film is, given by the user in one of three ways.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Focus {
    /// The film this far behind the last vertex (mm).
    FilmDistance(f64),
    /// Focused (paraxially, at the focus wavelength) on an axial point this far in
    /// front of the film (mm).
    ObjectDistance(f64),
    /// The prescription's last thickness when it gives one, else focused at infinity.
    Prescription,
}

/// The camera's settings besides the prescription.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LensSettings {
    /// Film diagonal in mm (35 mm film's is 43.27).
    pub film_diagonal: f64,
    pub focus: Focus,
    /// Wavelength (nm) at which the focus is solved and E₀ found.
    pub focus_wavelength: f64,
    pub pupil: PupilSampling,
    /// Millimetres per scene unit (1000: the scene is in metres).
    pub mm_per_unit: f64,
    /// Where the film's centre is in the image plane (mm from the optical axis), in the
    /// output image's orientation: +x toward the image's right, +y toward its top.
    pub film_offset: (f64, f64),
}

/// Radial rings of film radius with their own exit-pupil bounds.
const RINGS: usize = 64;
/// Film radii traced per ring, grid points per side of the rear square, and the
/// wavelengths (nm: the range's ends and its middle) whose rays the bounds hold: the
/// bounds are the union over them, widened by two grid cells. With a 48² grid the first
/// pass's cell is 1/12 of the rear semi-aperture and the second's 1/48 of the first
/// pass's rectangle; tests/lens_camera.rs checks by a z-test that the bounds lose no
/// light against sampling the whole square.
const RING_RADII: usize = 6;
const GRID: usize = 48;
const BOUND_WAVELENGTHS: [f64; 3] = [360.0, 595.0, 830.0];
/// Grid points per side for E₀.
const E0_GRID: usize = 512;

/// A lens in front of a film: what [`crate::camera::Camera`] traces its rays through.
#[derive(Clone, Debug)]
pub struct LensCamera {
    pub system: LensSystem,
    /// Distance from the last vertex to the film (mm).
    pub film_distance: f64,
    pub settings: LensSettings,
    /// Half side of the rear square (mm): 2 × the rear semi-aperture.
    rear_half: f64,
    /// Per ring: the bounds [x0, x1, y0, y1] on the rear plane (mm) for a film point on
    /// the +x axis.
    bounds: Vec<[f64; 4]>,
    /// The largest distance of a film point from the axis (mm): |film_offset| + half the
    /// film diagonal. The rings cover radii 0 to r_max.
    r_max: f64,
    inv_e0: f64,
    hero_only: bool,
}

/// A camera ray in the lens's frame leaving the front element, with its weight
/// (cos⁴θ A / z² / E₀, see the module docs).
#[derive(Clone, Copy, Debug)]
pub struct LensSample {
    pub ray: LensRay,
    pub weight: f64,
}

impl LensCamera {
    /// Places the film (solving the focus) and finds the exit pupil's bounds and E₀.
    pub fn new(system: LensSystem, settings: LensSettings) -> Result<LensCamera, String> {
        if !(settings.film_diagonal.is_finite() && settings.film_diagonal > 0.0) {
            return Err(format!(
                "film_diagonal: expected a length > 0 mm, got {}",
                settings.film_diagonal
            ));
        }
        let (ox, oy) = settings.film_offset;
        if !(ox.is_finite() && oy.is_finite()) {
            return Err(format!(
                "film_offset: expected [x, y] with two finite numbers (mm), got [{ox}, {oy}]"
            ));
        }
        if !(settings.mm_per_unit.is_finite() && settings.mm_per_unit > 0.0) {
            return Err(format!(
                "mm_per_unit: expected a number > 0 (millimetres per scene unit), got {}",
                settings.mm_per_unit
            ));
        }
        let lf = settings.focus_wavelength;
        let film_distance = match settings.focus {
            Focus::FilmDistance(d) => d,
            Focus::Prescription if system.rear().thickness > 0.0 => system.rear().thickness,
            Focus::Prescription => paraxial::paraxial(&system, lf).bfl,
            Focus::ObjectDistance(d) => solve_focus(&system, lf, d)?,
        };
        let rear = system.rear();
        let rim_sag = rear.sag(rear.semi_aperture).unwrap_or(0.0).max(0.0);
        if !(film_distance.is_finite() && film_distance > rim_sag) {
            return Err(format!(
                "film_distance: the film would be {film_distance:.4} mm behind the last vertex, inside or in front of the rear element (which reaches {rim_sag:.4} mm back): a lens whose image is virtual cannot make a photograph"
            ));
        }
        let mut cam = LensCamera {
            rear_half: 2.0 * rear.semi_aperture,
            system,
            film_distance,
            settings,
            bounds: Vec::new(),
            r_max: ox.hypot(oy) + 0.5 * settings.film_diagonal,
            inv_e0: 1.0,
            hero_only: false,
        };
        cam.hero_only = cam.system.is_dispersive();
        let h = cam.rear_half;
        cam.bounds = match settings.pupil {
            PupilSampling::RearElement => vec![[-h, h, -h, h]; RINGS],
            PupilSampling::Bounds => (0..RINGS)
                .into_par_iter()
                .map(|k| cam.ring_bounds(k))
                .collect(),
        };
        let e0 = cam.centre_irradiance();
        if !(e0 > 0.0) {
            return Err(format!(
                "lens: no ray from the film's centre gets through the lens at {lf} nm (check the semi-apertures and the stop)"
            ));
        }
        cam.inv_e0 = 1.0 / e0;
        Ok(cam)
    }

    /// z of the film in the lens's frame.
    #[inline]
    pub fn film_z(&self) -> f64 {
        self.system.length() + self.film_distance
    }

    /// Whether the companions end at the lens (some glass disperses).
    #[inline]
    pub fn hero_only(&self) -> bool {
        self.hero_only
    }

    /// Where the film's centre is in the lens's frame (mm): −film_offset, since the lens
    /// inverts the image and the offset is given in the output image's orientation.
    #[inline]
    pub fn film_centre(&self) -> (f64, f64) {
        let (ox, oy) = self.settings.film_offset;
        (-ox, -oy)
    }

    /// The film's width and height (mm) for an image of `w` × `h` pixels.
    pub fn film_size(&self, w: u32, h: u32) -> (f64, f64) {
        let (w, h) = (w as f64, h as f64);
        let k = self.settings.film_diagonal / w.hypot(h);
        (w * k, h * k)
    }

    /// The bounds on the rear plane of the rays from film points in ring `k` that get
    /// through, for film points on the +x axis: a grid over the whole rear square, then
    /// the same grid over the rectangle it found, so a small exit pupil (a lens stopped
    /// down) gets bounds a grid cell of its own size from its edge rather than one of
    /// the rear element's.
    fn ring_bounds(&self, k: usize) -> [f64; 4] {
        let h = self.rear_half;
        let coarse = self.grid_bounds(k, [-h, h, -h, h]);
        if coarse == [0.0; 4] {
            return coarse;
        }
        self.grid_bounds(k, coarse)
    }

    /// The rectangle within `within` [x0, x1, y0, y1] (rear plane, mm) holding every
    /// point of a GRID² grid over it whose ray from ring `k`'s film points gets through,
    /// widened by two cells and clipped to `within`; all zeros when none does.
    fn grid_bounds(&self, k: usize, within: [f64; 4]) -> [f64; 4] {
        let [wx0, wx1, wy0, wy1] = within;
        let (cx, cy) = ((wx1 - wx0) / GRID as f64, (wy1 - wy0) / GRID as f64);
        let mut b = [
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        let zf = self.film_z();
        let zr = self.system.length();
        for j in 0..RING_RADII {
            let r = self.r_max * (k as f64 + j as f64 / (RING_RADII - 1) as f64) / RINGS as f64;
            let o = DVec3::new(r, 0.0, zf);
            for &lambda in &BOUND_WAVELENGTHS {
                for gy in 0..GRID {
                    let y = wy0 + (gy as f64 + 0.5) * cy;
                    for gx in 0..GRID {
                        let x = wx0 + (gx as f64 + 0.5) * cx;
                        let d = (DVec3::new(x, y, zr) - o).normalize();
                        if trace_backward(&self.system, LensRay { o, d }, lambda).is_ok() {
                            b = [b[0].min(x), b[1].max(x), b[2].min(y), b[3].max(y)];
                        }
                    }
                }
            }
        }
        if b[0] > b[1] {
            // Nothing gets through from this ring: it stays black.
            return [0.0; 4];
        }
        [
            (b[0] - 2.0 * cx).max(wx0),
            (b[1] + 2.0 * cx).min(wx1),
            (b[2] - 2.0 * cy).max(wy0),
            (b[3] + 2.0 * cy).min(wy1),
        ]
    }

    /// E₀: the film centre's irradiance under a uniform radiance of 1 at the focus
    /// wavelength, ∫ T cos⁴θ / z² dA over the rear plane (midpoint rule on a 512² grid
    /// over ring 0's bounds; its error at the pupil's edge is below 1/512 of E₀).
    fn centre_irradiance(&self) -> f64 {
        let [x0, x1, y0, y1] = self.bounds[0];
        let (dx, dy) = ((x1 - x0) / E0_GRID as f64, (y1 - y0) / E0_GRID as f64);
        let (zf, zr) = (self.film_z(), self.system.length());
        let z = zf - zr;
        let o = DVec3::new(0.0, 0.0, zf);
        let lambda = self.settings.focus_wavelength;
        (0..E0_GRID)
            .into_par_iter()
            .map(|gy| {
                let y = y0 + (gy as f64 + 0.5) * dy;
                let mut s = 0.0;
                for gx in 0..E0_GRID {
                    let x = x0 + (gx as f64 + 0.5) * dx;
                    let d = (DVec3::new(x, y, zr) - o).normalize();
                    if trace_backward(&self.system, LensRay { o, d }, lambda).is_ok() {
                        let c = -d.z;
                        s += c * c * c * c;
                    }
                }
                s
            })
            .sum::<f64>()
            * dx
            * dy
            / (z * z)
    }

    /// A camera ray from film point (x, y) (mm, lens frame) aimed at the rear-plane
    /// point that `u` ∈ [0, 1)² picks in the bounds, traced at `lambda_nm`; None when
    /// the lens stops it.
    #[inline]
    pub fn sample(&self, film: (f64, f64), u: (f64, f64), lambda_nm: f64) -> Option<LensSample> {
        let r = film.0.hypot(film.1);
        let ring = ((r / self.r_max * RINGS as f64) as usize).min(RINGS - 1);
        let [x0, x1, y0, y1] = self.bounds[ring];
        let area = (x1 - x0) * (y1 - y0);
        if !(area > 0.0) {
            return None;
        }
        let (px, py) = (x0 + u.0 * (x1 - x0), y0 + u.1 * (y1 - y0));
        // The bounds are for a film point on +x: turn them to the film point's angle.
        let (s, c) = if r > 0.0 {
            (film.1 / r, film.0 / r)
        } else {
            (0.0, 1.0)
        };
        let p = DVec3::new(c * px - s * py, s * px + c * py, self.system.length());
        let o = DVec3::new(film.0, film.1, self.film_z());
        let d = (p - o).normalize();
        let out = trace_backward(&self.system, LensRay { o, d }, lambda_nm).ok()?;
        let cos = -d.z;
        let z = self.film_distance;
        let weight = cos * cos * cos * cos * area / (z * z) * self.inv_e0;
        Some(LensSample { ray: out, weight })
    }
}

/// The film distance (mm behind the last vertex) at which an axial point `object_mm`
/// in front of the film is in paraxial focus at `lambda_nm`. The object's distance
/// from the first vertex depends on the film distance, so the two are solved together
/// by fixed-point iteration (it converges while the lens is much shorter than the
/// object distance).
fn solve_focus(sys: &LensSystem, lambda_nm: f64, object_mm: f64) -> Result<f64, String> {
    let infinity = paraxial::paraxial(sys, lambda_nm).bfl;
    let mut film = infinity;
    for _ in 0..200 {
        let s = object_mm - sys.length() - film;
        let next = if s > 0.0 {
            paraxial::image_distance(sys, lambda_nm, s)
        } else {
            f64::NAN
        };
        if !(next.is_finite() && next > 0.0) {
            return Err(format!(
                "focus_distance: the lens cannot focus on a point {} mm in front of the film (it is closer than the lens's near limit; its focal length is {:.3} mm)",
                (object_mm * 1e6).round() / 1e6,
                paraxial::paraxial(sys, lambda_nm).efl
            ));
        }
        if (next - film).abs() <= 1e-12 * object_mm {
            return Ok(next);
        }
        film = next;
    }
    Err(format!(
        "focus_distance: the focus at {object_mm} mm from the film did not converge (the object is too close for this lens)"
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn singlet(sa_stop: f64) -> LensSystem {
        let surf = Surface::constant;
        LensSystem::new(
            "singlet",
            vec![
                surf(0.0, 1.0, 1.0, sa_stop, true),
                surf(50.0, 5.0, 1.5, 12.0, false),
                surf(-50.0, 0.0, 1.0, 12.0, false),
            ],
        )
        .unwrap()
    }

    fn settings(focus: Focus) -> LensSettings {
        LensSettings {
            film_diagonal: 20.0,
            focus,
            focus_wavelength: 587.56,
            pupil: PupilSampling::Bounds,
            mm_per_unit: 1000.0,
            film_offset: (0.0, 0.0),
        }
    }

    #[test]
    fn focus_at_a_distance_puts_the_image_on_the_film() {
        let sys = singlet(4.0);
        let d = 2000.0;
        let cam = LensCamera::new(sys.clone(), settings(Focus::ObjectDistance(d))).unwrap();
        let object = d - sys.length() - cam.film_distance;
        let img = paraxial::image_distance(&sys, 587.56, object);
        assert!((img - cam.film_distance).abs() < 1e-9, "{img}");
        let inf = LensCamera::new(sys.clone(), settings(Focus::Prescription)).unwrap();
        assert!(cam.film_distance > inf.film_distance);
        let e = LensCamera::new(sys, settings(Focus::ObjectDistance(60.0))).unwrap_err();
        assert!(
            e.starts_with("focus_distance: the lens cannot focus"),
            "{e}"
        );
    }

    /// At the film's centre the weights average to 1 (the normalisation by E₀): the
    /// estimate of E/E₀ there, from uniform samples of the bounds.
    #[test]
    fn centre_weight_averages_to_one() {
        let cam = LensCamera::new(singlet(4.0), settings(Focus::Prescription)).unwrap();
        let n = 400;
        let mut s = 0.0;
        for i in 0..n {
            for j in 0..n {
                let u = ((i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64);
                if let Some(x) = cam.sample((0.0, 0.0), u, 587.56) {
                    s += x.weight;
                }
            }
        }
        let mean = s / (n * n) as f64;
        assert!((mean - 1.0).abs() < 0.01, "{mean}");
    }

    /// A film window off the axis: the rings reach its far corner (|offset| + half the
    /// diagonal), and the exposure is still normalised by the on-axis irradiance E₀
    /// (found on ring 0's bounds, which now span a wider ring of radii, so E₀ moves by
    /// the quadrature's error only); non-finite offsets are refused, naming the key.
    #[test]
    fn an_offset_window_keeps_e0_and_widens_the_rings() {
        let centred = LensCamera::new(singlet(4.0), settings(Focus::Prescription)).unwrap();
        let mut s = settings(Focus::Prescription);
        s.film_diagonal = 2.0;
        s.film_offset = (3.0, -4.0);
        let off = LensCamera::new(singlet(4.0), s).unwrap();
        assert_eq!(off.r_max, 6.0);
        assert_eq!(off.film_centre(), (-3.0, 4.0));
        let ratio = off.inv_e0 / centred.inv_e0;
        assert!((ratio - 1.0).abs() < 2e-3, "{ratio}");
        for bad in [(f64::NAN, 0.0), (0.0, f64::INFINITY)] {
            s.film_offset = bad;
            let e = LensCamera::new(singlet(4.0), s).unwrap_err();
            assert!(e.starts_with("film_offset: expected [x, y]"), "{e}");
        }
    }
}
