//! `summary.csv`: one row per branch (converged and total points) and per lettered point of
//! the paper (found or not), for every figure.

use std::fmt::Write as _;
use std::path::Path;

/// One row of `summary.csv` below its figure.
pub struct Item {
    /// `point X` for the paper's lettered point `X`, else the branch's label (its mode
    /// first: `NSM2 (bar 2)`, `NSM2 sub3`).
    pub item: String,
    /// A branch's converged and total points.
    pub counts: Option<(usize, usize)>,
    /// Whether a lettered point was found (a point that meets the paper's description, as
    /// the figure's code checks it).
    pub found: Option<bool>,
}

impl Item {
    /// A branch's row.
    pub fn branch(label: &str, converged: usize, total: usize) -> Self {
        Self {
            item: label.to_string(),
            counts: Some((converged, total)),
            found: None,
        }
    }

    /// A lettered point's row.
    pub fn point(letter: &str, found: bool) -> Self {
        Self {
            item: format!("point {letter}"),
            counts: None,
            found: Some(found),
        }
    }
}

/// What the counts of the printed table and of `summary.csv` mean.
pub const LEGEND: &str = "\
points: steps computed (converged or not); converged: steps that converged to a motion of the
branch. A step that failed is a failure of the solver there, not the branch's end: backbones
visit their whole period grid. `summary.csv` has one row per branch and per lettered point of
the paper (`found` true or false). docs/validation.md compares every figure with the paper.";

/// Writes `summary.csv` in `out` from `(figure, items)`: header
/// `figure,item,converged,total,found`, empty cells where a row has no such value.
pub fn write(out: &Path, figures: &[(&str, &[Item])]) -> std::io::Result<()> {
    let mut text = String::from("figure,item,converged,total,found\n");
    for (figure, items) in figures {
        for it in items.iter() {
            let (converged, total) = it.counts.map_or((String::new(), String::new()), |(c, t)| {
                (c.to_string(), t.to_string())
            });
            let found = it.found.map_or(String::new(), |f| f.to_string());
            let item = if it.item.contains([',', '"']) {
                format!("\"{}\"", it.item.replace('"', "\"\""))
            } else {
                it.item.clone()
            };
            let _ = writeln!(text, "{figure},{item},{converged},{total},{found}");
        }
    }
    std::fs::write(out.join("summary.csv"), text)
}
