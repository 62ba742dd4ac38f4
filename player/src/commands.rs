//! The index buffer and the indirect commands in the order a mode plays them.
//!
//! A baked file stores its triangles front to back. Back-to-front playback (`blend`) reverses
//! the list of copies (each triangle keeps its own winding) and every frame's draw list: a draw
//! over indices `[first, first + count)` of `N` copies becomes `[3N − first − count, 3N − first)`
//! of the reversed buffer, so the same windows draw the same triangles in the opposite order.
//! Pure functions over plain data; the GPU upload is in [`crate::Player`].

use trisort_format::{Baked, DrawIndexedIndirectArgs, FrameWindow};

/// Which way the triangle list is played.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Order {
    /// As stored: front to back (`depth`, `saturate`).
    FrontToBack,
    /// Reversed: back to front (`blend`).
    BackToFront,
}

/// Index data, u16 where every vertex index fits.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Indices {
    /// 16-bit indices.
    U16(Vec<u16>),
    /// 32-bit indices.
    U32(Vec<u32>),
}

impl Indices {
    /// Number of indices.
    pub fn len(&self) -> usize {
        match self {
            Indices::U16(v) => v.len(),
            Indices::U32(v) => v.len(),
        }
    }

    /// Whether there are no indices.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The wgpu index format.
    pub fn format(&self) -> wgpu::IndexFormat {
        match self {
            Indices::U16(_) => wgpu::IndexFormat::Uint16,
            Indices::U32(_) => wgpu::IndexFormat::Uint32,
        }
    }

    /// The raw bytes to upload.
    pub fn bytes(&self) -> &[u8] {
        match self {
            Indices::U16(v) => bytemuck::cast_slice(v),
            Indices::U32(v) => bytemuck::cast_slice(v),
        }
    }

    /// Index `k` as u32.
    pub fn get(&self, k: usize) -> u32 {
        match self {
            Indices::U16(v) => v[k] as u32,
            Indices::U32(v) => v[k],
        }
    }
}

/// The index format [`index_buffer`] chooses: u16 when [`Baked::fits_u16`], unless
/// `force_u32`.
pub fn index_format(baked: &Baked, force_u32: bool) -> wgpu::IndexFormat {
    if baked.fits_u16() && !force_u32 {
        wgpu::IndexFormat::Uint16
    } else {
        wgpu::IndexFormat::Uint32
    }
}

/// Number of indirect commands [`frame_commands`] lists: every frame's draws.
pub fn command_count(baked: &Baked) -> usize {
    (0..baked.frames.len())
        .map(|f| baked.frame_draws(f).len())
        .sum()
}

/// The index buffer of `baked` in `order`: `geometry.triangles[copies[k]]` for each copy,
/// copies reversed for [`Order::BackToFront`], in [`index_format`]. Requires
/// `baked.check_structure()` to hold.
pub fn index_buffer(baked: &Baked, order: Order, force_u32: bool) -> Indices {
    let tris = &baked.geometry.triangles;
    let copies: Box<dyn Iterator<Item = &u32>> = match order {
        Order::FrontToBack => Box::new(baked.copies.iter()),
        Order::BackToFront => Box::new(baked.copies.iter().rev()),
    };
    if index_format(baked, force_u32) == wgpu::IndexFormat::Uint16 {
        let mut out = Vec::with_capacity(baked.copies.len() * 3);
        for &c in copies {
            out.extend(tris[c as usize].iter().map(|&v| v as u16));
        }
        Indices::U16(out)
    } else {
        let mut out = Vec::with_capacity(baked.copies.len() * 3);
        for &c in copies {
            out.extend_from_slice(&tris[c as usize]);
        }
        Indices::U32(out)
    }
}

/// Every frame's draws in `order`, back to back (frame 0's first), and each frame's window
/// into that list. For [`Order::BackToFront`] each frame's list is reversed and each draw's
/// range mirrored onto the reversed index buffer. Requires `baked.check_structure()` to hold.
pub fn frame_commands(
    baked: &Baked,
    order: Order,
) -> (Vec<DrawIndexedIndirectArgs>, Vec<FrameWindow>) {
    let total = baked.copies.len() as u32 * 3;
    let mut draws = Vec::with_capacity(command_count(baked));
    let mut windows = Vec::with_capacity(baked.frames.len());
    for f in 0..baked.frames.len() {
        let first = draws.len() as u32;
        let own = baked.frame_draws(f);
        match order {
            Order::FrontToBack => draws.extend_from_slice(own),
            Order::BackToFront => draws.extend(own.iter().rev().map(|d| {
                debug_assert!(d.first_index + d.index_count <= total);
                DrawIndexedIndirectArgs {
                    first_index: total - d.first_index - d.index_count,
                    ..*d
                }
            })),
        }
        windows.push(FrameWindow {
            first,
            count: own.len() as u32,
        });
    }
    (draws, windows)
}

#[cfg(test)]
mod tests {
    use super::*;
    use trisort_format::{Geometry, Vertex};

    fn args(first_index: u32, index_count: u32) -> DrawIndexedIndirectArgs {
        DrawIndexedIndirectArgs {
            index_count,
            instance_count: 1,
            first_index,
            base_vertex: 0,
            first_instance: 0,
        }
    }

    /// Five triangles over distinct vertices; copies [3, 0, 1, 4, 0, 2].
    fn baked() -> Baked {
        let v = Vertex {
            position: [0.0; 3],
            normal: [0.0; 3],
            uv: [0.0; 2],
            material: 0,
            node: 0,
            tangent: [0.0; 4],
            uv1: [0.0; 2],
        };
        let geometry = Geometry {
            vertices: vec![v; 15],
            triangles: (0..5).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect(),
            ..Default::default()
        };
        let mut b = crate_test_baked(geometry);
        b.copies = vec![3, 0, 1, 4, 0, 2];
        b.draws = vec![args(0, 9), args(12, 6), args(3, 6), args(15, 3)];
        b.frames = vec![
            FrameWindow { first: 0, count: 2 },
            FrameWindow { first: 2, count: 2 },
        ];
        b
    }

    fn crate_test_baked(geometry: Geometry) -> Baked {
        Baked {
            tool_version: String::new(),
            scene_hash: [0; 32],
            path_hash: [0; 32],
            recording_hashes: vec![],
            settings: Default::default(),
            device: Default::default(),
            merge: Default::default(),
            stats: Default::default(),
            scene_ids: (0..geometry.triangles.len() as u32).collect(),
            geometry,
            copies: vec![],
            draws: vec![],
            frames: vec![],
            frame_states: vec![],
            removed_edges: vec![],
            fps: None,
            environment: trisort_format::Environment::uniform(1.0),
            clips: vec![],
        }
    }

    /// The triangles (as index triples) a frame draws, in order.
    fn drawn(indices: &Indices, draws: &[DrawIndexedIndirectArgs]) -> Vec<[u32; 3]> {
        let mut out = Vec::new();
        for d in draws {
            for k in (d.first_index..d.first_index + d.index_count).step_by(3) {
                let k = k as usize;
                out.push([indices.get(k), indices.get(k + 1), indices.get(k + 2)]);
            }
        }
        out
    }

    #[test]
    fn back_to_front_draws_exactly_the_reverse_of_each_frame() {
        let b = baked();
        let fwd = index_buffer(&b, Order::FrontToBack, false);
        let rev = index_buffer(&b, Order::BackToFront, false);
        assert_eq!(fwd.format(), wgpu::IndexFormat::Uint16);
        assert_eq!(fwd.len(), 18);
        let (fd, fw) = frame_commands(&b, Order::FrontToBack);
        let (rd, rw) = frame_commands(&b, Order::BackToFront);
        assert_eq!(fw, rw);
        for (f, w) in fw.iter().enumerate() {
            let range = w.first as usize..(w.first + w.count) as usize;
            let front = drawn(&fwd, &fd[range.clone()]);
            let mut back = drawn(&rev, &rd[range]);
            back.reverse();
            assert_eq!(front, back, "frame {f}");
            assert!(!front.is_empty());
        }
        // Frame 0 front to back: copies 0..3 then 4..6 → triangles 3, 0, 1, 0, 2.
        let w = fw[0];
        let f0 = drawn(&fwd, &fd[w.first as usize..(w.first + w.count) as usize]);
        let ids: Vec<u32> = f0.iter().map(|t| t[0] / 3).collect();
        assert_eq!(ids, vec![3, 0, 1, 0, 2]);
        // The first draw of frame 0 in blend order is the mirror of its last one.
        assert_eq!(rd[0].first_index, 18 - 12 - 6);
        assert_eq!(rd[1].first_index, 18 - 9);
    }

    #[test]
    fn u32_path_holds_the_same_indices() {
        let b = baked();
        let a = index_buffer(&b, Order::BackToFront, false);
        let c = index_buffer(&b, Order::BackToFront, true);
        assert_eq!(c.format(), wgpu::IndexFormat::Uint32);
        assert_eq!(a.len(), c.len());
        assert!((0..a.len()).all(|k| a.get(k) == c.get(k)));
        assert_eq!(c.bytes().len(), 2 * a.bytes().len());
    }
}
