//! Figures beyond the paper's, one SVG and one CSV each.
//!
//! ```text
//! cargo run --release --features plot --example gallery -- [--out DIR] [--quick]
//! ```
//!
//! `--out` (default `gallery/`) receives:
//! - `stability_clamped.svg` and `.csv`: the clamped bar's first nonsmooth mode at `m = 20`
//!   (the default request, [`Method::Auto`] on the system's grid) with the Floquet verdict of
//!   every converged point ([`nonsmooth_modes::stability`]): stable runs solid, unstable runs
//!   dashed, points without a verdict hollow; the exact family, stable at every period
//!   checked, as a black line; and the largest multiplier modulus of every point with a
//!   verdict. CSV
//!   columns `period,omega_normalized,energy_normalized,verdict,max_multiplier,
//!   energy_correction` (`verdict`: 1 stable, -1 unstable, 0 unresolved).
//!
//! `--quick` uses 100 cells per travel time for the multipliers instead of 200 (for CI).

use nonsmooth_modes::branches::{compute, BackbonePoint, Request};
use nonsmooth_modes::io::write_columns_csv;
use nonsmooth_modes::plot::{
    backbone_panel, render_svg, stability_series, Figure, LinePanel, Rgb, Series, FREQUENCY_LABEL,
    PALETTE,
};
use nonsmooth_modes::reference::{clamped_bar_with_obstacle, ClampedFamily};
use nonsmooth_modes::stability::StabilityOptions;
use std::error::Error;
use std::path::PathBuf;
use std::process::ExitCode;

type Res<T> = Result<T, Box<dyn Error>>;

const USAGE: &str = "usage: gallery [--out DIR] [--quick]";

/// Whether a point is stable, when its multipliers were computed and give a verdict.
fn stable(p: &BackbonePoint) -> Option<bool> {
    p.stability.as_ref()?.as_ref().ok()?.verdict.stable()
}

/// The clamped bar's first nonsmooth mode with the verdict of every point.
fn stability_clamped(out: &std::path::Path, cells: f64) -> Res<()> {
    let gap = 1e-3;
    let system = clamped_bar_with_obstacle(gap)?;
    let options = StabilityOptions {
        cells_per_travel: cells,
        ..StabilityOptions::default()
    };
    let result = compute(
        &system,
        &Request::new(1).harmonics(20).with_stability(options),
    )?;
    // omega_1 = pi c / (2 l) for the clamped-free unit bar.
    let omega_1 = std::f64::consts::FRAC_PI_2;
    let points: Vec<&BackbonePoint> = result.converged().collect();
    let marked: Vec<(f64, f64, Option<bool>)> = points
        .iter()
        .map(|p| (p.omega / omega_1, p.energy_normalized, stable(p)))
        .collect();
    let exact = ClampedFamily::new(gap, 1)?.backbone(3.99, 3.04, 201);
    let mut backbone = backbone_panel("E/E_g, m = 20", &[], None);
    backbone.series = stability_series("NSM1", PALETTE[0], &marked);
    backbone.series.push(
        Series::line("exact family (stable)", exact)
            .with_color(Rgb::BLACK)
            .with_size(1),
    );
    let moduli: Vec<(f64, f64, Option<bool>)> = points
        .iter()
        .filter_map(|p| {
            let f = p.stability.as_ref()?.as_ref().ok()?;
            // An unresolved point's multipliers describe no motion: not drawn.
            let stable = f.verdict.stable()?;
            Some((p.omega / omega_1, f.max_modulus, Some(stable)))
        })
        .collect();
    let multipliers = LinePanel {
        series: stability_series("NSM1", PALETTE[0], &moduli),
        ..LinePanel::new(
            "largest multiplier modulus (points with a verdict)",
            FREQUENCY_LABEL,
            "max |mu|",
        )
    };
    let figure = Figure::new(
        "Stability of the clamped bar's first nonsmooth mode (harmonic balance, m = 20)",
        2,
        vec![backbone.into(), multipliers.into()],
    );
    render_svg(out.join("stability_clamped.svg"), &figure)?;
    let column = |f: &dyn Fn(&BackbonePoint) -> f64| points.iter().map(|p| f(p)).collect();
    let floquet = |p: &BackbonePoint| p.stability.clone().and_then(Result::ok);
    let columns: [Vec<f64>; 6] = [
        column(&|p| p.period),
        column(&|p| p.omega / omega_1),
        column(&|p| p.energy_normalized),
        column(&|p| match stable(p) {
            Some(true) => 1.0,
            Some(false) => -1.0,
            None => 0.0,
        }),
        column(&|p| floquet(p).map_or(f64::NAN, |f| f.max_modulus)),
        column(&|p| floquet(p).map_or(f64::NAN, |f| f.energy_correction)),
    ];
    let refs: Vec<&[f64]> = columns.iter().map(Vec::as_slice).collect();
    let names = [
        "period",
        "omega_normalized",
        "energy_normalized",
        "verdict",
        "max_multiplier",
        "energy_correction",
    ];
    let file = std::fs::File::create(out.join("stability_clamped.csv"))?;
    write_columns_csv(&names, &refs, std::io::BufWriter::new(file))?;
    let count = |v: f64| columns[3].iter().filter(|&&c| c == v).count();
    println!(
        "stability_clamped: {} points, {} stable, {} unstable, {} unresolved",
        points.len(),
        count(1.0),
        count(-1.0),
        count(0.0)
    );
    Ok(())
}

fn main() -> ExitCode {
    let mut out = PathBuf::from("gallery");
    let mut quick = false;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--out" => match args.next() {
                Some(d) => out = PathBuf::from(d),
                None => {
                    eprintln!("gallery: --out needs a directory\n{USAGE}");
                    return ExitCode::from(2);
                }
            },
            "--quick" => quick = true,
            _ => {
                eprintln!("gallery: unknown argument `{a}`\n{USAGE}");
                return ExitCode::from(2);
            }
        }
    }
    let run = || -> Res<()> {
        std::fs::create_dir_all(&out)?;
        stability_clamped(&out, if quick { 100.0 } else { 200.0 })
    };
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("gallery: {e}");
            ExitCode::FAILURE
        }
    }
}
