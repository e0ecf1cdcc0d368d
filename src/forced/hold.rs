//! A harmonic selection held along a curve: the equations stay smooth in `Omega` while a
//! continuation step is corrected, and the selection moves only between points, where the
//! caller re-corrects the point it has.

use crate::forced::ForcedSystem;

impl ForcedSystem {
    /// Holds (`true`) or releases the harmonic selection: while held, a new frequency keeps
    /// the harmonics dropped at the last one. The band switches harmonics on and off at fixed
    /// frequencies, and a corrector whose iterates cross one meets equations that jump.
    pub(crate) fn hold_selection(&mut self, hold: bool) {
        self.selection_held = hold;
        if !hold {
            self.reselect();
        }
    }

    /// Whether the selection at the current frequency drops other harmonics than those held.
    pub(crate) fn selection_moved(&mut self) -> bool {
        let (system, basis, omega) = (&self.system, &self.basis, self.omega);
        (self.selection.as_mut())
            .is_some_and(|s| s.dropped_at((system, basis), omega) != s.dropped())
    }

    /// Sets the dropped harmonics to those of the current frequency.
    pub(crate) fn reselect(&mut self) {
        if let Some(s) = &mut self.selection {
            s.select((&self.system, &self.basis), self.omega);
        }
    }

    /// The basis coefficients dropped now (empty without a selection).
    pub(crate) fn dropped_coefficients(&self) -> Vec<usize> {
        (self.selection.as_ref()).map_or_else(Vec::new, |s| s.dropped().to_vec())
    }

    /// Drops the coefficients `dropped` (from [`ForcedSystem::dropped_coefficients`]) again.
    pub(crate) fn set_dropped_coefficients(&mut self, dropped: Vec<usize>) {
        if let Some(s) = &mut self.selection {
            s.set_dropped(dropped);
        }
    }
}
