//! Mitsuba 3's reconstruction filters (`<rfilter>` in a film; `src/rfilters/*.cpp`) as
//! heron's `[render] filter`: `gaussian` (stddev 0.5, radius 4·stddev, less its value at
//! the radius as in Mitsuba's polynomial fit), `tent` (radius 1), `box` (radius 0.5),
//! `mitchell` (B, C, radius 2) and `catmullrom` (B = 0, C = 0.5, radius 2) exactly;
//! `lanczos` (a windowed sinc) is read as Catmull–Rom, the nearest filter heron has (also
//! with negative lobes), with a warning. Without an rfilter Mitsuba uses its Gaussian.
use super::*;

impl<'a> Converter<'a> {
    /// Sets `[render] filter` from the film's rfilter `r` (None: Mitsuba's default).
    pub(super) fn rfilter(&mut self, r: Option<&'a Node>) -> Result<(), Diagnostic> {
        let Some(r) = r else {
            let render = self.render();
            render.filter = Some("gaussian".into());
            render.filter_stddev = Some(0.5);
            render.filter_radius = Some(2.0);
            return Ok(());
        };
        let r = self.resolve(r)?;
        let kind = Self::plugin(r)?;
        let p = self.props(r);
        let (name, radius, stddev, bc) = match kind {
            "gaussian" => {
                let s = p.float("stddev")?.unwrap_or(0.5);
                if !(s > 0.0 && 4.0 * s <= crate::settings::MAX_FILTER_RADIUS) {
                    return Err(r.diag(format!(
                        "stddev: expected a standard deviation in (0, {}] pixels, got {s}",
                        crate::settings::MAX_FILTER_RADIUS / 4.0
                    )));
                }
                ("gaussian", 4.0 * s, Some(s), None)
            }
            "tent" => {
                let radius = p.float("radius")?.unwrap_or(1.0);
                if !(radius > 0.0 && radius <= crate::settings::MAX_FILTER_RADIUS) {
                    return Err(r.diag(format!(
                        "radius: expected a radius in (0, {}] pixels, got {radius}",
                        crate::settings::MAX_FILTER_RADIUS
                    )));
                }
                ("tent", radius, None, None)
            }
            "box" => ("box", 0.5, None, None),
            "mitchell" => {
                let b = p.float("B")?.unwrap_or(1.0 / 3.0);
                let c = p.float("C")?.unwrap_or(1.0 / 3.0);
                ("mitchell", 2.0, None, Some((b, c)))
            }
            "catmullrom" => ("mitchell", 2.0, None, Some((0.0, 0.5))),
            "lanczos" => {
                p.get("lobes");
                self.warn(r.diag(
                    "lanczos: heron has no windowed sinc; read as Catmull-Rom (Mitchell B = 0, C = 0.5, radius 2), the nearest filter with negative lobes",
                ))?;
                ("mitchell", 2.0, None, Some((0.0, 0.5)))
            }
            other => {
                self.warn(r.diag(format!(
                    "rfilter {other:?} is not known to heron; read as Mitsuba's default Gaussian (stddev 0.5)"
                )))?;
                ("gaussian", 2.0, Some(0.5), None)
            }
        };
        let render = self.render();
        render.filter = Some(name.into());
        render.filter_radius = Some(schema::tidy(radius));
        render.filter_stddev = stddev.map(schema::tidy);
        (render.filter_b, render.filter_c) = match bc {
            Some((b, c)) => (Some(schema::tidy(b)), Some(schema::tidy(c))),
            None => (None, None),
        };
        self.finish(&p)
    }
}
