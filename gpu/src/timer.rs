//! GPU time between two timestamps, for `trisort play` (one frame's render pass) and
//! `trisort bench` (a method's whole frame, several passes).

/// Two timestamp queries, their resolve buffer and a staging buffer to read them back.
pub struct GpuTimer {
    set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    staging: wgpu::Buffer,
    period_ns: f64,
}

impl GpuTimer {
    /// The timer, or `None` where the device lacks `TIMESTAMP_QUERY` (and, when
    /// `inside_encoders`, `TIMESTAMP_QUERY_INSIDE_ENCODERS`, which [`GpuTimer::write_start`]
    /// and [`GpuTimer::write_end`] need; a pass's [`GpuTimer::pass_writes`] do not).
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        inside_encoders: bool,
    ) -> Option<GpuTimer> {
        let mut needed = wgpu::Features::TIMESTAMP_QUERY;
        if inside_encoders {
            needed |= wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS;
        }
        if !device.features().contains(needed) {
            return None;
        }
        let buffer = |label, usage| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: 16,
                usage,
                mapped_at_creation: false,
            })
        };
        Some(GpuTimer {
            set: device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("trisort timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: 2,
            }),
            resolve: buffer(
                "trisort timestamps",
                wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            ),
            staging: buffer(
                "trisort timestamps readback",
                wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            ),
            period_ns: queue.get_timestamp_period() as f64,
        })
    }

    /// Timestamp writes at the beginning and end of one render pass.
    pub fn pass_writes(&self) -> wgpu::RenderPassTimestampWrites<'_> {
        wgpu::RenderPassTimestampWrites {
            query_set: &self.set,
            beginning_of_pass_write_index: Some(0),
            end_of_pass_write_index: Some(1),
        }
    }

    /// Writes the start timestamp into `enc` (outside any pass).
    pub fn write_start(&self, enc: &mut wgpu::CommandEncoder) {
        enc.write_timestamp(&self.set, 0);
    }

    /// Writes the end timestamp into `enc` (outside any pass).
    pub fn write_end(&self, enc: &mut wgpu::CommandEncoder) {
        enc.write_timestamp(&self.set, 1);
    }

    /// Resolves both timestamps and copies them to the staging buffer.
    pub fn resolve(&self, enc: &mut wgpu::CommandEncoder) {
        enc.resolve_query_set(&self.set, 0..2, &self.resolve, 0);
        enc.copy_buffer_to_buffer(&self.resolve, 0, &self.staging, 0, 16);
    }

    /// The staging buffer to map after the submission.
    pub fn staging(&self) -> &wgpu::Buffer {
        &self.staging
    }

    /// Milliseconds between the two timestamps from the staging buffer's mapped bytes
    /// (`None` if the end precedes the start).
    pub fn ms(&self, staging_bytes: &[u8]) -> Option<f64> {
        let ts: &[u64] = bytemuck::cast_slice(staging_bytes);
        (ts[1] >= ts[0]).then(|| (ts[1] - ts[0]) as f64 * self.period_ns / 1e6)
    }
}
