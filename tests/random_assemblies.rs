//! Backbones of seeded random assemblies, as a new user would compute them: 1 to 4 bars in a
//! chain, lengths, wave speeds and stiffnesses drawn over a factor of 6 (0.5 to 3), each
//! outer end clamped, free, on a ground spring or facing a wall, neighbouring bars facing
//! each other across a contact (so every assembly has a unilateral condition, and bars held
//! only by contacts are common).
//!
//! Some of these assemblies hold a bar from one side only (a free end beyond a contact, a
//! wall on one side of a bar and nothing on the other): a contact can push such a bar but
//! nothing pulls it back, so it drifts away after its first impact and no periodic motion
//! touches it. The crate refuses these with [`SettingsError::Unconfined`]; the others must
//! give a backbone or a typed reason, never points at rest.
//!
//! - `every_assembly_gives_a_branch_or_a_typed_reason` (normal run): the invariants on a
//!   few assemblies at `m = 8`.
//! - `random_assembly_census` (`#[ignore]`): the figures of `docs/assemblies.md`, at the
//!   harmonics `RANDOM_HARMONICS` (default 20) over `RANDOM_COUNT` (default 50) held
//!   assemblies from seed `RANDOM_SEED_OFFSET` (default 0), by the methods of
//!   `RANDOM_METHODS` (default `grid`), with the harmonic selection's band
//!   `RANDOM_RESONANCE_BAND` (default 0: none): `cargo test --release --all-features --test
//!   random_assemblies -- --ignored --nocapture`.

use nonsmooth_modes::bar::Bar;
use nonsmooth_modes::branches::{
    compute, ArclengthBackboneOptions, BackboneOptions, EnergyBackboneOptions, Method,
    ModeBranches, Request, TimeDomainCheck, TRIVIAL_ENERGY,
};
use nonsmooth_modes::modal::drifting_bars;
use nonsmooth_modes::solve::{NewtonOptions, SemismoothNewton, Solver};
use nonsmooth_modes::system::{AssemblyBuilder, BarSystem, HarmonicBalanceSettings};
use nonsmooth_modes::verify::{periodicity_check, PeriodicityOptions};
use nonsmooth_modes::{Error, SettingsError};

/// The gap of every unilateral condition (the results are homogeneous in it).
const GAP: f64 = 1e-3;

/// SplitMix64: a seeded generator with no dependency.
struct Draw(u64);

impl Draw {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in `[lo, hi)`.
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Uniform in `0..n`.
    fn index(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

/// What holds an outer end.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Outer {
    Clamped,
    Free,
    Spring(f64),
    Wall,
}

/// One drawn assembly and how it was drawn.
struct Drawn {
    system: BarSystem,
    description: String,
}

/// The assembly of `seed`.
fn draw(seed: u64) -> Drawn {
    let mut d = Draw(seed);
    let n = 1 + d.index(4);
    let bars: Vec<Bar> = (0..n)
        .map(|_| {
            let (l, c, k) = (
                d.uniform(0.5, 3.0),
                d.uniform(0.5, 3.0),
                d.uniform(0.5, 3.0),
            );
            Bar::new(l, c, k).expect("positive finite values")
        })
        .collect();
    let mut outer = || match d.index(4) {
        0 => Outer::Clamped,
        1 => Outer::Free,
        2 => Outer::Spring(d.uniform(0.5, 3.0)),
        _ => Outer::Wall,
    };
    let (mut left, mut right) = (outer(), outer());
    // A single bar needs a wall to have a unilateral condition.
    if n == 1 && left != Outer::Wall && right != Outer::Wall {
        right = Outer::Wall;
    }
    // Something must hold the assembly to the ground.
    if left == Outer::Free && right == Outer::Free {
        left = Outer::Wall;
    }
    let mut b = AssemblyBuilder::new();
    let ids: Vec<_> = bars.iter().map(|&bar| b.add_bar(bar)).collect();
    let hold = |b: &mut AssemblyBuilder, end, how| -> Result<(), nonsmooth_modes::ModelError> {
        match how {
            Outer::Clamped => b.dirichlet(end).map(drop),
            Outer::Free => b.neumann(end).map(drop),
            Outer::Spring(k) => b.robin(end, k).map(drop),
            Outer::Wall => b.signorini(end, GAP).map(drop),
        }
    };
    hold(&mut b, ids[0].left(), left).expect("a valid condition");
    for pair in ids.windows(2) {
        b.contact(pair[0].right(), pair[1].left(), GAP)
            .expect("a valid contact");
    }
    hold(&mut b, ids[n - 1].right(), right).expect("a valid condition");
    let description = format!(
        "seed {seed}: {n} bars {:?}, left {left:?}, right {right:?}",
        bars.iter()
            .map(|b| (b.length(), b.wave_speed(), b.stiffness()))
            .collect::<Vec<_>>()
    );
    Drawn {
        system: b.build().expect("a complete assembly"),
        description,
    }
}

/// What became of one assembly's default backbone.
#[derive(Debug)]
enum Outcome {
    /// Refused: a bar can drift away.
    Unconfined,
    /// A typed error before any point.
    Refused(Error),
    /// The run: converged points, and those whose time-domain displacement defect is below
    /// 5 % (`None` where the check was not asked for or cannot be made).
    Run {
        converged: usize,
        checked: Option<usize>,
    },
}

/// How a backbone is computed: each method's defaults from the system.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Way {
    /// The period grid ([`BackboneOptions::for_mode`]), fail-fast Newton.
    Grid,
    /// Pseudo-arclength in the frequency ([`ArclengthBackboneOptions::for_mode`]), Newton.
    Arclength,
    /// Sequential in the energy ([`EnergyBackboneOptions::for_mode`]), fail-fast Newton.
    Energy,
    /// The library's choice, [`Method::Auto`], with its own solvers and the library's
    /// time-domain check (by which it judges its period grid).
    Auto,
}

/// Converged points below which the census's "arclength, then grid" falls back to the
/// period grid: a rule `docs/assemblies.md` compares with `Method::Auto`.
const AUTO_POINTS: usize = 20;

impl Way {
    fn parse(name: &str) -> Option<Self> {
        match name.trim() {
            "grid" => Some(Self::Grid),
            "arclength" => Some(Self::Arclength),
            "energy" => Some(Self::Energy),
            "auto" => Some(Self::Auto),
            _ => None,
        }
    }

    /// The backbone of `system` by this way, and the fraction of `E_g` below which a point
    /// is at rest.
    fn backbone(
        self,
        system: &BarSystem,
        settings: HarmonicBalanceSettings,
    ) -> Result<(ModeBranches, f64), Error> {
        let fail_fast = || {
            let newton = SemismoothNewton::new(NewtonOptions::fail_fast()).expect("valid options");
            Some(Solver::Newton(newton))
        };
        let (method, solver) = match self {
            Self::Grid => (
                Method::PeriodGrid(BackboneOptions::for_mode(system, 1, 1)?),
                fail_fast(),
            ),
            Self::Arclength => (
                Method::Arclength(ArclengthBackboneOptions::for_mode(system, 1, 1)?),
                Some(Solver::default()),
            ),
            Self::Energy => (
                Method::Energy(EnergyBackboneOptions::for_mode(system, 1, 1)?),
                fail_fast(),
            ),
            Self::Auto => (Method::Auto(None), None),
        };
        let mut request = Request {
            settings,
            method,
            solver,
            ..Request::new(1)
        };
        // Auto's points carry the time-domain check (it annotates them; Auto's judge is the
        // same without it).
        if self == Self::Auto {
            request.check = Some(TimeDomainCheck::for_system(system));
        }
        // The energy backbone never accepts a point at rest: its levels start at `E_g`.
        Ok((compute(system, &request)?, TRIVIAL_ENERGY))
    }
}

/// The backbone of `system` by `method` at `harmonics`, checking the invariants every run
/// must keep; `verify` marches each converged point one period in time.
fn run(system: &BarSystem, method: Way, harmonics: usize, verify: bool) -> Outcome {
    let settings = HarmonicBalanceSettings {
        harmonics,
        resonance_band: env_real("RANDOM_RESONANCE_BAND", 0.0),
        ..HarmonicBalanceSettings::default()
    };
    let result = method.backbone(system, settings);
    let drifting = drifting_bars(system);
    let (bb, trivial_energy) = match result {
        Err(Error::Settings(SettingsError::Unconfined { bars })) => {
            assert_eq!(Some(bars), drifting, "the error names the drifting bars");
            return Outcome::Unconfined;
        }
        Err(e) => {
            assert!(drifting.is_none(), "a drifting assembly is refused as such");
            assert!(!e.to_string().is_empty());
            return Outcome::Refused(e);
        }
        Ok(bb) => bb,
    };
    assert!(drifting.is_none(), "a drifting assembly is refused");
    let converged: Vec<_> = bb.converged().collect();
    assert!(
        !converged.is_empty() || bb.error().is_some(),
        "a run without a converged point ends with a typed reason"
    );
    for p in &converged {
        assert!(p.energy_normalized.is_finite() && p.energy_normalized > trivial_energy);
    }
    let checked = verify.then(|| {
        let problem = nonsmooth_modes::system::NonsmoothSystem::new(system, settings)
            .expect("the settings the backbone used");
        converged
            .iter()
            .filter(|p| {
                let options = PeriodicityOptions {
                    adjust_grid: true,
                    ..PeriodicityOptions::default()
                };
                periodicity_check(system, problem.basis(), &p.x, p.omega, &options)
                    .is_ok_and(|r| r.displacement_defect < 0.05)
            })
            .count()
    });
    Outcome::Run {
        converged: converged.len(),
        checked,
    }
}

/// The invariants of every run, on the first assemblies of the sequence at `m = 8`: a
/// drifting assembly is refused as such, a run without a converged point ends with a typed
/// reason, and no converged point is at rest or non-finite.
#[test]
fn every_assembly_gives_a_branch_or_a_typed_reason() {
    let mut outcomes = Vec::new();
    for seed in 0..12 {
        let drawn = draw(seed);
        let outcome = run(&drawn.system, Way::Grid, 8, false);
        eprintln!("{}: {outcome:?}", drawn.description);
        outcomes.push(outcome);
    }
    // The sequence holds both kinds, so both paths are exercised.
    assert!(outcomes.iter().any(|o| matches!(o, Outcome::Unconfined)));
    assert!(outcomes
        .iter()
        .any(|o| matches!(o, Outcome::Run { converged, .. } if *converged > 0)));
}

/// Asking [`Method::Auto`] for the time-domain check annotates its answer and does not
/// change it: on the held assemblies of the sequence at `m = 8`, the same points (period,
/// energy, convergence), the same choice of runs, and the check's outcome on each converged
/// point of the checked request.
#[test]
fn asking_for_the_check_does_not_change_the_answer() {
    let settings = HarmonicBalanceSettings {
        harmonics: 8,
        ..HarmonicBalanceSettings::default()
    };
    let mut compared = 0;
    for seed in 0..12 {
        let drawn = draw(seed);
        if drifting_bars(&drawn.system).is_some() {
            continue;
        }
        let plain = Request::new(1).settings(settings);
        let checked = plain
            .clone()
            .checked(TimeDomainCheck::for_system(&drawn.system));
        let (Ok(a), Ok(b)) = (
            compute(&drawn.system, &plain),
            compute(&drawn.system, &checked),
        ) else {
            continue;
        };
        let d = &drawn.description;
        assert_eq!(a.points.len(), b.points.len(), "{d}");
        assert_eq!((a.auto, a.selection), (b.auto, b.selection), "{d}");
        for (p, q) in a.points.iter().zip(&b.points) {
            assert_eq!(
                (p.period, p.energy, p.converged()),
                (q.period, q.energy, q.converged())
            );
            assert!(p.check.is_none(), "{d}: the plain request checks nothing");
            assert_eq!(
                q.check.is_some(),
                q.converged() && q.character.is_some(),
                "{d}"
            );
        }
        compared += 1;
    }
    assert!(compared >= 4, "{compared} assemblies compared");
}

/// The energy backbone refuses the drifting assemblies of the sequence as the others do,
/// before any solve.
#[test]
fn the_energy_backbone_refuses_drifting_assemblies() {
    let mut refused = 0;
    for seed in 0..12 {
        let drawn = draw(seed);
        if drifting_bars(&drawn.system).is_none() {
            continue;
        }
        let outcome = run(&drawn.system, Way::Energy, 8, false);
        assert!(matches!(outcome, Outcome::Unconfined), "{outcome:?}");
        refused += 1;
    }
    assert!(refused > 0);
}

/// The number in environment variable `name`, or `default` if unset or unreadable.
fn env_real(name: &str, default: f64) -> f64 {
    std::env::var(name)
        .ok()
        .and_then(|v| v.trim().parse().ok())
        .unwrap_or(default)
}

fn env_number(name: &str, default: usize) -> usize {
    std::env::var(name)
        .ok()
        .and_then(|v| v.trim().parse().ok())
        .unwrap_or(default)
}

/// The census of `docs/assemblies.md`: of `RANDOM_COUNT` held assemblies, how many give a
/// branch of at least 20 converged points whose time-domain displacement defect is below
/// 5 %, at `RANDOM_HARMONICS` harmonics, by each method of `RANDOM_METHODS` (a comma list of
/// `grid`, `arclength`, `energy`; default `grid`), over the seeds from `RANDOM_SEED_OFFSET`
/// (default 0). With both `grid` and `arclength`, also the rule "arclength, and the period
/// grid where arclength converges fewer than [`AUTO_POINTS`] points".
#[test]
#[ignore = "minutes; the figures of docs/assemblies.md"]
fn random_assembly_census() {
    let count = env_number("RANDOM_COUNT", 50);
    let harmonics = env_number("RANDOM_HARMONICS", 20);
    let offset = env_number("RANDOM_SEED_OFFSET", 0) as u64;
    let names = std::env::var("RANDOM_METHODS").unwrap_or_else(|_| "grid".into());
    let methods: Vec<Way> = names.split(',').filter_map(Way::parse).collect();
    assert!(
        !methods.is_empty(),
        "RANDOM_METHODS names no method: {names}"
    );
    // Per method: good, converged but fewer than 20 checked, refused, no point converged.
    let mut tally = vec![[0usize; 4]; methods.len() + 1];
    let position = |m: Way| methods.iter().position(|&n| n == m);
    let auto = position(Way::Arclength).zip(position(Way::Grid));
    let (mut held, mut unconfined) = (0, 0);
    let mut seed = offset;
    while held < count {
        let drawn = draw(seed);
        seed += 1;
        println!("{}", drawn.description);
        let mut outcomes = methods
            .iter()
            .map(|&method| (method, run(&drawn.system, method, harmonics, true)));
        let Some(first) = outcomes.next() else {
            break;
        };
        if matches!(first.1, Outcome::Unconfined) {
            unconfined += 1;
            continue;
        }
        held += 1;
        let mut classes = Vec::new();
        for (method, outcome) in std::iter::once(first).chain(outcomes) {
            println!("  {method:?}: {outcome:?}");
            let converged = match outcome {
                Outcome::Run { converged, .. } => converged,
                _ => 0,
            };
            let class = match outcome {
                Outcome::Unconfined => 2,
                Outcome::Refused(e) => {
                    println!("    refused: {e}");
                    2
                }
                Outcome::Run { checked, .. } if checked.unwrap_or(0) >= 20 => 0,
                Outcome::Run { converged: 0, .. } => 3,
                Outcome::Run { .. } => 1,
            };
            classes.push((class, converged));
        }
        for (k, &(class, _)) in classes.iter().enumerate() {
            tally[k][class] += 1;
        }
        if let Some((arclength, grid)) = auto {
            let chosen = if classes[arclength].1 >= AUTO_POINTS {
                arclength
            } else {
                grid
            };
            tally[methods.len()][classes[chosen].0] += 1;
        }
    }
    println!(
        "m = {harmonics}, {held} held assemblies ({unconfined} drifting ones refused, seeds \
         {offset}..{seed}):"
    );
    let mut names: Vec<String> = methods.iter().map(|m| format!("{m:?}")).collect();
    names.push("auto (arclength, grid below 20 points)".into());
    let rows = if auto.is_some() {
        tally.len()
    } else {
        methods.len()
    };
    for (method, [good, few, refused, none]) in names.iter().zip(&tally).take(rows) {
        println!(
            "  {method}: {good} give >= 20 checked points (defect < 5 %), {few} fewer, \
             {refused} refused with a typed reason, {none} without a converged point"
        );
        assert!(good + refused <= held);
    }
}

/// The exact-branch census of `docs/validation.md`: of `RANDOM_COUNT` (default 10) held
/// assemblies from seed `RANDOM_SEED_OFFSET`, those with a verified harmonic-balance backbone
/// at `m = 20` (at least 20 converged points passing the time-domain check on the system's
/// grid), and among them those whose exact branch over the grid's first 25 periods
/// (`Request::with_exact`, `ExactOptions::for_request`: the grid the system can afford) has
/// at least 20 points with a verdict.
#[test]
#[ignore = "minutes; the exact census of docs/validation.md"]
fn random_assembly_exact_census() {
    use nonsmooth_modes::branches::PeriodGrid;
    use nonsmooth_modes::exact::ExactOptions;
    let count = env_number("RANDOM_COUNT", 10);
    let offset = env_number("RANDOM_SEED_OFFSET", 0) as u64;
    let (mut held, mut verified, mut exact_ok, mut seed) = (0, 0, 0, offset);
    while held < count {
        let drawn = draw(seed);
        seed += 1;
        let hb = run(&drawn.system, Way::Grid, 20, true);
        let checked = match hb {
            Outcome::Unconfined => continue,
            Outcome::Run { checked, .. } => checked.unwrap_or(0),
            Outcome::Refused(_) => 0,
        };
        held += 1;
        println!("{}\n  harmonic balance: {hb:?}", drawn.description);
        if checked < 20 {
            continue;
        }
        verified += 1;
        let mut options = BackboneOptions::for_mode(&drawn.system, 1, 1).unwrap();
        let step = (options.grid.end - options.grid.start) / (options.grid.steps - 1) as f64;
        options.grid = PeriodGrid {
            end: options.grid.start + 24.0 * step,
            steps: 25,
            ..options.grid
        };
        let request = Request::new(1)
            .harmonics(20)
            .method(Method::PeriodGrid(options));
        let exact = ExactOptions::for_request(&drawn.system, &request).unwrap();
        println!(
            "  exact on {} cells per shortest travel time",
            exact.stability.cells_per_travel
        );
        let request = request.with_exact(exact);
        let start = std::time::Instant::now();
        let exact = compute(&drawn.system, &request).map(|r| r.exact);
        let seconds = start.elapsed().as_secs_f64();
        match exact {
            Ok(Some(Ok(branch))) => {
                let resolved = branch
                    .points
                    .iter()
                    .filter(|p| {
                        let f = p.point.stability.as_ref().and_then(|s| s.as_ref().ok());
                        f.is_some_and(|f| f.verdict.stable().is_some())
                    })
                    .count();
                println!(
                    "  exact: {} points, {resolved} with a verdict, {} skipped, {:?}, {seconds:.1} s",
                    branch.points.len(),
                    branch.skipped.len(),
                    branch.end
                );
                if resolved >= 20 {
                    exact_ok += 1;
                }
            }
            Ok(Some(Err(e))) | Err(e) => println!("  exact: {e} ({seconds:.1} s)"),
            Ok(None) => panic!("compute asked for an exact branch returned none"),
        }
    }
    println!(
        "m = 20, {held} held assemblies (seeds {offset}..{seed}): {verified} with a verified \
         backbone, {exact_ok} of them with an exact branch of at least 20 points with a verdict"
    );
    assert!(exact_ok <= verified && verified <= held);
}
