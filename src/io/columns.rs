//! The columns of a backbone point's CSV row, in one table: [`COLUMNS`].
//!
//! Every CSV of backbone points (the library's [`write_backbone_csv`](super::write_backbone_csv)
//! and [`write_branches_csv`](super::write_branches_csv), the `backbone` example's tables) is a
//! choice of [`Group`]s: its header is the names of the table's columns in those groups, in
//! table order ([`header`]), and each row their cells ([`write_row`]). A new column is one
//! entry of [`COLUMNS`]: the tables whose groups include its group gain it, at its place.

use crate::branches::BackbonePoint;
use crate::continuation::Event;
use crate::stability::Verdict;
use std::fmt::{Display, Write};

/// The tables a column belongs to: a CSV writes the columns of the groups it asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Group {
    /// `branch,harmonics`, first in [`write_branches_csv`](super::write_branches_csv): the
    /// branch's label and number of harmonics.
    Branch,
    /// The point's own columns, in every table: `step` to `event`.
    Point,
    /// The columns of the `backbone` example's runs: the exact `E / E_g`, the continued
    /// parameter, the contacts per period, the label, branch index and dominant harmonic.
    Run,
    /// The time-domain check: `periodicity_defect` to `time_domain_check`.
    Verify,
    /// `subharmonic_share`, for a subharmonic order `K > 1`.
    Subharmonic,
    /// The Floquet verdict: `stable,max_multiplier,stability_reason`.
    Stability,
    /// Hill's verdict: `hill_stable,hill_max_multiplier,hill_reason`.
    Hill,
    /// A point of an exact branch: `harmonic_balance_distance,seeded`, how far its energy is
    /// from the harmonic-balance point at its period and whether it was corrected from one
    /// (a seed) rather than continued.
    ExactBranch,
    /// `omega_ratio,exact_energy_normalized,label`, last in
    /// [`write_branches_csv`](super::write_branches_csv).
    Comparison,
}

/// How many digits a table writes its numbers with (the time-domain defects and the step size
/// always have 6 significant digits, the subharmonic share too).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Digits {
    /// Digits after the point of the period, frequency, energies, ratio, parameter and
    /// multipliers.
    pub values: usize,
    /// Digits after the point of the residual norm.
    pub residual: usize,
}

impl Digits {
    /// The library's tables: 12 digits, 4 for the residual.
    pub const FULL: Digits = Digits {
        values: 12,
        residual: 4,
    };
    /// The `backbone` example's table: 10 digits, 3 for the residual.
    pub const SHORT: Digits = Digits {
        values: 10,
        residual: 3,
    };
}

/// A point and what its row says beyond the point: the values a cell needs that a
/// [`BackbonePoint`] does not carry (`None` writes an empty cell).
#[derive(Clone, Copy, Debug)]
pub struct Row<'a> {
    /// The point.
    pub point: &'a BackbonePoint,
    /// The digits of the numbers.
    pub digits: Digits,
    /// Label and number of harmonics of the branch (the [`Group::Branch`] columns).
    pub branch: Option<(&'a str, usize)>,
    /// The exact `E / E_g` at the point's period.
    pub exact: Option<f64>,
    /// The continued parameter's value.
    pub parameter: Option<f64>,
    /// Contact intervals per period, summed over the contacts.
    pub contacts: Option<usize>,
    /// Share of the energy in the harmonics that are not multiples of `K`.
    pub subharmonic_share: Option<f64>,
    /// The frequency `Omega` is divided by in `omega_ratio` (`omega_1`).
    pub reference_omega: Option<f64>,
    /// An exact point's `(E - E_hb) / E_hb` against the harmonic-balance point at its period.
    pub harmonic_balance_distance: Option<f64>,
    /// Whether an exact point was corrected from a harmonic-balance point.
    pub seeded: Option<bool>,
}

impl<'a> Row<'a> {
    /// The row of `point` with nothing beyond it, its numbers written with `digits`.
    pub fn new(point: &'a BackbonePoint, digits: Digits) -> Self {
        Row {
            point,
            digits,
            branch: None,
            exact: None,
            parameter: None,
            contacts: None,
            subharmonic_share: None,
            reference_omega: None,
            harmonic_balance_distance: None,
            seeded: None,
        }
    }
}

/// One column: its header name, its group, and how it writes its cell of a row.
#[derive(Clone, Copy, Debug)]
pub struct Column {
    /// The header name.
    pub name: &'static str,
    /// The tables that have it.
    pub group: Group,
    /// Appends the cell of a row (no comma) to the line.
    pub cell: fn(&Row<'_>, &mut String),
}

const fn column(name: &'static str, group: Group, cell: fn(&Row<'_>, &mut String)) -> Column {
    Column { name, group, cell }
}

/// Every column, in the order of every table. A name appears twice where two tables place
/// the same cell differently (`exact_energy_normalized`, `label`) or name different cells
/// alike (`branch`); no table asks for both groups.
pub static COLUMNS: &[Column] = {
    use Group::*;
    &[
        column("branch", Branch, |r, s| {
            if let Some((label, _)) = r.branch {
                s.push_str(&label.replace(',', ";"));
            }
        }),
        column("harmonics", Branch, |r, s| {
            shown(s, r.branch.map(|(_, harmonics)| harmonics));
        }),
        column("step", Point, |r, s| shown(s, Some(r.point.step))),
        column("period", Point, |r, s| {
            fixed(s, r.digits.values, r.point.period)
        }),
        column("omega", Point, |r, s| {
            fixed(s, r.digits.values, r.point.omega)
        }),
        column("energy", Point, |r, s| {
            exp(s, r.digits.values, r.point.energy)
        }),
        column("energy_normalized", Point, |r, s| {
            exp(s, r.digits.values, r.point.energy_normalized);
        }),
        column("exact_energy_normalized", Run, exact_energy_normalized),
        column("converged", Point, |r, s| {
            shown(s, Some(r.point.converged()))
        }),
        column("status", Point, |r, s| s.push_str(r.point.status.label())),
        column("residual_norm", Point, |r, s| {
            exp(s, r.digits.residual, r.point.residual_norm);
        }),
        column("iterations", Point, |r, s| {
            shown(s, Some(r.point.iterations))
        }),
        column("step_size", Point, |r, s| exp(s, 6, r.point.step_size)),
        column("event", Point, |r, s| {
            let events: Vec<&str> = r.point.events.iter().map(Event::label).collect();
            s.push_str(&events.join(";"));
        }),
        column("parameter", Run, |r, s| {
            if let Some(v) = r.parameter {
                exp(s, r.digits.values, v);
            }
        }),
        column("periodicity_defect", Verify, |r, s| {
            if let Some(t) = r.point.time_domain {
                exp(s, 6, t.defect);
            }
        }),
        column("displacement_defect", Verify, |r, s| {
            if let Some(t) = r.point.time_domain {
                exp(s, 6, t.displacement_defect);
            }
        }),
        column("max_penetration", Verify, |r, s| {
            if let Some(t) = r.point.time_domain {
                exp(s, 6, t.max_penetration);
            }
        }),
        column("time_domain_check", Verify, |r, s| {
            shown(s, r.point.check.as_ref())
        }),
        column("contacts_per_period", Run, |r, s| shown(s, r.contacts)),
        column("subharmonic_share", Subharmonic, |r, s| {
            if let Some(share) = r.subharmonic_share {
                exp(s, 6, share);
            }
        }),
        column("label", Run, label),
        column("branch", Run, |r, s| shown(s, Some(r.point.branch))),
        column("dominant_harmonic", Run, |r, s| {
            shown(s, r.point.character.as_ref().map(|c| c.dominant_harmonic));
        }),
        column("stable", Stability, |r, s| verdict(s, floquet(r))),
        column("max_multiplier", Stability, |r, s| {
            multiplier(r, s, floquet(r))
        }),
        column("stability_reason", Stability, |r, s| reason(s, floquet(r))),
        column("hill_stable", Hill, |r, s| verdict(s, hill(r))),
        column("hill_max_multiplier", Hill, |r, s| {
            multiplier(r, s, hill(r))
        }),
        column("hill_reason", Hill, |r, s| reason(s, hill(r))),
        column("harmonic_balance_distance", ExactBranch, |r, s| {
            if let Some(d) = r.harmonic_balance_distance {
                exp(s, 6, d);
            }
        }),
        column("seeded", ExactBranch, |r, s| shown(s, r.seeded)),
        column("omega_ratio", Comparison, |r, s| {
            if let Some(omega_1) = r.reference_omega {
                fixed(s, r.digits.values, r.point.omega / omega_1);
            }
        }),
        column(
            "exact_energy_normalized",
            Comparison,
            exact_energy_normalized,
        ),
        column("label", Comparison, label),
    ]
};

/// The columns of `groups`, in table order.
pub fn columns(groups: &[Group]) -> impl Iterator<Item = &'static Column> + '_ {
    COLUMNS.iter().filter(|c| groups.contains(&c.group))
}

/// The header of the table of `groups`: its column names joined with commas.
pub fn header(groups: &[Group]) -> String {
    columns(groups)
        .map(|c| c.name)
        .collect::<Vec<_>>()
        .join(",")
}

/// Appends the cells of `row` in the columns of `groups`, joined with commas, to `line`.
pub fn write_row(groups: &[Group], row: &Row<'_>, line: &mut String) {
    for (i, c) in columns(groups).enumerate() {
        if i > 0 {
            line.push(',');
        }
        (c.cell)(row, line);
    }
}

/// `text` as one CSV cell: commas become semicolons and line breaks spaces.
pub fn csv_text(text: &str) -> String {
    text.replace(',', ";").replace(['\n', '\r'], " ")
}

/// `value` as written by `Display`, nothing for `None`.
fn shown(s: &mut String, value: Option<impl Display>) {
    if let Some(v) = value {
        let _ = write!(s, "{v}");
    }
}

/// `value` with `digits` digits after the point.
fn fixed(s: &mut String, digits: usize, value: f64) {
    let _ = write!(s, "{value:.digits$}");
}

/// `value` in scientific notation with `digits` digits after the point.
fn exp(s: &mut String, digits: usize, value: f64) {
    let _ = write!(s, "{value:.digits$e}");
}

fn exact_energy_normalized(r: &Row<'_>, s: &mut String) {
    if let Some(e) = r.exact {
        exp(s, r.digits.values, e);
    }
}

fn label(r: &Row<'_>, s: &mut String) {
    shown(s, r.point.label.as_ref());
}

/// A stability outcome: the verdict, the largest multiplier and why there is no verdict; or
/// the error that prevented it.
type Assessed = Result<(Verdict, f64, Option<String>), String>;

/// The point's Floquet outcome, `None` where none was asked; a stable verdict's reason is the
/// grid's damping it holds up to, where there is one.
fn floquet(r: &Row<'_>) -> Option<Assessed> {
    let outcome = r.point.stability.as_ref()?;
    Some(match outcome {
        Ok(f) => {
            let damped = f
                .damping
                .map(|d| format!("stable up to the grid's damping of {d:.1e} per period"));
            let why = f.unresolved.map(|u| u.to_string()).or(damped);
            Ok((f.verdict, f.max_multiplier, why))
        }
        Err(e) => Err(e.to_string()),
    })
}

/// The point's Hill outcome, `None` where none was asked.
fn hill(r: &Row<'_>) -> Option<Assessed> {
    let outcome = r.point.hill.as_ref()?;
    Some(match outcome {
        Ok(h) => Ok((
            h.verdict,
            h.max_multiplier,
            h.unresolved.map(|u| u.to_string()),
        )),
        Err(e) => Err(e.to_string()),
    })
}

/// `true`, `false` or `unresolved`; empty without a verdict.
fn verdict(s: &mut String, outcome: Option<Assessed>) {
    match outcome {
        Some(Ok((Verdict::Stable, ..))) => s.push_str("true"),
        Some(Ok((Verdict::Unstable(_), ..))) => s.push_str("false"),
        Some(Ok((Verdict::Unresolved, ..))) => s.push_str("unresolved"),
        _ => {}
    }
}

/// The largest multiplier where there is a verdict (it means nothing where unresolved).
fn multiplier(r: &Row<'_>, s: &mut String, outcome: Option<Assessed>) {
    if let Some(Ok((verdict, m, _))) = outcome {
        if verdict != Verdict::Unresolved {
            exp(s, r.digits.values, m);
        }
    }
}

/// Why there is no verdict, or the error that prevented one.
fn reason(s: &mut String, outcome: Option<Assessed>) {
    match outcome {
        Some(Ok((_, _, Some(why)))) | Some(Err(why)) => s.push_str(&csv_text(&why)),
        _ => {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use Group::*;

    #[test]
    fn no_table_names_a_column_twice() {
        let tables: [&[Group]; 4] = [
            &[Point],
            &[Branch, Point, Comparison],
            &[
                Point,
                Run,
                Verify,
                Subharmonic,
                Stability,
                Hill,
                ExactBranch,
            ],
            &[Verify, Stability, Hill],
        ];
        for groups in tables {
            let names: Vec<&str> = columns(groups).map(|c| c.name).collect();
            let mut unique = names.clone();
            unique.sort_unstable();
            unique.dedup();
            assert_eq!(unique.len(), names.len(), "{names:?}");
            assert_eq!(header(groups).split(',').collect::<Vec<_>>(), names);
        }
    }

    /// An exact point's columns are empty on other rows, and say what its row is given.
    #[test]
    fn exact_branch_cells_are_written_where_given() {
        let point = BackbonePoint::for_test(0, 3.5, None, true);
        let mut line = String::new();
        write_row(&[ExactBranch], &Row::new(&point, Digits::SHORT), &mut line);
        assert_eq!(line, ",");
        let row = Row {
            harmonic_balance_distance: Some(-0.25),
            seeded: Some(true),
            ..Row::new(&point, Digits::SHORT)
        };
        line.clear();
        write_row(&[ExactBranch], &row, &mut line);
        assert_eq!(line, "-2.500000e-1,true");
    }

    #[test]
    fn text_cells_hold_no_separator() {
        assert_eq!(csv_text("a, b\nc\r"), "a; b c ");
    }
}
