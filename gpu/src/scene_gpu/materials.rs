//! The material table as the shaders read it (`MaterialGpu`): factors, alpha mode, and per
//! texture slot its transform and where its texture lies in the arrays. The packing itself is
//! [`trisort_format::gpu_layout`]'s, shared with the C API.

pub(super) use trisort_format::gpu_layout::material_table;
pub use trisort_format::gpu_layout::MaterialGpu;
