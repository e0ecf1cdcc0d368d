//! The per-harmonic rows of the last few frequencies, shared by every problem on a system.
//!
//! # Why
//! A period-grid run builds the rows of every harmonic at each new frequency in its driver,
//! then again in the annotator that describes the converged point there, and a failed step's
//! retry at the same frequency builds them once more. The rows are a function of the
//! system's bars and conditions, which a [`BarSystem`] never changes once it is built (its
//! clones share [`BarSystem::identity`]), and of the frequency, so a copy of rows built at
//! the same frequency is, bit for bit, what a rebuild gives. A copy of the `m + 1`
//! harmonics' rows costs a small fraction of rebuilding them (two sines and cosines per bar
//! and harmonic, the condition rows and the rank screen).

use crate::system::rows::HarmonicRows;
use crate::system::spectra::Spectra;
use crate::system::BarSystem;
use std::sync::{Mutex, PoisonError, Weak};

/// Frequencies kept: the driver, the annotator and a retry of one run ask the same frequency
/// one after the other; the runs of other threads have their own.
const KEPT: usize = 8;

/// The rows of every harmonic of one system at one fundamental frequency.
struct Entry {
    /// The system ([`BarSystem::identity`]): a weak handle keeps the identity of a dropped
    /// system from being given to another.
    system: Weak<Spectra>,
    /// `Omega`, bit for bit.
    omega: u64,
    rows: Vec<HarmonicRows>,
}

/// The frequencies kept, oldest first.
static RECENT: Mutex<Vec<Entry>> = Mutex::new(Vec::new());

/// Copies into `rows` the rows of `harmonics` harmonics of `system` at `omega` (after
/// [`HarmonicRows::regularise`], as [`keep`] was given them), if they are kept; whether they
/// were.
pub(super) fn copy_into(
    system: &BarSystem,
    omega: f64,
    harmonics: usize,
    rows: &mut Vec<HarmonicRows>,
) -> bool {
    let identity = system.identity();
    let recent = RECENT.lock().unwrap_or_else(PoisonError::into_inner);
    let found = recent.iter().rev().find(|e| {
        e.omega == omega.to_bits() && e.rows.len() == harmonics && e.system.ptr_eq(&identity)
    });
    match found {
        Some(entry) => {
            rows.clone_from(&entry.rows);
            true
        }
        None => false,
    }
}

/// Keeps the rows of `system` at `omega`, forgetting the oldest frequency beyond [`KEPT`].
pub(super) fn keep(system: &BarSystem, omega: f64, rows: &[HarmonicRows]) {
    let identity = system.identity();
    let mut recent = RECENT.lock().unwrap_or_else(PoisonError::into_inner);
    let same = |e: &Entry| {
        e.omega == omega.to_bits() && e.rows.len() == rows.len() && e.system.ptr_eq(&identity)
    };
    if recent.iter().any(same) {
        return;
    }
    // The oldest entry's storage takes the new rows.
    let mut entry = if recent.len() >= KEPT {
        recent.remove(0)
    } else {
        Entry {
            system: Weak::new(),
            omega: 0,
            rows: Vec::new(),
        }
    };
    entry.system = identity;
    entry.omega = omega.to_bits();
    entry.rows.truncate(rows.len());
    let reused = entry.rows.len();
    entry.rows.clone_from_slice(&rows[..reused]);
    entry.rows.extend_from_slice(&rows[reused..]);
    recent.push(entry);
}

#[cfg(test)]
mod tests {
    use crate::bar::Bar;
    use crate::reference::two_bars_in_contact;
    use crate::reference::{clamped_bar_with_obstacle, robin_bar_with_obstacle};
    use crate::system::problem::state::RANK_TOLERANCE;
    use crate::system::rows::HarmonicRows;
    use crate::system::{BarSystem, HarmonicBalanceSettings, NonsmoothSystem};

    /// The rows of every harmonic of `system` at `omega`, built afresh.
    fn built(system: &BarSystem, harmonics: usize, omega: f64) -> Vec<HarmonicRows> {
        (0..=harmonics)
            .map(|h| {
                let mut rows = HarmonicRows::new(system, h as f64 * omega);
                rows.regularise(RANK_TOLERANCE);
                rows
            })
            .collect()
    }

    /// A problem at a frequency another problem on the same system prepared gets the rows a
    /// rebuild gives; a problem on another system at the same frequency, with as many
    /// harmonics, gets its own.
    #[test]
    fn rows_are_shared_by_the_problems_of_one_system_only() {
        let settings = HarmonicBalanceSettings {
            harmonics: 6,
            ..Default::default()
        };
        let omega = 1.2345;
        let clamped = clamped_bar_with_obstacle(1e-3).unwrap();
        let mut first = NonsmoothSystem::new(&clamped, settings).unwrap();
        assert_eq!(first.rows_at(omega), built(&clamped, 6, omega));
        let mut second = NonsmoothSystem::new(&clamped.clone(), settings).unwrap();
        assert_eq!(second.rows_at(omega), built(&clamped, 6, omega));
        let two = two_bars_in_contact(Bar::new(0.8, 1.3, 2.5).unwrap(), 1e-3).unwrap();
        let mut other = NonsmoothSystem::new(&two, settings).unwrap();
        assert_eq!(other.rows_at(omega), built(&two, 6, omega));
        // Another condition, the same layout: rows of the same shape with other values.
        let robin = robin_bar_with_obstacle(0.5, 1e-3).unwrap();
        assert_ne!(built(&robin, 6, omega), built(&clamped, 6, omega));
        let mut third = NonsmoothSystem::new(&robin, settings).unwrap();
        assert_eq!(third.rows_at(omega), built(&robin, 6, omega));
    }
}
