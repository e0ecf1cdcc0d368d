//! Command-line fuzz of the `backbone` and `frf` examples: random command lines, each run as a
//! child process, must exit with 0 (success), 1 (run failure) or 2 (usage error), never panic,
//! never die on a signal, explain every failure on stderr and end within [`TIMEOUT`].
//!
//! The tests run the example binary that cargo built next to this test
//! (`<target>/<profile>/examples/backbone`): `cargo test --release` builds it before running
//! the tests; with a target filter (`--test cli_fuzz`) build it first with
//! `cargo build --release --example backbone`. A missing or stale binary fails the test.
//!
//! `fuzz_short` runs [`SHORT_LINES`] lines; the ignored `fuzz_long` runs `CLI_FUZZ_LINES`
//! lines (default [`LONG_LINES`]):
//!
//! ```text
//! cargo test --release --all-features --test cli_fuzz -- --ignored --nocapture
//! ```
//!
//! The lines come from a seeded generator (`CLI_FUZZ_SEED` overrides the seed), so a run is
//! reproducible; every failing line is printed in a form that can be pasted into a shell.

use std::collections::BTreeMap;
use std::fs::File;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::time::{Duration, Instant, SystemTime};

/// A line still running after this long is killed and counted as a hang.
const TIMEOUT: Duration = Duration::from_secs(120);
/// Lines of the normal test.
const SHORT_LINES: usize = 60;
/// Default lines of the ignored long test.
const LONG_LINES: usize = 1000;

/// SplitMix64: a small deterministic generator.
struct Rng(u64);

impl Rng {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in `0..n` (`n > 0`).
    fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }

    /// Uniform in `lo..=hi`.
    fn between(&mut self, lo: usize, hi: usize) -> usize {
        lo + self.below(hi - lo + 1)
    }

    /// Uniform in `[0, 1)`.
    fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// True with probability `p`.
    fn chance(&mut self, p: f64) -> bool {
        self.unit() < p
    }

    fn pick<'a>(&mut self, items: &[&'a str]) -> &'a str {
        items[self.below(items.len())]
    }

    /// A number in `[lo, hi]`, uniform in its logarithm (both bounds positive).
    fn log_uniform(&mut self, lo: f64, hi: f64) -> f64 {
        (lo.ln() + self.unit() * (hi.ln() - lo.ln())).exp()
    }
}

/// What follows a flag, and which values of it are cheap and valid.
#[derive(Clone, Copy)]
enum Value {
    /// A switch: no value.
    Switch,
    /// One of these words.
    Word(&'static [&'static str]),
    /// An integer in `lo..=hi`.
    Count(usize, usize),
    /// A real in `[lo, hi]` (log-uniform).
    Real(f64, f64),
    /// `LO:HI` with both ends in `[lo, hi]`.
    Range(f64, f64),
    /// An output file.
    File,
}

/// The system flags both examples share, with their cheap valid values.
const SYSTEM_FLAGS: &[(&str, Value)] = &[
    ("system", Value::Word(&["ds", "rs", "two-bar"])),
    ("gap", Value::Real(5e-4, 2e-3)),
    ("robin-stiffness", Value::Real(0.2, 2.0)),
    ("length2", Value::Real(0.8, 1.2)),
    ("speed2", Value::Real(0.8, 1.2)),
    ("stiffness-ratio", Value::Real(0.5, 2.0)),
];

/// Every other flag of the `backbone` example with its cheap valid values.
const FLAGS: &[(&str, Value)] = &[
    ("harmonics", Value::Count(1, 30)),
    ("samples-per-harmonic", Value::Count(2, 48)),
    ("complementarity", Value::Real(0.5, 10.0)),
    ("resonance-band", Value::Real(0.01, 0.5)),
    ("mode", Value::Count(1, 3)),
    ("subharmonic", Value::Count(1, 3)),
    ("period-start", Value::Real(0.5, 12.0)),
    ("period-end", Value::Real(0.5, 12.0)),
    ("steps", Value::Count(2, 60)),
    ("solver", Value::Word(&["newton", "dogleg"])),
    ("newton", Value::Word(&["fail-fast", "full"])),
    ("retry-depth", Value::Count(0, 5)),
    ("max-failures", Value::Count(0, 50)),
    ("selection", Value::Word(&["first", "lowest-energy"])),
    ("serial", Value::Switch),
    ("out", Value::File),
    ("method", Value::Word(&["sequential", "down", "arclength"])),
    ("ds", Value::Real(1e-4, 0.1)),
    ("ds-min", Value::Real(1e-7, 1e-3)),
    ("ds-max", Value::Real(1e-2, 0.5)),
    ("max-steps", Value::Count(1, 300)),
    ("omega-range", Value::Range(0.5, 3.0)),
    (
        "parameter",
        Value::Word(&["omega", "gap", "robin-stiffness", "stiffness-ratio"]),
    ),
    ("parameter-range", Value::Range(1e-4, 5.0)),
    ("progress", Value::Switch),
    ("verify", Value::Switch),
    ("stability", Value::Switch),
    ("hill", Value::Switch),
    ("basis", Value::Word(&["cosine", "full"])),
    // The exact branch's grid: without `--exact` (not fuzzed: seconds per point) a usage
    // error, its values checked all the same.
    ("cells-per-travel", Value::Real(1.0, 1000.0)),
];

/// Every other flag of the `frf` example with its cheap valid values (`--steps` and
/// `--harmonics` are appended to every line: [`frf_tail`]).
const FRF_FLAGS: &[(&str, Value)] = &[
    ("samples-per-harmonic", Value::Count(2, 48)),
    ("complementarity", Value::Real(0.5, 10.0)),
    ("resonance-band", Value::Real(0.01, 0.5)),
    ("forcing", Value::Word(FORCINGS)),
    ("damping", Value::Real(1e-4, 0.1)),
    ("omega-range", Value::Range(0.3, 3.0)),
    ("steps", Value::Count(2, 40)),
    ("method", Value::Word(&["sequential", "down", "arclength"])),
    ("solver", Value::Word(&["newton", "dogleg"])),
    ("out", Value::File),
];

/// `--forcing` values: valid ones on the shorthands' ends, and malformed or impossible ones
/// (a force at a clamped end, a base motion at the contact end, unknown bars and sides).
const FORCINGS: &[&str] = &[
    "base:1.start:1e-6",
    "base:1.start:3e-6",
    "end:1.start:1e-6",
    "base:2.end:1e-6",
    "base:1.end:1e-6",
    "end:1.end:1e-6",
    "base:3.start:1e-6",
    "base:1.middle:1e-6",
    "shake:1.start:1e-6",
    "base:1.start:nan",
    "base:1.start:inf",
    "base:1.start",
    "base:1.start:0",
];

/// Edge values tried for any flag that takes a value.
const EDGES: &[&str] = &[
    "0",
    "1",
    "-1",
    "-0",
    "18446744073709551615",
    "18446744073709551616",
    // Over the example's limits (points, harmonics, samples) but within the library's budget.
    "1000001",
    "20000",
    // A period whose time-domain verification is over the example's limit.
    "1e4",
    "1e300",
    "1e309",
    "1e-320",
    "nan",
    "inf",
    "-inf",
    "",
    " 3",
    "0x10",
    "garbage",
    "--verify",
];

/// Edge values tried for `LO:HI` flags.
const RANGE_EDGES: &[&str] = &[
    "1:",
    ":2",
    ":",
    "2:1",
    "1:1",
    "nan:inf",
    "-1:1",
    "1e-320:1e300",
    "0:1e300",
    "1:2:3",
];

/// Arguments the example does not know.
const UNKNOWN: &[&str] = &[
    "--bogus",
    "-x",
    "positional",
    "--verify=1",
    "--Gap",
    "-",
    "--",
    "--help",
];

/// One random command line (without the program) of flags from `flags`. `dir` is where output
/// files may go.
fn command_line(
    rng: &mut Rng,
    (dir, index): (&Path, usize),
    tables: &[&[(&'static str, Value)]],
) -> Vec<String> {
    let flags: Vec<(&str, Value)> = tables.iter().flat_map(|t| t.iter().copied()).collect();
    let mut args = Vec::new();
    for _ in 0..rng.below(7) {
        if rng.chance(0.04) {
            args.push(rng.pick(UNKNOWN).to_string());
            continue;
        }
        let (name, value) = flags[rng.below(flags.len())];
        // `--name=value` is the same flag to the parser.
        let joined = rng.chance(0.1);
        let value = match value {
            Value::Switch => {
                args.push(format!("--{name}"));
                continue;
            }
            _ if rng.chance(0.12) => edge(rng, value).to_string(),
            _ => valid(rng, value, dir, index),
        };
        if joined {
            args.push(format!("--{name}={value}"));
        } else {
            args.push(format!("--{name}"));
            args.push(value);
        }
    }
    if rng.chance(0.05) {
        // A flag missing its value.
        let valued: Vec<&str> = flags
            .iter()
            .filter(|(_, v)| !matches!(v, Value::Switch))
            .map(|(name, _)| *name)
            .collect();
        args.push(format!("--{}", rng.pick(&valued)));
    }
    args
}

/// What the `backbone` lines always end with: sometimes a period grid whose ends are equal
/// (which the library refuses), and few points when they verify or compute multipliers or
/// Hill exponents (later flags override earlier ones).
fn backbone_tail(rng: &mut Rng, args: &mut Vec<String>) {
    if rng.chance(0.05) {
        let period = format!("{:.4e}", rng.log_uniform(0.5, 12.0));
        for flag in ["--period-start", "--period-end"] {
            args.push(flag.to_string());
            args.push(period.clone());
        }
    }
    if (args.iter()).any(|a| a == "--verify" || a == "--stability" || a == "--hill") {
        for flag in ["--steps", "--max-steps"] {
            args.push(flag.to_string());
            args.push(rng.between(2, 8).to_string());
        }
    }
    if args.iter().any(|a| a == "--hill") {
        // An arclength run may still give a thousand points, each a Hill search of 54
        // eigenvalue problems of the matrix's size.
        args.push("--harmonics".to_string());
        args.push(rng.between(2, 8).to_string());
    }
}

/// What the `frf` lines always hold: mostly a forcing (the example requires one), and few
/// harmonics and steps (its default steps follow the damping, up to many thousands).
fn frf_tail(rng: &mut Rng, args: &mut Vec<String>) {
    if rng.chance(0.85) {
        // Mostly one that every shorthand takes.
        let forcing = if rng.chance(0.7) {
            rng.pick(&FORCINGS[..2])
        } else {
            rng.pick(FORCINGS)
        };
        args.insert(0, "--forcing".to_string());
        args.insert(1, forcing.to_string());
    }
    for (flag, hi) in [("--steps", 40), ("--harmonics", 10)] {
        args.push(flag.to_string());
        args.push(rng.between(1, hi).to_string());
    }
}

/// An example under fuzz: its name, its sources, its flags and what every line ends with.
struct Cli {
    example: &'static str,
    source: &'static str,
    flags: &'static [&'static [(&'static str, Value)]],
    tail: fn(&mut Rng, &mut Vec<String>),
    /// Exit codes that must each occur at least once.
    codes: &'static [i32],
}

const BACKBONE: Cli = Cli {
    example: "backbone",
    source: "examples/backbone",
    flags: &[SYSTEM_FLAGS, FLAGS],
    tail: backbone_tail,
    codes: &[0, 1, 2],
};

const FRF: Cli = Cli {
    example: "frf",
    source: "examples/frf.rs",
    flags: &[SYSTEM_FLAGS, FRF_FLAGS],
    tail: frf_tail,
    codes: &[0, 2],
};

/// An edge value for a flag taking `value`.
fn edge(rng: &mut Rng, value: Value) -> &'static str {
    match value {
        Value::Range(..) if rng.chance(0.6) => rng.pick(RANGE_EDGES),
        _ => rng.pick(EDGES),
    }
}

/// A valid and cheap value.
fn valid(rng: &mut Rng, value: Value, dir: &Path, index: usize) -> String {
    match value {
        Value::Switch => String::new(),
        Value::Word(words) => rng.pick(words).to_string(),
        Value::Count(lo, hi) => rng.between(lo, hi).to_string(),
        Value::Real(lo, hi) => format!("{:.4e}", rng.log_uniform(lo, hi)),
        Value::Range(lo, hi) => {
            let (a, b) = (rng.log_uniform(lo, hi), rng.log_uniform(lo, hi));
            // Mostly rising; sometimes reversed or empty, which the library refuses.
            match rng.below(10) {
                0 => format!("{:.4e}:{:.4e}", a.max(b), a.min(b)),
                1 => format!("{a:.4e}:{a:.4e}"),
                _ => format!("{:.4e}:{:.4e}", a.min(b), a.max(b)),
            }
        }
        Value::File => match rng.below(4) {
            // A directory that does not exist.
            0 => dir.join("missing").join("out.csv"),
            // The directory itself.
            1 => dir.to_path_buf(),
            _ => dir.join(format!("line-{index}.csv")),
        }
        .display()
        .to_string(),
    }
}

/// How a line ended.
enum Outcome {
    /// The child exited on its own.
    Exited { status: ExitStatus, stderr: String },
    /// Killed after [`TIMEOUT`].
    Hang,
}

/// Runs the binary on `args` in the directory `dir` (where an edge value given to `--out`, a
/// relative path, lands); stdout is discarded and stderr goes through a file, so neither pipe
/// can fill up and block the child.
fn run_line(binary: &Path, args: &[String], dir: &Path, stderr_path: &Path) -> Outcome {
    let stderr_file = File::create(stderr_path).expect("create the stderr file");
    let mut child = Command::new(binary)
        .args(args)
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(stderr_file)
        .spawn()
        .expect("spawn the example");
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().expect("wait for the child") {
            break Some(status);
        }
        if start.elapsed() > TIMEOUT {
            // The child may end between the check and the kill: ignore that error.
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    match status {
        Some(status) => Outcome::Exited {
            status,
            stderr: String::from_utf8_lossy(&std::fs::read(stderr_path).unwrap_or_default())
                .into_owned(),
        },
        None => Outcome::Hang,
    }
}

/// Counts of a fuzz run and its failing lines.
#[derive(Default)]
struct Report {
    lines: usize,
    /// Exit code -> lines; `None` for a death by signal.
    codes: BTreeMap<Option<i32>, usize>,
    panics: usize,
    hangs: usize,
    /// Nonzero exits with an empty stderr.
    unexplained: usize,
    /// Each failing line with what went wrong.
    failures: Vec<String>,
}

impl Report {
    fn record(&mut self, line: &str, outcome: &Outcome) {
        self.lines += 1;
        let mut problems = Vec::new();
        match outcome {
            Outcome::Hang => {
                self.hangs += 1;
                problems.push(format!("no exit within {} s", TIMEOUT.as_secs()));
            }
            Outcome::Exited { status, stderr } => {
                let code = status.code();
                *self.codes.entry(code).or_default() += 1;
                if stderr.contains("panicked") || code == Some(101) {
                    self.panics += 1;
                    problems.push("panic".to_string());
                }
                if !matches!(code, Some(0..=2)) {
                    problems.push(format!("exit status {status}"));
                }
                if !status.success() && stderr.trim().is_empty() {
                    self.unexplained += 1;
                    problems.push("failure with an empty stderr".to_string());
                }
                if !problems.is_empty() {
                    problems.push(format!("stderr: {}", stderr.trim()));
                }
            }
        }
        if !problems.is_empty() {
            self.failures
                .push(format!("{line}\n    {}", problems.join("\n    ")));
        }
    }

    fn count(&self, code: i32) -> usize {
        self.codes.get(&Some(code)).copied().unwrap_or(0)
    }

    fn summary(&self) -> String {
        let other: usize = self
            .codes
            .iter()
            .filter(|(code, _)| !matches!(code, Some(0..=2)))
            .map(|(_, n)| n)
            .sum();
        format!(
            "cli_fuzz: {} lines; exit 0: {}, exit 1: {}, exit 2: {}, other: {other}; \
             panics: {}, hangs: {}, unexplained failures: {}",
            self.lines,
            self.count(0),
            self.count(1),
            self.count(2),
            self.panics,
            self.hangs,
            self.unexplained
        )
    }
}

/// A temporary directory removed when dropped.
struct TempDir(PathBuf);

impl TempDir {
    fn new(name: &str) -> Self {
        let path = std::env::temp_dir().join(format!(
            "nonsmooth-modes-cli-fuzz-{name}-{}",
            std::process::id()
        ));
        std::fs::create_dir_all(&path).expect("create the temporary directory");
        Self(path)
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// The newest modification time of a file or of the files under a directory.
fn newest(path: &Path) -> SystemTime {
    let own = std::fs::metadata(path)
        .and_then(|m| m.modified())
        .unwrap_or(SystemTime::UNIX_EPOCH);
    let children = std::fs::read_dir(path)
        .into_iter()
        .flatten()
        .flatten()
        .map(|entry| newest(&entry.path()));
    children.fold(own, SystemTime::max)
}

/// The binary of example `name` of this test's profile; fails the test if it is missing or
/// older than `source` (a file or folder), `src` or `Cargo.toml`.
fn example_binary(name: &str, source: &str) -> PathBuf {
    let exe = std::env::current_exe().expect("the test's own path");
    // The test is `<target>/<profile>/deps/cli_fuzz-<hash>`.
    let profile = exe
        .parent()
        .and_then(Path::parent)
        .expect("the test lives in <target>/<profile>/deps");
    let binary = profile
        .join("examples")
        .join(format!("{name}{}", std::env::consts::EXE_SUFFIX));
    let release = if profile.ends_with("release") {
        " --release"
    } else {
        ""
    };
    let built = std::fs::metadata(&binary)
        .and_then(|m| m.modified())
        .unwrap_or_else(|e| {
            panic!(
                "the {name} example is not built ({}: {e}): run `cargo build{release} \
                 --all-features --example {name}` first",
                binary.display()
            )
        });
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let sources = [source, "src", "Cargo.toml"]
        .iter()
        .map(|p| newest(&root.join(p)))
        .fold(SystemTime::UNIX_EPOCH, SystemTime::max);
    assert!(
        built >= sources,
        "{} is older than its sources: run `cargo build{release} --all-features --example {name}` first",
        binary.display()
    );
    binary
}

/// `args` quoted for a POSIX shell.
fn shell_line(binary: &Path, args: &[String]) -> String {
    std::iter::once(binary.display().to_string())
        .chain(args.iter().cloned())
        .map(|a| format!("'{}'", a.replace('\'', r"'\''")))
        .collect::<Vec<_>>()
        .join(" ")
}

/// A number from the environment variable `name`, or `default`.
fn from_env<T: std::str::FromStr>(name: &str, default: T) -> T {
    match std::env::var(name) {
        Ok(text) => text
            .parse()
            .unwrap_or_else(|_| panic!("{name} must be a number, got `{text}`")),
        Err(_) => default,
    }
}

/// Runs `lines` random lines from `seed` and fails on any panic, signal, unknown exit code,
/// unexplained failure or hang; also fails if any of the exit codes 0, 1 and 2 never occurs
/// (the lines would not be exercising the example).
fn fuzz(cli: &Cli, name: &str, lines: usize, seed: u64) {
    let binary = example_binary(cli.example, cli.source);
    let dir = TempDir::new(name);
    let stderr_path = dir.0.join("stderr.txt");
    let mut rng = Rng(seed);
    let mut report = Report::default();
    let mut slowest = (Duration::ZERO, String::new());
    for index in 0..lines {
        let mut args = command_line(&mut rng, (&dir.0, index), cli.flags);
        (cli.tail)(&mut rng, &mut args);
        let start = Instant::now();
        let outcome = run_line(&binary, &args, &dir.0, &stderr_path);
        let line = shell_line(&binary, &args);
        if start.elapsed() > slowest.0 {
            slowest = (start.elapsed(), line.clone());
        }
        report.record(&line, &outcome);
    }
    println!("{}: {} (seed {seed})", cli.example, report.summary());
    println!(
        "slowest line, {:.1} s: {}",
        slowest.0.as_secs_f64(),
        slowest.1
    );
    for failure in &report.failures {
        println!("FAILED: {failure}");
    }
    assert!(
        report.failures.is_empty(),
        "{} of {lines} lines failed (listed above)",
        report.failures.len()
    );
    for &code in cli.codes {
        assert!(
            report.count(code) > 0,
            "no line exited with {code}: {}",
            report.summary()
        );
    }
}

#[test]
fn fuzz_short() {
    fuzz(
        &BACKBONE,
        "short",
        SHORT_LINES,
        from_env("CLI_FUZZ_SEED", 0x5eed),
    );
}

#[test]
#[ignore = "long: 1,000 lines by default (CLI_FUZZ_LINES)"]
fn fuzz_long() {
    fuzz(
        &BACKBONE,
        "long",
        from_env("CLI_FUZZ_LINES", LONG_LINES),
        from_env("CLI_FUZZ_SEED", 0x1000_5eed),
    );
}

#[test]
fn fuzz_frf_short() {
    fuzz(
        &FRF,
        "frf-short",
        SHORT_LINES,
        from_env("CLI_FUZZ_SEED", 0x5eed),
    );
}

#[test]
#[ignore = "long: 1,000 lines by default (CLI_FUZZ_LINES)"]
fn fuzz_frf_long() {
    fuzz(
        &FRF,
        "frf-long",
        from_env("CLI_FUZZ_LINES", LONG_LINES),
        from_env("CLI_FUZZ_SEED", 0x1000_5eed),
    );
}

/// A range the library refuses as given is a usage error: exit code 2, the range quoted on
/// stderr as typed (a period grid from 3.5 to 3.5 once computed 181 identical points; a
/// reversed forcing range was reported as an empty continuation option, with neither end).
#[test]
fn degenerate_ranges_are_usage_errors() {
    let forcing = [
        "--system",
        "ds",
        "--forcing",
        "base:1.start:1e-6",
        "--damping",
        "1e-3",
    ];
    let reversed: Vec<&str> = forcing
        .iter()
        .copied()
        .chain(["--omega-range", "2:1"])
        .collect();
    let cases: [(&Cli, &[&str], &[&str]); 3] = [
        (
            &BACKBONE,
            &["--period-start", "3.5", "--period-end", "3.5"],
            &["period grid from 3.5 to 3.5 in 181 steps is empty"],
        ),
        (
            &BACKBONE,
            &["--period-start", "-3.5"],
            &["period grid from -3.5 to 3.05", "not positive"],
        ),
        (
            &FRF,
            &reversed,
            &["forcing frequency range from 2 to 1 is reversed"],
        ),
    ];
    for (cli, args, quoted) in cases {
        let binary = example_binary(cli.example, cli.source);
        let output = Command::new(&binary)
            .args(args)
            .stdin(Stdio::null())
            .output()
            .expect("spawn the example");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{args:?}: {stderr}");
        for text in quoted {
            assert!(stderr.contains(text), "{args:?}: {stderr}");
        }
        assert!(stderr.contains("usage:"), "{args:?}: {stderr}");
    }
}

/// The `gallery` example refuses what it does not know before any computation: an unknown
/// argument or `--out` without a folder exit with 2 and the usage, a folder that cannot be
/// created with 1 and the reason; none panics.
#[cfg(feature = "plot")]
#[test]
fn gallery_refuses_bad_arguments() {
    let binary = example_binary("gallery", "examples/gallery.rs");
    let cases: [(&[&str], i32, &str); 3] = [
        (&["--bogus"], 2, "usage: gallery"),
        (&["--out"], 2, "usage: gallery"),
        (&["--out", "/dev/null/inside", "--quick"], 1, "gallery:"),
    ];
    for (args, code, message) in cases {
        let output = Command::new(&binary)
            .args(args)
            .output()
            .expect("spawn the gallery example");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(code), "{args:?}: {stderr}");
        assert!(stderr.contains(message), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    }
}

/// `backbone --exact` and its grid refuse what they cannot use with the usage code 2 and a
/// message quoting it, before any march; none panics.
#[test]
fn exact_refuses_bad_arguments() {
    let binary = example_binary("backbone", "examples/backbone");
    let exact = ["--system", "ds", "--exact", "--steps", "3"];
    let cases: [(&[&str], &str); 7] = [
        (&["--cells-per-travel", "0"], "got 0"),
        (&["--cells-per-travel", "nan"], "got NaN"),
        (&["--cells-per-travel", "1e9"], "got 1000000000"),
        (&["--cells-per-travel", "garbage"], "garbage"),
        (
            &["--parameter", "energy"],
            "--exact continues in the period",
        ),
        (&["--hill"], "without --hill"),
        (
            &["--period-start", "3.5", "--period-end", "3.5"],
            "from 3.5 to 3.5",
        ),
    ];
    for (extra, message) in cases {
        let output = Command::new(&binary)
            .args(exact.iter().chain(extra))
            .args(["--out", "/dev/null"])
            .output()
            .expect("spawn the backbone example");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{extra:?}: {stderr}");
        assert!(stderr.contains(message), "{extra:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{extra:?}: {stderr}");
    }
    // The grid of --exact without --exact is a usage error too, not silently ignored.
    let output = Command::new(&binary)
        .args([
            "--system",
            "ds",
            "--steps",
            "3",
            "--cells-per-travel",
            "100",
        ])
        .args(["--out", "/dev/null"])
        .output()
        .expect("spawn the backbone example");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("--cells-per-travel"), "{stderr}");
}

/// `backbone --stability` writes `stable,max_multiplier,stability_reason` last: a number and
/// no reason where there is a verdict (or the grid's damping of a stable one), no number and
/// a reason where there is none (the clamped bar at `T = 3.95 ... 3.94`, where both occur).
#[test]
fn backbone_stability_columns_say_why_there_is_no_verdict() {
    let args = [
        "--system",
        "ds",
        "--period-start",
        "3.95",
        "--period-end",
        "3.94",
        "--steps",
        "3",
        "--stability",
    ];
    let text = backbone_csv("stability-columns", &args);
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("a header").split(',').collect();
    assert_eq!(
        header[header.len() - 3..],
        ["stable", "max_multiplier", "stability_reason"]
    );
    let (mut verdicts, mut reasons) = (0, 0);
    for line in lines {
        let cells: Vec<&str> = line.split(',').collect();
        assert_eq!(cells.len(), header.len(), "{line}");
        let [stable, max, reason] = cells[cells.len() - 3..] else {
            unreachable!()
        };
        match stable {
            "true" | "false" => {
                assert!(max.parse::<f64>().is_ok_and(f64::is_finite), "{line}");
                // A verdict says nothing more, unless the grid damped it.
                let damped = stable == "true" && reason.starts_with("stable up to the grid's");
                assert!(reason.is_empty() || damped, "{line}");
                verdicts += 1;
            }
            _ => {
                assert!(max.is_empty() && !reason.is_empty(), "{line}");
                reasons += 1;
            }
        }
    }
    assert!(verdicts >= 1 && reasons >= 1, "{text}");
}

/// `backbone --basis full --verify --stability` writes as many cells as the header on every
/// row, the rejected steps too (the Robin bar over `T = 9.5 -> 6.0` in 15 steps rejects its
/// last ones).
#[test]
fn full_basis_rows_have_every_column() {
    let args = [
        "--system",
        "rs",
        "--steps",
        "15",
        "--basis",
        "full",
        "--verify",
        "--stability",
    ];
    let text = backbone_csv("full-basis-columns", &args);
    let mut lines = text.lines();
    let columns = lines.next().expect("a header").split(',').count();
    let mut rejected = 0;
    for line in lines {
        assert_eq!(line.split(',').count(), columns, "{line}");
        rejected += usize::from(line.contains(",rejected,") || line.contains(",before-start,"));
    }
    assert!(rejected >= 1, "no rejected row to check:\n{text}");
}

/// The CSV `backbone ARGS --out FILE` writes, in a temporary directory named `name`; the run
/// must succeed.
fn backbone_csv(name: &str, args: &[&str]) -> String {
    let binary = example_binary("backbone", "examples/backbone");
    let dir = TempDir::new(name);
    let csv = dir.0.join("out.csv");
    let output = Command::new(&binary)
        .args(args)
        .arg("--out")
        .arg(&csv)
        .output()
        .expect("spawn the backbone example");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(0), "{stderr}");
    std::fs::read_to_string(&csv).expect("the CSV")
}

/// `backbone --exact` writes `harmonic_balance_distance,seeded` last: one point is the seed,
/// the others are continued from it, and each is within a few per cent of the
/// harmonic-balance point at its period (the clamped bar at `T = 3.95 ... 3.94`, where the
/// two agree).
#[test]
fn backbone_exact_columns_compare_with_harmonic_balance() {
    let args = [
        "--system",
        "ds",
        "--period-start",
        "3.95",
        "--period-end",
        "3.94",
        "--steps",
        "3",
        "--exact",
    ];
    let text = backbone_csv("exact-columns", &args);
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("a header").split(',').collect();
    assert_eq!(
        header[header.len() - 2..],
        ["harmonic_balance_distance", "seeded"]
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 3, "{text}");
    let mut seeds = 0;
    for cells in &rows {
        assert_eq!(cells.len(), header.len(), "{cells:?}");
        let [distance, seeded] = cells[cells.len() - 2..] else {
            unreachable!()
        };
        let distance: f64 = distance.parse().expect("a distance");
        assert!(distance.abs() < 0.05, "{cells:?}");
        seeds += match seeded {
            "true" => 1,
            "false" => 0,
            other => panic!("seeded is `{other}`: {text}"),
        };
    }
    assert_eq!(seeds, 1, "{text}");
}
