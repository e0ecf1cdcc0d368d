//! Writing results: CSV without dependencies, JSON behind the `serde` feature.

use crate::continuation::Event;
use crate::modal::BackbonePoint;
use std::io::{self, Write};

/// Header of [`write_backbone_csv`].
pub const BACKBONE_CSV_HEADER: &str =
    "step,period,omega,energy,energy_normalized,converged,residual_norm,iterations,step_size,event";

/// Writes a backbone as CSV: [`BACKBONE_CSV_HEADER`], then one row per point (events joined
/// with `;`).
///
/// # Errors
/// Any I/O error of `out`.
pub fn write_backbone_csv(points: &[BackbonePoint], mut out: impl Write) -> io::Result<()> {
    writeln!(out, "{BACKBONE_CSV_HEADER}")?;
    for p in points {
        let events: Vec<&str> = p.events.iter().map(Event::label).collect();
        writeln!(
            out,
            "{},{:.12},{:.12},{:.12e},{:.12e},{},{:.4e},{},{:.6e},{}",
            p.step,
            p.period,
            p.omega,
            p.energy,
            p.energy_normalized,
            p.converged,
            p.residual_norm,
            p.iterations,
            p.step_size,
            events.join(";")
        )?;
    }
    Ok(())
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

    fn point() -> BackbonePoint {
        BackbonePoint {
            step: 3,
            period: 3.5,
            omega: 2.0 * std::f64::consts::PI / 3.5,
            energy: 1e-6,
            energy_normalized: 2.25,
            converged: true,
            residual_norm: 1e-15,
            iterations: 2,
            x: vec![0.0, 1e-3],
            step_size: -0.005,
            events: vec![Event::Fold { lambda: 1.8 }],
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

    #[cfg(feature = "serde")]
    #[test]
    fn json_round_trips_through_serde_json_values() {
        let text = to_json(&vec![point()]).unwrap();
        let value: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(value[0]["step"], 3);
        assert_eq!(value[0]["events"][0]["Fold"]["lambda"], 1.8);
    }
}
