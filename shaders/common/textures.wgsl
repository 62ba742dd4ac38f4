// Binding prelude of the data-texture tier (GLES 3.0 / WebGL2: no storage buffers in the
// vertex stage). Node matrices of every frame and the materials are Rgba32Float texels read
// with textureLoad, DATA_WIDTH texels a row, four texels (columns) a node matrix and
// MATERIAL_TEXELS (fields) a material; this
// frame's first node is `node_base.x`, a uniform bound by dynamic offset.
@group(0) @binding(1) var<uniform> node_base: vec4<u32>;
@group(0) @binding(2) var material_texels: texture_2d<f32>;
@group(0) @binding(5) var node_texels: texture_2d<f32>;

const DATA_WIDTH: u32 = 1024u;

fn node_texel(i: u32) -> vec4<f32> {
    return textureLoad(node_texels, vec2<i32>(i32(i % DATA_WIDTH), i32(i / DATA_WIDTH)), 0);
}

fn material_texel(i: u32) -> vec4<f32> {
    return textureLoad(material_texels, vec2<i32>(i32(i % DATA_WIDTH), i32(i / DATA_WIDTH)), 0);
}

fn node_matrix(node: u32) -> mat4x4<f32> {
    let i = (node_base.x + node) * 4u;
    return mat4x4<f32>(node_texel(i), node_texel(i + 1u), node_texel(i + 2u), node_texel(i + 3u));
}

// MATERIAL_TEXELS texels a material (the fields of `MaterialGpu` in order).
const MATERIAL_TEXELS: u32 = 20u;

fn material_at(index: u32) -> MaterialGpu {
    let i = index * MATERIAL_TEXELS;
    return MaterialGpu(
        material_texel(i), material_texel(i + 1u), material_texel(i + 2u), material_texel(i + 3u),
        material_texel(i + 4u), material_texel(i + 5u), material_texel(i + 6u), material_texel(i + 7u),
        material_texel(i + 8u), material_texel(i + 9u), material_texel(i + 10u), material_texel(i + 11u),
        material_texel(i + 12u), material_texel(i + 13u), material_texel(i + 14u), material_texel(i + 15u),
        material_texel(i + 16u), material_texel(i + 17u), material_texel(i + 18u), material_texel(i + 19u),
    );
}
