//! Writing results: CSV without dependencies, JSON behind the `serde` feature; with it too,
//! assemblies read from and written to TOML or JSON files ([`assembly`]).

#[cfg(feature = "serde")]
pub mod assembly;
pub mod columns;

use crate::branches::BackbonePoint;
use columns::{Digits, Group, Row};
use std::io::{self, Write};

/// Header of [`write_backbone_csv`]: the [`Group::Point`] columns of [`columns::COLUMNS`].
pub const BACKBONE_CSV_HEADER: &str =
    "step,period,omega,energy,energy_normalized,converged,status,residual_norm,iterations,step_size,event";

/// The groups of [`write_backbone_csv`].
const BACKBONE_GROUPS: &[Group] = &[Group::Point];

/// Writes a backbone as CSV: [`BACKBONE_CSV_HEADER`], then one row per point (events joined
/// with `;`).
///
/// The `backbone` example's columns `contacts_per_period` and `subharmonic_share` are not
/// here: a [`BackbonePoint`] does not carry the system and basis they are computed with
/// ([`crate::modal::contact_intervals`], [`crate::modal::subharmonic_share`]); compute them
/// per point and write them with [`columns::write_row`] (in a [`Row`]) or
/// [`write_columns_csv`].
///
/// # Errors
/// Any I/O error of `out`.
pub fn write_backbone_csv(points: &[BackbonePoint], out: impl Write) -> io::Result<()> {
    write_table(
        BACKBONE_GROUPS,
        points.iter().map(|p| Row::new(p, Digits::FULL)),
        out,
    )
}

/// Writes the header of `groups`, then the line of each row.
fn write_table<'a>(
    groups: &[Group],
    rows: impl IntoIterator<Item = Row<'a>>,
    mut out: impl Write,
) -> io::Result<()> {
    writeln!(out, "{}", columns::header(groups))?;
    let mut line = String::new();
    for row in rows {
        line.clear();
        columns::write_row(groups, &row, &mut line);
        writeln!(out, "{line}")?;
    }
    Ok(())
}

/// Header of [`write_branches_csv`]: `branch,harmonics`, the columns of
/// [`BACKBONE_CSV_HEADER`], then `omega_ratio,exact_energy_normalized,label` (the
/// [`Group::Branch`], [`Group::Point`] and [`Group::Comparison`] columns of
/// [`columns::COLUMNS`]).
pub const BRANCHES_CSV_HEADER: &str = "branch,harmonics,step,period,omega,energy,\
     energy_normalized,converged,status,residual_norm,iterations,step_size,event,omega_ratio,\
     exact_energy_normalized,label";

/// The groups of [`write_branches_csv`].
const BRANCHES_GROUPS: &[Group] = &[Group::Branch, Group::Point, Group::Comparison];
/// One branch of a table written by [`write_branches_csv`].
#[derive(Clone, Copy)]
pub struct LabelledBranch<'a> {
    /// Name written in the `branch` column (a comma in it is written as `;`).
    pub label: &'a str,
    /// Number of harmonics `m` the branch was computed with (the `harmonics` column).
    pub harmonics: usize,
    /// The points, one row each.
    pub points: &'a [BackbonePoint],
    /// Exact `E / E_g` as a function of the period, for the `exact_energy_normalized` column
    /// (left empty when `None`).
    pub exact: Option<&'a dyn Fn(f64) -> f64>,
}

impl std::fmt::Debug for LabelledBranch<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LabelledBranch")
            .field("label", &self.label)
            .field("harmonics", &self.harmonics)
            .field("points", &self.points.len())
            .field("exact", &self.exact.is_some())
            .finish()
    }
}

/// Writes several labelled branches as one CSV table: [`BRANCHES_CSV_HEADER`], then one row
/// per point, branch after branch: the branch label and its number of harmonics, the cells of
/// [`write_backbone_csv`], `Omega / omega_1`, the exact `E / E_g` at the point's period (an
/// empty cell for a branch without one), and the point's [`Label`](crate::modal::Label)
/// (`skeleton`, `subharmonic-2`, `internal-resonance-h3-mode2`, ...; empty where the point has
/// none).
///
/// # Errors
/// Any I/O error of `out`.
pub fn write_branches_csv(
    branches: &[LabelledBranch<'_>],
    omega_1: f64,
    out: impl Write,
) -> io::Result<()> {
    let rows = branches.iter().flat_map(|b| {
        b.points.iter().map(move |p| Row {
            branch: Some((b.label, b.harmonics)),
            exact: b.exact.map(|exact| exact(p.period)),
            reference_omega: Some(omega_1),
            ..Row::new(p, Digits::FULL)
        })
    });
    write_table(BRANCHES_GROUPS, rows, out)
}

/// Writes columns of equal length as CSV with the given header names.
///
/// # Errors
/// [`io::ErrorKind::InvalidInput`] if the columns differ in length or the names do not match
/// them; any I/O error of `out`.
pub fn write_columns_csv(
    names: &[&str],
    columns: &[&[f64]],
    mut out: impl Write,
) -> io::Result<()> {
    let rows = columns.first().map_or(0, |c| c.len());
    if names.len() != columns.len() || columns.iter().any(|c| c.len() != rows) {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            "column names and lengths do not match",
        ));
    }
    writeln!(out, "{}", names.join(","))?;
    for r in 0..rows {
        let row: Vec<String> = columns.iter().map(|c| format!("{:.12e}", c[r])).collect();
        writeln!(out, "{}", row.join(","))?;
    }
    Ok(())
}

/// Any serialisable result (points, branches, diagnostics, histories) as pretty JSON.
///
/// # Errors
/// A serialisation error (non-string map keys; not produced by this crate's types).
#[cfg(feature = "serde")]
pub fn to_json<T: serde::Serialize + ?Sized>(value: &T) -> Result<String, serde_json::Error> {
    serde_json::to_string_pretty(value)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::continuation::Event;

    #[test]
    fn headers_are_those_of_the_column_table() {
        assert_eq!(columns::header(BACKBONE_GROUPS), BACKBONE_CSV_HEADER);
        assert_eq!(columns::header(BRANCHES_GROUPS), BRANCHES_CSV_HEADER);
    }

    fn point() -> BackbonePoint {
        BackbonePoint {
            step: 3,
            period: 3.5,
            omega: 2.0 * std::f64::consts::PI / 3.5,
            energy: 1e-6,
            energy_normalized: 2.25,
            status: crate::branches::PointStatus::Converged,
            residual_norm: 1e-15,
            iterations: 2,
            x: vec![0.0, 1e-3],
            step_size: -0.005,
            events: vec![Event::Fold { parameter: 1.8 }],
            branch: 0,
            time_domain: None,
            check: None,
            character: None,
            label: None,
            stability: None,
            hill: None,
        }
    }

    #[test]
    fn csv_has_header_and_one_row_per_point() {
        let mut out = Vec::new();
        write_backbone_csv(&[point(), point()], &mut out).unwrap();
        let text = String::from_utf8(out).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 3);
        assert_eq!(lines[0], BACKBONE_CSV_HEADER);
        assert_eq!(lines[1].split(',').count(), lines[0].split(',').count());
        assert!(lines[1].ends_with(",fold"));
        let mut bad = Vec::new();
        assert!(write_columns_csv(&["a", "b"], &[&[1.0], &[1.0, 2.0]], &mut bad).is_err());
    }

    /// "NSM1, m = 20" over all of `points` with the exact values `exact`, and "NSM2" over
    /// the first point without them.
    fn two_branches<'a>(
        points: &'a [BackbonePoint],
        exact: &'a dyn Fn(f64) -> f64,
    ) -> [LabelledBranch<'a>; 2] {
        [
            LabelledBranch {
                label: "NSM1, m = 20",
                harmonics: 20,
                points,
                exact: Some(exact),
            },
            LabelledBranch {
                label: "NSM2",
                harmonics: 40,
                points: &points[..1],
                exact: None,
            },
        ]
    }

    #[test]
    fn branches_csv_labels_rows_and_leaves_missing_exact_values_empty() {
        let mut resonant = point();
        resonant.label = Some(crate::modal::Label::InternalResonance {
            harmonic: 3,
            mode: 2,
            omega: 4.7,
        });
        let points = [point(), resonant];
        let exact = |t: f64| 2.0 * t;
        let branches = two_branches(&points, &exact);
        let mut out = Vec::new();
        write_branches_csv(&branches, 0.5, &mut out).unwrap();
        let text = String::from_utf8(out).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 4);
        assert_eq!(lines[0], BRANCHES_CSV_HEADER);
        assert!(BRANCHES_CSV_HEADER.contains(BACKBONE_CSV_HEADER));
        let header: Vec<&str> = lines[0].split(',').collect();
        let mut single = Vec::new();
        write_backbone_csv(&points[..1], &mut single).unwrap();
        let single = String::from_utf8(single).unwrap();
        let backbone_row = single.lines().nth(1).unwrap();
        // The backbone's columns sit after `branch,harmonics`; the ratio and exact value after.
        let k = 2 + BACKBONE_CSV_HEADER.split(',').count();
        for line in &lines[1..] {
            let cells: Vec<&str> = line.split(',').collect();
            assert_eq!(cells.len(), header.len());
            assert_eq!(cells[2..k].join(","), backbone_row);
        }
        let cells: Vec<&str> = lines[1].split(',').collect();
        assert_eq!(cells[..2], ["NSM1; m = 20", "20"]);
        let ratio: f64 = cells[k].parse().unwrap();
        assert!((ratio - point().omega / 0.5).abs() < 1e-11);
        assert_eq!(cells[k + 1].parse::<f64>().unwrap(), 7.0);
        assert_eq!(cells[k + 2], "");
        let cells: Vec<&str> = lines[2].split(',').collect();
        assert_eq!(cells[k + 2], "internal-resonance-h3-mode2");
        let cells: Vec<&str> = lines[3].split(',').collect();
        assert_eq!(cells[..2], ["NSM2", "40"]);
        assert_eq!(cells[k + 1], "");
        assert!(format!("{:?}", branches[0]).contains("points: 2"));
    }

    #[test]
    fn csv_bytes_are_those_of_the_column_table() {
        let mut resonant = point();
        resonant.label = Some(crate::modal::Label::Skeleton);
        let points = [point(), resonant];
        let exact = |t: f64| 2.0 * t;
        let branches = two_branches(&points, &exact);
        let mut out = Vec::new();
        write_branches_csv(&branches, 0.5, &mut out).unwrap();
        write_backbone_csv(&points, &mut out).unwrap();
        let row = "3,3.500000000000,1.795195802051,1.000000000000e-6,2.250000000000e0,true,\
                   converged,1.0000e-15,2,-5.000000e-3,fold";
        let expected = format!(
            "{BRANCHES_CSV_HEADER}\n\
             NSM1; m = 20,20,{row},3.590391604103,7.000000000000e0,\n\
             NSM1; m = 20,20,{row},3.590391604103,7.000000000000e0,skeleton\n\
             NSM2,40,{row},3.590391604103,,\n\
             {BACKBONE_CSV_HEADER}\n{row}\n{row}\n"
        );
        assert_eq!(String::from_utf8(out).unwrap(), expected);
    }

    #[cfg(feature = "serde")]
    #[test]
    fn json_round_trips_through_serde_json_values() {
        let text = to_json(&vec![point()]).unwrap();
        let value: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(value[0]["step"], 3);
        assert_eq!(value[0]["events"][0]["Fold"]["parameter"], 1.8);
    }
}
