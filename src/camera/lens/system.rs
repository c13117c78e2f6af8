//! A lens prescription: spherical (or flat) surfaces on one axis, from the object side,
//! each with its radius of curvature, the thickness to the next surface, the medium
//! behind it and its clear semi-aperture; one of them is the aperture stop.
//!
//! Sign convention of optical design programs (Zemax, Optiland, rayoptics; Smith,
//! "Modern Optical Engineering", 4th ed., §2.2): light travels in +z from the object to
//! the image, and a radius is positive when the centre of curvature lies on the image
//! side of the vertex. Lengths are in millimetres, as in lens catalogues and pbrt-v4's
//! lens files.
use crate::spectrum::ior::Ior;

/// One refracting surface (or the stop, a flat surface in air).
#[derive(Clone, Debug)]
pub struct Surface {
    /// Radius of curvature in mm; 0 is flat.
    pub radius: f64,
    /// Distance along the axis to the next vertex (for the last surface: to the image
    /// plane the prescription gives, 0 when it gives none).
    pub thickness: f64,
    /// The medium behind the surface (on the image side).
    pub medium: Ior,
    /// Clear semi-aperture in mm: rays farther from the axis are stopped.
    pub semi_aperture: f64,
    /// Whether this surface is the aperture stop.
    pub stop: bool,
}

impl Surface {
    /// A surface with a constant index behind it, for the lens modules' tests.
    #[cfg(test)]
    pub fn constant(radius: f64, thickness: f64, n: f32, semi_aperture: f64, stop: bool) -> Self {
        Surface {
            radius,
            thickness,
            medium: Ior::Constant(n),
            semi_aperture,
            stop,
        }
    }

    /// Curvature 1/R (0 for a flat surface).
    #[inline]
    pub fn curvature(&self) -> f64 {
        if self.radius == 0.0 {
            0.0
        } else {
            1.0 / self.radius
        }
    }

    /// Sag z(h) of the surface at height h from the axis, relative to its vertex
    /// (the stable form h²/(R(1 + √(1 − h²/R²)))); None beyond the sphere (h > |R|).
    pub fn sag(&self, h: f64) -> Option<f64> {
        if self.radius == 0.0 {
            return Some(0.0);
        }
        let c = self.curvature();
        let q = 1.0 - (c * h) * (c * h);
        (q >= 0.0).then(|| c * h * h / (1.0 + q.sqrt()))
    }
}

/// A checked prescription: the surfaces, the index of the stop and each vertex's z.
#[derive(Clone, Debug)]
pub struct LensSystem {
    pub name: String,
    pub surfaces: Vec<Surface>,
    /// Index of the aperture stop in `surfaces`.
    pub stop: usize,
    /// The wavelength (nm) of the design's paraxial focus and focal shift: the
    /// prescription's `reference_wavelength`, by default the helium d line.
    pub reference_wavelength: f64,
    /// z of each vertex, the first at 0.
    z: Vec<f64>,
}

/// The helium d line (nm), design programs' usual reference wavelength.
pub const D_LINE: f64 = 587.5618;
/// The hydrogen F and C lines (nm), between which the Abbe number measures dispersion.
pub const F_LINE: f64 = 486.1327;
pub const C_LINE: f64 = 656.2725;

/// Heights at which two neighbouring surfaces are checked for crossing.
const OVERLAP_SAMPLES: usize = 64;

impl LensSystem {
    /// Checks the surfaces and places their vertices. Errors name the surface (from 1,
    /// as design programs number them): a semi-aperture larger than the surface's
    /// sphere, neighbouring surfaces that cross inside their apertures, no stop or
    /// several, a medium other than air behind the last surface (the film is in air).
    pub fn new(name: &str, surfaces: Vec<Surface>) -> Result<LensSystem, String> {
        if surfaces.is_empty() {
            return Err("expected at least one surface".into());
        }
        let mut stops = Vec::new();
        for (i, s) in surfaces.iter().enumerate() {
            let k = i + 1;
            if !s.radius.is_finite() {
                return Err(format!(
                    "surface {k}: expected a finite radius, got {}",
                    s.radius
                ));
            }
            if !(s.thickness.is_finite() && s.thickness >= 0.0) {
                return Err(format!(
                    "surface {k}: expected a thickness ≥ 0 mm, got {}",
                    s.thickness
                ));
            }
            if !(s.semi_aperture.is_finite() && s.semi_aperture > 0.0) {
                return Err(format!(
                    "surface {k}: expected a semi-aperture > 0 mm, got {}",
                    s.semi_aperture
                ));
            }
            if s.radius != 0.0 && s.semi_aperture > s.radius.abs() {
                return Err(format!(
                    "surface {k}: semi-aperture {} mm is larger than the radius of curvature |R| = {} mm (the sphere has no zone that wide)",
                    s.semi_aperture,
                    s.radius.abs()
                ));
            }
            if s.stop {
                stops.push(k);
            }
        }
        let stop = match stops.as_slice() {
            [k] => k - 1,
            [] => {
                return Err(
                    "no aperture stop: mark one surface with stop = true (in a pbrt lens file, a row with ior 0)".into(),
                )
            }
            many => {
                return Err(format!(
                    "surfaces {many:?} are all marked as the aperture stop; expected one"
                ))
            }
        };
        let last = surfaces.len();
        let back = &surfaces[last - 1].medium;
        if back.is_dispersive() || back.eval(550.0) != 1.0 {
            return Err(format!(
                "surface {last}: the medium behind the last surface must be air (n = 1), where the film is"
            ));
        }
        let mut z = Vec::with_capacity(last);
        let mut at = 0.0;
        for s in &surfaces {
            z.push(at);
            at += s.thickness;
        }
        for i in 0..last - 1 {
            let (a, b) = (&surfaces[i], &surfaces[i + 1]);
            let h_max = a.semi_aperture.min(b.semi_aperture);
            for j in 0..=OVERLAP_SAMPLES {
                let h = h_max * j as f64 / OVERLAP_SAMPLES as f64;
                let (Some(sa), Some(sb)) = (a.sag(h), b.sag(h)) else {
                    continue;
                };
                let gap = z[i + 1] + sb - (z[i] + sa);
                if gap < -1e-9 * (1.0 + a.thickness) {
                    return Err(format!(
                        "surface {}: crosses surface {} at {h:.4} mm from the axis (the gap there is {gap:.4} mm; raise the thickness of surface {} or lower their semi-apertures)",
                        i + 1,
                        i + 2,
                        i + 1
                    ));
                }
            }
        }
        Ok(LensSystem {
            name: name.to_string(),
            surfaces,
            stop,
            reference_wavelength: D_LINE,
            z,
        })
    }

    /// z of surface i's vertex (the first at 0, +z toward the image).
    #[inline]
    pub fn vertex_z(&self, i: usize) -> f64 {
        self.z[i]
    }

    /// Distance from the first vertex to the last.
    #[inline]
    pub fn length(&self) -> f64 {
        self.z[self.z.len() - 1]
    }

    /// Index of the medium in front of surface i (air before the first).
    #[inline]
    pub fn n_before(&self, i: usize, lambda_nm: f64) -> f64 {
        if i == 0 {
            1.0
        } else {
            self.n_after(i - 1, lambda_nm)
        }
    }

    /// Index of the medium behind surface i.
    #[inline]
    pub fn n_after(&self, i: usize, lambda_nm: f64) -> f64 {
        self.surfaces[i].medium.eval(lambda_nm as f32) as f64
    }

    /// Whether any glass disperses, so that the wavelengths of one camera ray leave the
    /// lens in different directions.
    pub fn is_dispersive(&self) -> bool {
        self.surfaces.iter().any(|s| s.medium.is_dispersive())
    }

    /// The last surface (the rear element's rear face, toward the film).
    #[inline]
    pub fn rear(&self) -> &Surface {
        &self.surfaces[self.surfaces.len() - 1]
    }

    /// Scales the stop's semi-aperture by `k` (another f-number). A stop wider than the
    /// other surfaces' rims is allowed: those rims then stop the rays, as in a real lens.
    pub fn with_stop_scaled(mut self, k: f64) -> LensSystem {
        self.surfaces[self.stop].semi_aperture *= k;
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn s(radius: f64, thickness: f64, n: f32, sa: f64) -> Surface {
        Surface {
            radius,
            thickness,
            medium: Ior::Constant(n),
            semi_aperture: sa,
            stop: false,
        }
    }

    fn stop(thickness: f64, sa: f64) -> Surface {
        Surface {
            stop: true,
            ..s(0.0, thickness, 1.0, sa)
        }
    }

    #[test]
    fn sag_matches_the_sphere() {
        let a = s(-20.0, 1.0, 1.5, 5.0);
        let h: f64 = 5.0;
        let exact = -20.0 + (400.0 - h * h).sqrt();
        assert!((a.sag(h).unwrap() - exact).abs() < 1e-12);
        assert!(a.sag(21.0).is_none());
        assert_eq!(s(0.0, 1.0, 1.5, 5.0).sag(3.0), Some(0.0));
    }

    #[test]
    fn bad_prescriptions_name_the_surface() {
        let ok = vec![
            stop(1.0, 4.0),
            s(30.0, 5.0, 1.5, 10.0),
            s(0.0, 40.0, 1.0, 10.0),
        ];
        assert!(LensSystem::new("ok", ok).is_ok());
        // A semi-aperture beyond the sphere.
        let e = LensSystem::new(
            "x",
            vec![
                stop(1.0, 4.0),
                s(8.0, 5.0, 1.5, 10.0),
                s(0.0, 40.0, 1.0, 8.0),
            ],
        )
        .unwrap_err();
        assert!(e.starts_with("surface 2: semi-aperture 10"), "{e}");
        // A biconvex lens too thin for its aperture: the faces cross at the rim.
        let e = LensSystem::new(
            "x",
            vec![
                stop(1.0, 4.0),
                s(20.0, 1.0, 1.5, 10.0),
                s(-20.0, 40.0, 1.0, 10.0),
            ],
        )
        .unwrap_err();
        assert!(e.starts_with("surface 2: crosses surface 3"), "{e}");
        let e = LensSystem::new("x", vec![s(30.0, 5.0, 1.5, 10.0), s(0.0, 4.0, 1.0, 10.0)])
            .unwrap_err();
        assert!(e.starts_with("no aperture stop"), "{e}");
        let e = LensSystem::new("x", vec![stop(1.0, 4.0), s(30.0, 5.0, 1.5, 10.0)]).unwrap_err();
        assert!(
            e.starts_with("surface 2: the medium behind the last"),
            "{e}"
        );
    }
}
