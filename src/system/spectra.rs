//! The natural-frequency scans of one system, kept with it and shared by its clones.
//!
//! # Why
//! A run asks the same scans many times: harmonic selection scans the open and the closed
//! system once for every problem built on the system (the start search, the driver, the
//! annotator, each candidate run of [`Method::Auto`](crate::branches::Method::Auto)), and
//! labels scan the open system from every annotator. A scan is a few thousand small
//! singular-value decompositions; at the default `m = 20` the repeats cost about a quarter of
//! the default request. The scan's result depends only on the system's bars and conditions,
//! which a [`BarSystem`](crate::system::BarSystem) never changes after it is built, so its
//! clones share one cache and a system with other conditions gets its own.

use std::collections::BTreeMap;
use std::sync::{Mutex, PoisonError};

/// What a scan is asked besides its upper frequency: an opaque tag of the linear state and
/// the resolution (samples per spacing and refinement tolerance), as the scanner defines them.
pub(crate) type ScanKey = (u8, f64, f64);

/// One scan's natural frequencies, ascending, with what it was asked.
#[derive(Debug, Clone)]
struct Scan {
    key: ScanKey,
    omega_max: f64,
    values: Vec<f64>,
}

/// What the scans of one key computed at each index of their common grid of samples, kept so
/// that a longer scan computes only what it adds: the samples `(ratio, sign)` in order from
/// index 0, and the roots refined from an index (a minimum of the ratio at sample `i`, a
/// change of sign between samples `i` and `i + 1`), each with the ratio at the root. Each
/// entry is a function of its index alone (the samples of a key lie at the same
/// frequencies), so a scan that reads it gets what computing it again gives, bit for bit.
#[derive(Debug, Clone, Default)]
pub(crate) struct ScanMemo {
    pub(crate) samples: Vec<(f64, f64)>,
    pub(crate) minima: BTreeMap<usize, (f64, f64)>,
    pub(crate) crossings: BTreeMap<usize, (f64, f64)>,
}

/// Most scans kept per system: a long-lived system whose callers ask many upper frequencies
/// forgets the oldest rather than growing.
const KEPT: usize = 64;

/// The scans of one system (shared by its clones).
#[derive(Default)]
pub(crate) struct Spectra {
    scans: Mutex<Vec<Scan>>,
    memos: Mutex<Vec<(ScanKey, ScanMemo)>>,
}

impl std::fmt::Debug for Spectra {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Spectra").finish_non_exhaustive()
    }
}

impl Spectra {
    /// The values of the scan asked exactly `key` up to `omega_max`, if one ran.
    pub(crate) fn exact(&self, key: ScanKey, omega_max: f64) -> Option<Vec<f64>> {
        let scans = self.scans.lock().unwrap_or_else(PoisonError::into_inner);
        scans
            .iter()
            .find(|s| s.key == key && s.omega_max == omega_max)
            .map(|s| s.values.clone())
    }

    /// The scan asked `key` with the lowest upper frequency at or above `omega_max`, with
    /// that frequency, if one ran. Its values below `omega_max` less a few scan steps are
    /// those of a scan up to `omega_max` itself (each root is found from the samples around
    /// it, which do not depend on the upper frequency).
    pub(crate) fn covering(&self, key: ScanKey, omega_max: f64) -> Option<(f64, Vec<f64>)> {
        let scans = self.scans.lock().unwrap_or_else(PoisonError::into_inner);
        scans
            .iter()
            .filter(|s| s.key == key && s.omega_max >= omega_max)
            .min_by(|a, b| a.omega_max.total_cmp(&b.omega_max))
            .map(|s| (s.omega_max, s.values.clone()))
    }

    /// What the scans asked `key` computed so far (empty if none ran).
    pub(crate) fn memo(&self, key: ScanKey) -> ScanMemo {
        let memos = self.memos.lock().unwrap_or_else(PoisonError::into_inner);
        (memos.iter().find(|(k, _)| *k == key)).map_or_else(ScanMemo::default, |(_, m)| m.clone())
    }

    /// Adds what a scan asked `key` computed to what is kept: the longer run of samples, and
    /// every root.
    pub(crate) fn keep_memo(&self, key: ScanKey, memo: ScanMemo) {
        let mut memos = self.memos.lock().unwrap_or_else(PoisonError::into_inner);
        let Some((_, kept)) = memos.iter_mut().find(|(k, _)| *k == key) else {
            memos.push((key, memo));
            return;
        };
        if memo.samples.len() > kept.samples.len() {
            kept.samples = memo.samples;
        }
        kept.minima.extend(memo.minima);
        kept.crossings.extend(memo.crossings);
    }

    /// Keeps the values of a scan asked `key` up to `omega_max`.
    pub(crate) fn keep(&self, key: ScanKey, omega_max: f64, values: &[f64]) {
        let mut scans = self.scans.lock().unwrap_or_else(PoisonError::into_inner);
        if scans
            .iter()
            .any(|s| s.key == key && s.omega_max == omega_max)
        {
            return;
        }
        if scans.len() >= KEPT {
            scans.remove(0);
        }
        scans.push(Scan {
            key,
            omega_max,
            values: values.to_vec(),
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scans_are_found_by_exact_key_or_covering_bound() {
        let spectra = Spectra::default();
        let key = (0, 200.0, 1e-15);
        assert_eq!(spectra.exact(key, 10.0), None);
        spectra.keep(key, 10.0, &[1.0, 4.0]);
        spectra.keep(key, 20.0, &[1.0, 4.0, 15.0]);
        assert_eq!(spectra.exact(key, 10.0), Some(vec![1.0, 4.0]));
        assert_eq!(spectra.exact((1, 200.0, 1e-15), 10.0), None);
        assert_eq!(
            spectra.covering(key, 12.0),
            Some((20.0, vec![1.0, 4.0, 15.0]))
        );
        assert_eq!(spectra.covering(key, 8.0), Some((10.0, vec![1.0, 4.0])));
        assert_eq!(spectra.covering(key, 25.0), None);
    }

    #[test]
    fn the_oldest_scan_is_forgotten_beyond_the_bound() {
        let spectra = Spectra::default();
        let key = (0, 50.0, 1e-10);
        for i in 0..=KEPT {
            spectra.keep(key, i as f64 + 1.0, &[]);
        }
        assert_eq!(spectra.exact(key, 1.0), None);
        assert_eq!(spectra.exact(key, KEPT as f64 + 1.0), Some(vec![]));
    }
}
