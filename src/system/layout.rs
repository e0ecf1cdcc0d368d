//! Where each unknown of the harmonic-balance problem lives.

use crate::system::BarSystem;

/// The layout of the harmonic-balance unknowns: for basis coefficient `i` and bar `b`, the
/// Helmholtz coefficients `(A, B)` of `A cos(kx) + B sin(kx)/k` at
/// `(i n_bars + b) 2 + {0, 1}`. One place says it; the problem, the fields and the energy read
/// it from here.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Layout {
    bars: usize,
}

impl Layout {
    /// The layout of `system`'s unknowns.
    pub fn of(system: &BarSystem) -> Self {
        Self {
            bars: system.bars().len(),
        }
    }

    /// Unknowns per basis coefficient (`2 n_bars`).
    pub fn per_coefficient(&self) -> usize {
        2 * self.bars
    }

    /// Index of coefficient `i`, bar `bar`, Helmholtz component `which` (0: `A`, 1: `B`).
    ///
    /// # Panics
    /// If `bar` is not a bar of the layout, `which` is not 0 or 1, or the index overflows
    /// `usize` (an index out of range must not land on another unknown).
    pub fn index(&self, i: usize, bar: usize, which: usize) -> usize {
        assert!(
            bar < self.bars && which < 2,
            "Layout::index: bar and component in range"
        );
        i.checked_mul(self.bars)
            .and_then(|v| v.checked_add(bar))
            .and_then(|v| v.checked_mul(2))
            .map(|v| v + which)
            .expect("Layout::index: the index overflows usize")
    }

    /// The pair `(A, B)` of coefficient `i` and bar `bar` in `x`.
    ///
    /// # Panics
    /// If `x` is shorter than the layout implies.
    pub fn pair(&self, x: &[f64], i: usize, bar: usize) -> (f64, f64) {
        let j = self.index(i, bar, 0);
        (x[j], x[j + 1])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bar::Bar;
    use crate::reference::two_bars_in_contact;

    #[test]
    fn pairs_are_interleaved_by_coefficient_then_bar() {
        let system = two_bars_in_contact(Bar::new(0.95, 1.0, 1.0).unwrap(), 1e-3).unwrap();
        let layout = Layout::of(&system);
        assert_eq!(layout.per_coefficient(), 4);
        assert_eq!(layout.index(0, 1, 0), 2);
        assert_eq!(layout.index(3, 1, 1), 15);
        let x: Vec<f64> = (0..16).map(f64::from).collect();
        assert_eq!(layout.pair(&x, 2, 0), (8.0, 9.0));
    }
}
