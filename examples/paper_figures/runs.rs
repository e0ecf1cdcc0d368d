//! The branches of the figures: what to continue (`Branch`), how (period grid, energy levels,
//! pseudo-arclength), and the result (`Run`), with the exact clamped-bar branches and the
//! choice of points on a run.

use crate::common::{settings, Ctx, Res, GAP};
use nonsmooth_modes::branches::{
    compute, ArclengthBackboneOptions, BackboneOptions, BackbonePoint, EnergyBackboneOptions,
    Method, PeriodGrid, Request, TRIVIAL_ENERGY,
};
use nonsmooth_modes::continuation::{
    ArclengthOptions, EndReason, PeriodParametrised, Sequential, SequentialOptions, Step,
};
use nonsmooth_modes::fourier::CosineBasis;
use nonsmooth_modes::modal::{energy, grazing_energy};
use nonsmooth_modes::reference::ClampedFamily;
use nonsmooth_modes::solve::{NewtonOptions, SemismoothNewton, SolveInfo, Solver};
use nonsmooth_modes::system::{BarSystem, NonsmoothSystem};
use std::f64::consts::PI;

/// The request of `method` for NSM `mode` sub `subharmonic` with `m` harmonics, solved by
/// `solver`.
fn request(
    m: usize,
    (mode, subharmonic): (usize, usize),
    method: Method,
    solver: Solver,
) -> Request {
    Request {
        settings: settings(m),
        method,
        solver: Some(solver),
        ..Request::new(mode).subharmonic(subharmonic)
    }
}

/// Exact `E/E_g` of a clamped-bar branch: an exact family, on its `subharmonic`-th branch.
#[derive(Clone, Copy)]
pub struct Exact {
    family: ClampedFamily,
    subharmonic: f64,
}

impl Exact {
    /// Family `index` of the clamped bar, followed on its `subharmonic`-th branch.
    pub fn new(index: usize, subharmonic: usize) -> Res<Self> {
        Ok(Self {
            family: ClampedFamily::new(GAP, index)?,
            subharmonic: subharmonic as f64,
        })
    }

    /// `E/E_g` at the branch's period `period`.
    pub fn at(&self, period: f64) -> f64 {
        self.family.energy_normalized(period / self.subharmonic)
    }
}

/// A backbone computed by sequential continuation in the period.
pub struct Run {
    /// Branch name (legend and CSV).
    pub label: String,
    /// Number of harmonics.
    pub m: usize,
    /// All points, converged or not.
    pub points: Vec<BackbonePoint>,
    /// The exact branch it approximates, when known.
    pub exact: Option<Exact>,
}

impl Run {
    /// The run with the exact branch `exact`.
    pub fn with_exact(self, exact: Exact) -> Self {
        Self {
            exact: Some(exact),
            ..self
        }
    }

    /// Its converged points.
    pub fn converged(&self) -> impl Iterator<Item = &BackbonePoint> {
        self.points.iter().filter(|p| p.converged())
    }

    /// The run up to the end of its branch, and the rest labelled `beyond`: the branch ends
    /// at its last converged point before the first `gap` steps in a row that did not
    /// converge (failed, or slid to rest).
    pub fn split_at_end(&self, gap: usize, beyond: &str) -> (Run, Run) {
        let mut end = self.points.len();
        let mut misses = 0;
        for (i, p) in self.points.iter().enumerate() {
            misses = if p.converged() { 0 } else { misses + 1 };
            if misses == gap {
                end = i + 1 - gap;
                break;
            }
        }
        let part = |label: &str, points: &[BackbonePoint]| Run {
            label: label.to_string(),
            m: self.m,
            points: points.to_vec(),
            exact: self.exact,
        };
        (
            part(&self.label, &self.points[..end]),
            part(beyond, &self.points[end..]),
        )
    }
}

/// What to continue: mode and subharmonic of the seed, and the period grid.
pub struct Branch<'a> {
    /// Branch name.
    pub label: &'a str,
    /// Open-contact mode the branch starts from (1-based).
    pub mode: usize,
    /// Subharmonic order.
    pub subharmonic: usize,
    /// First and last period.
    pub periods: (f64, f64),
    /// Steps of the period grid.
    pub steps: usize,
    /// For a subharmonic: follow the genuinely `T`-periodic branch that leaves the repeated
    /// one ([`Method::GenuineSubharmonic`]) instead of the repeated branch.
    pub genuine: bool,
}

impl<'a> Branch<'a> {
    /// The branch of `mode` (subharmonic 1) over `periods` in `steps` steps.
    pub fn new(label: &'a str, mode: usize, periods: (f64, f64), steps: usize) -> Self {
        Self {
            label,
            mode,
            subharmonic: 1,
            periods,
            steps,
            genuine: false,
        }
    }

    /// The same subharmonic branch, followed off the repeated one where it leaves it.
    pub fn genuine(self) -> Self {
        Self {
            genuine: true,
            ..self
        }
    }

    /// The same branch on subharmonic `order`.
    pub fn subharmonic(self, order: usize) -> Self {
        Self {
            subharmonic: order,
            ..self
        }
    }
}

/// NSM `mode` of `system` with `m` harmonics, continued in the energy level from the mode's
/// own grazing energy to 300 times it ([`EnergyGrid::for_mode`]).
pub fn energy_run(system: &BarSystem, m: usize, label: &str, mode: usize) -> Res<Run> {
    let options = EnergyBackboneOptions::for_mode(system, mode, 1)?;
    let method = Method::Energy(options);
    let points = compute(system, &request(m, (mode, 1), method, Solver::default()))?;
    let ok = points.converged().count();
    println!(
        "    {label:<28} m = {m:<3} E/E_g {:.3} -> {:.3}: {ok}/{} converged",
        options.levels.start,
        options.levels.end,
        points.points.len()
    );
    Ok(Run {
        label: label.to_string(),
        m,
        points: points.points,
        exact: None,
    })
}

/// Follows `branch` of `system` with `m` harmonics, visiting the whole grid.
pub fn run(system: &BarSystem, m: usize, branch: &Branch<'_>) -> Res<Run> {
    let (start, end) = branch.periods;
    let grid = PeriodGrid {
        start,
        end,
        steps: branch.steps,
    };
    let options = BackboneOptions {
        // Visit the whole grid: failed stretches (near resonances) are reported, not fatal.
        max_consecutive_failures: usize::MAX,
        ..BackboneOptions::on_grid(grid, branch.mode, branch.subharmonic)
    };
    let (method, solver) = if branch.genuine {
        // As the `backbone` example: each step starts from a converged neighbour.
        let solver = SemismoothNewton::new(NewtonOptions::fail_fast())?;
        (Method::GenuineSubharmonic(options), Solver::Newton(solver))
    } else {
        (Method::PeriodGrid(options), Solver::default())
    };
    let order = (branch.mode, branch.subharmonic);
    let points = compute(system, &request(m, order, method, solver))?;
    let ok = points.converged().count();
    println!(
        "    {:<28} m = {m:<3} T {start:.4} -> {end:.4}: {ok}/{} converged",
        branch.label,
        points.points.len()
    );
    Ok(Run {
        label: branch.label.to_string(),
        m,
        points: points.points,
        exact: None,
    })
}

/// `branch` of `system` (its label, mode and periods; not its steps) by arclength
/// continuation with `m` harmonics, from `T = start` while `T` stays in `[end, start + 0.01]`,
/// with the stall escape.
pub fn arclength_run(
    ctx: &Ctx,
    system: &BarSystem,
    m: usize,
    branch: &Branch<'_>,
    w1: f64,
) -> Res<Run> {
    let (start, end) = branch.periods;
    let range = (2.0 * PI / (start + 0.01), 2.0 * PI / end);
    let order = (branch.mode, branch.subharmonic);
    let options = ArclengthBackboneOptions {
        arclength: ArclengthOptions {
            max_steps: if ctx.quick { 150 } else { 2000 },
            ..Default::default()
        },
        ..ArclengthBackboneOptions::seeded_at(start, range, order)
    };
    let label = branch.label;
    let method = Method::Arclength(options);
    let run = compute(system, &request(m, order, method, Solver::default()))?;
    let points = run.points;
    let reached = points
        .iter()
        .map(|p| p.omega / w1)
        .fold(f64::NEG_INFINITY, f64::max);
    println!(
        "    {label} (m = {m}): {} points, {} rejections, end {:?}, max Omega/omega_1 = {reached:.3}",
        points.len(),
        run.rejected_steps,
        match &run.end {
            EndReason::ParameterOutOfRange { .. } => "range".to_string(),
            other => format!("{other:?}"),
        }
    );
    Ok(Run {
        label: label.to_string(),
        m,
        points,
        exact: None,
    })
}

/// A motion `x` of `system` solved at the fixed frequency `omega` (not continued), as a
/// converged point with its energy.
pub fn solved_point(
    system: &BarSystem,
    basis: &CosineBasis,
    (x, omega): (Vec<f64>, f64),
    info: &SolveInfo,
) -> Res<BackbonePoint> {
    let e_g = grazing_energy(system)?.0;
    let e = energy(system, basis, &x, omega);
    Ok(BackbonePoint::solved(x, omega, e, e_g, info))
}

/// The branch through the converged point `p` of `system` with `m` harmonics: sequential
/// continuation in the period from `p`, `steps` steps of `step` towards longer and towards
/// shorter periods (each direction ends after three failures in a row), joined in order of
/// decreasing period with `p` among them. Points at rest (below `TRIVIAL_ENERGY E_g`) are not
/// kept.
pub fn continued_from(
    system: &BarSystem,
    m: usize,
    p: &BackbonePoint,
    (step, steps): (f64, usize),
    label: &str,
) -> Res<Run> {
    let e_g = grazing_energy(system)?.0;
    let mut points = vec![p.clone()];
    for direction in [1.0, -1.0] {
        let problem = NonsmoothSystem::new(system, settings(m))?;
        let basis = problem.basis().clone();
        let periods: Vec<f64> = (1..=steps)
            .map(|i| p.period + direction * step * i as f64)
            .collect();
        let options = SequentialOptions {
            max_consecutive_failures: 3,
            ..SequentialOptions::default()
        };
        let mut driver = Sequential::new(
            PeriodParametrised::new(problem),
            SemismoothNewton::default(),
            p.x.clone(),
            periods,
            options,
        )?;
        loop {
            match driver.step() {
                Step::Accepted(q) => {
                    let omega = 2.0 * PI / q.parameter;
                    let e = energy(system, &basis, &q.x, omega);
                    let point = BackbonePoint::from_point(&q, omega, e, e_g);
                    if point.converged() && point.energy_normalized > TRIVIAL_ENERGY {
                        points.push(point);
                    }
                }
                Step::Rejected(_) => {}
                Step::Finished(_) => break,
            }
        }
    }
    points.sort_by(|a, b| b.period.total_cmp(&a.period));
    Ok(Run {
        label: label.to_string(),
        m,
        points,
        exact: None,
    })
}

/// The stretch of `all` (a run from [`continued_from`] through `p`) around `p` whose points
/// all satisfy `keep`: the branch of `p`'s own motion, without the other motions the
/// continuation falls onto where that branch ends.
pub fn kept_around(
    all: Run,
    p: &BackbonePoint,
    mut keep: impl FnMut(&BackbonePoint) -> Res<bool>,
) -> Res<Run> {
    let mut same = Vec::with_capacity(all.points.len());
    for q in &all.points {
        same.push(keep(q)?);
    }
    let at = all.points.iter().position(|q| q.period == p.period);
    let (lo, hi) = at.map_or((0, 0), |i| {
        let lo = (0..=i).rev().take_while(|&k| same[k]).last().unwrap_or(i);
        let hi = (i..same.len()).take_while(|&k| same[k]).last().unwrap_or(i);
        (lo, hi + 1)
    });
    Ok(Run {
        points: all.points[lo..hi].to_vec(),
        ..all
    })
}
