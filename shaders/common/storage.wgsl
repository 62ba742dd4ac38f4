// Binding prelude of the storage tier (Vulkan, Metal, DX12, GL with vertex storage): node
// matrices of this frame bound by dynamic offset, and the materials, in storage buffers.
@group(0) @binding(1) var<storage, read> node_view: array<mat4x4<f32>>;
@group(0) @binding(2) var<storage, read> materials: array<MaterialGpu>;

fn node_matrix(node: u32) -> mat4x4<f32> {
    return node_view[node];
}

fn material_at(index: u32) -> MaterialGpu {
    return materials[index];
}
