//! Branches drawn by stability, as the field draws them: stable parts solid, unstable parts
//! dashed, and points without a verdict apart.

use super::types::{LineKind, Marker, Rgb, Series};

/// The three ways a point is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Class {
    Stable,
    Unstable,
    Unresolved,
}

impl Class {
    fn of(stable: Option<bool>) -> Self {
        match stable {
            Some(true) => Self::Stable,
            Some(false) => Self::Unstable,
            None => Self::Unresolved,
        }
    }

    fn name(self) -> &'static str {
        match self {
            Self::Stable => "stable",
            Self::Unstable => "unstable",
            Self::Unresolved => "no verdict",
        }
    }
}

/// The series of one branch `points` (`(x, y, stable)` in branch order; `stable` as
/// [`Verdict::stable`](crate::stability::Verdict::stable) gives it, `None` for a point
/// without a verdict) split into runs of consecutive points of the same kind: stable runs a
/// solid line with filled circles, unstable runs a dashed line with crosses, both in
/// `color`; points without a verdict hollow circles in `color` paled halfway to white, not
/// joined. A run of one point is its marker. The first series of each
/// kind carries the legend entry `"<label> (stable)"`, `"(unstable)"` or `"(no verdict)"`.
pub fn stability_series(
    label: &str,
    color: Rgb,
    points: &[(f64, f64, Option<bool>)],
) -> Vec<Series> {
    let mut series: Vec<Series> = Vec::new();
    let mut named = Vec::new();
    let mut start = 0;
    while start < points.len() {
        let class = Class::of(points[start].2);
        let end = points[start..]
            .iter()
            .position(|p| Class::of(p.2) != class)
            .map_or(points.len(), |k| start + k);
        let run: Vec<(f64, f64)> = points[start..end].iter().map(|p| (p.0, p.1)).collect();
        let legend = if named.contains(&class) {
            String::new()
        } else {
            named.push(class);
            format!("{label} ({})", class.name())
        };
        let (line, marker, color) = match class {
            Class::Stable => (LineKind::Solid, Marker::Circle, color),
            Class::Unstable => (LineKind::Dashed, Marker::Cross, color),
            Class::Unresolved => (LineKind::None, Marker::Ring, color.mix(Rgb::WHITE, 0.5)),
        };
        series.push(Series {
            line,
            ..Series::markers(legend, run)
                .with_marker(marker)
                .with_color(color)
        });
        start = end;
    }
    series
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Runs split where the verdict changes; each kind is named once in the legend.
    #[test]
    fn runs_follow_the_verdicts() {
        let points = [
            (0.0, 1.0, Some(true)),
            (1.0, 2.0, Some(true)),
            (2.0, 3.0, Some(false)),
            (3.0, 4.0, None),
            (4.0, 5.0, None),
            (5.0, 6.0, Some(true)),
        ];
        let series = stability_series("NSM1", Rgb(0, 100, 0), &points);
        let kinds: Vec<(LineKind, usize, &str)> = series
            .iter()
            .map(|s| (s.line, s.points.len(), s.label.as_str()))
            .collect();
        assert_eq!(
            kinds,
            [
                (LineKind::Solid, 2, "NSM1 (stable)"),
                (LineKind::Dashed, 1, "NSM1 (unstable)"),
                (LineKind::None, 2, "NSM1 (no verdict)"),
                (LineKind::Solid, 1, ""),
            ]
        );
        assert_eq!(series[2].color, Some(Rgb(0, 100, 0).mix(Rgb::WHITE, 0.5)));
        assert!(stability_series("x", Rgb::BLACK, &[]).is_empty());
    }
}
