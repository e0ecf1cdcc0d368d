//! The harness: each case drawn from its own seed and run under `catch_unwind` on a worker
//! thread, with a panic hook recording the message, a hang bound, and the summary table.

use crate::cases::{Kind, KINDS};
use crate::checks::Checks;
use crate::draw::{Draw, SplitMix};
use std::collections::BTreeMap;
use std::panic::{self, AssertUnwindSafe};
use std::sync::{mpsc, Arc, Mutex};
use std::time::{Duration, Instant};

/// A case that has not answered after this long is a hang (a valid case takes milliseconds).
pub(crate) const HANG_SECONDS: u64 = 60;

/// A case that answers after this many seconds counts as slow in the report.
const SLOW_SECONDS: f64 = 5.0;

/// How many of the slowest cases the report lists.
const SLOWEST_LISTED: usize = 5;

/// How a case ended.
#[derive(Debug, Clone, PartialEq)]
enum Outcome {
    Ok,
    TypedError,
    Panic(String),
    NonFinite(String),
    NoEnd(String),
    Wrong(String),
    Hang,
}

/// One case's report.
pub(crate) struct Report {
    index: usize,
    kind: Kind,
    outcome: Outcome,
    inputs: String,
}

/// The message and place of the last panic, recorded by the harness' panic hook.
static LAST_PANIC: Mutex<Option<String>> = Mutex::new(None);
/// One stress run at a time: the panic hook is global.
static SUITE: Mutex<()> = Mutex::new(());

/// The seed of case `index`: a SplitMix64 step of the base seed and the index, so that a
/// case can be rerun alone (`STRESS_ONLY=index`).
fn case_seed(base: u64, index: usize) -> u64 {
    SplitMix(base ^ (index as u64).wrapping_mul(0xD1B5_4A32_D192_ED03)).next()
}

/// Draws and runs case `index`; its inputs go to `log` as they are drawn.
fn run_case(base: u64, index: usize, log: Arc<Mutex<String>>) -> Report {
    let mut rng = SplitMix(case_seed(base, index));
    let kind = KINDS[rng.below(KINDS.len() as u64) as usize];
    let edge = [0.0, 0.05, 0.15, 0.4][rng.below(4) as usize];
    let mut draw = Draw {
        rng,
        log: Arc::clone(&log),
        edge,
    };
    let mut checks = Checks::default();
    *LAST_PANIC.lock().unwrap_or_else(|e| e.into_inner()) = None;
    let result = panic::catch_unwind(AssertUnwindSafe(|| kind.run(&mut draw, &mut checks)));
    let outcome = match result {
        Err(payload) => {
            let recorded = LAST_PANIC.lock().unwrap_or_else(|e| e.into_inner()).take();
            let message = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned());
            Outcome::Panic(recorded.or(message).unwrap_or_default())
        }
        Ok(_) if !checks.non_finite.is_empty() => Outcome::NonFinite(checks.non_finite.join("; ")),
        Ok(_) if !checks.no_end.is_empty() => Outcome::NoEnd(checks.no_end.join("; ")),
        Ok(_) if !checks.wrong.is_empty() => Outcome::Wrong(checks.wrong.join("; ")),
        Ok(Ok(())) => Outcome::Ok,
        Ok(Err(message)) => {
            if std::env::var_os("STRESS_ERRORS").is_some() {
                println!("typed {kind:?}: {message}");
            }
            Outcome::TypedError
        }
    };
    let inputs = log.lock().unwrap_or_else(|e| e.into_inner()).clone();
    Report {
        index,
        kind,
        outcome,
        inputs,
    }
}

/// A thread that runs the cases it is sent; replaced when a case hangs.
struct Worker {
    cases: mpsc::Sender<(usize, Arc<Mutex<String>>)>,
    reports: mpsc::Receiver<Report>,
}

impl Worker {
    fn spawn(base: u64) -> Self {
        let (cases, jobs) = mpsc::channel::<(usize, Arc<Mutex<String>>)>();
        let (done, reports) = mpsc::channel();
        std::thread::Builder::new()
            .name("stress case".into())
            .spawn(move || {
                for (index, log) in jobs {
                    if done.send(run_case(base, index, log)).is_err() {
                        break;
                    }
                }
            })
            .expect("spawn the worker");
        Self { cases, reports }
    }
}

#[derive(Default)]
struct Counts {
    cases: usize,
    ok: usize,
    typed: usize,
    panics: usize,
    non_finite: usize,
    no_end: usize,
    wrong: usize,
    hangs: usize,
}

impl Counts {
    fn add(&mut self, outcome: &Outcome) {
        self.cases += 1;
        match outcome {
            Outcome::Ok => self.ok += 1,
            Outcome::TypedError => self.typed += 1,
            Outcome::Panic(_) => self.panics += 1,
            Outcome::NonFinite(_) => self.non_finite += 1,
            Outcome::NoEnd(_) => self.no_end += 1,
            Outcome::Wrong(_) => self.wrong += 1,
            Outcome::Hang => self.hangs += 1,
        }
    }

    fn row(&self, name: &str) -> String {
        format!(
            "{name:<20} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7}",
            self.cases,
            self.ok,
            self.typed,
            self.panics,
            self.non_finite,
            self.no_end,
            self.wrong,
            self.hangs
        )
    }
}

/// Runs `indices` of the suite of seed `base`, prints the summary and every failure, and
/// returns the failures.
pub(crate) fn run_suite(base: u64, indices: impl Iterator<Item = usize>) -> Vec<Report> {
    let _one_at_a_time = SUITE.lock().unwrap_or_else(|e| e.into_inner());
    let previous_hook = panic::take_hook();
    panic::set_hook(Box::new(|info| {
        *LAST_PANIC.lock().unwrap_or_else(|e| e.into_inner()) = Some(info.to_string());
    }));
    let started = Instant::now();
    let mut worker = Worker::spawn(base);
    let mut per_kind: BTreeMap<Kind, Counts> = BTreeMap::new();
    let mut total = Counts::default();
    let mut failures = Vec::new();
    // The slowest cases that answered, slowest first: (seconds, index, kind); and how many
    // answered after `SLOW_SECONDS`.
    let mut slowest: Vec<(f64, usize, Kind)> = Vec::new();
    let mut slow = 0;
    for index in indices {
        let log = Arc::new(Mutex::new(String::new()));
        let sent = Instant::now();
        worker
            .cases
            .send((index, Arc::clone(&log)))
            .expect("the worker takes cases");
        let report = match worker
            .reports
            .recv_timeout(Duration::from_secs(HANG_SECONDS))
        {
            Ok(report) => {
                let seconds = sent.elapsed().as_secs_f64();
                slow += usize::from(seconds > SLOW_SECONDS);
                slowest.push((seconds, index, report.kind));
                slowest.sort_by(|a, b| b.0.total_cmp(&a.0));
                slowest.truncate(SLOWEST_LISTED);
                report
            }
            Err(_) => {
                // The hung thread cannot be stopped: leave it and carry on with a new one.
                worker = Worker::spawn(base);
                let inputs = log.lock().unwrap_or_else(|e| e.into_inner()).clone();
                let kind =
                    KINDS[SplitMix(case_seed(base, index)).below(KINDS.len() as u64) as usize];
                Report {
                    index,
                    kind,
                    outcome: Outcome::Hang,
                    inputs,
                }
            }
        };
        per_kind
            .entry(report.kind)
            .or_default()
            .add(&report.outcome);
        total.add(&report.outcome);
        if !matches!(report.outcome, Outcome::Ok | Outcome::TypedError) {
            // At once too: a run with hangs takes long to reach the summary.
            eprintln!("failing case {index}: {:?}", report.outcome);
            failures.push(report);
        }
    }
    let elapsed = started.elapsed();
    panic::set_hook(previous_hook);
    println!(
        "\nstress suite, seed {base:#x}: {} cases in {:.1} s",
        total.cases,
        elapsed.as_secs_f64()
    );
    println!(
        "{:<20} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7}",
        "kind", "cases", "ok", "typed", "panic", "nonfin", "no end", "wrong", "hang"
    );
    for (kind, counts) in &per_kind {
        println!("{}", counts.row(&format!("{kind:?}")));
    }
    println!("{}", total.row("total"));
    println!("slow cases (over {SLOW_SECONDS} s): {slow}");
    for (seconds, index, kind) in &slowest {
        println!("slowest case: {index} ({kind:?}), {seconds:.2} s");
    }
    println!("aborts: 0 (the process finished)");
    for f in &failures {
        println!(
            "FAILURE case {} ({:?}) STRESS_SEED={base:#x} STRESS_ONLY={}: {:?}\n    inputs: {}",
            f.index, f.kind, f.index, f.outcome, f.inputs
        );
    }
    failures
}
