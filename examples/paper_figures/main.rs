//! Recomputes the figures of Lu & Legrand (Nonlinear Dynamics, 2021) and writes one SVG and one
//! CSV per figure.
//!
//! ```text
//! cargo run --release --features plot --example paper_figures -- [--out DIR] [--quick]
//!     [--only 5,7,14]
//! ```
//!
//! `--out` (default `figures/`) receives `figNN_<name>.svg` and `figNN_<name>.csv`, and
//! `summary.csv` (`figure,item,converged,total,found`: one row per branch and per lettered
//! point of the paper); `--quick`
//! runs coarser grids and fewer harmonics (for CI); `--only` restricts the run to the listed
//! figures. Progress is printed per figure, then a summary table (figure, points computed,
//! converged, seconds, files). The gallery section of `docs/validation.md` describes every figure
//! and how it compares with the paper. Backbone figures write their branches with
//! `io::write_branches_csv` (one row per point, with `Omega / omega_1` and, for the clamped
//! bar, the exact `E / E_g`), the other figures named columns with `io::write_columns_csv`.
//!
//! Conventions: `g0 = 1e-3`, `a_c = 4`, `n_h = 30`; energies are `E / E_g` with `E_g` the first
//! grazing energy of the open-contact system (for two bars: of bar 1, whose first mode is the
//! lowest), frequencies `Omega / omega_1` with `omega_1` its first open-contact natural
//! frequency. Backbones use sequential continuation in the period, two-bar runs start at
//! `T = 3.95` and go down.

mod clamped;
mod common;
mod designs;
mod lettered;
mod residual;
mod robin;
mod runs;
mod seeded;
mod summary;
mod two_bar;

use common::{Ctx, Res, Stats};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

const USAGE: &str = "usage: paper_figures [--out DIR] [--quick] [--only 2,4,5,...]";

/// Command-line arguments.
struct Args {
    out: PathBuf,
    quick: bool,
    only: Option<Vec<u32>>,
}

fn parse() -> Result<Args, lexopt::Error> {
    use lexopt::prelude::*;
    let mut a = Args {
        out: PathBuf::from("figures"),
        quick: false,
        only: None,
    };
    let mut parser = lexopt::Parser::from_env();
    while let Some(arg) = parser.next()? {
        match arg {
            Long("out") => a.out = PathBuf::from(parser.value()?.string()?),
            Long("quick") => a.quick = true,
            Long("only") => {
                let list = parser.value()?.string()?;
                let mut v = Vec::new();
                for item in list.split(',') {
                    v.push(
                        item.trim()
                            .parse::<u32>()
                            .map_err(|e| format!("--only `{item}`: {e}"))?,
                    );
                }
                a.only = Some(v);
            }
            Short('h') | Long("help") => return Err("help requested".into()),
            _ => return Err(arg.unexpected()),
        }
    }
    Ok(a)
}

/// One line of the summary table.
struct Row {
    figure: String,
    result: Result<Stats, String>,
    seconds: f64,
}

/// Runs one figure, prints its progress line and records its row.
fn timed(rows: &mut Vec<Row>, figure: &str, f: impl FnOnce() -> Res<Stats>) {
    println!("Fig. {figure} ...");
    let start = Instant::now();
    let result = f().map_err(|e| e.to_string());
    let seconds = start.elapsed().as_secs_f64();
    match &result {
        Ok(s) => println!(
            "Fig. {figure}: {} points, {} converged, {seconds:.1} s{}",
            s.points,
            s.converged,
            if s.note.is_empty() {
                String::new()
            } else {
                format!(" ({})", s.note)
            }
        ),
        Err(e) => println!("Fig. {figure}: FAILED: {e}"),
    }
    rows.push(Row {
        figure: figure.to_string(),
        result,
        seconds,
    });
}

/// A figure computed on its own.
type Figure = fn(&Ctx) -> Res<Stats>;

/// Figs. 14-16, which share the runs of configuration 1 and its points.
fn config1(ctx: &Ctx, rows: &mut Vec<Row>) {
    let mut config1 = None;
    let mut points = Vec::new();
    timed(rows, "14", || {
        let tb = two_bar::TwoBar::config1(ctx)?;
        let (s, p) = two_bar::fig14(ctx, &tb)?;
        config1 = Some(tb);
        points = p;
        Ok(s)
    });
    match &config1 {
        Some(tb) if !points.is_empty() => {
            timed(rows, "15", || two_bar::fig15(ctx, tb, &points));
            timed(rows, "16", || two_bar::fig16(ctx, tb, &points[0]));
        }
        _ => {
            for f in ["15", "16"] {
                println!("Fig. {f}: skipped: no converged point of Fig. 14");
                rows.push(Row {
                    figure: f.into(),
                    result: Err("skipped: no converged point of Fig. 14".into()),
                    seconds: 0.0,
                });
            }
        }
    }
}

fn main() -> ExitCode {
    let args = match parse() {
        Ok(a) => a,
        Err(e) => {
            eprintln!("paper_figures: {e}\n{USAGE}");
            return ExitCode::from(2);
        }
    };
    if let Err(e) = std::fs::create_dir_all(&args.out) {
        eprintln!("paper_figures: cannot create {}: {e}", args.out.display());
        return ExitCode::FAILURE;
    }
    let ctx = Ctx {
        out: args.out.clone(),
        quick: args.quick,
    };
    let wanted = |n: u32| args.only.as_ref().is_none_or(|v| v.contains(&n));
    let total = Instant::now();
    let mut rows = Vec::new();
    let figure = |rows: &mut Vec<Row>, n: u32, f: Figure| {
        if wanted(n) {
            timed(rows, &n.to_string(), || f(&ctx));
        }
    };
    for (n, f) in [
        (2, residual::fig02 as Figure),
        (4, residual::fig04),
        (5, residual::fig05),
        (6, residual::fig06),
        (7, clamped::fig07),
        (8, clamped::fig08),
        (9, clamped::fig09),
    ] {
        figure(&mut rows, n, f);
    }
    if wanted(10) || wanted(11) {
        let mut s11 = None;
        timed(&mut rows, "10", || {
            let (a, b) = robin::fig10_11(&ctx)?;
            s11 = Some(b);
            Ok(a)
        });
        if let Some(s) = s11 {
            rows.push(Row {
                figure: "11".into(),
                result: Ok(s),
                seconds: 0.0,
            });
        }
    }
    figure(&mut rows, 12, robin::fig12);
    figure(&mut rows, 13, robin::fig13);
    if wanted(14) || wanted(15) || wanted(16) {
        config1(&ctx, &mut rows);
    }
    figure(&mut rows, 17, designs::fig17);
    figure(&mut rows, 18, designs::fig18);
    println!();
    println!(
        "{:<7} {:>7} {:>10} {:>8}  files",
        "figure", "points", "converged", "seconds"
    );
    let mut failed = 0;
    for r in &rows {
        match &r.result {
            Ok(s) => println!(
                "{:<7} {:>7} {:>10} {:>8.1}  {}",
                r.figure,
                s.points,
                s.converged,
                r.seconds,
                s.files.join(" ")
            ),
            Err(e) => {
                failed += 1;
                println!(
                    "{:<7} {:>7} {:>10} {:>8.1}  {e}",
                    r.figure, "-", "-", r.seconds
                )
            }
        }
    }
    println!(
        "total {:.1} s; output in {}",
        total.elapsed().as_secs_f64(),
        Path::new(&args.out).display()
    );
    println!("{}", summary::LEGEND);
    let figures: Vec<(&str, &[summary::Item])> = rows
        .iter()
        .filter_map(|r| {
            r.result
                .as_ref()
                .ok()
                .map(|s| (r.figure.as_str(), &s.items[..]))
        })
        .collect();
    if let Err(e) = summary::write(&args.out, &figures) {
        eprintln!("paper_figures: cannot write summary.csv: {e}");
        failed += 1;
    }
    if failed > 0 {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    }
}
