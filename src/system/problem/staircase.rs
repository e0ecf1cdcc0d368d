//! The staircase shape of a frequency's Jacobian, unknowns taken bar by bar: the bars each
//! row involves (`band.rs` explains why a chain's Jacobian is a staircase). The state of a
//! frequency keeps the shape; the staircase step uses it.

use super::discretization::Discretization;
use crate::fourier::Basis;
use crate::linalg::Staircase;
use crate::system::rows::HarmonicRows;

/// The blocks (bars) whose unknowns `row` involves at some harmonic, `(first, last)`, given
/// the row of each harmonic: `None` if it involves none.
fn bar_span(
    rows: &[HarmonicRows],
    row: impl Fn(&HarmonicRows) -> &[f64],
) -> Option<(usize, usize)> {
    let mut span: Option<(usize, usize)> = None;
    for r in rows {
        let pairs = row(r).chunks_exact(2).enumerate();
        for (bar, _) in pairs.filter(|(_, p)| p[0] != 0.0 || p[1] != 0.0) {
            span = Some(span.map_or((bar, bar), |(f, l)| (f.min(bar), l.max(bar))));
        }
    }
    span
}

/// The staircase shape of the Jacobian of `d` with the rows `rows` of one frequency, unknowns
/// bar by bar, if the system has two contacts or more and every row involves some bar;
/// `None` otherwise.
pub(super) fn staircase_of<B: Basis>(
    d: &Discretization<B>,
    rows: &[HarmonicRows],
) -> Option<Staircase> {
    let (len, rpc, laws) = (d.basis().len(), d.linear_count, d.laws);
    if laws < 2 {
        return None;
    }
    let linear = (0..rpc)
        .map(|r| bar_span(rows, |h| h.linear_row(r)))
        .collect::<Option<Vec<_>>>()?;
    let law = (0..laws)
        .map(|l| {
            let gap = bar_span(rows, |h| h.gap_row(l));
            let force = bar_span(rows, |h| h.force_row(l));
            match (gap, force) {
                (Some((f, l)), Some((g, m))) => Some((f.min(g), l.max(m))),
                (one, other) => one.or(other),
            }
        })
        .collect::<Option<Vec<_>>>()?;
    // Rows in the residual's order: linear rows coefficient by coefficient, then each law's
    // projections.
    let spans: Vec<_> = (0..len)
        .flat_map(|_| linear.iter().copied())
        .chain(law.iter().flat_map(|&s| std::iter::repeat_n(s, len)))
        .collect();
    Staircase::new(2 * len, d.unknowns / 2, &spans)
}
