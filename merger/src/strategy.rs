//! Strategy order: the six merging strategies and the two layouts that linearize the
//! upper-triangular matrix of cells (paper §5.1, Figure 11; DESIGN § Merger, Strategies).
//!
//! A copy in cell (i, j), i ≤ j, is drawn in every frame i..=j. With L = (i, j−1),
//! I = (i, j) and B = (i+1, j), a strategy fixes the order of L, I and B; a layout is one total
//! order of all cells (the index-buffer order) consistent with it. Frame f's window is every
//! cell with i ≤ f ≤ j, drawn in layout order, so the layout alone decides the draw order of
//! cells inside every window; the merger therefore works with the layout's [`cell_key`].

use std::fmt;

/// The order of L = (i, j−1), I = (i, j) and B = (i+1, j) in every window (paper §5.1).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Strategy {
    /// L, then I, then B: rows top to bottom, each row left to right.
    Lib,
    /// L, then B, then I.
    Lbi,
    /// I, then L, then B: the corner (longest-lived) cells first.
    Ilb,
    /// I, then B, then L.
    Ibl,
    /// B, then L, then I.
    Bli,
    /// B, then I, then L: the exact reverse of LIB.
    Bil,
}

impl Strategy {
    /// All six strategies, in a fixed order (ties of `auto` go to the first).
    pub const ALL: [Strategy; 6] = [
        Strategy::Lib,
        Strategy::Lbi,
        Strategy::Ilb,
        Strategy::Ibl,
        Strategy::Bli,
        Strategy::Bil,
    ];

    /// Lower-case name as the CLI spells it (`lib`, `lbi`, …).
    pub fn name(self) -> &'static str {
        match self {
            Strategy::Lib => "lib",
            Strategy::Lbi => "lbi",
            Strategy::Ilb => "ilb",
            Strategy::Ibl => "ibl",
            Strategy::Bli => "bli",
            Strategy::Bil => "bil",
        }
    }

    /// Parses a lower-case name.
    pub fn from_name(name: &str) -> Option<Strategy> {
        Strategy::ALL.into_iter().find(|s| s.name() == name)
    }
}

impl fmt::Display for Strategy {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// How the cells are linearized into the index buffer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Layout {
    /// The paper's: row-wise for LIB and BIL, by diagonals for the other four (a window then
    /// needs up to F ranges).
    Paper,
    /// Rows or columns chosen so that frame f's window needs at most max(f+1, F−f) ranges:
    /// LIB column-major; ILB rows with j descending; BLI rows descending, j ascending; IBL
    /// columns descending; LBI columns ascending, i descending; BIL columns descending,
    /// i descending.
    Compact,
}

impl Layout {
    /// Both layouts.
    pub const ALL: [Layout; 2] = [Layout::Paper, Layout::Compact];

    /// Lower-case name (`paper`, `compact`).
    pub fn name(self) -> &'static str {
        match self {
            Layout::Paper => "paper",
            Layout::Compact => "compact",
        }
    }
}

impl fmt::Display for Layout {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The position of cell (i, j) in the index buffer of a matrix of `frames` frames, as a
/// sort key: cells are stored in ascending key order, and every window is drawn in that order.
///
/// Requires i ≤ j < frames (frames relative to the matrix, i.e. to its segment). Distinct
/// cells get distinct keys. For every strategy and layout the order satisfies the strategy's
/// L/I/B relation wherever the three cells exist. O(1).
///
/// ```
/// use trisort_merger::strategy::{cell_key, Layout, Strategy};
/// // LIB, paper layout: row-major.
/// assert!(cell_key(Strategy::Lib, Layout::Paper, 4, 0, 3) < cell_key(Strategy::Lib, Layout::Paper, 4, 1, 1));
/// // ILB, paper layout: the top-right corner (I of everything) first.
/// assert!(cell_key(Strategy::Ilb, Layout::Paper, 4, 0, 3) < cell_key(Strategy::Ilb, Layout::Paper, 4, 0, 0));
/// ```
pub fn cell_key(strategy: Strategy, layout: Layout, frames: u32, i: u32, j: u32) -> u64 {
    debug_assert!(
        i <= j && j < frames,
        "cell ({i}, {j}) outside a {frames}-frame matrix"
    );
    let n = frames as u64;
    let (i, j) = (i as u64, j as u64);
    let d = j - i;
    let last = n - 1;
    let (major, minor) = match (strategy, layout) {
        (Strategy::Lib, Layout::Paper) => (i, j),
        (Strategy::Lib, Layout::Compact) => (j, i),
        (Strategy::Bil, Layout::Paper) => (last - i, last - j),
        (Strategy::Bil, Layout::Compact) => (last - j, last - i),
        (Strategy::Ilb, Layout::Paper) => (last - d, i),
        (Strategy::Ilb, Layout::Compact) => (i, last - j),
        (Strategy::Ibl, Layout::Paper) => (last - d, last - i),
        (Strategy::Ibl, Layout::Compact) => (last - j, i),
        (Strategy::Lbi, Layout::Paper) => (d, i),
        (Strategy::Lbi, Layout::Compact) => (j, last - i),
        (Strategy::Bli, Layout::Paper) => (d, last - i),
        (Strategy::Bli, Layout::Compact) => (last - i, j),
    };
    major * n + minor
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every layout respects its strategy's L/I/B order wherever the three cells exist.
    #[test]
    fn layouts_respect_their_strategy() {
        let n = 7;
        for s in Strategy::ALL {
            for l in Layout::ALL {
                let k = |i, j| cell_key(s, l, n, i, j);
                for i in 0..n - 1 {
                    for j in i + 1..n {
                        let (lk, ik, bk) = (k(i, j - 1), k(i, j), k(i + 1, j));
                        let want = match s {
                            Strategy::Lib => lk < ik && ik < bk,
                            Strategy::Lbi => lk < bk && bk < ik,
                            Strategy::Ilb => ik < lk && lk < bk,
                            Strategy::Ibl => ik < bk && bk < lk,
                            Strategy::Bli => bk < lk && lk < ik,
                            Strategy::Bil => bk < ik && ik < lk,
                        };
                        assert!(want, "{s} {l} violates its order at ({i}, {j})");
                    }
                }
            }
        }
    }

    /// Keys are distinct, and the compact layouts need at most max(f+1, F−f) ranges per
    /// window (F for the paper's diagonal layouts).
    #[test]
    fn window_range_counts() {
        let n = 9u32;
        for s in Strategy::ALL {
            for l in Layout::ALL {
                let mut cells: Vec<(u64, u32, u32)> = (0..n)
                    .flat_map(|i| (i..n).map(move |j| (cell_key(s, l, n, i, j), i, j)))
                    .collect();
                cells.sort();
                assert!(
                    cells.windows(2).all(|w| w[0].0 < w[1].0),
                    "{s} {l}: equal keys"
                );
                for f in 0..n {
                    let inside: Vec<bool> =
                        cells.iter().map(|&(_, i, j)| i <= f && f <= j).collect();
                    let ranges = inside
                        .iter()
                        .enumerate()
                        .filter(|&(k, &b)| b && (k == 0 || !inside[k - 1]))
                        .count() as u32;
                    let bound = match l {
                        Layout::Compact => (f + 1).max(n - f),
                        Layout::Paper => n,
                    };
                    assert!(
                        ranges <= bound,
                        "{s} {l} frame {f}: {ranges} ranges > {bound}"
                    );
                }
            }
        }
    }
}
