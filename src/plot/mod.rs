//! Line charts as PNG files, drawn in Rust so that no Python is needed at run time:
//! `heron converge --plot` ([`converge`]: error against time, log–log, with the 1/√t
//! slope) and `heron sky profile --plot` ([`sky`]: radiance against the angle from the
//! antisolar point, one line per wavelength). The figure sets in `papers/` keep
//! matplotlib. [`stokes`] writes false-colour previews of a polarised render's degree
//! and angle of linear polarisation (viridis; hue wheel with brightness = DoLP) with a
//! colour-bar legend.
//!
//! Drawing is by the `plotters` crate's bitmap backend into an RGB buffer in memory,
//! encoded as PNG by the `image` crate and written through [`Staged`] (a temporary file
//! renamed into place), so a failed plot leaves no file. Text is set in DejaVu Sans
//! (`src/plot/DejaVuSans.ttf`, from Debian's fonts-dejavu-core, licence in
//! `src/plot/DejaVuSans-LICENSE.txt`), embedded in the binary and rasterised by
//! `ab_glyph`: no system font or fontconfig is looked up, nothing is read at run time,
//! and the same chart gives the same bytes on every machine (no clock, no randomness,
//! no hash-ordered drawing). The font is registered on the first plot only, so renders
//! and the commands that do not plot pay nothing for it.
//!
//! Series colours are Okabe & Ito's palette for colour-blind readers (Okabe, M. & Ito,
//! K. (2008), *Color Universal Design (CUD): how to make figures and presentations that
//! are friendly to colorblind people*, https://jfly.uni-koeln.de/color/), in the order
//! [`PALETTE`], without its yellow, which does not show on white.
pub mod converge;
pub mod sky;
pub mod stokes;

use crate::files::Staged;
use crate::{HeronError, Result};
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::prelude::*;
use std::path::Path;
use std::sync::OnceLock;

/// Width and height of every plot, pixels.
pub const SIZE: (u32, u32) = (960, 600);

/// Okabe & Ito's colours (2008) less yellow: blue, vermillion, bluish green, reddish
/// purple, orange, sky blue, black.
pub const PALETTE: [[u8; 3]; 7] = [
    [0, 114, 178],
    [213, 94, 0],
    [0, 158, 115],
    [204, 121, 167],
    [230, 159, 0],
    [86, 180, 233],
    [0, 0, 0],
];

/// The slate grey of guide lines (the 1/√t slope); not a neutral grey, so that no
/// anti-aliased text or grid pixel has its exact colour.
pub const GUIDE: [u8; 3] = [90, 90, 110];

const FONT: &[u8] = include_bytes!("DejaVuSans.ttf");
const FAMILY: &str = "sans-serif";

/// Registers the embedded font with plotters once per process.
fn register_font() -> Result<()> {
    static DONE: OnceLock<bool> = OnceLock::new();
    let ok = *DONE
        .get_or_init(|| plotters::style::register_font(FAMILY, FontStyle::Normal, FONT).is_ok());
    if ok {
        Ok(())
    } else {
        Err(HeronError::Invalid(
            "plot: the embedded font DejaVuSans.ttf cannot be read".into(),
        ))
    }
}

/// How an axis maps values to pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scale {
    Linear,
    /// Logarithmic: only positive values can be drawn.
    Log,
}

/// One line of a chart.
#[derive(Clone, Debug)]
pub struct Series {
    /// The legend's text.
    pub label: String,
    pub colour: [u8; 3],
    /// (x, y) in data units, drawn in this order; points a log axis cannot show
    /// (non-positive) and non-finite points are left out.
    pub points: Vec<(f64, f64)>,
    /// Dashed (a guide) instead of solid.
    pub dashed: bool,
    /// A filled circle at each point.
    pub markers: bool,
}

/// A line chart.
#[derive(Clone, Debug)]
pub struct Chart {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub x_scale: Scale,
    pub y_scale: Scale,
    /// Start a linear y axis at 0 when every value is positive (radiance).
    pub y_from_zero: bool,
    pub series: Vec<Series>,
}

/// Where the data went: the plotting area's pixel rectangle and the axes' ranges, so
/// that a data point's pixel can be found without plotters (the tests do).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// Left, top, right, bottom pixel of the plotting area (inclusive).
    pub area: [i32; 4],
    pub x_range: (f64, f64),
    pub y_range: (f64, f64),
    pub x_scale: Scale,
    pub y_scale: Scale,
}

impl Frame {
    /// The pixel (column, row) of data point (x, y), or `None` outside the axes.
    pub fn pixel(&self, x: f64, y: f64) -> Option<(f64, f64)> {
        let f = |v: f64, (lo, hi): (f64, f64), s: Scale| -> Option<f64> {
            let t = match s {
                Scale::Linear => (v - lo) / (hi - lo),
                Scale::Log if v > 0.0 => (v.ln() - lo.ln()) / (hi.ln() - lo.ln()),
                Scale::Log => return None,
            };
            (0.0..=1.0).contains(&t).then_some(t)
        };
        let [l, t, r, b] = self.area.map(f64::from);
        let u = f(x, self.x_range, self.x_scale)?;
        let v = f(y, self.y_range, self.y_scale)?;
        Some((l + u * (r - l), b - v * (b - t)))
    }
}

/// A drawn chart: RGB bytes, row by row, [`SIZE`] pixels.
pub struct Picture {
    pub width: u32,
    pub height: u32,
    pub rgb: Vec<u8>,
    pub frame: Frame,
}

fn plot_err(e: impl std::fmt::Display) -> HeronError {
    HeronError::Invalid(format!("plot: {e}"))
}

fn drawable(v: f64, s: Scale) -> bool {
    v.is_finite() && (s == Scale::Linear || v > 0.0)
}

/// The axis range of `values` on scale `s`, padded so that lines at the edge show: 5%
/// of the span on a linear axis, a factor of 1.25 on a log axis; a single value gets a
/// range around it.
fn axis_range(values: &[f64], s: Scale, from_zero: bool) -> (f64, f64) {
    let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    match s {
        Scale::Log => {
            let (lo, hi) = if hi / lo < 1.0 + 1e-9 {
                (lo / 2.0, hi * 2.0)
            } else {
                (lo, hi)
            };
            (lo / 1.25, hi * 1.25)
        }
        Scale::Linear => {
            let lo = if from_zero && lo > 0.0 { 0.0 } else { lo };
            let span = hi - lo;
            if span <= 1e-12 * hi.abs().max(lo.abs()).max(1e-300) {
                let d = hi.abs().max(1e-3) * 0.1;
                (lo - d, hi + d)
            } else {
                let pad = 0.05 * span;
                (if lo == 0.0 { 0.0 } else { lo - pad }, hi + pad)
            }
        }
    }
}

/// Draws `chart` into memory.
pub fn draw(chart: &Chart) -> Result<Picture> {
    register_font()?;
    let keep = |(x, y): &(f64, f64)| drawable(*x, chart.x_scale) && drawable(*y, chart.y_scale);
    let xs: Vec<f64> = chart
        .series
        .iter()
        .flat_map(|s| s.points.iter().filter(|p| keep(p)).map(|p| p.0))
        .collect();
    let ys: Vec<f64> = chart
        .series
        .iter()
        .flat_map(|s| s.points.iter().filter(|p| keep(p)).map(|p| p.1))
        .collect();
    if xs.is_empty() {
        return Err(plot_err(format!(
            "{}: no point to draw (every value is missing{})",
            chart.title,
            if chart.x_scale == Scale::Log || chart.y_scale == Scale::Log {
                ", not finite or not positive on a log axis"
            } else {
                " or not finite"
            }
        )));
    }
    let x_range = axis_range(&xs, chart.x_scale, false);
    let y_range = axis_range(&ys, chart.y_scale, chart.y_from_zero);
    let (w, h) = SIZE;
    let mut rgb = vec![255u8; (w * h * 3) as usize];
    let area = {
        let root = BitMapBackend::with_buffer(&mut rgb, SIZE).into_drawing_area();
        root.fill(&WHITE).map_err(plot_err)?;
        let (x0, x1) = x_range;
        let (y0, y1) = y_range;
        let area = match (chart.x_scale, chart.y_scale) {
            (Scale::Linear, Scale::Linear) => draw_on(&root, chart, x0..x1, y0..y1, keep),
            (Scale::Log, Scale::Log) => draw_on(
                &root,
                chart,
                (x0..x1).log_scale(),
                (y0..y1).log_scale(),
                keep,
            ),
            (Scale::Linear, Scale::Log) => {
                draw_on(&root, chart, x0..x1, (y0..y1).log_scale(), keep)
            }
            (Scale::Log, Scale::Linear) => {
                draw_on(&root, chart, (x0..x1).log_scale(), y0..y1, keep)
            }
        }?;
        root.present().map_err(plot_err)?;
        area
    };
    Ok(Picture {
        width: w,
        height: h,
        rgb,
        frame: Frame {
            area,
            x_range,
            y_range,
            x_scale: chart.x_scale,
            y_scale: chart.y_scale,
        },
    })
}

fn rgb(c: [u8; 3]) -> RGBColor {
    RGBColor(c[0], c[1], c[2])
}

/// The chart on `root` with axes `x` and `y` (linear or log, whichever plotters type);
/// returns the plotting area's pixel rectangle.
fn draw_on<X, Y>(
    root: &DrawingArea<BitMapBackend<'_>, plotters::coord::Shift>,
    chart: &Chart,
    x: X,
    y: Y,
    keep: impl Fn(&(f64, f64)) -> bool,
) -> Result<[i32; 4]>
where
    X: AsRangedCoord<Value = f64>,
    Y: AsRangedCoord<Value = f64>,
    X::CoordDescType: ValueFormatter<f64>,
    Y::CoordDescType: ValueFormatter<f64>,
{
    let mut ctx = ChartBuilder::on(root)
        .caption(&chart.title, (FAMILY, 22))
        .margin(16)
        .x_label_area_size(52)
        .y_label_area_size(84)
        .build_cartesian_2d(x, y)
        .map_err(plot_err)?;
    ctx.configure_mesh()
        .x_desc(chart.x_label.as_str())
        .y_desc(chart.y_label.as_str())
        .label_style((FAMILY, 15))
        .axis_desc_style((FAMILY, 17))
        .light_line_style(RGBColor(238, 238, 238))
        .bold_line_style(RGBColor(215, 215, 215))
        .draw()
        .map_err(plot_err)?;
    for s in &chart.series {
        let pts: Vec<(f64, f64)> = s.points.iter().copied().filter(|p| keep(p)).collect();
        let colour = rgb(s.colour);
        let style = ShapeStyle {
            color: colour.to_rgba(),
            filled: true,
            stroke_width: 2,
        };
        let legend_style = style;
        let anno = if s.dashed {
            ctx.draw_series(DashedLineSeries::new(pts.clone(), 9, 6, style))
                .map_err(plot_err)?
        } else {
            ctx.draw_series(LineSeries::new(pts.clone(), style))
                .map_err(plot_err)?
        };
        anno.label(s.label.as_str())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], legend_style));
        if s.markers {
            ctx.draw_series(pts.iter().map(|&p| Circle::new(p, 4, colour.filled())))
                .map_err(plot_err)?;
        }
    }
    ctx.configure_series_labels()
        .label_font((FAMILY, 15))
        .background_style(WHITE.mix(0.9))
        .border_style(RGBColor(160, 160, 160))
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(plot_err)?;
    let (xr, yr) = ctx.plotting_area().get_pixel_range();
    Ok([xr.start, yr.start, xr.end - 1, yr.end - 1])
}

/// Checks before any work that `path` can take a plot: it ends in `.png` and its
/// folder exists; errors name `flag` (e.g. `--plot`).
pub fn check_path(path: &Path, flag: &str) -> Result<()> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    if !ext.eq_ignore_ascii_case("png") {
        return Err(HeronError::Invalid(format!(
            "{flag} {}: expected a path ending in .png",
            path.display()
        )));
    }
    if let Some(d) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        if !d.is_dir() {
            return Err(HeronError::Invalid(format!(
                "{flag} {}: folder {} does not exist",
                path.display(),
                d.display()
            )));
        }
    }
    Ok(())
}

/// Encodes a picture as PNG bytes (the same picture gives the same bytes).
pub fn png_bytes(p: &Picture) -> Result<Vec<u8>> {
    let img = image::RgbImage::from_raw(p.width, p.height, p.rgb.clone())
        .ok_or_else(|| plot_err("buffer size does not match the picture"))?;
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png)
        .map_err(plot_err)?;
    Ok(out.into_inner())
}

/// Draws `chart` and writes it to `path` as PNG, atomically (a temporary file renamed
/// into place); errors name `flag`. Returns where the data went.
pub fn write_png(path: &Path, chart: &Chart, flag: &str) -> Result<Frame> {
    check_path(path, flag)?;
    let picture = draw(chart)?;
    let bytes = png_bytes(&picture)?;
    Staged::write(path, |tmp| {
        std::fs::write(tmp, &bytes).map_err(|e| format!("{flag}: cannot write the PNG: {e}"))
    })?
    .commit()?;
    Ok(picture.frame)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chart(x: Scale, y: Scale, points: Vec<(f64, f64)>) -> Chart {
        Chart {
            title: "t".into(),
            x_label: "x".into(),
            y_label: "y".into(),
            x_scale: x,
            y_scale: y,
            y_from_zero: false,
            series: vec![Series {
                label: "s".into(),
                colour: PALETTE[0],
                points,
                dashed: false,
                markers: true,
            }],
        }
    }

    #[test]
    fn frame_maps_the_ends_of_the_axes_to_the_area_corners() {
        let f = Frame {
            area: [100, 20, 900, 520],
            x_range: (1.0, 100.0),
            y_range: (0.0, 2.0),
            x_scale: Scale::Log,
            y_scale: Scale::Linear,
        };
        assert_eq!(f.pixel(1.0, 0.0), Some((100.0, 520.0)));
        assert_eq!(f.pixel(100.0, 2.0), Some((900.0, 20.0)));
        assert_eq!(f.pixel(10.0, 1.0), Some((500.0, 270.0)));
        assert_eq!(f.pixel(0.0, 1.0), None);
        assert_eq!(f.pixel(1000.0, 1.0), None);
    }

    #[test]
    fn ranges_pad_and_handle_single_values() {
        // From zero: 5% of the span 0–4 above.
        let (lo, hi) = axis_range(&[2.0, 4.0], Scale::Linear, true);
        assert!(lo == 0.0 && (hi - 4.2).abs() < 1e-12, "{lo} {hi}");
        let (lo, hi) = axis_range(&[1.0, 1.0], Scale::Linear, false);
        assert!(lo < 1.0 && hi > 1.0);
        let (lo, hi) = axis_range(&[0.01, 1.0], Scale::Log, false);
        assert!((lo - 0.008).abs() < 1e-12 && (hi - 1.25).abs() < 1e-12);
        let (lo, hi) = axis_range(&[3.0], Scale::Log, false);
        assert!(lo < 3.0 && hi > 3.0);
    }

    #[test]
    fn nothing_drawable_is_an_error_and_bad_paths_are_named() {
        let e = draw(&chart(
            Scale::Log,
            Scale::Log,
            vec![(0.0, 1.0), (1.0, -1.0)],
        ))
        .err()
        .unwrap()
        .to_string();
        assert!(
            e.contains("no point to draw") && e.contains("log axis"),
            "{e}"
        );
        let e = check_path(Path::new("out.jpg"), "--plot")
            .unwrap_err()
            .to_string();
        assert_eq!(e, "--plot out.jpg: expected a path ending in .png");
        let e = check_path(Path::new("no/such/folder/out.png"), "--plot")
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "--plot no/such/folder/out.png: folder no/such/folder does not exist"
        );
        assert!(check_path(Path::new("out.PNG"), "--plot").is_ok());
    }
}
