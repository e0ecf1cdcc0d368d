//! A search for periodic motions that are not even in time, in the full Fourier basis.
//!
//! ```text
//! cargo run --release --example odd_motions -- [--harmonics 20] [--periods 12]
//! ```
//!
//! The paper's cosine basis holds only motions with an instant at which the whole velocity
//! field vanishes. A motion without one needs sines; this example looks for it from seeds
//! that combine two linear modes in quadrature. On the clamped bar and the two-bar
//! configurations 1 and 2, at `--periods` periods of the first nonsmooth mode's grid
//! (`BackboneOptions::for_mode`), each seed is the first mode's grazing seed on harmonic 1
//! (scaled by 1 or 2) plus the seed of mode `j = 2..4` on the harmonic `n` nearest to its
//! frequency, put in quadrature (on the sine of harmonic `n`), scaled by 0.1, 0.3, 1 or 3
//! relative to it. Each is solved once on the phase-locked system
//! (`branches::full_basis_branch` over one period).
//!
//! A converged point is *even* when its [`asymmetry`](nonsmooth_modes::branches::asymmetry)
//! (the smallest sine share over the time shifts) is below `1e-8`; the others are checked
//! in the time domain (`verify::periodicity_check`, the backbone's check) and printed with
//! their displacement defect, then solved again on a time grid 4 times finer and with `2m`
//! harmonics (the `fine_*` and `lifted_*` columns). One that stays not even at `2m` is
//! continued in the period both ways, 40 steps of `5e-4` each (the phase following the
//! branch), and `not_even_from`, `not_even_to` give the periods between which it stays not
//! even. The last lines count, per system, the seeds that converged,
//! reached the state of rest, converged to even motions and to motions that are not even,
//! and how many of those pass the check (displacement defect at most 5 %).

use nonsmooth_modes::branches::{
    full_basis_branch, full_basis_system, quadrature_start, with_harmonics, BackboneOptions,
    FullBasisPoint, Request, TimeDomainCheck,
};
use nonsmooth_modes::continuation::linspace;
use nonsmooth_modes::fourier::{frequency_of_period, Basis};
use nonsmooth_modes::reference::{
    clamped_bar_with_obstacle, paper_second_bar, two_bars_in_contact,
};

use nonsmooth_modes::system::{BarSystem, HarmonicBalanceSettings};
use nonsmooth_modes::verify::periodicity_check;

/// Below this asymmetry a motion is even about some instant (rounding and the solver's
/// tolerance leave about `1e-20`).
const EVEN: f64 = 1e-8;

/// An asymmetry that falls below this fraction of the first solve's on a refined
/// problem was made by the coarser one.
const SHRINK: f64 = 0.1;

/// What the seeds of one system gave.
#[derive(Default)]
struct Tally {
    seeds: usize,
    converged: usize,
    even: usize,
    /// Not even, but even (or 10 times less asymmetric) once solved again on a time grid 4
    /// times finer: the grid's sampling of the law broke the symmetry.
    even_on_finer_grid: usize,
    /// Not even on either time grid.
    odd: usize,
    /// Of those, still not even (at least a tenth of the asymmetry) once solved again with
    /// `2m` harmonics.
    odd_lifted: usize,
    /// Of those, passing the time-domain check at `2m` harmonics.
    odd_verified: usize,
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let (mut harmonics, mut periods) = (20usize, 12usize);
    let args: Vec<String> = std::env::args().skip(1).collect();
    for pair in args.chunks(2) {
        let value = pair.get(1).ok_or("missing value")?;
        match pair[0].as_str() {
            "--harmonics" => harmonics = value.parse()?,
            "--periods" => periods = value.parse()?,
            other => return Err(format!("unknown flag `{other}`").into()),
        }
    }
    let settings = HarmonicBalanceSettings {
        harmonics,
        ..Default::default()
    };
    let systems: [(&str, BarSystem); 3] = [
        ("clamped", clamped_bar_with_obstacle(1e-3)?),
        (
            "two-bar 1",
            two_bars_in_contact(paper_second_bar(0.95, 1.0, 1.0)?, 1e-3)?,
        ),
        (
            "two-bar 2",
            two_bars_in_contact(paper_second_bar(3.8, 4.0, 4.0)?, 1e-3)?,
        ),
    ];
    println!(
        "system,period,mode,harmonic,scale,ratio,energy_normalized,asymmetry,\
         displacement_defect,fine_energy_normalized,fine_asymmetry,fine_displacement_defect,\
         lifted_energy_normalized,lifted_asymmetry,lifted_displacement_defect,\
         not_even_from,not_even_to"
    );
    let mut tallies = Vec::new();
    for (name, system) in &systems {
        let tally = search(name, system, &settings, periods)?;
        tallies.push((name, tally));
    }
    for (name, t) in tallies {
        println!(
            "# {name}: {} seeds, {} converged ({} at rest or failed), {} even, {} even on a \
             finer time grid, {} not even; of those, {} still not even with 2m harmonics, {} of \
             which pass the time-domain check there",
            t.seeds,
            t.converged,
            t.seeds - t.converged,
            t.even,
            t.even_on_finer_grid,
            t.odd,
            t.odd_lifted,
            t.odd_verified
        );
    }
    Ok(())
}

/// Solves every seed of `system` at `periods` periods of its grid.
fn search(
    name: &str,
    system: &BarSystem,
    settings: &HarmonicBalanceSettings,
    periods: usize,
) -> Result<Tally, Box<dyn std::error::Error>> {
    let grid = BackboneOptions::for_mode(system, 1, 1)?.grid;
    let mut problem = full_basis_system(system, settings)?;
    let m = problem.basis().harmonics();
    let check = TimeDomainCheck::for_system(system);
    let mut tally = Tally::default();
    for period in linspace(grid.start, grid.end, periods)? {
        let omega = frequency_of_period(period);
        for mode in 2..=4 {
            for scale in [1.0, 2.0] {
                for ratio in [0.1, 0.3, 1.0, 3.0] {
                    let Ok((start, n)) = quadrature_start(&mut problem, mode, ratio, omega) else {
                        continue;
                    };
                    tally.seeds += 1;
                    let start: Vec<f64> = start.iter().map(|v| scale * v).collect();
                    let run = full_basis_branch(
                        system,
                        &Request::new(1).settings(*settings),
                        &start,
                        vec![period],
                    );
                    let Some(p) = run.ok().and_then(|r| r.points.into_iter().next()) else {
                        continue;
                    };
                    tally.converged += 1;
                    if p.asymmetry < EVEN {
                        tally.even += 1;
                        continue;
                    }
                    let finer =
                        refined(system, settings, &p, 4 * settings.samples_per_harmonic, m)?;
                    // An asymmetry the grid made shrinks with it.
                    let vanishes = |a: f64| a < EVEN.max(SHRINK * p.asymmetry);
                    if finer.is_some_and(|r| vanishes(r.asymmetry)) {
                        tally.even_on_finer_grid += 1;
                        continue;
                    }
                    tally.odd += 1;
                    let defect = periodicity_check(
                        system,
                        problem.basis(),
                        &p.point.x,
                        omega,
                        &check.options,
                    )
                    .map_or_else(
                        |e| format!("not checked: {e}"),
                        |r| format!("{:e}", r.displacement_defect),
                    );
                    let more = refined(system, settings, &p, settings.samples_per_harmonic, 2 * m)?;
                    let mut extent = None;
                    if let Some(r) = more.filter(|r| !vanishes(r.asymmetry)) {
                        tally.odd_lifted += 1;
                        if r.displacement_defect <= check.max_displacement_defect {
                            tally.odd_verified += 1;
                        }
                        extent = Some(not_even_extent(system, settings, &p)?);
                    }
                    let show = |r: &Option<Refined>| match r {
                        Some(r) => format!(
                            "{},{:e},{:e}",
                            r.energy_normalized, r.asymmetry, r.displacement_defect
                        ),
                        None => ",,".into(),
                    };
                    let (from, to) = extent.map_or((String::new(), String::new()), |(a, b)| {
                        (a.to_string(), b.to_string())
                    });
                    println!(
                        "{name},{period},{mode},{n},{scale},{ratio},{},{:e},{defect},{},{},{from},{to}",
                        p.point.energy_normalized,
                        p.asymmetry,
                        show(&finer),
                        show(&more)
                    );
                }
            }
        }
    }
    Ok(tally)
}

/// How far in the period a motion that is not even stays so: continued from `p` both ways
/// by [`FOLLOW_STEPS`] steps of [`FOLLOW_STEP`] (`branches::full_basis_branch`, the phase
/// following the branch), the periods `(from, to)` between which its points keep an
/// asymmetry of at least a tenth of `p`'s, without a gap.
fn not_even_extent(
    system: &BarSystem,
    settings: &HarmonicBalanceSettings,
    p: &FullBasisPoint,
) -> Result<(f64, f64), Box<dyn std::error::Error>> {
    let mut extent = (p.point.period, p.point.period);
    for direction in [-1.0, 1.0] {
        let end = p.point.period + direction * FOLLOW_STEP * FOLLOW_STEPS as f64;
        let periods = linspace(p.point.period, end, FOLLOW_STEPS + 1)?;
        let run = full_basis_branch(
            system,
            &Request::new(1).settings(*settings),
            &p.point.x,
            periods,
        )?;
        for (expected, q) in run.points.iter().enumerate() {
            if q.point.step != expected || q.asymmetry < SHRINK * p.asymmetry {
                break;
            }
            extent = (extent.0.min(q.point.period), extent.1.max(q.point.period));
        }
    }
    Ok(extent)
}

/// Steps of a continuation from a motion that is not even, each way.
const FOLLOW_STEPS: usize = 40;
/// Their period step.
const FOLLOW_STEP: f64 = 5e-4;

/// A point solved again on a refined problem.
#[derive(Clone, Copy)]
struct Refined {
    energy_normalized: f64,
    asymmetry: f64,
    displacement_defect: f64,
}

/// `p` solved again with `samples_per_harmonic` samples per harmonic and `harmonics`
/// harmonics (its coefficients kept, the new ones zero): `(E / E_g, asymmetry,
/// displacement defect)`, or `None` where the solve fails or the check cannot run.
fn refined(
    system: &BarSystem,
    settings: &HarmonicBalanceSettings,
    p: &FullBasisPoint,
    samples_per_harmonic: usize,
    harmonics: usize,
) -> Result<Option<Refined>, Box<dyn std::error::Error>> {
    let finer = HarmonicBalanceSettings {
        harmonics,
        samples_per_harmonic,
        ..*settings
    };
    let start = with_harmonics(&p.point.x, settings.harmonics, harmonics)?;
    let request = Request::new(1)
        .settings(finer)
        .checked(TimeDomainCheck::for_system(system));
    let run = full_basis_branch(system, &request, &start, vec![p.point.period]);
    let Some(q) = run.ok().and_then(|r| r.points.into_iter().next()) else {
        return Ok(None);
    };
    Ok(q.point.time_domain.map(|r| Refined {
        energy_normalized: q.point.energy_normalized,
        asymmetry: q.asymmetry,
        displacement_defect: r.displacement_defect,
    }))
}
