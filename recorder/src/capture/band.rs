//! A band of rows read back from a capture: each sample's fragment list, sorted into the
//! peel's order, walked in parallel runs of samples.

use super::Fragment;

/// One band of rows read back: list heads and the node pool, as words of the mapped readback.
pub(crate) struct Band<'a> {
    pub(super) words: &'a [u32],
    /// Heads are `words[..split]`, nodes (4 words each) `words[split..]`.
    pub(super) split: usize,
    /// The image's slot of the band's first sample (`(y · width + x) · samples + s`).
    pub(super) first: usize,
}

impl Band<'_> {
    /// Samples in this band.
    pub fn slots(&self) -> usize {
        self.split
    }

    /// Walks every sample's sorted fragment list ([`Band::sorted`]) with `walk` (which also gets
    /// the sample's slot in the image, `(y · width + x) · samples + s`), in parallel
    /// over runs of samples, each run into its own state made by `init`; returns the states
    /// (in run order) for the caller to merge. What the caller merges must not depend on how
    /// samples were split into runs (sums, unions, maxima), so recordings stay identical
    /// whatever the thread count.
    pub fn walk<S: Send>(
        &self,
        init: impl Fn() -> S + Sync,
        walk: impl Fn(&mut S, usize, &[Fragment]) + Sync,
    ) -> Vec<S> {
        use rayon::prelude::*;
        let runs = (rayon::current_num_threads() * 4).max(1);
        let per_run = self.slots().div_ceil(runs).max(1);
        (0..self.slots())
            .step_by(per_run)
            .collect::<Vec<usize>>()
            .into_par_iter()
            .map(|start| {
                let mut state = init();
                let mut list = Vec::new();
                for slot in start..(start + per_run).min(self.slots()) {
                    self.sorted(slot, &mut list);
                    walk(&mut state, self.first + slot, &list);
                }
                state
            })
            .collect()
    }

    /// The fragments of the band's sample `slot` (0-based within the band) sorted by
    /// (depth, id), the order the peel's layers give them, into `out` (cleared first).
    pub fn sorted(&self, slot: usize, out: &mut Vec<Fragment>) {
        out.clear();
        let nodes = &self.words[self.split..];
        let mut n = self.words[slot];
        while n != 0 {
            let node = &nodes[(n as usize - 1) * 4..n as usize * 4];
            out.push(Fragment {
                depth: f32::from_bits(node[0]),
                id: node[1],
                alpha: f32::from_bits(node[2]),
            });
            n = node[3];
        }
        // The peel's order: a fragment comes after another when its depth is greater, or equal
        // (as `==` compares: -0 and +0 are equal) with a greater id. Depths are never NaN.
        out.sort_unstable_by(|a, b| {
            a.depth
                .partial_cmp(&b.depth)
                .unwrap_or(std::cmp::Ordering::Equal)
                .then(a.id.cmp(&b.id))
        });
    }
}
