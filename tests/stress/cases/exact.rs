//! Exact branches through the request (`Request::with_exact`): any reference system, grid and
//! options, on small grids of cells. A typed error before anything runs, or a result whose
//! exact branch is a typed error or a branch with finite numbers, each point with a verdict
//! or its reason.

use super::{reference_system, settings};
use crate::checks::{typed, CaseResult, Checks};
use crate::draw::Draw;
use nonsmooth_modes::branches::{compute, BackboneOptions, Method, PeriodGrid, Request};
use nonsmooth_modes::exact::ExactOptions;
use nonsmooth_modes::stability::{StabilityOptions, Verdict};

pub(crate) fn exact_case(d: &mut Draw, c: &mut Checks) -> CaseResult {
    // Half the cases draw no edge value at all, so that the walk itself is reached: one bad
    // option among the twenty drawn is refused before anything runs.
    let saved = d.edge;
    if d.flag("valid exact case", 0.5) {
        d.edge = 0.0;
    }
    let system = reference_system(d, c);
    let mut s = settings(d);
    s.harmonics = s.harmonics.min(6);
    let period = 3.9 * d.real("period factor", 0.5..=2.0);
    let grid = PeriodGrid {
        start: d.real("grid start", period..=period),
        end: d.real("grid end", period * 0.9..=period),
        steps: d.size("steps", 2..=4).min(4),
    };
    let stability = StabilityOptions {
        cells_per_travel: d.real("cells per travel", 6.0..=12.0),
        corrections: d.size("corrections", 0..=2).min(2),
        tolerance: d.real("tolerance", 1e-4..=1e-2),
        max_damping: d.real("max damping", 0.0..=0.2),
        ..StabilityOptions::default()
    };
    let options = ExactOptions {
        stability,
        iterations: d.size("iterations", 1..=6).min(6),
        refreshes: d.size("refreshes", 0..=2).min(2),
        max_energy_jump: d.real("max energy jump", 0.0..=0.1),
        first_step_jump: d.real("first step jump", 0.0..=0.5),
        seed_attempts: d.size("seed attempts", 1..=2).min(2),
        max_lost: d.size("max lost", 1..=2).min(2),
        max_removed_energy: d.real("max removed energy", 0.0..=1e-4),
    };
    let request = Request::new(1)
        .settings(s)
        .method(Method::PeriodGrid(BackboneOptions::on_grid(grid, 1, 1)))
        .with_exact(options);
    d.edge = saved;
    let system = system?;
    let run = typed(
        c,
        "compute with an exact branch",
        compute(&system, &request),
    )?;
    c.mode_branches("harmonic balance under the exact branch", &run, false);
    let Some(exact) = run.exact else {
        c.expect(false, || {
            "compute asked for an exact branch returned none".into()
        });
        return Ok(());
    };
    let branch = typed(c, "exact branch", exact)?;
    c.finite("exact branch", [&branch.grazing_energy, &branch.dt]);
    for p in &branch.points {
        c.finite(
            "exact point",
            [
                &p.point.period,
                &p.point.energy,
                &p.point.energy_normalized,
                &p.requested_period,
                &p.removed_energy,
            ],
        );
        match &p.point.stability {
            Some(Ok(f)) => {
                c.expect(
                    (f.verdict == Verdict::Unresolved) == f.unresolved.is_some(),
                    || {
                        format!(
                            "exact point at T = {}: verdict without its reason",
                            f.period
                        )
                    },
                );
                c.finite(
                    "exact multipliers",
                    f.multipliers.iter().flat_map(|m| [&m.re, &m.im]),
                );
            }
            Some(Err(e)) => {
                c.error("exact point's multipliers", e);
            }
            None => c.expect(false, || "an exact point without multipliers".into()),
        }
    }
    Ok(())
}
