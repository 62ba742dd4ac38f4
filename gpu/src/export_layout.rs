//! The binding layout written beside exported shaders ([`crate::export_shaders`]):
//! `layout.json` (per (group, binding): what it is, its GLSL names per stage file, a uniform
//! block's std140 members, a texture's format and sampler state, and which C API function
//! copies out the bytes the player uploads there; the vertex attributes) and `README.md`.

use serde_json::{json, Value};

use crate::export_shaders::{names_of, ShaderLang};

/// What the player binds at a WGSL variable: its contents, format and the C API function that
/// copies the bytes out.
fn binding_notes(name: &str) -> Value {
    match name {
        "frame" => json!({
            "contents": "the Frame uniform of the frame drawn (144 bytes)",
            "c_api": "trisort_gpu_frame_uniform",
        }),
        "node_base" => json!({
            "contents": "x: the frame's first node in the node texels (frame × node count; node count = max(1, TrisortInfo.node_count)), yzw 0",
            "c_api": "computed by the host",
        }),
        "material_texels" => json!({
            "contents": "the material table, 20 RGBA32F texels a material (the fields of MaterialGpu in order), 1024 texels a row",
            "format": "RGBA32F (GL_RGBA32F, GL_FLOAT), 1 level, read with texelFetch",
            "c_api": "trisort_gpu_material_texels",
        }),
        "node_texels" => json!({
            "contents": "every frame's camera-relative node matrices (view × world), 4 RGBA32F texels (columns) a node, 1024 texels a row",
            "format": "RGBA32F (GL_RGBA32F, GL_FLOAT), 1 level, read with texelFetch",
            "c_api": "trisort_gpu_node_texels",
        }),
        "node_view" => json!({
            "contents": "this frame's camera-relative node matrices (view × world), mat4x4<f32> each, bound at the frame's offset",
            "c_api": "trisort_gpu_node_texels (one frame is node count × 64 bytes)",
        }),
        "materials" => json!({
            "contents": "the material table, MaterialGpu (320 bytes) each",
            "c_api": "trisort_gpu_material_texels",
        }),
        "srgb_textures" => json!({
            "contents": "base-colour and emissive textures, one a layer, every level",
            "format": "RGBA8 sRGB (GL_SRGB8_ALPHA8), 2D array, full mip chain",
            "c_api": "trisort_gpu_texture_array (TRISORT_TEXTURE_ARRAY_SRGB), trisort_gpu_texture_array_level",
        }),
        "linear_textures" => json!({
            "contents": "metallic-roughness, normal and occlusion textures, one a layer, every level",
            "format": "RGBA8 (GL_RGBA8), 2D array, full mip chain",
            "c_api": "trisort_gpu_texture_array (TRISORT_TEXTURE_ARRAY_LINEAR), trisort_gpu_texture_array_level",
        }),
        "material_sampler" => json!({
            "sampler": {"min": "linear, mipmap linear", "mag": "linear", "wrap_s": "clamp to edge", "wrap_t": "clamp to edge"},
        }),
        "lighting" => json!({
            "contents": "the Lighting uniform (192 bytes)",
            "c_api": "trisort_gpu_lighting_uniform",
        }),
        "environment" => json!({
            "contents": "the prefiltered environment radiance, equirectangular, row 0 at the zenith; level k for roughness k / (levels − 1)",
            "format": "RGBA16F (GL_RGBA16F, GL_HALF_FLOAT), 2D, the levels given (GL_TEXTURE_MAX_LEVEL = levels − 1)",
            "c_api": "trisort_gpu_environment, trisort_gpu_environment_level",
        }),
        "environment_sampler" => json!({
            "sampler": {"min": "linear, mipmap linear", "mag": "linear", "wrap_s": "repeat", "wrap_t": "clamp to edge"},
        }),
        _ => json!({}),
    }
}

/// A type's GLSL name (std140 view) and WGSL name.
fn type_names(module: &naga::Module, ty: naga::Handle<naga::Type>) -> (String, String) {
    use naga::TypeInner as T;
    let scalar = |s: naga::Scalar| match s.kind {
        naga::ScalarKind::Uint => ("u", "u32"),
        naga::ScalarKind::Sint => ("i", "i32"),
        _ => ("", "f32"),
    };
    let t = &module.types[ty];
    match &t.inner {
        T::Scalar(s) => {
            let (g, w) = scalar(*s);
            let glsl = match g {
                "u" => "uint",
                "i" => "int",
                _ => "float",
            };
            (glsl.into(), w.into())
        }
        T::Vector { size, scalar: s } => {
            let (g, w) = scalar(*s);
            (
                format!("{g}vec{}", *size as u8),
                format!("vec{}<{w}>", *size as u8),
            )
        }
        T::Matrix { columns, rows, .. } => {
            let (c, r) = (*columns as u8, *rows as u8);
            let g = if c == r {
                format!("mat{c}")
            } else {
                format!("mat{c}x{r}")
            };
            (g, format!("mat{c}x{r}<f32>"))
        }
        T::Array { base, size, .. } => {
            let (g, w) = type_names(module, *base);
            match size {
                naga::ArraySize::Constant(n) => (format!("{g}[{n}]"), format!("array<{w}, {n}>")),
                _ => (format!("{g}[]"), format!("array<{w}>")),
            }
        }
        _ => {
            let name = t.name.clone().unwrap_or_default();
            (name.clone(), name)
        }
    }
}

/// The members of a buffer's type with std140 offsets and sizes (WGSL's uniform layout and
/// std140 agree for every type the player's uniforms use).
fn members(
    module: &naga::Module,
    layouter: &naga::proc::Layouter,
    ty: naga::Handle<naga::Type>,
) -> Value {
    match &module.types[ty].inner {
        naga::TypeInner::Struct { members, .. } => members
            .iter()
            .map(|m| {
                let (glsl, wgsl) = type_names(module, m.ty);
                json!({
                    "name": m.name,
                    "offset": m.offset,
                    "size": layouter[m.ty].size,
                    "glsl_type": glsl,
                    "wgsl_type": wgsl,
                })
            })
            .collect(),
        _ => {
            let (glsl, wgsl) = type_names(module, ty);
            json!([{ "name": null, "offset": 0, "size": layouter[ty].size, "glsl_type": glsl, "wgsl_type": wgsl }])
        }
    }
}

/// `layout.json`: the export's files, every binding of group 0 and the vertex attributes.
pub(crate) fn layout_json(
    lang: ShaderLang,
    module: &naga::Module,
    files: Vec<Value>,
    stage_names: &[(String, crate::export_shaders::StageNames)],
) -> Value {
    let mut layouter = naga::proc::Layouter::default();
    layouter
        .update(module.to_ctx())
        .expect("the player's types lay out");
    let mut bindings: Vec<(u32, u32, Value)> = Vec::new();
    for (_, var) in module.global_variables.iter() {
        let Some(rb) = &var.binding else { continue };
        let name = var.name.clone().unwrap_or_default();
        let (glsl_type, wgsl_type) = type_names(module, var.ty);
        let kind = match (&var.space, &module.types[var.ty].inner) {
            (naga::AddressSpace::Uniform, _) => "uniform buffer",
            (naga::AddressSpace::Storage { .. }, _) => "storage buffer (read only)",
            (_, naga::TypeInner::Sampler { .. }) => "sampler",
            _ => "texture",
        };
        let mut entry = json!({
            "group": rb.group,
            "binding": rb.binding,
            "wgsl_name": name,
            "kind": kind,
            "wgsl_type": wgsl_type,
        });
        let obj = entry.as_object_mut().expect("object");
        if kind.ends_with("buffer") || kind.starts_with("storage") {
            obj.insert("size".into(), json!(layouter[var.ty].size));
            obj.insert("members".into(), members(module, &layouter, var.ty));
            obj.insert(
                "layout".into(),
                json!(if kind == "uniform buffer" {
                    "std140"
                } else {
                    "std430"
                }),
            );
        } else if kind == "texture" {
            obj.insert("glsl_type".into(), json!(glsl_type));
        }
        if lang == ShaderLang::GlslEs300 {
            obj.insert(
                "glsl_names".into(),
                names_of(stage_names, rb.group, rb.binding),
            );
        }
        if let Value::Object(notes) = binding_notes(&name) {
            obj.extend(notes);
        }
        bindings.push((rb.group, rb.binding, entry));
    }
    bindings.sort_by_key(|a| (a.0, a.1));
    let attributes = [
        (0, "position", "float32x3", 0, "GL_FLOAT × 3"),
        (1, "normal", "float32x3", 12, "GL_FLOAT × 3"),
        (2, "uv", "float32x2", 24, "GL_FLOAT × 2"),
        (
            3,
            "material",
            "uint32",
            32,
            "GL_UNSIGNED_INT × 1, glVertexAttribIPointer",
        ),
        (
            4,
            "node",
            "uint32",
            36,
            "GL_UNSIGNED_INT × 1, glVertexAttribIPointer",
        ),
        (5, "tangent", "float32x4", 40, "GL_FLOAT × 4"),
        (6, "uv1", "float32x2", 56, "GL_FLOAT × 2"),
    ];
    json!({
        "generator": "trisort export-shaders",
        "lang": lang.name(),
        "tier": lang.bindings().name(),
        "files": files,
        "bindings": bindings.into_iter().map(|(_, _, v)| v).collect::<Vec<_>>(),
        "vertex": {
            "stride": 64,
            "c_api": "trisort_vertices (TrisortVertex)",
            "attributes": attributes.iter().map(|(location, name, format, offset, gl)| json!({
                "location": location, "name": name, "format": format, "offset": offset, "gl": gl,
            })).collect::<Vec<_>>(),
        },
        "data_textures": {
            "width": trisort_format::gpu_layout::DATA_WIDTH,
            "material_texels": trisort_format::gpu_layout::MATERIAL_TEXELS,
            "node_texels": 4,
        },
        "pipeline": {
            "front_face": "counter-clockwise in WGSL's clip space (the GLSL negates y: clockwise in GL's)",
            "cull": "none (the fragment stage discards back faces of single-sided materials)",
            "blend": {
                "straight": "colour src-alpha, one-minus-src-alpha; alpha one, one-minus-src-alpha (blend mode, drawn back to front)",
                "premultiplied": "colour and alpha one-minus-dst-alpha, one (saturate mode, drawn front to back)",
            },
            "target": "linear RGBA16F at the recorded size and sample count, resolved, then quantized once to 8-bit sRGB",
        },
    })
}

/// The `README.md` written beside the shaders.
pub(crate) fn readme(lang: ShaderLang) -> String {
    let specific = match lang {
        ShaderLang::GlslEs300 => GLSL_NOTES,
        ShaderLang::Spirv => SPIRV_NOTES,
        ShaderLang::Wgsl => WGSL_NOTES,
    };
    format!("{README_HEAD}\n{specific}\n{README_DATA}")
}

const README_HEAD: &str = "# trisort's player shaders (`trisort export-shaders`)

The vertex and fragment stages `trisort play` draws with, translated by naga from the WGSL the
player compiles (`shaders/common/common.wgsl`, a binding prelude, `shaders/play/player.wgsl`).
`layout.json` lists every binding of group 0 (its kind, std140 members with offsets and sizes,
texture formats, sampler state, and for GLSL the names each stage file gives it), the vertex
attributes (the 64-byte `TrisortVertex`: `trisort_vertices`) and the pipeline state.

Files: `player.vert` (entry `vs_player`), and per surface model (`pbr`: glTF
metallic-roughness lit by the bake's environment, exposed and tone mapped per fragment;
`basic`: one light plus ambient) a fragment stage with straight alpha (`blend` and `depth`
modes) and one with premultiplied alpha (`saturate` mode).
";

const GLSL_NOTES: &str = "## GLSL ES 3.00

The data-texture tier: node matrices and materials are RGBA32F textures read with `texelFetch`
(GLES 3.0 has no storage buffers). `SHADING_MODEL` is resolved in each fragment file. GLSL ES
3.00 has no `layout(binding = …)`, so a host binds by name after linking, as wgpu's GL backend
does: `bindings.txt` has a line per name, `FILE uniform GROUP BINDING BLOCK` (call
`glUniformBlockBinding(program, glGetUniformBlockIndex(program, BLOCK), POINT)` and bind the
buffer at that point) and `FILE texture GROUP BINDING SAMPLER SAMPLER_BINDING` (set the
`sampler2D`/`sampler2DArray` uniform to a texture unit holding the texture of BINDING, with the
sampler state of SAMPLER_BINDING; −1: read with `texelFetch`, nearest, no mips). The vertex and
fragment stage name the same binding differently (`_vs`/`_fs`, `…Vertex`/`…Fragment` blocks):
bind both.

Clip space is adjusted to GL's in the vertex stage (`gl_Position.y` negated, depth mapped
from 0..w to −w..w), as wgpu's GL backend does: the `Frame` uniform's projection is the
player's own (depth 0 to 1, `trisort_gpu_frame_uniform`), the image comes out upside down in
GL's window coordinates (GL's row 0 is the image's top row: read back rows as they come for
top-to-bottom images, flip when presenting), and front faces turn clockwise (`glFrontFace(GL_CW)`;
culling stays off). Drawn this way, MSAA sample positions (GL counts them from a pixel's lower
corner) fall where Vulkan's do.
";

const SPIRV_NOTES: &str = "## SPIR-V

SPIR-V 1.0, one module per stage (entry points as in WGSL), the storage tier: descriptor set =
group, binding = binding; node matrices (binding 1, this frame's, a dynamic offset) and
materials (binding 2) are read-only storage buffers. `SHADING_MODEL` is resolved in each
fragment module. Clip space is WGSL's (y up, depth 0 to 1): draw with a negative-height
viewport (as wgpu does) to get the image's top row first.
";

const WGSL_NOTES: &str = "## WGSL

One module per surface model with all three entry points (`vs_player`, `fs_player_straight`,
`fs_player_premultiplied`), the storage tier. `SHADING_MODEL` stays a pipeline-overridable
constant whose default is the file's model (1 pbr, 0 basic).
";

const README_DATA: &str = "## Where the bytes come from

The C API (`trisort.h`, ABI 5) copies out exactly what the player uploads:
`trisort_gpu_frame_uniform` (binding 0), `trisort_gpu_lighting_uniform` (binding 7),
`trisort_gpu_material_texels` (binding 2), `trisort_gpu_node_texels` (binding 5 on the texture
tier; frame f's matrices start at node f × node count, binding 1's `x`),
`trisort_gpu_texture_array` / `trisort_gpu_texture_array_level` (bindings 3 and 6),
`trisort_gpu_environment` / `trisort_gpu_environment_level` (binding 8). Vertices:
`trisort_vertices`; the sorted indices and each frame's ranges: `trisort_indices_u16`/`_u32`
and `trisort_frame_ranges`. Draw into a linear RGBA16F target at the recorded size and sample
count with the blend state of `layout.json`'s `pipeline`, resolve, and quantize once to 8-bit
sRGB (`saturate` mode: add (1 − alpha) × the background first). `examples/c-gles/host.c
--shading pbr --shaders DIR` does all of this.
";
