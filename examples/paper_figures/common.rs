//! What every figure group uses: the run context and its output files, the harmonic-balance
//! settings, the counts of a figure, and the panels built from runs and points (the runs
//! themselves are in `runs`).

use crate::runs::Run;
use crate::summary::Item;
use nonsmooth_modes::branches::BackbonePoint;
use nonsmooth_modes::continuation::Event;
use nonsmooth_modes::fourier::CosineBasis;
use nonsmooth_modes::io::{write_branches_csv, write_columns_csv, LabelledBranch};
use nonsmooth_modes::modal::diagnostics::EndHistory;
use nonsmooth_modes::modal::{displacement_grid, end_history, grazing_energy, Label};
use nonsmooth_modes::plot::{
    render_svg, space_time_panel, Annotation, Figure, LinePanel, MapPanel, Marker, Panel, Rgb,
    Series, SpaceTimeField, PALETTE,
};
use nonsmooth_modes::system::{BarSystem, HarmonicBalanceSettings};
use std::io::Write as _;
use std::path::PathBuf;

/// Result of a figure: any error ends that figure only.
pub type Res<T> = Result<T, Box<dyn std::error::Error>>;

/// Gap at rest `g0` of every system.
pub const GAP: f64 = 1e-3;
/// Colour of the first branch.
pub const GREEN: Rgb = PALETTE[0];
/// Colour of the second branch.
pub const RED: Rgb = PALETTE[1];
/// Colour of the third branch.
pub const YELLOW: Rgb = PALETTE[2];
/// Colour of the fourth branch.
pub const BLUE: Rgb = PALETTE[3];

/// What one figure produced.
#[derive(Default)]
pub struct Stats {
    /// Points computed.
    pub points: usize,
    /// Points converged.
    pub converged: usize,
    /// Files written, in order.
    pub files: Vec<String>,
    /// A one-line remark for the progress line.
    pub note: String,
    /// Its rows of `summary.csv`: branches and lettered points.
    pub items: Vec<Item>,
}

impl Stats {
    /// Counts the points of `runs`, each a branch row of `summary.csv`.
    pub fn count<'a>(&mut self, runs: impl IntoIterator<Item = &'a Run>) {
        for run in runs {
            let converged = run.converged().count();
            self.points += run.points.len();
            self.converged += converged;
            self.items
                .push(Item::branch(&run.label, converged, run.points.len()));
        }
    }

    /// Records whether the paper's lettered point `letter` was found.
    pub fn lettered(&mut self, letter: &str, found: bool) {
        self.items.push(Item::point(letter, found));
    }
}

/// Output folder and run mode, shared by all figures.
pub struct Ctx {
    /// Folder receiving the files.
    pub out: PathBuf,
    /// Coarser grids and fewer harmonics.
    pub quick: bool,
}

impl Ctx {
    fn path(&self, name: &str) -> PathBuf {
        self.out.join(name)
    }

    /// Steps of a period grid: `full` normally, about a third in quick mode.
    pub fn steps(&self, full: usize) -> usize {
        if self.quick {
            (full / 3).max(8)
        } else {
            full
        }
    }

    /// Writes the SVG `name`.
    pub fn svg(&self, stats: &mut Stats, name: &str, figure: &Figure) -> Res<()> {
        render_svg(self.path(name), figure)?;
        stats.files.push(name.to_string());
        Ok(())
    }

    /// Writes `stem.svg` and `stem.csv` (the backbone table of `runs`), the files of a
    /// backbone figure.
    pub fn backbone_figure(
        &self,
        stats: &mut Stats,
        stem: &str,
        figure: &Figure,
        runs: &[&Run],
        omega_1: f64,
    ) -> Res<()> {
        self.svg(stats, &format!("{stem}.svg"), figure)?;
        self.branches(stats, &format!("{stem}.csv"), runs, omega_1)
    }

    /// Writes the backbone table of `runs` (with the exact energies of the runs that have
    /// one) as the CSV `name`.
    fn branches(&self, stats: &mut Stats, name: &str, runs: &[&Run], omega_1: f64) -> Res<()> {
        let exact: Vec<_> = runs
            .iter()
            .map(|r| r.exact.map(|e| move |t: f64| e.at(t)))
            .collect();
        let branches: Vec<LabelledBranch<'_>> = runs
            .iter()
            .zip(&exact)
            .map(|(r, e)| LabelledBranch {
                label: &r.label,
                harmonics: r.m,
                points: &r.points,
                exact: e.as_ref().map(|f| f as &dyn Fn(f64) -> f64),
            })
            .collect();
        self.write(stats, name, |w| write_branches_csv(&branches, omega_1, w))
    }

    /// Writes named columns as the CSV `name`.
    pub fn columns(
        &self,
        stats: &mut Stats,
        name: &str,
        names: &[&str],
        cols: &[&[f64]],
    ) -> Res<()> {
        self.write(stats, name, |w| write_columns_csv(names, cols, w))
    }

    /// Writes `table` as the CSV `name`.
    pub fn table(&self, stats: &mut Stats, name: &str, table: &Table) -> Res<()> {
        let names: Vec<&str> = table.names.iter().map(|s| s.as_str()).collect();
        let cols: Vec<&[f64]> = table.columns.iter().map(|c| c.as_slice()).collect();
        self.columns(stats, name, &names, &cols)
    }

    fn write(
        &self,
        stats: &mut Stats,
        name: &str,
        body: impl FnOnce(&mut dyn std::io::Write) -> std::io::Result<()>,
    ) -> Res<()> {
        let f = std::fs::File::create(self.path(name))?;
        let mut w = std::io::BufWriter::new(f);
        body(&mut w)?;
        w.flush()?;
        stats.files.push(name.to_string());
        Ok(())
    }
}

/// Named columns gathered while a figure is computed.
#[derive(Default)]
pub struct Table {
    names: Vec<String>,
    columns: Vec<Vec<f64>>,
}

impl Table {
    /// Appends a column.
    pub fn push(&mut self, name: impl Into<String>, column: Vec<f64>) {
        self.names.push(name.into());
        self.columns.push(column);
    }

    /// Puts a column first.
    pub fn push_front(&mut self, name: impl Into<String>, column: Vec<f64>) {
        self.names.insert(0, name.into());
        self.columns.insert(0, column);
    }
}

/// Harmonic-balance settings with `m` harmonics, 30 samples per harmonic, `a_c = 4`.
pub fn settings(m: usize) -> HarmonicBalanceSettings {
    HarmonicBalanceSettings {
        harmonics: m,
        samples_per_harmonic: 30,
        complementarity: 4.0,
        ..Default::default()
    }
}

/// First open-contact natural frequency (the one the grazing energy is built on).
pub fn omega_1(system: &BarSystem) -> Res<f64> {
    Ok(grazing_energy(system)?.1.omega)
}

/// The converged points of `run` as `(Omega/omega_1, E/E_g)` markers.
pub fn series(run: &Run, omega_1: f64, color: Rgb, marker: Marker) -> Series {
    let pts = run
        .converged()
        .map(|p| (p.omega / omega_1, p.energy_normalized))
        .collect();
    Series::markers(run.label.clone(), pts)
        .with_color(color)
        .with_marker(marker)
}

/// The line of a branch continued through a lettered point (`runs::continued_from`), in one
/// colour for every figure, named by the run.
pub fn through_series(run: &Run, omega_1: f64) -> Series {
    Series::line(
        &run.label,
        run.converged()
            .map(|q| (q.omega / omega_1, q.energy_normalized))
            .collect(),
    )
    .with_color(PALETTE[4])
    .with_marker(Marker::Circle)
    .with_size(1)
}

/// The runs' converged points split by label: each run's own branch (skeleton or subharmonic,
/// and any point without a label) as markers in its colour and marker, named by the run; then
/// each run's internal resonances as small rings in the same colour, one legend entry for them
/// all.
pub fn labelled_series(runs: &[(&Run, Rgb, Marker)], omega_1: f64) -> Vec<Series> {
    let at = |p: &BackbonePoint| (p.omega / omega_1, p.energy_normalized);
    let resonant = |p: &BackbonePoint| matches!(p.label, Some(Label::InternalResonance { .. }));
    let mut own = Vec::new();
    let mut apart = Vec::new();
    for &(run, color, marker) in runs {
        let (resonances, branch): (Vec<&BackbonePoint>, Vec<&BackbonePoint>) =
            run.converged().partition(|p| resonant(p));
        let points = |ps: Vec<&BackbonePoint>| ps.into_iter().map(at).collect::<Vec<_>>();
        let (resonances, branch) = (points(resonances), points(branch));
        // The branch is a line through its consecutive points, broken where a step failed,
        // met a resonance or jumped; its markers carry the legend entry.
        for piece in pieces(run, |p| !resonant(p)) {
            own.push(
                Series::line("", piece.into_iter().map(at).collect())
                    .with_color(color)
                    .with_size(1),
            );
        }
        own.push(
            Series::markers(run.label.clone(), branch)
                .with_color(color)
                .with_marker(marker),
        );
        if !resonances.is_empty() {
            let label = if apart.is_empty() {
                "internal resonances (rings, branch colour)"
            } else {
                ""
            };
            apart.push(
                Series::markers(label, resonances)
                    .with_color(color)
                    .with_marker(Marker::Ring)
                    .with_size(3),
            );
        }
    }
    own.extend(apart);
    own
}

/// The pieces of `run`'s line: its maximal runs of consecutive converged points that `keep`
/// takes, on one branch (a step that did not converge, a point left out or a jump to another
/// branch ends a piece), with at least two points.
fn pieces(run: &Run, keep: impl Fn(&BackbonePoint) -> bool) -> Vec<Vec<&BackbonePoint>> {
    let mut pieces: Vec<Vec<&BackbonePoint>> = vec![Vec::new()];
    for p in &run.points {
        let joins = p.converged() && keep(p);
        let last = pieces.last_mut().expect("one piece at least");
        let same_branch = last.last().is_none_or(|q| q.branch == p.branch);
        if joins && same_branch {
            last.push(p);
        } else {
            pieces.push(if joins { vec![p] } else { Vec::new() });
        }
    }
    pieces.retain(|piece| piece.len() >= 2);
    pieces
}

/// A thin dashed black line: a reference curve.
pub fn reference_line(label: &str, points: Vec<(f64, f64)>) -> Series {
    Series::line(label, points)
        .with_color(Rgb::BLACK)
        .dashed()
        .with_size(1)
}

/// History of the right end (`x = l`) of bar `bar` over one period.
pub fn right_end(
    system: &BarSystem,
    basis: &CosineBasis,
    p: &BackbonePoint,
    bar: usize,
    samples: usize,
) -> Res<EndHistory> {
    let end = system
        .bar_id(bar)
        .ok_or_else(|| format!("no bar {bar}"))?
        .right();
    Ok(end_history(system, basis, &p.x, p.omega, end, samples))
}

/// `v / g0` for every value.
pub fn over_gap(values: &[f64]) -> Vec<f64> {
    values.iter().map(|v| v / GAP).collect()
}

/// `u(x, t)` of bar `bar` on 41 positions and `instants` instants over the period of `p`.
pub fn field(
    system: &BarSystem,
    basis: &CosineBasis,
    p: &BackbonePoint,
    bar: usize,
    instants: usize,
) -> SpaceTimeField {
    let g = displacement_grid(system, basis, &p.x, p.omega, bar, 41, instants);
    SpaceTimeField {
        position: g.position,
        time: g.time,
        values: g.displacement,
    }
}

/// The backbone panel `bb` with the lettered `points` marked (black rings, each labelled with
/// its letter, and one legend entry naming the letters found, with `note` in parentheses if
/// not empty), followed by `panels`.
pub fn marked(
    mut bb: LinePanel,
    note: &str,
    points: &[(&str, &BackbonePoint)],
    omega_1: f64,
    panels: Vec<Panel>,
) -> Vec<Panel> {
    let at = |p: &BackbonePoint| (p.omega / omega_1, p.energy_normalized);
    let letters: Vec<&str> = points.iter().map(|(letter, _)| *letter).collect();
    let noun = if letters.len() == 1 {
        "point"
    } else {
        "points"
    };
    let mut label = format!("{noun} {}", letters.join(", "));
    if !note.is_empty() {
        label.push_str(&format!(" ({note})"));
    }
    bb.series.push(
        Series::markers(label, points.iter().map(|(_, p)| at(p)).collect())
            .with_color(Rgb::BLACK)
            .with_marker(Marker::Ring)
            .with_size(7),
    );
    bb.annotations.extend(
        points
            .iter()
            .map(|(letter, p)| Annotation::new(at(p), *letter)),
    );
    let mut all = vec![Panel::Lines(bb)];
    all.extend(panels);
    all
}

/// Space-time map of `f` in units of `g0`.
pub fn map_panel(title: String, f: &SpaceTimeField) -> Res<Panel> {
    let mut p: MapPanel = space_time_panel(title, f, "u/g₀")?;
    p.values.iter_mut().for_each(|v| *v /= GAP);
    Ok(p.into())
}

/// Map panel of bar 1 of `system` at `p` on `instants` instants.
pub fn point_map(
    system: &BarSystem,
    basis: &CosineBasis,
    p: &BackbonePoint,
    instants: usize,
    title: String,
) -> Res<Panel> {
    map_panel(title, &field(system, basis, p, 0, instants))
}

/// `n` in subscript digits (`ω₁₂` for `ω` and 12).
pub fn subscript(n: usize) -> String {
    n.to_string()
        .chars()
        .map(|d| char::from_u32(0x2080 + d.to_digit(10).unwrap_or(0)).unwrap_or(d))
        .collect()
}

/// `Ω/ω₁ = ..., E/E_g = ...` of a point.
pub fn frequency_energy(p: &BackbonePoint, omega_1: f64) -> String {
    format!(
        "Ω/ω₁ = {:.3}, E/E_g = {:.2}",
        p.omega / omega_1,
        p.energy_normalized
    )
}

/// An arclength run drawn as a line broken where the stall escape jumped (a jump is no part of
/// the branch), with the landing points marked; with `markers`, every point as a small dot.
pub fn arclength_series(run: &Run, w1: f64, color: Rgb, markers: bool) -> [Series; 2] {
    let jumped = |p: &BackbonePoint| p.events.iter().any(|e| matches!(e, Event::Jump { .. }));
    let mut line = Vec::with_capacity(run.points.len());
    let mut jumps = Vec::new();
    for p in &run.points {
        let at = (p.omega / w1, p.energy_normalized);
        if jumped(p) {
            // A non-finite point breaks the line.
            line.push((f64::NAN, f64::NAN));
            jumps.push(at);
        }
        line.push(at);
    }
    let mut line = Series::line(run.label.clone(), line)
        .with_color(color)
        .with_size(1);
    if markers {
        line = line.with_marker(Marker::Circle);
    }
    let jumps = Series::markers("jump past a stall (lands here)", jumps)
        .with_color(color)
        .with_marker(Marker::Cross)
        .with_size(5);
    [line, jumps]
}

/// Frames a backbone panel on its branches: the horizontal range of the series drawn as
/// lines or filled markers, widened by a twentieth of its width on each side. Points drawn
/// as rings or crosses (internal resonances, isolated points, landings of the stall escape)
/// beyond that range would otherwise set the axis and squeeze the branches into a corner;
/// they are left out of the drawing, and the axis label says how many (the figure's CSV keeps
/// every point).
pub fn frame_on_branches(panel: &mut LinePanel) {
    let apart = |s: &Series| matches!(s.marker, Some(Marker::Ring | Marker::Cross));
    let (lo, hi) = (panel.series.iter())
        .filter(|s| !apart(s))
        .flat_map(|s| s.points.iter().map(|p| p.0))
        .filter(|x| x.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(x), b.max(x))
        });
    // No finite branch point, or a single abscissa: the plot's own range stays.
    if lo >= hi || !lo.is_finite() {
        return;
    }
    let margin = (hi - lo) / 20.0;
    let (lo, hi) = (lo - margin, hi + margin);
    panel.x_range = Some((lo, hi));
    // A point drawn by two series (an isolated point that is also a landing) counts once.
    let mut left_out = std::collections::BTreeSet::new();
    for s in panel.series.iter_mut().filter(|s| apart(s)) {
        s.points.retain(|p| {
            let inside = (lo..=hi).contains(&p.0);
            if !inside {
                left_out.insert((p.0.to_bits(), p.1.to_bits()));
            }
            inside
        });
    }
    let left_out = left_out.len();
    // Said under the axis: a series left empty has no legend entry to say it.
    if left_out > 0 {
        panel.x_label = format!(
            "{} ({left_out} points outside [{lo:.2}, {hi:.2}] not drawn)",
            panel.x_label
        );
    }
}
