//! Strategy order: the six merging strategies and the two layouts that linearize the
//! upper-triangular matrix of cells (paper §5.1, Figure 11).
//!
//! A copy in cell (i, j), i ≤ j, is drawn in every frame i..=j. With L = (i, j−1),
//! I = (i, j) and B = (i+1, j), a strategy fixes the order of L, I and B; a layout is one total
//! order of all cells (the index-buffer order) consistent with it. Frame f's window is every
//! cell with i ≤ f ≤ j, drawn in layout order, so the layout alone decides the draw order of
//! cells inside every window; the merger therefore works with the layout's [`cell_key`].

pub use trisort_format::{Layout, Strategy};

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
