//! Mitsuba 3's `homogeneous` medium (src/media/homogeneous.cpp) as heron's
//! Henyey–Greenstein medium inside a closed shape, and the `null` BSDF of the shape
//! around it. Mitsuba parametrises a medium by its extinction σ_t (times `scale`) and
//! single-scattering albedo; heron by σ_a and σ_s, so σ_s(λ) = albedo(λ) σ_t(λ) and
//! σ_a = σ_t − σ_s. An RGB parameter is uplifted as Mitsuba 3.9's parser does it, as
//! a bounded reflectance ([`mitsuba_spectrum`]), and the product written as samples.
//!
//! Mitsuba 3's `heterogeneous` medium (src/media/heterogeneous.cpp) with its σ_t a
//! `gridvolume` (src/volumes/grid.cpp) becomes the same medium with a `grid` density
//! (`medium::density::grid`): the grid's values are the density, `scale` (times a
//! `constvolume` or plain σ_t, 1 for a grid) its coefficient, and the grid is placed in
//! the box `to_world` maps the unit cube to (or the file's own box under
//! `use_grid_bbox`). heron's grids are trilinear, clamped and axis-aligned, Mitsuba's
//! defaults; other filter and wrap modes, a rotated grid and a grid albedo (heron's
//! density scales σ_a and σ_s alike: the grid's mean is used) warn.
use super::*;
use crate::medium::density::Grid;
use crate::scene::file::{Coefficient, Colour, DensityFile, GridFile, MediumFile};

/// Wavelength step (nm) of the table written when σ_t or the albedo is RGB (or both
/// vary with wavelength): the product is written as samples; both are
/// smooth (sigmoid uplifts or Mitsuba's tables), and linear interpolation between
/// samples 5 nm apart keeps it within 0.1% of the product on heron's 1 nm grid.
const PRODUCT_STEP_NM: usize = 5;

impl<'a> Converter<'a> {
    /// heron's medium for the `<medium>` (nested, or a `ref` to one) that a shape names
    /// `interior`; None, after a warning, for a medium heron does not have.
    pub(super) fn medium(&mut self, n: &'a Node) -> Result<Option<MediumFile>, Diagnostic> {
        let n = self.resolve(n)?;
        let kind = Self::plugin(n)?;
        let p = self.props(n);
        if kind != "homogeneous" && kind != "heterogeneous" {
            self.warn(n.diag(format!(
                "medium {kind:?} is not supported (homogeneous, heterogeneous are); the shape is left without a medium"
            )))?;
            for c in &n.children {
                if let Some(name) = c.attr("name") {
                    p.get(name);
                }
            }
            p.objects(&["phase", "volume"]);
            return Ok(None);
        }
        let (sigma_t, density, albedo) = if kind == "heterogeneous" {
            let (sigma_t, density) = self.volume(&p, "sigma_t", 1.0)?;
            let (albedo, grid) = self.volume(&p, "albedo", 0.75)?;
            let albedo = match grid {
                Some(g) => {
                    let mean = self.grid_mean(&p, &g)?;
                    self.warn(p.get("albedo").unwrap_or(n).diag(format!(
                        "albedo: a grid albedo is not supported (heron's density scales absorption and scattering alike); its mean {mean} is used"
                    )))?;
                    ColourValue::Grey(schema::tidy(mean))
                }
                None => albedo,
            };
            (sigma_t, density, albedo)
        } else {
            let sigma_t = self.coefficient(&p, "sigma_t", 1.0)?;
            (sigma_t, None, self.coefficient(&p, "albedo", 0.75)?)
        };
        let scale = p.float("scale")?.unwrap_or(1.0);
        if !(scale >= 0.0 && scale.is_finite()) {
            return Err(n.diag(format!("scale: expected a finite number >= 0, got {scale}")));
        }
        if albedo.max() > 1.0 {
            return Err(n.diag(format!("albedo: expected values in [0, 1], got {albedo:?}")));
        }
        for k in ["sample_emitters", "has_spectral_extinction"] {
            p.get(k);
        }
        let g = self.phase(&p)?;
        self.finish(&p)?;
        let (sigma_a, sigma_s) = split(&sigma_t, &albedo, scale);
        let mut m = schema::hg_medium(sigma_a, sigma_s, g);
        m.density = density.map(DensityFile::Grid);
        Ok(Some(m))
    }

    /// A heterogeneous medium's parameter `name`: a number, `<rgb>`, `<spectrum>` or a
    /// `constvolume` of one (the value, no grid), or a `gridvolume` (1 and the grid).
    fn volume(
        &mut self,
        p: &Props<'a>,
        name: &str,
        default: f64,
    ) -> Result<(ColourValue, Option<GridFile>), Diagnostic> {
        let Some(v) = p.get(name).filter(|v| v.tag == "volume") else {
            return Ok((self.coefficient(p, name, default)?, None));
        };
        let q = self.props(v);
        match Self::plugin(v)? {
            "constvolume" => {
                let c = self.coefficient(&q, "value", 1.0)?;
                self.finish(&q)?;
                Ok((c, None))
            }
            "gridvolume" => {
                let g = self.grid_volume(v, &q)?;
                self.finish(&q)?;
                Ok((ColourValue::Grey(1.0), Some(g)))
            }
            other => {
                self.warn(v.diag(format!(
                    "{name}: volume {other:?} is not supported (constvolume, gridvolume are); the default {default} is used"
                )))?;
                for c in &v.children {
                    if let Some(k) = c.attr("name") {
                        q.get(k);
                    }
                }
                Ok((ColourValue::Grey(default), None))
            }
        }
    }

    /// A `gridvolume` as heron's grid density: its file (checked here, so that a bad
    /// grid is named at its element) and its box.
    fn grid_volume(&mut self, v: &'a Node, q: &Props<'a>) -> Result<GridFile, Diagnostic> {
        let Some(file) = q.string("filename")? else {
            return Err(v.diag("expected <string name=\"filename\" value=\"…\"/>"));
        };
        let path = self.find(v, file);
        let bytes = std::fs::read(&path)
            .map_err(|e| v.diag(format!("filename: cannot read {}: {e}", path.display())))?;
        let grid = Grid::from_vol(&bytes)
            .map_err(|e| v.diag(format!("filename: {}: {e}", path.display())))?;
        for (k, want) in [("filter_type", "trilinear"), ("wrap_mode", "clamp")] {
            if let Some(m) = q.string(k)? {
                if m != want {
                    self.warn(v.diag(format!(
                        "{k}: {m:?} is not supported (heron's grids are {want}); {want} is used"
                    )))?;
                }
            }
        }
        for k in ["raw", "accel"] {
            q.get(k);
        }
        let to_world = q.transform("to_world")?.unwrap_or(DMat4::IDENTITY);
        let (lo, hi) = if q.boolean("use_grid_bbox")?.unwrap_or(false) {
            (grid.lo.as_dvec3(), grid.hi.as_dvec3())
        } else {
            (DVec3::ZERO, DVec3::ONE)
        };
        let (min, max, axis_aligned) = schema::grid_box(to_world, lo, hi);
        if !axis_aligned {
            self.warn(v.diag(
                "to_world: heron's grids are axis-aligned; the grid fills the box around its rotated or mirrored one",
            ))?;
        }
        Ok(GridFile {
            file: Some(
                relative_to(&path, &self.base)
                    .to_string_lossy()
                    .into_owned(),
            ),
            resolution: None,
            values: None,
            min: Some(min),
            max: Some(max),
            outside: None,
        })
    }

    /// The mean of a grid file's values.
    fn grid_mean(&self, p: &Props<'a>, g: &GridFile) -> Result<f64, Diagnostic> {
        let path = self.base.join(g.file.as_deref().unwrap_or_default());
        let bytes = std::fs::read(&path).map_err(|e| {
            p.node
                .diag(format!("albedo: cannot read {}: {e}", path.display()))
        })?;
        let grid = Grid::from_vol(&bytes)
            .map_err(|e| p.node.diag(format!("albedo: {}: {e}", path.display())))?;
        Ok(grid.values.iter().map(|&v| v as f64).sum::<f64>() / grid.values.len() as f64)
    }

    /// A medium's `sigma_t` or `albedo`: a number, `<rgb>` or `<spectrum>` pairs, ≥ 0
    /// (other forms warn and take Mitsuba's default).
    fn coefficient(
        &mut self,
        p: &Props<'a>,
        name: &str,
        default: f64,
    ) -> Result<ColourValue, Diagnostic> {
        let c = self.colour(p, name, ColourValue::Grey(default))?;
        let c = match c {
            ColourValue::Blackbody { .. } | ColourValue::Named { .. } => {
                let d = p.node.diag(format!(
                    "{name}: a medium's coefficient is a number, <rgb> or <spectrum> pairs; the default {default} is used"
                ));
                self.warn(d)?;
                ColourValue::Grey(default)
            }
            c => c,
        };
        let s = Coefficient(c.colour()).spectrum();
        if !(s.min_value() >= 0.0 && s.max_value().is_finite()) {
            let at = p.get(name).unwrap_or(p.node);
            return Err(at.diag(format!("{name}: expected finite values >= 0, got {c:?}")));
        }
        Ok(c)
    }

    /// The medium's phase function as a Henyey–Greenstein g: Mitsuba's `isotropic`
    /// (the default) is g = 0, `hg` its `g` (default 0.8); the others warn and are
    /// isotropic.
    fn phase(&mut self, p: &Props<'a>) -> Result<f64, Diagnostic> {
        let phases = p.objects(&["phase"]);
        let Some(ph) = phases.first() else {
            return Ok(0.0);
        };
        let ph = self.resolve(ph)?;
        let q = self.props(ph);
        let g = match Self::plugin(ph)? {
            "isotropic" => 0.0,
            "hg" => {
                let g = q.float("g")?.unwrap_or(0.8);
                if !(g.abs() < 1.0) {
                    return Err(ph.diag(format!("g: expected a mean cosine in (-1, 1), got {g}")));
                }
                g
            }
            other => {
                self.warn(ph.diag(format!(
                    "phase function {other:?} is not supported (isotropic, hg are); isotropic is used"
                )))?;
                for c in &ph.children {
                    if let Some(name) = c.attr("name") {
                        q.get(name);
                    }
                }
                q.objects(&["phase"]);
                0.0
            }
        };
        self.finish(&q)?;
        Ok(g)
    }
}

/// σ_a and σ_s from Mitsuba's σ_t, albedo and scale: numbers when both are grey, a
/// scaled copy of σ_t's samples when only it varies, else the product tabulated.
fn split(sigma_t: &ColourValue, albedo: &ColourValue, scale: f64) -> (Coefficient, Coefficient) {
    let times = |c: &ColourValue, k: f64| {
        if k == 0.0 {
            Coefficient::grey(0.0)
        } else {
            Coefficient(tidied(c.scaled(k)).colour())
        }
    };
    match (sigma_t, albedo) {
        (ColourValue::Grey(_) | ColourValue::Samples { .. }, ColourValue::Grey(a)) => {
            return (times(sigma_t, (1.0 - a) * scale), times(sigma_t, a * scale))
        }
        (ColourValue::Grey(t), _) if *t == 0.0 || scale == 0.0 => {
            return (Coefficient::grey(0.0), Coefficient::grey(0.0))
        }
        _ => {}
    }
    let (t, a) = (mitsuba_spectrum(sigma_t), mitsuba_spectrum(albedo));
    let table = |f: &dyn Fn(f32) -> f64| {
        let samples = (0..)
            .map(|i| crate::spectrum::LAMBDA_MIN as usize + i * PRODUCT_STEP_NM)
            .take_while(|l| *l as f32 <= crate::spectrum::LAMBDA_MAX)
            .map(|l| (l as f64, schema::tidy(f(l as f32).max(0.0))))
            .collect();
        Coefficient(Colour::Samples {
            samples,
            scale: 1.0,
        })
    };
    let a = |l: f32| (a.eval(l) as f64).clamp(0.0, 1.0);
    let st = |l: f32| t.eval(l) as f64 * scale;
    (table(&|l| st(l) * (1.0 - a(l))), table(&|l| st(l) * a(l)))
}

/// A medium parameter's spectrum as Mitsuba 3.9's spectral variants read it: its
/// parser makes an `<rgb>` a reflectance spectrum (`SRGBReflectanceSpectrum`, refusing
/// components above 1) before the medium's `ConstVolume` wraps it, so an RGB σ_t or
/// albedo is uplifted as a bounded reflectance; one above 1 (which Mitsuba refuses) is
/// read unbounded, as pbrt-v4 would.
fn mitsuba_spectrum(c: &ColourValue) -> crate::spectrum::DenseSpectrum {
    match c {
        ColourValue::Rgb(rgb) if c.max() <= 1.0 => {
            crate::spectrum::uplift::rgb_to_reflectance(rgb.map(|x| x as f32))
        }
        _ => Coefficient(c.colour()).spectrum(),
    }
}

/// The colour's numbers tidied ([`schema::tidy`]) after a product.
fn tidied(c: ColourValue) -> ColourValue {
    match c {
        ColourValue::Grey(x) => ColourValue::Grey(schema::tidy(x)),
        ColourValue::Rgb(rgb) => ColourValue::Rgb(rgb.map(schema::tidy)),
        ColourValue::Samples { samples, scale } => ColourValue::Samples {
            samples,
            scale: schema::tidy(scale),
        },
        other => other,
    }
}

impl<'a> Converter<'a> {
    /// The material of shape `n` (a `kind`) from its BSDF (None: Mitsuba's default),
    /// whether that BSDF is `null`, its emission and its interior medium: `Some(None)`
    /// for an index-matched boundary around the medium or an emitter without a BSDF
    /// (black, as Mitsuba 3 makes it), `None` for a shape that is not
    /// rendered at all (a `null` surface with neither a medium nor an emitter is
    /// invisible). A medium heron cannot hold in this shape is dropped, with a warning.
    pub(super) fn surface(
        &mut self,
        n: &Node,
        kind: &str,
        material: Option<String>,
        null: bool,
        emission: &Option<crate::scene::file::ShapeEmission>,
        medium: &mut Option<MediumFile>,
    ) -> Result<Option<Option<String>>, Diagnostic> {
        if medium.is_some() {
            let why = if matches!(kind, "rectangle" | "disk" | "cylinder") {
                Some(format!("a {kind} is open, and heron's media fill closed shapes (a sphere, a cube or a closed mesh)"))
            } else if emission.is_some() {
                Some("heron's shapes around a medium do not emit".to_string())
            } else if null {
                return Ok(Some(None));
            } else if !material
                .as_ref()
                .and_then(|m| self.materials.get(m))
                .is_some_and(|m| matches!(m, MaterialFile::Dielectric(_)))
            {
                Some(
                    "its BSDF does not let light into a medium (a null or dielectric BSDF does)"
                        .to_string(),
                )
            } else {
                None
            };
            if let Some(why) = why {
                self.warn(n.diag(format!("the interior medium is ignored: {why}")))?;
                *medium = None;
            }
        }
        if null {
            if emission.is_none() {
                return Ok(None);
            }
            self.warn(n.diag(
                "a null BSDF on an area emitter: heron's emitting surface reflects as Mitsuba's default BSDF",
            ))?;
        }
        Ok(Some(match material {
            Some(m) => Some(m),
            // Mitsuba 3 gives an emitter without a BSDF a black diffuse one
            // (`Shape::Shape` in src/render/shape.cpp): heron's black emitter, no
            // material; other shapes its diffuse 0.5.
            None if emission.is_some() && !null => None,
            None => Some(self.default_material()),
        }))
    }
}
