//! The draw calls the player makes, as a small trait: implemented by `wgpu::RenderPass` (the
//! real thing) and by [`CallLog`], a recorder the tests use to count what a frame issues.

use std::ops::Range;

/// The subset of a render pass the player uses.
pub trait DrawCalls {
    /// `RenderPass::set_pipeline`.
    fn set_pipeline(&mut self, pipeline: &wgpu::RenderPipeline);
    /// `RenderPass::set_bind_group` with dynamic offsets.
    fn set_bind_group(&mut self, index: u32, bind_group: &wgpu::BindGroup, offsets: &[u32]);
    /// `RenderPass::set_vertex_buffer`.
    fn set_vertex_buffer(&mut self, slot: u32, buffer: wgpu::BufferSlice<'_>);
    /// `RenderPass::set_index_buffer`.
    fn set_index_buffer(&mut self, buffer: wgpu::BufferSlice<'_>, format: wgpu::IndexFormat);
    /// `RenderPass::multi_draw_indexed_indirect`: `count` draws of
    /// `DrawIndexedIndirectArgs` read from `buffer` at byte `offset`.
    fn multi_draw_indexed_indirect(&mut self, buffer: &wgpu::Buffer, offset: u64, count: u32);
    /// `RenderPass::draw_indexed`.
    fn draw_indexed(&mut self, indices: Range<u32>, base_vertex: i32, instances: Range<u32>);
}

impl DrawCalls for wgpu::RenderPass<'_> {
    fn set_pipeline(&mut self, pipeline: &wgpu::RenderPipeline) {
        wgpu::RenderPass::set_pipeline(self, pipeline);
    }
    fn set_bind_group(&mut self, index: u32, bind_group: &wgpu::BindGroup, offsets: &[u32]) {
        wgpu::RenderPass::set_bind_group(self, index, bind_group, offsets);
    }
    fn set_vertex_buffer(&mut self, slot: u32, buffer: wgpu::BufferSlice<'_>) {
        wgpu::RenderPass::set_vertex_buffer(self, slot, buffer);
    }
    fn set_index_buffer(&mut self, buffer: wgpu::BufferSlice<'_>, format: wgpu::IndexFormat) {
        wgpu::RenderPass::set_index_buffer(self, buffer, format);
    }
    fn multi_draw_indexed_indirect(&mut self, buffer: &wgpu::Buffer, offset: u64, count: u32) {
        wgpu::RenderPass::multi_draw_indexed_indirect(self, buffer, offset, count);
    }
    fn draw_indexed(&mut self, indices: Range<u32>, base_vertex: i32, instances: Range<u32>) {
        wgpu::RenderPass::draw_indexed(self, indices, base_vertex, instances);
    }
}

/// One recorded call.
#[derive(Clone, Debug, PartialEq)]
pub enum Call {
    /// `set_pipeline`.
    SetPipeline(wgpu::RenderPipeline),
    /// `set_bind_group`.
    SetBindGroup {
        /// Group index.
        index: u32,
        /// The bind group.
        bind_group: wgpu::BindGroup,
        /// Dynamic offsets.
        offsets: Vec<u32>,
    },
    /// `set_vertex_buffer`.
    SetVertexBuffer {
        /// Slot.
        slot: u32,
        /// The buffer.
        buffer: wgpu::Buffer,
        /// Byte offset of the slice.
        offset: u64,
        /// Byte size of the slice.
        size: u64,
    },
    /// `set_index_buffer`.
    SetIndexBuffer {
        /// The buffer.
        buffer: wgpu::Buffer,
        /// Index format.
        format: wgpu::IndexFormat,
        /// Byte offset of the slice.
        offset: u64,
        /// Byte size of the slice.
        size: u64,
    },
    /// `multi_draw_indexed_indirect`.
    MultiDrawIndexedIndirect {
        /// The indirect buffer.
        buffer: wgpu::Buffer,
        /// Byte offset of the first command.
        offset: u64,
        /// Number of commands.
        count: u32,
    },
    /// `draw_indexed`.
    DrawIndexed {
        /// Index range.
        indices: Range<u32>,
        /// Base vertex.
        base_vertex: i32,
        /// Instance range.
        instances: Range<u32>,
    },
}

impl Call {
    /// Whether the call draws (a multi-draw or a direct draw).
    pub fn is_draw(&self) -> bool {
        matches!(
            self,
            Call::MultiDrawIndexedIndirect { .. } | Call::DrawIndexed { .. }
        )
    }
}

/// A recorder of calls: what a pass would have been asked to do, in order.
#[derive(Clone, Debug, Default)]
pub struct CallLog {
    /// The calls, in order.
    pub calls: Vec<Call>,
}

impl CallLog {
    /// The drawing calls only.
    pub fn draws(&self) -> Vec<&Call> {
        self.calls.iter().filter(|c| c.is_draw()).collect()
    }
}

impl DrawCalls for CallLog {
    fn set_pipeline(&mut self, pipeline: &wgpu::RenderPipeline) {
        self.calls.push(Call::SetPipeline(pipeline.clone()));
    }
    fn set_bind_group(&mut self, index: u32, bind_group: &wgpu::BindGroup, offsets: &[u32]) {
        self.calls.push(Call::SetBindGroup {
            index,
            bind_group: bind_group.clone(),
            offsets: offsets.to_vec(),
        });
    }
    fn set_vertex_buffer(&mut self, slot: u32, buffer: wgpu::BufferSlice<'_>) {
        self.calls.push(Call::SetVertexBuffer {
            slot,
            buffer: buffer.buffer().clone(),
            offset: buffer.offset(),
            size: buffer.size(),
        });
    }
    fn set_index_buffer(&mut self, buffer: wgpu::BufferSlice<'_>, format: wgpu::IndexFormat) {
        self.calls.push(Call::SetIndexBuffer {
            buffer: buffer.buffer().clone(),
            format,
            offset: buffer.offset(),
            size: buffer.size(),
        });
    }
    fn multi_draw_indexed_indirect(&mut self, buffer: &wgpu::Buffer, offset: u64, count: u32) {
        self.calls.push(Call::MultiDrawIndexedIndirect {
            buffer: buffer.clone(),
            offset,
            count,
        });
    }
    fn draw_indexed(&mut self, indices: Range<u32>, base_vertex: i32, instances: Range<u32>) {
        self.calls.push(Call::DrawIndexed {
            indices,
            base_vertex,
            instances,
        });
    }
}
