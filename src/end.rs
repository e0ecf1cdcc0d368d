//! Identifiers of bars and of their ends: plain values that every other module may name
//! (the error types among them), so this module depends on no other module of the crate.
//! They are re-exported by [`crate::bar`], where they are documented for users.

use std::fmt;

/// Identifies a bar inside one assembly; minted by
/// [`AssemblyBuilder::add_bar`](crate::system::AssemblyBuilder::add_bar).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct BarId(pub(crate) usize);

impl BarId {
    /// Position of the bar in its assembly (0-based, in the order bars were added).
    pub fn index(self) -> usize {
        self.0
    }

    /// The end at `x = 0`.
    pub fn left(self) -> EndRef {
        EndRef {
            bar: self,
            end: End::Left,
        }
    }

    /// The end at `x = l`.
    pub fn right(self) -> EndRef {
        EndRef {
            bar: self,
            end: End::Right,
        }
    }
}

/// One of the two ends of a bar.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum End {
    /// The end at `x = 0`, outward normal `-1`.
    Left,
    /// The end at `x = l`, outward normal `+1`.
    Right,
}

impl End {
    /// Outward normal `n`: `-1` at `x = 0`, `+1` at `x = l`.
    pub fn normal(self) -> f64 {
        match self {
            End::Left => -1.0,
            End::Right => 1.0,
        }
    }
}

/// An end of a given bar.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct EndRef {
    /// The bar.
    pub bar: BarId,
    /// Which end.
    pub end: End,
}

impl fmt::Display for EndRef {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let side = match self.end {
            End::Left => "left (x = 0)",
            End::Right => "right (x = l)",
        };
        write!(f, "{} of bar {}", side, self.bar.0)
    }
}
