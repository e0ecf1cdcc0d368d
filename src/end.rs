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

/// `right end (x = l) of bar 2 (the 3rd added)`: the end as a Rust caller wrote it
/// (`bar.right()`), its bar by [`BarId::index`], which counts from 0, with its rank in words so
/// that the count cannot be misread. Systems read from a file name their ends as the file does
/// (`b3.end`, `io::assembly`).
impl fmt::Display for EndRef {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let side = match self.end {
            End::Left => "left end (x = 0)",
            End::Right => "right end (x = l)",
        };
        write!(f, "{side} of {}", self.bar)
    }
}

/// `bar 2 (the 3rd added)`: the index of [`BarId::index`], counted from 0, and its rank.
impl fmt::Display for BarId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "bar {} (the {} added)",
            self.0,
            Ordinal(self.0.saturating_add(1))
        )
    }
}

/// `1st`, `2nd`, `3rd`, `4th`, ..., `11th`, `12th`, `13th`, `21st`, ...
struct Ordinal(usize);

impl fmt::Display for Ordinal {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let n = self.0;
        let suffix = match (n % 10, n % 100) {
            (_, 11..=13) => "th",
            (1, _) => "st",
            (2, _) => "nd",
            (3, _) => "rd",
            _ => "th",
        };
        write!(f, "{n}{suffix}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ends_are_named_as_written_with_their_rank() {
        assert_eq!(
            BarId(2).right().to_string(),
            "right end (x = l) of bar 2 (the 3rd added)"
        );
        assert_eq!(
            BarId(0).left().to_string(),
            "left end (x = 0) of bar 0 (the 1st added)"
        );
        let ranks: Vec<String> = [1, 2, 3, 4, 11, 12, 13, 21, 22, 101, 111, 112]
            .iter()
            .map(|&n| Ordinal(n).to_string())
            .collect();
        assert_eq!(
            ranks,
            [
                "1st", "2nd", "3rd", "4th", "11th", "12th", "13th", "21st", "22nd", "101st",
                "111th", "112th"
            ]
        );
    }
}
