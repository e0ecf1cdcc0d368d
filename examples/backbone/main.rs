//! Backbone of a nonsmooth mode, written as CSV: a thin front end of `branches::compute`.
//!
//! ```text
//! cargo run --release --example backbone -- [--system ds|rs|two-bar] [--gap 1e-3]
//!     [--robin-stiffness 0.5] [--length2 0.95 --speed2 1 --stiffness-ratio 1]
//!     [--assembly FILE]
//!     [--harmonics 20 --samples-per-harmonic 30 --complementarity 4] [--resonance-band C]
//!     [--mode 1] [--subharmonic 1]
//!     [--period-start T0 --period-end T1 --steps S] [--solver newton|dogleg] [--out FILE]
//!     [--newton fail-fast|full] [--retry-depth K] [--max-failures F]
//!     [--selection first|lowest-energy] [--serial]
//!     [--method sequential|arclength] [--ds DS --ds-min A --ds-max B --max-steps N]
//!     [--omega-range LO:HI] [--switch-at N[:SIDE]] [--parameter omega|energy|gap|robin-stiffness|stiffness-ratio]
//!     [--parameter-range LO:HI] [--energy-range LO:HI] [--progress] [--verify] [--stability]
//!     [--hill] [--basis cosine|full] [--exact [--cells-per-travel N]]
//! ```
//!
//! The system: `--system ds|rs|two-bar` are shorthands for the paper's three systems
//! (`reference::clamped_bar_with_obstacle`, `robin_bar_with_obstacle`, `two_bars_in_contact`,
//! set by `--gap`, `--robin-stiffness`, `--length2`, `--speed2`, `--stiffness-ratio`; their
//! bars are named `1` and `2`). `--assembly FILE` reads any assembly from a TOML or JSON file
//! instead (`io::assembly`, which documents the schema; `examples/assemblies/` has the three
//! shorthands as files and a three-bar chain). It uses the `serde` feature, on by default
//! (`cargo run --release --example backbone -- --assembly FILE`; a build with
//! `--no-default-features` refuses the flag with that command), excludes `--system` and the shorthands' value
//! flags (the values are in the file) and continues in the period (`--parameter omega`) or in
//! the energy (`--parameter energy`).
//! A file that cannot be read or built is a usage error, explained on stderr.
//!
//! Default periods: the shorthands keep the grids they have always had (`ds` and `two-bar`
//! 3.95 -> 3.05, `rs` 9.5 -> 6.0, whatever the mode). For a file they come from the system's
//! own linear mode `i = --mode` (open contacts, `modal::open_mode`): with `T_i = 2 pi / omega_i`
//! rounded to 6 significant digits and `K = --subharmonic`, the periods go from
//! `K T_i 79/80` down to `K T_i 61/80` (181 steps by default), from just below the linear
//! period into the strongly nonlinear range. For the clamped bar `T_1 = 4`, which gives the
//! paper's grid 3.95 -> 3.05 exactly (`4 * 79 / 80` and `4 * 61 / 80` round to the doubles of
//! 3.95 and 3.05), so `--assembly examples/assemblies/clamped.toml` writes the same CSV as
//! `--system ds`, byte for byte. `--period-start` and `--period-end` override either default.
//!
//! Columns: `step,period,omega,energy,energy_normalized,exact_energy_normalized,converged,
//! status,residual_norm,iterations,step_size,event,parameter` (`status` is `converged`,
//! `solver-failed` or `collapsed-to-rest`: `branches::PointStatus`; every step computed is
//! written, also when the run then stalls and exits with code 1; `exact_energy_normalized` is the exact
//! first mode of the clamped bar, formulation §9, when the system is the clamped bar —
//! `--system ds` or a file with the same bars and conditions — with `--mode 1 --subharmonic 1`,
//! and empty otherwise; `event` lists fold/jump/grazing events separated by `;`; `parameter` is the
//! continued parameter's value). `--verify` asks the library to check every converged point
//! (`branches::TimeDomainCheck::for_system`: one period of the exact integrator with a step of
//! 1/400 of the shortest travel time, at most 10^6 steps per point) and adds the columns
//! `periodicity_defect,displacement_defect,max_penetration,time_domain_check`: the numbers
//! are empty for a point that was not marched, and `time_domain_check` is `passed`,
//! `failed` (the point is labelled `unverified`), `unchecked` (a condition declares no
//! time-domain form: the label stays that of the harmonic content), `over-budget` or
//! `not-run` (with the reason on stderr).
//!
//! `--resonance-band C` holds at zero every harmonic `n >= 2` whose frequency lies within
//! `C / m` (relative) of an open- or closed-contact natural frequency
//! (`HarmonicBalanceSettings::resonance_band`; `system::RESONANCE_BAND` = 0.1 is the measured
//! choice): the truncation's internal resonances go, and the skeleton converges as
//! `--harmonics` grows (`docs/theory.md`, "Harmonic selection"). Without it (or with 0),
//! the library's choice (no `--method`) runs the branch both on the paper's equations and
//! with band 0.1, and keeps the run whose skeleton covers more periods, as stderr says
//! (`branches::SelectionJudgement`); a `--method` keeps every harmonic. A band that is not
//! finite, negative or above `m` is a usage error.
//!
//! `--stability` asks the library for the Floquet multipliers of every converged point
//! (`stability`, default options: 200 cells per shortest travel time, the state corrected to
//! a periodic orbit of the exact map first) and adds, after every other column,
//! `stable,max_multiplier,stability_reason`: `true`, `false` or `unresolved` (no periodic
//! orbit of the map within 5 % of the point's energy and displacement, or its trivial
//! multipliers not found); the largest multiplier modulus (1 when every multiplier lies
//! within `1e-3` of the unit circle), empty where unresolved; and why there is no verdict:
//! the `stability::UnresolvedReason` with its numbers, or the error where the multipliers
//! could not be computed (commas written as semicolons); for a verdict, empty, or the grid's
//! damping the stable verdict holds up to (`Floquet::damping`).
//! Changes of verdict along a branch appear in `event` as `stability-lost` and
//! `stability-gained`. Period and energy runs only; empty cells for `--parameter` runs.
//!
//! `--exact` runs the harmonic-balance branch of the flags (its rows not written), then the
//! exact branch seeded by it over the same period grid (`Request::with_exact`: periodic
//! orbits of the integrator's one-period map, continued in the period) and writes one row per
//! exact point, in the same columns with the stability columns always present: `iterations`
//! and `residual_norm` are the corrector's steps and the orbit's periodicity defect, `label`
//! that of the harmonic-balance point the segment was seeded from, `branch` one more after
//! each reseed, `contacts_per_period` counted on the orbit, `dominant_harmonic` empty; then,
//! last, `harmonic_balance_distance` (`(E - E_hb) / E_hb` against the converged
//! harmonic-balance point at the same period, empty where there is none) and `seeded`
//! (`true` for a point corrected from a harmonic-balance point, `false` for one continued
//! from the orbit before it). A distance that grows step after step while the harmonic-balance
//! points stay put is a branch that has left their family (`docs/validation.md`).
//! `--cells-per-travel N` (at most 1000) is the map's smallest grid, in cells per shortest
//! travel time; the grid used may be finer, so that every period is a whole number of steps.
//! Without it, `ExactOptions::for_request`: 200, or fewer where the system's other bars
//! would make the matrices larger than the limits of `stability`. Stderr says how many
//! points, verdicts and seconds, why the walk ended and why each skipped period has no
//! point. With `--parameter omega` only, in the cosine basis, without `--hill`.
//!
//! `--hill` adds, after those, `hill_stable,hill_max_multiplier`: the verdict and largest
//! multiplier of Hill's method on the truncated harmonic-balance equations (`stability::hill`,
//! default options), a cross-check that differs from the exact map's verdict where the
//! truncation matters (`docs/validation.md`). Unresolved where the point does not solve the
//! full system (a harmonic selection) or its trivial exponent is not found.
//!
//! Last in every row, so that the columns before them keep their places:
//! `contacts_per_period`, the number of contact intervals per period summed over the
//! contacts (`modal::contact_intervals` on the harmonic-balance time grid: 1 for the clamped
//! bar's first mode, `K` for that mode run `K` times on a `K`-subharmonic branch, 0 for a
//! point collapsed to rest), and, with `--subharmonic K` for `K > 1`, `subharmonic_share`, the
//! share of the bars' time-averaged energy in the harmonics that are not multiples of `K`
//! (`modal::subharmonic_share`: 0 while the branch is the `T`-periodic mode repeated, away
//! from 0 where it is genuinely subharmonic; empty for a point collapsed to rest). A cell is
//! left empty, with a message on stderr, where the point's unknowns do not allow the
//! computation (not finite). Then `label,branch,dominant_harmonic` (`modal::Label`,
//! `BackbonePoint::branch`, `modal::Character::dominant_harmonic`): `skeleton`,
//! `internal-resonance-hJ-modeK` (harmonic `J` meets linear mode `K`), `subharmonic-K` or,
//! with `--verify`, `unverified` for a point whose displacement defect exceeds 5 % (empty for
//! a point that did not converge); the index of the branch within the run (one more after
//! each jump); the harmonic holding the most energy.
//!
//! `--basis full` continues the branch in the constant + cosine + sine basis
//! (`branches::full_basis_branch`, with the phase condition of `system::PhaseLocked`): the
//! period grid is run in the cosine basis (`--basis cosine`, the default) for its first
//! converged point, which starts the full-basis run over the same periods. Its columns are
//! `step,period,omega,energy,energy_normalized,converged,status,unfolding,sine_share,
//! asymmetry,residual_norm,iterations,label` (`status`: `converged`, `rejected`, or
//! `before-start` for the periods before the cosine run's first converged one; `unfolding`
//! is the phase-locked system's `mu`, `sine_share` and `asymmetry` say how far the motion is
//! from even about `t = 0` and about any instant; `label` as below), then with `--verify`
//! `periodicity_defect,displacement_defect,max_penetration,time_domain_check`, with `--stability`
//! `stable,max_multiplier,stability_reason` and with `--hill` `hill_stable,hill_max_multiplier`, as for the
//! cosine basis. It takes `--parameter omega`,
//! sequential steps and `--subharmonic 1`; other combinations are usage errors.

//! `--subharmonic K > 1` (sequential runs in the period): the seed on harmonic `K` gives the
//! mode of period `T/K` traced `K` times, a subspace Newton's method never leaves; the run
//! follows it until a point can be left along the most singular direction off the multiples
//! of `K`, then continues on that genuinely `T`-periodic branch
//! (`Method::GenuineSubharmonic`). `--repeated` keeps the repeated branch.
//!
//! `--method sequential` visits `--steps` equispaced periods. `--method arclength` follows
//! the branch in `Omega` inside `--omega-range` (default: the periods' range) with automatic
//! escape from internal-resonance stalls, walking it back first where its start is found only
//! above the first period's frequency. Without `--method` the library chooses
//! (`Method::Auto` on the period grid): sequential, except where the branch cannot be
//! entered at the first period (the three-bar chain), which is followed by arclength, as
//! stderr says; its `event` column marks folds, jumps, grazing and
//! branch points (`branch-point`: the sign of the bordered Jacobian's determinant changed),
//! and `--switch-at N[:SIDE]` leaves the branch at its `N`-th branch point for the branch
//! crossing there, on side `SIDE` (`1`, the default, or `-1`) of its direction
//! (`ArclengthBackboneOptions::switch`). `--parameter energy` continues the branch in the
//! energy level `E/E_g` with the frequency an unknown (`Method::Energy`; levels from
//! `--energy-range LO:HI`, default from mode `i`'s grazing energy to 300 times it, in `--steps`
//! geometric levels; sequential only); the points where it walks an internal resonance in the
//! period are rows too (`docs/assemblies.md`). `--parameter gap|robin-stiffness|stiffness-ratio`
//! continues in that parameter at the fixed period `--period-start` inside
//! `--parameter-range` (default: a decade either side), starting from the branch point at that
//! period (reached by a short sequential run from the system's default start).
//!
//! Newton's budget: `--newton fail-fast` (`NewtonOptions::fail_fast`, the default of sequential
//! runs: each step starts from a converged neighbour and a failed step is skipped) or
//! `--newton full` (`NewtonOptions::default`, the default of arclength runs, whose stall
//! escapes solve from far starts). A failed sequential step is retried from up to
//! `--retry-depth` earlier converged points (default 1; 2 for a period backbone of a file
//! with a bar held only by contacts, `BackboneOptions::for_mode`; 0
//! switches the retry off). Where the machine has more than one core, the first retry runs on
//! a second thread beside the first attempt (`Request::speculation`; the same points, bit
//! for bit); `--serial` keeps everything on one thread. A sequential run ends as stalled
//! (exit code 1, after writing every row) after `--max-failures` consecutive failed steps
//! (`BackboneOptions::max_consecutive_failures`, default 40).
//!
//! `--selection lowest-energy` (`Selection::LowestMeasure` through
//! `BackboneOptions::selection`; period runs only) solves every step from the prediction and
//! from the `--retry-depth` earlier converged points and keeps the lowest-energy solution,
//! which near an internal resonance stays on the backbone rather than on a resonance spike of
//! the truncated system. It costs about `--retry-depth` extra solves per step and runs serially
//! (every start is solved anyway); `docs/performance.md` measures what it gains on the
//! clamped bar. `--selection first` (the default) keeps the first accepted solution.
//!
//! Limits: requests the library accepts (within its memory budget) but that would run for
//! hours or days are refused with exit code 2: `--steps` and `--max-steps` at most
//! [`MAX_POINTS`] (an arclength run whose steps are too small to move the parameter only ends
//! at `--max-steps`), `--harmonics` at most [`MAX_HARMONICS`], `--samples-per-harmonic` at
//! most [`MAX_SAMPLES_PER_HARMONIC`].
//!
//! Exit codes: 0 when the run completed (steps that did not converge are reported, not
//! errors); 1 when the run failed, including values the library rejects (`--gap nan`, sizes
//! over its memory budget, an unwritable `--out`); 2 on a usage error (an unknown flag, a
//! missing or unparsable value, a value over the example's limits, `--system` with
//! `--assembly`, an assembly file that cannot be read or built, and a range the library
//! refuses as given, `nonsmooth_modes::BadRange`: a period grid whose ends are equal
//! (`--period-start 3.5 --period-end 3.5`), with fewer than 2 steps or a period that is not
//! positive and finite, a falling `--energy-range`, an empty or reversed `--omega-range` or
//! `--parameter-range`). Every failure is explained on stderr. `--help` prints the usage on
//! stdout and exits with 0.
//!
//! [`MAX_POINTS`]: args::MAX_POINTS
//! [`MAX_HARMONICS`]: args::MAX_HARMONICS
//! [`MAX_SAMPLES_PER_HARMONIC`]: args::MAX_SAMPLES_PER_HARMONIC

mod args;
mod full;
mod output;
mod runs;
mod systems;

use args::{parse, USAGE};
use runs::run;
use std::process::ExitCode;

/// Whether `e` is the library refusing a range of the command line as given: input to
/// correct, a usage error like an unparsable value, not a run that failed.
fn is_bad_range(e: &(dyn std::error::Error + 'static)) -> bool {
    e.downcast_ref::<nonsmooth_modes::Error>()
        .and_then(nonsmooth_modes::Error::bad_range)
        .is_some()
}

fn main() -> ExitCode {
    let args = match parse() {
        Ok(Some(a)) => a,
        Ok(None) => {
            println!("{USAGE}");
            return ExitCode::SUCCESS;
        }
        Err(e) => {
            eprintln!("backbone: {e}\n{USAGE}");
            return ExitCode::from(2);
        }
    };
    let result = match &args.out {
        Some(path) => match std::fs::File::create(path) {
            Ok(f) => run(&args, &mut std::io::BufWriter::new(f)),
            Err(e) => Err(e.into()),
        },
        None => run(&args, &mut std::io::stdout().lock()),
    };
    match result {
        Ok((total, converged)) => {
            eprintln!("backbone: {converged} of {total} steps converged");
            ExitCode::SUCCESS
        }
        Err(e) if is_bad_range(e.as_ref()) => {
            eprintln!("backbone: {e}\n{USAGE}");
            ExitCode::from(2)
        }
        Err(e) => {
            eprintln!("backbone: error: {e}");
            ExitCode::FAILURE
        }
    }
}
