//! Axes: data ranges and their padding, tick values and labels of linear and logarithmic
//! axes, and the splitting of series into runs of points the axes can show.

use super::canvas::PlotError;
use plotters::coord::combinators::{LogCoord, WithKeyPoints};
use plotters::prelude::*;

/// Whether an axis can show coordinate `v`: finite, and positive on a logarithmic axis.
pub(super) fn shown(v: f64, log: bool) -> bool {
    v.is_finite() && (!log || v > 0.0)
}

/// Smallest and largest finite value (positive only on a log axis), `None` if there is none.
pub(super) fn finite_range<I: Iterator<Item = f64>>(values: I, log: bool) -> Option<(f64, f64)> {
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for v in values {
        if shown(v, log) {
            lo = lo.min(v);
            hi = hi.max(v);
        }
    }
    (lo <= hi).then_some((lo, hi))
}

/// Padded range for an axis: 4% either side (a factor on a log axis), widened if degenerate.
pub(super) fn padded((lo, hi): (f64, f64), log: bool) -> (f64, f64) {
    if log {
        let (l, h) = (lo.log10(), hi.log10());
        let pad = if h - l < 1e-9 { 0.5 } else { 0.04 * (h - l) };
        (10f64.powf(l - pad), 10f64.powf(h + pad))
    } else {
        let span = hi - lo;
        let pad = if span <= 1e-300 * lo.abs().max(1.0) || span == 0.0 {
            if lo == 0.0 {
                1.0
            } else {
                0.1 * lo.abs()
            }
        } else {
            0.04 * span
        };
        (lo - pad, hi + pad)
    }
}

/// Range of an axis: `fixed` if given (checked), else the padded `data` range, else a default.
pub(super) fn axis_range(
    fixed: Option<(f64, f64)>,
    data: Option<(f64, f64)>,
    log: bool,
    what: &'static str,
) -> Result<(f64, f64), PlotError> {
    if let Some((lo, hi)) = fixed {
        let ok = lo.is_finite() && hi.is_finite() && lo < hi && (!log || lo > 0.0);
        if !ok {
            return Err(PlotError::InvalidData {
                what,
                reason: format!("bad fixed range [{lo}, {hi}] (log axis: {log})"),
            });
        }
        return Ok((lo, hi));
    }
    Ok(match data {
        Some(r) => padded(r, log),
        None if log => (1.0, 10.0),
        None => (0.0, 1.0),
    })
}

/// Short tick label: plain for moderate magnitudes, scientific otherwise.
pub(super) fn tick(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 {
        "0".into()
    } else if !(1e-3..1e4).contains(&a) {
        let s = format!("{v:.1e}");
        s.replace(".0e", "e")
    } else {
        let s = format!("{v:.4}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        s.to_string()
    }
}

/// Tick label of a logarithmic axis: powers of ten in short form.
fn log_tick(v: f64) -> String {
    let e = v.log10();
    if (e - e.round()).abs() < 1e-6 {
        let e = e.round() as i32;
        if (-2..=3).contains(&e) {
            tick(10f64.powi(e))
        } else {
            format!("1e{e}")
        }
    } else {
        tick(v)
    }
}

/// Tick label of a line panel's axis on `range`, logarithmic or linear; on a linear axis a
/// tick within rounding of zero is labelled zero (not `-1.4e-17`).
pub(super) fn axis_tick(v: f64, log: bool, (lo, hi): (f64, f64)) -> String {
    if log {
        log_tick(v)
    } else if v.abs() < 1e-9 * (hi - lo) {
        tick(0.0)
    } else {
        tick(v)
    }
}

/// Splits a series into runs of points the axes can show.
pub(super) fn segments(points: &[(f64, f64)], x_log: bool, y_log: bool) -> Vec<Vec<(f64, f64)>> {
    let mut out = Vec::new();
    let mut run = Vec::new();
    for &(x, y) in points {
        if shown(x, x_log) && shown(y, y_log) {
            run.push((x, y));
        } else if !run.is_empty() {
            out.push(std::mem::take(&mut run));
        }
    }
    if !run.is_empty() {
        out.push(run);
    }
    out
}

/// Clips `(x, y)` runs to a rectangle in the axes' own (log or linear) measure, so that
/// curves extending outside a fixed range do not spill over the frame.
pub(super) fn clip_segments(
    runs: Vec<Vec<(f64, f64)>>,
    xr: (f64, f64),
    yr: (f64, f64),
) -> Vec<Vec<(f64, f64)>> {
    let inside = |&(x, y): &(f64, f64)| x >= xr.0 && x <= xr.1 && y >= yr.0 && y <= yr.1;
    let mut out = Vec::new();
    for run in runs {
        let mut cur: Vec<(f64, f64)> = Vec::new();
        for (i, p) in run.iter().enumerate() {
            let keep = inside(p)
                || (i > 0 && inside(&run[i - 1]))
                || (i + 1 < run.len() && inside(&run[i + 1]));
            if keep {
                cur.push(*p);
            } else if !cur.is_empty() {
                out.push(std::mem::take(&mut cur));
            }
        }
        if !cur.is_empty() {
            out.push(cur);
        }
    }
    out
}

/// Bold (labelled) and light tick values of a logarithmic axis on `[lo, hi]`: every
/// integer mantissa within about a decade, 1-2-5 up to three decades, decades beyond (every
/// other decade past eight).
fn log_ticks(lo: f64, hi: f64) -> (Vec<f64>, Vec<f64>) {
    let decades = (hi / lo).log10();
    let bold_mantissas: &[f64] = if decades < 1.2 {
        &[1.0, 1.5, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]
    } else if decades < 3.0 {
        &[1.0, 2.0, 5.0]
    } else {
        &[1.0]
    };
    let every = if decades > 8.0 { 2 } else { 1 };
    let (e0, e1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    let (mut bold, mut light) = (Vec::new(), Vec::new());
    for e in e0..=e1 {
        let base = 10f64.powi(e);
        for k in 1..10 {
            let v = base * k as f64;
            if v >= lo && v <= hi && decades < 8.0 {
                light.push(v);
            }
        }
        if e.rem_euclid(every) == 0 {
            for &m in bold_mantissas {
                let v = base * m;
                if v >= lo * (1.0 - 1e-12) && v <= hi * (1.0 + 1e-12) {
                    bold.push(v);
                }
            }
        }
    }
    (bold, light)
}

/// A logarithmic axis on `[lo, hi]` with the ticks of [`log_ticks`].
pub(super) fn log_axis((lo, hi): (f64, f64)) -> WithKeyPoints<LogCoord<f64>> {
    let (bold, light) = log_ticks(lo, hi);
    (lo..hi)
        .log_scale()
        .with_key_points(bold)
        .with_light_points(light)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segments_break_at_nan_and_nonpositive_on_log_axes() {
        let p = [
            (1.0, 1.0),
            (2.0, f64::NAN),
            (3.0, 3.0),
            (4.0, -1.0),
            (5.0, 5.0),
        ];
        assert_eq!(segments(&p, false, false).len(), 2);
        assert_eq!(segments(&p, false, true).len(), 3);
        assert_eq!(segments(&[(0.0, 1.0), (1.0, 1.0)], true, false)[0].len(), 1);
    }

    #[test]
    fn ranges_are_padded_and_never_degenerate() {
        let (a, b) = axis_range(None, Some((2.0, 2.0)), false, "x").unwrap();
        assert!(a < 2.0 && b > 2.0);
        let (a, b) = axis_range(None, Some((1.0, 100.0)), true, "y").unwrap();
        assert!(a > 0.0 && a < 1.0 && b > 100.0);
        assert!(axis_range(Some((1.0, 0.0)), None, false, "x").is_err());
        assert!(axis_range(Some((0.0, 1.0)), None, true, "x").is_err());
        assert_eq!(axis_range(None, None, true, "y").unwrap(), (1.0, 10.0));
    }

    #[test]
    fn ticks_are_short() {
        assert_eq!(tick(0.5), "0.5");
        assert_eq!(tick(1.0), "1");
        assert_eq!(tick(1e-5), "1e-5");
        assert_eq!(log_tick(1000.0), "1000");
        assert_eq!(log_tick(1e-6), "1e-6");
        assert_eq!(axis_tick(-1.4e-17, false, (-1.0, 1.0)), "0");
        assert_eq!(axis_tick(100.0, true, (1.0, 1e3)), "100");
    }
}
