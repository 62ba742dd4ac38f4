//! A bounding volume hierarchy over axis-aligned boxes: the broad phase.
//!
//! Binary, built top-down by splitting at the median centroid along the longest axis of the
//! centroids' bounds, at most [`LEAF_SIZE`] boxes per leaf. Building is O(n log n) and
//! deterministic (ties broken by box index); a query visits only subtrees whose bounds
//! overlap the query box.

use glam::DVec3;

/// Most boxes in one leaf.
const LEAF_SIZE: usize = 4;

/// A closed axis-aligned box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Aabb {
    /// Smallest corner.
    pub lo: DVec3,
    /// Largest corner.
    pub hi: DVec3,
}

impl Aabb {
    /// The box around `points`.
    pub fn around(points: &[DVec3]) -> Aabb {
        let mut b = Aabb::EMPTY;
        for &p in points {
            b.lo = b.lo.min(p);
            b.hi = b.hi.max(p);
        }
        b
    }

    /// The box containing nothing (the identity of [`Aabb::union`]).
    const EMPTY: Aabb = Aabb {
        lo: DVec3::splat(f64::INFINITY),
        hi: DVec3::splat(f64::NEG_INFINITY),
    };

    fn union(self, other: Aabb) -> Aabb {
        Aabb {
            lo: self.lo.min(other.lo),
            hi: self.hi.max(other.hi),
        }
    }

    /// Whether the closed boxes share a point.
    pub fn overlaps(&self, other: &Aabb) -> bool {
        self.lo.cmple(other.hi).all() && other.lo.cmple(self.hi).all()
    }

    fn centre(&self) -> DVec3 {
        (self.lo + self.hi) * 0.5
    }
}

/// One node of the tree: a leaf holds `items[first..first + count]`; an inner node
/// (`count == 0`) has its left child right after it and its right child at `right`.
#[derive(Clone, Copy, Debug)]
struct BvhNode {
    bounds: Aabb,
    first: u32,
    count: u32,
    right: u32,
}

/// The hierarchy over a slice of boxes; items are indices into that slice.
pub(crate) struct Bvh {
    nodes: Vec<BvhNode>,
    items: Vec<u32>,
}

impl Bvh {
    /// Builds the tree over `boxes`.
    pub fn build(boxes: &[Aabb]) -> Bvh {
        let mut bvh = Bvh {
            nodes: Vec::with_capacity(2 * boxes.len() / LEAF_SIZE + 1),
            items: (0..boxes.len() as u32).collect(),
        };
        if !boxes.is_empty() {
            bvh.build_node(boxes, 0, boxes.len());
        }
        bvh
    }

    /// Builds the subtree over `items[start..end]` (non-empty) and returns its node index.
    fn build_node(&mut self, boxes: &[Aabb], start: usize, end: usize) -> u32 {
        let items = &mut self.items[start..end];
        let bounds = items
            .iter()
            .fold(Aabb::EMPTY, |b, &i| b.union(boxes[i as usize]));
        let index = self.nodes.len() as u32;
        self.nodes.push(BvhNode {
            bounds,
            first: start as u32,
            count: (end - start) as u32,
            right: 0,
        });
        if end - start <= LEAF_SIZE {
            return index;
        }
        let centres = items.iter().fold(Aabb::EMPTY, |b, &i| {
            let c = boxes[i as usize].centre();
            b.union(Aabb { lo: c, hi: c })
        });
        let extent = centres.hi - centres.lo;
        let axis = if extent.x >= extent.y && extent.x >= extent.z {
            0
        } else if extent.y >= extent.z {
            1
        } else {
            2
        };
        let mid = items.len() / 2;
        items.select_nth_unstable_by(mid, |&a, &b| {
            let ca = boxes[a as usize].centre()[axis];
            let cb = boxes[b as usize].centre()[axis];
            ca.total_cmp(&cb).then(a.cmp(&b))
        });
        self.build_node(boxes, start, start + mid);
        let right = self.build_node(boxes, start + mid, end);
        let node = &mut self.nodes[index as usize];
        node.count = 0;
        node.right = right;
        index
    }

    /// Calls `f` with every item whose box overlaps `query` (in no particular order).
    pub fn for_each_overlap(&self, boxes: &[Aabb], query: &Aabb, mut f: impl FnMut(u32)) {
        if self.nodes.is_empty() {
            return;
        }
        let mut stack = vec![0u32];
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n as usize];
            if !node.bounds.overlaps(query) {
                continue;
            }
            if node.count > 0 {
                let first = node.first as usize;
                for &item in &self.items[first..first + node.count as usize] {
                    if boxes[item as usize].overlaps(query) {
                        f(item);
                    }
                }
            } else {
                stack.push(node.right);
                stack.push(n + 1);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic scatter of small boxes; every overlapping pair the tree reports equals
    /// the brute-force set.
    #[test]
    fn queries_match_brute_force() {
        let mut seed = 12345u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let boxes: Vec<Aabb> = (0..500)
            .map(|_| {
                let c = DVec3::new(next(), next(), next()) * 10.0;
                let h = DVec3::new(next(), next(), next()) * 0.6;
                Aabb {
                    lo: c - h,
                    hi: c + h,
                }
            })
            .collect();
        let bvh = Bvh::build(&boxes);
        for (i, b) in boxes.iter().enumerate() {
            let mut found = Vec::new();
            bvh.for_each_overlap(&boxes, b, |j| found.push(j as usize));
            found.sort_unstable();
            let expected: Vec<usize> = (0..boxes.len()).filter(|&j| boxes[j].overlaps(b)).collect();
            assert_eq!(found, expected, "box {i}");
        }
    }
}
