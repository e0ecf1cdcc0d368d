//! Whether every bar of an assembly is held: a bar that a contact can push but nothing pulls
//! back (a free end across from a contact, a bar facing a wall on one side only) drifts away
//! after its first impact, so no periodic motion touches it.
//!
//! The rigid-body motions of the open-contact system are the combinations `d = sum_j a_j
//! phi_j` of its null vectors at `omega = 0`. Along `d` the gap of law `l` changes by
//! `(C a)_l`, with `C_lj` the gap row of `l` applied to `phi_j`. The assembly can drift when
//! some `a != 0` closes no gap: `C a >= 0`. The cone `{a : C a >= 0}` is `{0}` exactly when it
//! has no extreme ray; an extreme ray is the null direction of `r - 1` linearly independent
//! rows of `C` (`r` the number of rigid-body motions) that satisfies every other row, or a
//! null vector of the whole of `C` where `C` has rank below `r`. Both are enumerated.

use crate::error::SettingsError;
use crate::modal::linear::{rigid_body_modes, ContactState};
use crate::system::rows::{dot, HarmonicRows};
use crate::system::BarSystem;

/// Rows of `C` whose norm is below this fraction of the largest are gaps that no rigid-body
/// motion moves; a gap change above `-TOLERANCE` (rows and directions of unit norm) counts as
/// not closing.
const TOLERANCE: f64 = 1e-9;

/// Subsets of rows enumerated at most: beyond it (hundreds of floating bars) the check is
/// not made and the assembly is taken as held.
const MAX_SUBSETS: usize = 100_000;

/// The bars (0-based) that a rigid-body motion closing no contact gap moves, or `None` if
/// every bar is held (or the check would enumerate more than 100 000 sets of rows).
pub fn drifting_bars(system: &BarSystem) -> Option<Vec<usize>> {
    let shapes = rigid_body_modes(system, ContactState::Open)?.shapes;
    let r = shapes.len();
    if r == 0 {
        return None;
    }
    let rows = HarmonicRows::new(system, 0.0);
    let raw: Vec<Vec<f64>> = (0..system.contact_count())
        .map(|l| shapes.iter().map(|s| dot(rows.gap_row(l), s)).collect())
        .collect();
    let largest = raw.iter().map(|c| norm(c)).fold(0.0, f64::max);
    let c: Vec<Vec<f64>> = raw
        .into_iter()
        .filter(|row| norm(row) > TOLERANCE * largest && largest > 0.0)
        .map(|row| {
            let n = norm(&row);
            row.into_iter().map(|v| v / n).collect()
        })
        .collect();
    let direction = drift_direction(&c, r)?;
    let motion: Vec<f64> = (0..shapes[0].len())
        .map(|i| shapes.iter().zip(&direction).map(|(s, a)| a * s[i]).sum())
        .collect();
    let scale = norm(&motion);
    let bars = (0..system.bars().len())
        .filter(|&b| {
            motion[2 * b..2 * b + 2]
                .iter()
                .any(|v| v.abs() > 1e-6 * scale)
        })
        .collect();
    Some(bars)
}

/// [`drifting_bars`] as a check.
///
/// # Errors
/// [`SettingsError::Unconfined`] naming the bars that can drift.
pub fn check_held(system: &BarSystem) -> Result<(), SettingsError> {
    match drifting_bars(system) {
        Some(bars) => Err(SettingsError::Unconfined { bars }),
        None => Ok(()),
    }
}

/// A unit `a` with `C a >= 0` (rows of `c` of unit norm, `r` columns), if there is one.
fn drift_direction(c: &[Vec<f64>], r: usize) -> Option<Vec<f64>> {
    let closes_none = |a: &[f64]| c.iter().all(|row| dot(row, a) >= -TOLERANCE);
    if let Some(a) = null_direction(c, r) {
        return Some(a);
    }
    let mut subsets = 0usize;
    let mut chosen = Vec::with_capacity(r.saturating_sub(1));
    let mut found = None;
    for_each_subset(c.len(), r - 1, &mut chosen, 0, &mut |rows: &[usize]| {
        subsets += 1;
        if subsets > MAX_SUBSETS {
            return true;
        }
        let sub: Vec<Vec<f64>> = rows.iter().map(|&i| c[i].clone()).collect();
        if let Some(a) = null_direction(&sub, r) {
            for sign in [1.0, -1.0] {
                let a: Vec<f64> = a.iter().map(|v| sign * v).collect();
                if closes_none(&a) {
                    found = Some(a);
                    return true;
                }
            }
        }
        false
    });
    found
}

/// Calls `visit` with every `k`-subset of `0..n` (in increasing order) until it returns
/// `true`; returns whether it did.
fn for_each_subset(
    n: usize,
    k: usize,
    chosen: &mut Vec<usize>,
    from: usize,
    visit: &mut dyn FnMut(&[usize]) -> bool,
) -> bool {
    if chosen.len() == k {
        return visit(chosen);
    }
    for i in from..n {
        chosen.push(i);
        let stop = for_each_subset(n, k, chosen, i + 1, visit);
        chosen.pop();
        if stop {
            return true;
        }
    }
    false
}

/// A unit vector of the null space of the rows `m` (`r` columns), if it is not trivial:
/// Gauss-Jordan elimination with partial pivoting, the first free column set to 1.
fn null_direction(m: &[Vec<f64>], r: usize) -> Option<Vec<f64>> {
    let mut a: Vec<Vec<f64>> = m.to_vec();
    let mut pivots: Vec<usize> = Vec::new();
    let mut row = 0;
    for col in 0..r {
        let best = (row..a.len()).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()));
        let Some(p) = best.filter(|&p| a[p][col].abs() > TOLERANCE) else {
            continue;
        };
        a.swap(row, p);
        let pivot_row = a[row].clone();
        for (i, other) in a.iter_mut().enumerate() {
            let f = other[col] / pivot_row[col];
            if i != row && f != 0.0 {
                for (v, w) in other[col..r].iter_mut().zip(&pivot_row[col..r]) {
                    *v -= f * w;
                }
            }
        }
        pivots.push(col);
        row += 1;
    }
    let free = (0..r).find(|c| !pivots.contains(c))?;
    let mut v = vec![0.0; r];
    v[free] = 1.0;
    for (i, &col) in pivots.iter().enumerate() {
        v[col] = -a[i][free] / a[i][col];
    }
    let n = norm(&v);
    Some(v.into_iter().map(|x| x / n).collect())
}

fn norm(a: &[f64]) -> f64 {
    dot(a, a).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bar::Bar;
    use crate::system::AssemblyBuilder;

    const GAP: f64 = 1e-3;

    /// A chain of `n` unit bars with contacts between neighbours; `outer` sets the two outer
    /// ends (`'c'` clamped, `'f'` free, `'s'` spring, `'w'` wall).
    fn chain(n: usize, outer: [char; 2]) -> BarSystem {
        let mut b = AssemblyBuilder::new();
        let ids: Vec<_> = (0..n).map(|_| b.add_bar(Bar::unit())).collect();
        for (end, how) in [(ids[0].left(), outer[0]), (ids[n - 1].right(), outer[1])] {
            match how {
                'c' => b.dirichlet(end),
                'f' => b.neumann(end),
                's' => b.robin(end, 0.5),
                _ => b.signorini(end, GAP),
            }
            .expect("valid condition");
        }
        for pair in ids.windows(2) {
            b.contact(pair[0].right(), pair[1].left(), GAP)
                .expect("valid contact");
        }
        b.build().expect("complete assembly")
    }

    #[test]
    fn held_assemblies_do_not_drift() {
        for (n, outer) in [
            (1, ['c', 'w']),
            (1, ['w', 'c']),
            (1, ['w', 'w']),
            (1, ['s', 'w']),
            (2, ['c', 'c']),
            (2, ['w', 'w']),
            (3, ['c', 's']),
            (3, ['w', 'w']),
            (4, ['w', 'c']),
        ] {
            assert_eq!(drifting_bars(&chain(n, outer)), None, "{n} bars {outer:?}");
            assert!(check_held(&chain(n, outer)).is_ok());
        }
    }

    /// Each assembly drifts; the bars named are those of one drift direction, which always
    /// moves the bar held from one side (several directions may exist: a free bar can leave
    /// alone or push its floating neighbour along).
    #[test]
    fn bars_held_from_one_side_drift() {
        for (n, outer, held_from_one_side) in [
            (1, ['f', 'w'], 0),
            (1, ['w', 'f'], 0),
            (2, ['c', 'f'], 1),
            (2, ['f', 'w'], 0),
            (3, ['f', 'c'], 0),
            (3, ['s', 'f'], 2),
            (4, ['w', 'f'], 3),
        ] {
            let system = chain(n, outer);
            let bars = drifting_bars(&system).expect("a drift");
            assert!(
                bars.contains(&held_from_one_side),
                "{n} {outer:?}: {bars:?}"
            );
            assert!(bars.iter().all(|&b| b < n));
            assert_eq!(
                check_held(&system),
                Err(SettingsError::Unconfined { bars }),
                "{n} {outer:?}"
            );
        }
    }

    #[test]
    fn the_null_direction_solves_the_rows() {
        let m = vec![vec![1.0, 2.0, -1.0], vec![0.5, -1.0, 3.0]];
        let v = null_direction(&m, 3).expect("a 2 x 3 matrix has a null vector");
        assert!((norm(&v) - 1.0).abs() < 1e-12);
        for row in &m {
            assert!(dot(row, &v).abs() < 1e-12);
        }
        assert_eq!(null_direction(&[vec![1.0, 0.0], vec![0.0, 1.0]], 2), None);
    }
}
