//! pbrt-v4's `PixelFilter` (`filters.cpp`, `*Filter::Create`) as heron's `[render]
//! filter`: `gaussian` (radius 1.5, sigma 0.5, less its value at the radius, as pbrt
//! does), `triangle` (radius 2), `box` (radius 0.5) and `mitchell` (radius 2, B = C =
//! 1/3) exactly; `lanczos` and `sinc` (windowed sincs) are read as Catmull–Rom (Mitchell
//! B = 0, C = 0.5), the nearest filter with negative lobes heron has, with a warning.
//! pbrt's separate `xradius` and `yradius` become one radius (the larger, with a warning
//! when they differ). Without a PixelFilter, pbrt uses its Gaussian: so does the import.
use super::tokens::Params;
use super::*;

impl Conv {
    /// `PixelFilter "name" …` at `path`:`line` with parameters `p`.
    pub(super) fn pixel_filter(
        &mut self,
        path: &Path,
        line: u32,
        name: String,
        p: &Params,
    ) -> Result<(), Diagnostic> {
        let (kind, default_radius) = match name.as_str() {
            "gaussian" => ("gaussian", 1.5),
            "triangle" => ("tent", 2.0),
            "box" => ("box", 0.5),
            "mitchell" => ("mitchell", 2.0),
            "lanczos" | "sinc" => {
                p.get("tau");
                self.warn(self.diag(
                    path,
                    line,
                    format!("PixelFilter {name:?}: heron has no windowed sinc; read as Catmull-Rom (Mitchell B = 0, C = 0.5) of the same radius, the nearest filter with negative lobes"),
                ))?;
                ("mitchell", 4.0)
            }
            other => {
                return Err(self.diag(
                    path,
                    line,
                    format!("PixelFilter: expected box, gaussian, mitchell, triangle, lanczos or sinc, got {other:?}"),
                ))
            }
        };
        let xr = p.float("xradius").unwrap_or(default_radius);
        let yr = p.float("yradius").unwrap_or(default_radius);
        if xr != yr {
            self.warn(self.diag(
                path,
                line,
                format!("PixelFilter {name:?}: heron's filters have one radius; xradius {xr} and yradius {yr} read as {}", xr.max(yr)),
            ))?;
        }
        let radius = xr.max(yr);
        if !(radius > 0.0 && radius <= crate::settings::MAX_FILTER_RADIUS) {
            return Err(self.diag(
                path,
                line,
                format!(
                    "PixelFilter: expected a radius in (0, {}] pixels, got {radius}",
                    crate::settings::MAX_FILTER_RADIUS
                ),
            ));
        }
        let sinc = matches!(name.as_str(), "lanczos" | "sinc");
        let stddev = (kind == "gaussian").then(|| p.float("sigma").unwrap_or(0.5));
        let (b, c) = match kind {
            "mitchell" if sinc => (Some(0.0), Some(0.5)),
            "mitchell" => (
                Some(p.float("B").unwrap_or(1.0 / 3.0)),
                Some(p.float("C").unwrap_or(1.0 / 3.0)),
            ),
            _ => (None, None),
        };
        let r = self.render();
        r.filter = Some(kind.into());
        r.filter_radius = Some(schema::tidy(radius));
        r.filter_stddev = stddev.map(schema::tidy);
        (r.filter_b, r.filter_c) = (b.map(schema::tidy), c.map(schema::tidy));
        Ok(())
    }

    /// pbrt-v4's default filter when the file names none: a Gaussian of radius 1.5 and
    /// sigma 0.5.
    pub(super) fn default_filter(&mut self) {
        let r = self.render();
        if r.filter.is_none() {
            r.filter = Some("gaussian".into());
            r.filter_radius = Some(1.5);
            r.filter_stddev = Some(0.5);
        }
    }
}
