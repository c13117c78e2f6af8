//! pbrt-v4's participating media: `MakeNamedMedium` of type `homogeneous`
//! (`HomogeneousMedium::Create` in src/pbrt/media.cpp: σ_a and σ_s default 1, unbounded
//! spectra, times `scale`; a Henyey–Greenstein phase function of `g`, default 0),
//! `MediumInterface "inside" "outside"` in the graphics state, and the `interface`
//! material, a boundary that only separates media. heron's media fill closed shapes and
//! the camera is outside every medium, so a shape's inside medium becomes its
//! `medium`; an outside medium (fog around the scene, a camera in water) is not
//! rendered, with a warning.
use super::tokens::Params;
use super::*;
use crate::scene::file::{Coefficient, MediumFile};

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
        if ty != "homogeneous" {
            for q in &p.0 {
                q.used.set(true);
            }
            self.warn(self.diag(path, line, format!("MakeNamedMedium {name:?}: type {ty:?} is not supported (homogeneous is); shapes inside it get no medium")))?;
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
        if p.get("Le").is_some() {
            p.get("Lescale");
            let m = format!("MakeNamedMedium {name:?}: an emitting medium (Le) is not supported; it does not emit");
            self.warn(self.diag(path, line, m))?;
        }
        self.media.insert(
            name.to_string(),
            Some(schema::hg_medium(sigma_a, sigma_s, g)),
        );
        Ok(())
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
