//! pbrt-v4's participating media: `MakeNamedMedium` of type `homogeneous`
//! (`HomogeneousMedium::Create` in src/pbrt/media.cpp: σ_a and σ_s default 1, unbounded
//! spectra, times `scale`; a Henyey–Greenstein phase function of `g`, default 0),
//! `MediumInterface "inside" "outside"` in the graphics state, and the `interface`
//! material, a boundary that only separates media. heron's media fill closed shapes and
//! the camera is outside every medium, so a shape's inside medium becomes its
//! `medium`; an outside medium (fog around the scene, a camera in water) is not
//! rendered, with a warning.
//!
//! A `uniformgrid` medium (`GridMedium::Create`: `density` values, x fastest, on an
//! `nx` × `ny` × `nz` grid over the box `p0`–`p1` in the medium's space, the CTM at
//! `MakeNamedMedium`; σ_a, σ_s, `scale` and `g` as the homogeneous one's) becomes the same
//! medium with a `grid` density written in the scene, its box the CTM's image of
//! `p0`–`p1` and `outside = "zero"` (pbrt's `SampledGrid` is 0 beyond its cells and its
//! medium empty outside its bounds). A rotated box warns (heron's grids are
//! axis-aligned), as do an emitting grid's `Le`, `Lescale` and `temperature`.
use super::tokens::Params;
use super::*;
use crate::scene::file::{Coefficient, DensityFile, GridFile, MediumFile, PositiveCount};

/// The material name a shape gets from `Material "interface"`: no heron material is
/// made; the shape is a medium's index-matched boundary, or invisible around no medium.
pub(super) const INTERFACE: &str = "\u{0}pbrt-interface";

impl Conv {
    /// `MakeNamedMedium`: a homogeneous medium is kept under its name; other types warn
    /// and are kept as None, so that shapes naming them get no medium.
    pub(super) fn make_medium(
        &mut self,
        path: &Path,
        line: u32,
        name: &str,
        p: &Params,
    ) -> Result<(), Diagnostic> {
        let ty = p.string("type").unwrap_or("").to_string();
        if ty != "homogeneous" && ty != "uniformgrid" {
            for q in &p.0 {
                q.used.set(true);
            }
            self.warn(self.diag(path, line, format!("MakeNamedMedium {name:?}: type {ty:?} is not supported (homogeneous, uniformgrid are); shapes inside it get no medium")))?;
            self.media.insert(name.to_string(), None);
            return Ok(());
        }
        if let Some(preset) = p.string("preset") {
            let m = format!("MakeNamedMedium {name:?}: preset {preset:?} is not in heron's catalogue; sigma_a and sigma_s as given (default 1) are used");
            self.warn(self.diag(path, line, m))?;
        }
        let scale = p.float("scale").unwrap_or(1.0);
        if !(scale >= 0.0 && scale.is_finite()) {
            let m = format!(
                "MakeNamedMedium {name:?}: scale: expected a finite number >= 0, got {scale}"
            );
            return Err(self.diag(path, line, m));
        }
        let sigma = |this: &mut Self, key: &str| -> Result<Coefficient, Diagnostic> {
            let c = match this.colour(path, p, key, 1.0)? {
                ColourValue::Blackbody { .. } | ColourValue::Named { .. } => {
                    let m = format!("MakeNamedMedium {name:?}: {key} is a coefficient (a number, rgb or spectrum pairs), not an illuminant; 1 is used");
                    this.warn(this.diag(path, line, m))?;
                    ColourValue::Grey(1.0)
                }
                c => scaled(c, scale),
            };
            let s = Coefficient(c.colour()).spectrum();
            if !(s.min_value() >= 0.0 && s.max_value().is_finite()) {
                let m = format!("MakeNamedMedium {name:?}: {key}: expected finite values >= 0 at every wavelength");
                return Err(this.diag(path, line, m));
            }
            Ok(Coefficient(c.colour()))
        };
        let sigma_a = sigma(self, "sigma_a")?;
        let sigma_s = sigma(self, "sigma_s")?;
        let g = p.float("g").unwrap_or(0.0);
        if !(g.abs() < 1.0) {
            let m =
                format!("MakeNamedMedium {name:?}: g: expected a mean cosine in (-1, 1), got {g}");
            return Err(self.diag(path, line, m));
        }
        if p.get("Le").is_some() || p.get("temperature").is_some() {
            for k in [
                "Lescale",
                "temperatureoffset",
                "temperaturecutoff",
                "temperaturescale",
            ] {
                p.get(k);
            }
            let m = format!("MakeNamedMedium {name:?}: an emitting medium (Le, temperature) is not supported; it does not emit");
            self.warn(self.diag(path, line, m))?;
        }
        let mut medium = schema::hg_medium(sigma_a, sigma_s, g);
        if ty == "uniformgrid" {
            medium.density = Some(DensityFile::Grid(self.uniform_grid(path, line, name, p)?));
        }
        self.media.insert(name.to_string(), Some(medium));
        Ok(())
    }

    /// A `uniformgrid`'s densities and box (module docs), checked as pbrt checks them.
    fn uniform_grid(
        &mut self,
        path: &Path,
        line: u32,
        name: &str,
        p: &Params,
    ) -> Result<GridFile, Diagnostic> {
        let err = |m: String| self.diag(path, line, format!("MakeNamedMedium {name:?}: {m}"));
        let density = p.get("density").map(|q| q.nums.clone()).unwrap_or_default();
        if density.is_empty() {
            return Err(err("no \"density\" values for a uniformgrid medium".into()));
        }
        let n = |k: &str| -> Result<u32, Diagnostic> {
            let v = p.float(k).unwrap_or(1.0);
            if v >= 1.0 && v.fract() == 0.0 && v <= u32::MAX as f64 {
                Ok(v as u32)
            } else {
                Err(err(format!("{k}: expected an integer >= 1, got {v}")))
            }
        };
        let (nx, ny, nz) = (n("nx")?, n("ny")?, n("nz")?);
        let count = nx as u64 * ny as u64 * nz as u64;
        if density.len() as u64 != count {
            return Err(err(format!(
                "density: expected nx*ny*nz = {count} values, got {}",
                density.len()
            )));
        }
        if let Some(v) = density.iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
            return Err(err(format!(
                "density: expected values finite and >= 0, got {v}"
            )));
        }
        let point = |k: &str, d: DVec3| -> Result<DVec3, Diagnostic> {
            match p.get(k) {
                None => Ok(d),
                Some(q) if q.nums.len() == 3 => Ok(DVec3::new(q.nums[0], q.nums[1], q.nums[2])),
                Some(q) => Err(err(format!(
                    "{k}: expected 3 numbers, got {}",
                    q.nums.len()
                ))),
            }
        };
        let (p0, p1) = (point("p0", DVec3::ZERO)?, point("p1", DVec3::ONE)?);
        if !p0.cmplt(p1).all() {
            return Err(err(format!(
                "p0, p1: expected p0 < p1 in each axis, got {p0} and {p1}"
            )));
        }
        let (min, max, axis_aligned) = schema::grid_box(self.g.ctm, p0, p1);
        if !axis_aligned {
            let m = format!("MakeNamedMedium {name:?}: heron's grids are axis-aligned; the grid fills the box around its rotated or mirrored one");
            self.warn(self.diag(path, line, m))?;
        }
        Ok(GridFile {
            file: None,
            resolution: Some([PositiveCount(nx), PositiveCount(ny), PositiveCount(nz)]),
            values: Some(density),
            min: Some(min),
            max: Some(max),
            outside: Some("zero".into()),
        })
    }

    /// `MediumInterface "inside" ["outside"]` (one name: both sides).
    pub(super) fn medium_interface(&mut self, names: &[String]) {
        let inside = names.first().cloned().unwrap_or_default();
        let outside = names.get(1).cloned().unwrap_or_else(|| inside.clone());
        self.g.inside = inside;
        self.g.outside = outside;
    }

    /// The medium inside shape `sd` (None: none, or one heron cannot hold, after a
    /// warning at the shape's `file` and `line`). `closed` says whether the shape's
    /// geometry can hold one (a sphere, a PLY mesh, a closed triangle mesh).
    pub(super) fn interior(
        &mut self,
        sd: &ShapeDef,
        closed: bool,
        file: &Path,
        line: u32,
        ctx: &str,
    ) -> Result<Option<MediumFile>, Diagnostic> {
        let (inside, outside) = (&sd.inside, &sd.outside);
        // Once per medium: a scene in fog names it outside every shape.
        if !outside.is_empty() && outside != inside && self.outside_warned.insert(outside.clone()) {
            let m = format!("{ctx}MediumInterface: the outside medium {outside:?} is not rendered (heron's media fill closed shapes; the space around them is empty)");
            self.warn(self.diag(file, line, m))?;
        }
        if inside.is_empty() {
            return Ok(None);
        }
        let Some(def) = self.media.get(inside) else {
            let m = format!("{ctx}MediumInterface: no medium named {inside:?} was made (MakeNamedMedium {inside:?} …)");
            return Err(self.diag(file, line, m));
        };
        let Some(medium) = def.clone() else {
            return Ok(None);
        };
        if outside == inside {
            let m = format!("{ctx}MediumInterface: the shape is inside the medium {inside:?} on both sides, which heron does not render (its media fill closed shapes)");
            self.warn(self.diag(file, line, m))?;
            return Ok(None);
        }
        let opaque = sd.material != INTERFACE
            && !matches!(
                self.materials.get(&sd.material),
                Some(MaterialFile::Dielectric(_))
            );
        let why = if !closed {
            Some("the shape is not closed")
        } else if sd.area.is_some() {
            Some("heron's shapes around a medium do not emit")
        } else if opaque {
            Some("its material does not let light into a medium (interface or dielectric do)")
        } else {
            None
        };
        if let Some(why) = why {
            let m = format!("{ctx}the inside medium {inside:?} is ignored: {why}");
            self.warn(self.diag(file, line, m))?;
            return Ok(None);
        }
        Ok(Some(medium))
    }
}
