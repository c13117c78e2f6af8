//! The chart of `heron converge --plot`: relative RMSE against wall time, log–log, one
//! line per lane count through its spp settings, and the 1/√t slope.
//!
//! An unbiased Monte Carlo estimator's variance falls as 1/N, so its RMSE falls as
//! 1/√N and, at a fixed cost per sample, as 1/√t (e.g. Veach 1997, §2.4; pbrt-v4 §2.1.4):
//! a slope of −1/2 on log–log axes. The guide is drawn through the most efficient
//! measurement (smallest RMSE·√t), so a setting on the line is as efficient as the best
//! and one above it is less; a setting whose points bend away from the slope is not
//! (yet) converging as 1/√t (a biased estimator, or the reference's own noise, which
//! `heron converge` states, flattening the curve at long times).
use super::{Chart, Scale, Series, GUIDE, PALETTE};
use crate::converge::ConvergeRow;

/// The chart of `rows` (from [`crate::converge::converge`]) under `title`.
pub fn chart(title: &str, rows: &[ConvergeRow]) -> Chart {
    let mut lanes: Vec<usize> = Vec::new();
    for r in rows {
        if !lanes.contains(&r.lanes) {
            lanes.push(r.lanes);
        }
    }
    let mut series: Vec<Series> = lanes
        .iter()
        .enumerate()
        .map(|(i, &l)| {
            let mut rs: Vec<&ConvergeRow> = rows.iter().filter(|r| r.lanes == l).collect();
            rs.sort_by_key(|r| r.spp);
            Series {
                label: format!("{l} lane{}", if l == 1 { "" } else { "s" }),
                colour: PALETTE[i % PALETTE.len()],
                points: rs.iter().map(|r| (r.wall_s, r.rel_rmse)).collect(),
                dashed: false,
                markers: true,
            }
        })
        .collect();
    if let Some(g) = guide(rows) {
        series.push(g);
    }
    Chart {
        title: title.to_string(),
        x_label: "wall time (s)".into(),
        y_label: "relative RMSE of linear sRGB".into(),
        x_scale: Scale::Log,
        y_scale: Scale::Log,
        y_from_zero: false,
        series,
    }
}

/// The 1/√t line through the row of smallest RMSE·√t, across the rows' time span.
pub fn guide(rows: &[ConvergeRow]) -> Option<Series> {
    let ok: Vec<&ConvergeRow> = rows
        .iter()
        .filter(|r| r.wall_s > 0.0 && r.rel_rmse > 0.0 && r.rmse_sqrt_time.is_finite())
        .collect();
    let c = ok
        .iter()
        .map(|r| r.rel_rmse * r.wall_s.sqrt())
        .fold(f64::INFINITY, f64::min);
    let t0 = ok.iter().map(|r| r.wall_s).fold(f64::INFINITY, f64::min);
    let t1 = ok.iter().map(|r| r.wall_s).fold(0.0, f64::max);
    if ok.is_empty() || !c.is_finite() {
        return None;
    }
    // Enough points that the dashes follow the line evenly in pixels.
    let n = 64;
    let points = (0..=n)
        .map(|i| {
            let t = t0 * (t1 / t0).powf(i as f64 / n as f64);
            (t, c / t.sqrt())
        })
        .collect();
    Some(Series {
        label: "∝ 1/√t through the best RMSE·√t".into(),
        colour: GUIDE,
        points,
        dashed: true,
        markers: false,
    })
}
