//! The player's shaders for hosts (`trisort export-shaders`): its vertex stage and its
//! fragment stages (physically based with the tone map, and basic; straight and premultiplied
//! alpha) translated by naga from the very WGSL the player compiles ([`crate::compose_with`]
//! of [`crate::PLAYER`]), with the binding layout a host needs written beside them
//! (`layout.json`, `bindings.txt`, `README.md`).
//!
//! GLSL ES 3.00 takes the data-texture tier (`shaders/common/textures.wgsl`: GLES 3.0 has no
//! storage buffers); SPIR-V and WGSL the storage tier. The `SHADING_MODEL` override is
//! resolved per fragment file (naga's pipeline-constant processing) before GLSL or SPIR-V is
//! written; the WGSL modules keep it as an `override` whose default is the file's model.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use naga::back::{glsl, spv};
use serde_json::{json, Value};

use crate::scene_gpu::Bindings;

/// A language the player's shaders are exported in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShaderLang {
    /// GLSL ES 3.00 (OpenGL ES 3.0, WebGL2): the data-texture tier.
    GlslEs300,
    /// SPIR-V 1.0 (Vulkan): the storage tier.
    Spirv,
    /// WGSL (WebGPU, wgpu): the storage tier.
    Wgsl,
}

impl ShaderLang {
    /// Every language, in the order of [`ShaderLang::name`]'s list.
    pub const ALL: [ShaderLang; 3] = [ShaderLang::GlslEs300, ShaderLang::Spirv, ShaderLang::Wgsl];

    /// The command-line name: `glsl-es-300`, `spirv` or `wgsl`.
    pub fn name(self) -> &'static str {
        match self {
            ShaderLang::GlslEs300 => "glsl-es-300",
            ShaderLang::Spirv => "spirv",
            ShaderLang::Wgsl => "wgsl",
        }
    }

    /// The language of a command-line name.
    pub fn parse(name: &str) -> Option<ShaderLang> {
        ShaderLang::ALL.into_iter().find(|l| l.name() == name)
    }

    /// The binding tier the language's shaders are composed for.
    pub fn bindings(self) -> Bindings {
        match self {
            ShaderLang::GlslEs300 => Bindings::Textures,
            ShaderLang::Spirv | ShaderLang::Wgsl => Bindings::Storage,
        }
    }
}

/// One file of an export: its name in the output folder and its bytes.
#[derive(Clone, Debug)]
pub struct ShaderFile {
    /// File name (no folders).
    pub name: String,
    /// Contents.
    pub contents: Vec<u8>,
}

/// Why an export failed.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    /// naga refused the player's WGSL or could not translate it (a bug: the naga test compiles
    /// every shader).
    #[error("{what}: {message}")]
    Naga {
        /// What was being done (`parse`, `validate`, a file's name).
        what: String,
        /// naga's message.
        message: String,
    },
    /// The output folder could not be written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The path that failed.
        path: PathBuf,
        /// The error.
        #[source]
        source: std::io::Error,
    },
    /// The output path exists and is not a folder.
    #[error("{}: exists and is not a directory", .0.display())]
    NotADirectory(PathBuf),
}

/// The surface models exported, with their `SHADING_MODEL` value.
const MODELS: [(&str, f64); 2] = [("pbr", 1.0), ("basic", 0.0)];

/// The fragment entry points exported: straight alpha (`blend`, `depth` modes) and
/// premultiplied (`saturate`).
const OUTPUTS: [(&str, &str); 2] = [
    ("straight", "fs_player_straight"),
    ("premultiplied", "fs_player_premultiplied"),
];

/// One stage file of an export.
struct Stage {
    /// File name without the language's extension.
    stem: String,
    stage: naga::ShaderStage,
    entry: &'static str,
    /// `SHADING_MODEL` for a fragment stage.
    model: Option<(&'static str, f64)>,
}

/// The vertex stage, then each model × output fragment stage.
fn stages() -> Vec<Stage> {
    let mut out = vec![Stage {
        stem: "player.vert".into(),
        stage: naga::ShaderStage::Vertex,
        entry: "vs_player",
        model: None,
    }];
    for model in MODELS {
        for (output, entry) in OUTPUTS {
            out.push(Stage {
                stem: format!("{}_{output}.frag", model.0),
                stage: naga::ShaderStage::Fragment,
                entry,
                model: Some(model),
            });
        }
    }
    out
}

/// The player's module for a tier, parsed and validated.
fn player_module(
    bindings: Bindings,
) -> Result<(String, naga::Module, naga::valid::ModuleInfo), ExportError> {
    let source = crate::compose_with(bindings, &[], crate::PLAYER);
    let module = naga::front::wgsl::parse_str(&source).map_err(|e| ExportError::Naga {
        what: "parse the player's WGSL".into(),
        message: e.emit_to_string(&source),
    })?;
    let info = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::empty(),
    )
    .validate(&module)
    .map_err(|e| ExportError::Naga {
        what: "validate the player's WGSL".into(),
        message: e.emit_to_string(&source),
    })?;
    Ok((source, module, info))
}

/// What a host binds for one stage file: per (group, binding), the GLSL name(s) and kind.
#[derive(Default)]
pub(crate) struct StageNames {
    /// (group, binding, kind, GLSL name, sampler binding).
    entries: Vec<(u32, u32, &'static str, String, Option<u32>)>,
}

/// A stage with its overrides resolved: the module and info to hand a backend.
fn resolved<'a>(
    module: &'a naga::Module,
    info: &'a naga::valid::ModuleInfo,
    stage: &Stage,
) -> Result<
    (
        std::borrow::Cow<'a, naga::Module>,
        std::borrow::Cow<'a, naga::valid::ModuleInfo>,
    ),
    ExportError,
> {
    let mut constants = naga::back::PipelineConstants::default();
    if let Some((_, value)) = stage.model {
        constants.insert("SHADING_MODEL".into(), value);
    }
    naga::back::pipeline_constants::process_overrides(
        module,
        info,
        Some((stage.stage, stage.entry)),
        &constants,
    )
    .map_err(|e| ExportError::Naga {
        what: format!("resolve the overrides of {}", stage.stem),
        message: e.to_string(),
    })
}

/// One stage as GLSL ES 3.00, and the names it gives each binding. Options as wgpu's GL
/// backend writes them: clip space adjusted to GL's (y negated, depth −w..w), no bounds checks.
fn glsl_stage(
    module: &naga::Module,
    info: &naga::valid::ModuleInfo,
    stage: &Stage,
) -> Result<(String, StageNames), ExportError> {
    let (module, info) = resolved(module, info, stage)?;
    let options = glsl::Options {
        version: glsl::Version::new_gles(300),
        writer_flags: glsl::WriterFlags::ADJUST_COORDINATE_SPACE,
        binding_map: Default::default(),
        zero_initialize_workgroup_memory: true,
    };
    let pipeline = glsl::PipelineOptions {
        shader_stage: stage.stage,
        entry_point: stage.entry.into(),
        multiview: None,
    };
    let fail = |e: glsl::Error| ExportError::Naga {
        what: format!("write {}", stage.stem),
        message: e.to_string(),
    };
    let mut text = String::new();
    let reflection = glsl::Writer::new(
        &mut text,
        &module,
        &info,
        &options,
        &pipeline,
        naga::proc::BoundsCheckPolicies::default(),
    )
    .map_err(fail)?
    .write()
    .map_err(fail)?;
    let binding = |h: naga::Handle<naga::GlobalVariable>| {
        module.global_variables[h]
            .binding
            .as_ref()
            .map(|b| (b.group, b.binding))
            // naga reflects bound resources only: an unbound one here is a bug, not a line
            // of bindings.txt.
            .expect("a reflected resource has a binding")
    };
    let mut names = StageNames::default();
    for (h, name) in &reflection.uniforms {
        let (g, b) = binding(*h);
        names.entries.push((g, b, "uniform", name.clone(), None));
    }
    for (name, mapping) in &reflection.texture_mapping {
        let (g, b) = binding(mapping.texture);
        let sampler = mapping.sampler.map(|s| binding(s).1);
        names.entries.push((g, b, "texture", name.clone(), sampler));
    }
    names.entries.sort_by_key(|a| (a.0, a.1));
    Ok((text, names))
}

/// One stage as SPIR-V 1.0 words, with options as wgpu's Vulkan backend writes them (no
/// coordinate adjustment: wgpu draws with a negative-height viewport).
fn spirv_stage(
    module: &naga::Module,
    info: &naga::valid::ModuleInfo,
    stage: &Stage,
) -> Result<Vec<u8>, ExportError> {
    let (module, info) = resolved(module, info, stage)?;
    let options = spv::Options {
        lang_version: (1, 0),
        flags: spv::WriterFlags::LABEL_VARYINGS,
        ..Default::default()
    };
    let pipeline = spv::PipelineOptions {
        shader_stage: stage.stage,
        entry_point: stage.entry.into(),
    };
    let words = spv::write_vec(&module, &info, &options, Some(&pipeline)).map_err(|e| {
        ExportError::Naga {
            what: format!("write {}.spv", stage.stem),
            message: e.to_string(),
        }
    })?;
    Ok(words.iter().flat_map(|w| w.to_le_bytes()).collect())
}

/// The player's shaders in `lang`, with `layout.json`, `bindings.txt` (GLSL only) and
/// `README.md`, in the order written.
pub fn export_player_shaders(lang: ShaderLang) -> Result<Vec<ShaderFile>, ExportError> {
    let (source, module, info) = player_module(lang.bindings())?;
    let mut files = Vec::new();
    let mut stage_names = Vec::new();
    let mut listing = Vec::new();
    match lang {
        ShaderLang::GlslEs300 => {
            for stage in stages() {
                let (text, names) = glsl_stage(&module, &info, &stage)?;
                files.push(ShaderFile {
                    name: stage.stem.clone(),
                    contents: text.into_bytes(),
                });
                listing.push(stage_json(&stage, &stage.stem));
                stage_names.push((stage.stem, names));
            }
        }
        ShaderLang::Spirv => {
            for stage in stages() {
                let name = format!("{}.spv", stage.stem);
                files.push(ShaderFile {
                    name: name.clone(),
                    contents: spirv_stage(&module, &info, &stage)?,
                });
                listing.push(stage_json(&stage, &name));
            }
        }
        ShaderLang::Wgsl => {
            for (model, value) in MODELS {
                let name = format!("{model}.wgsl");
                let text = with_model_default(&source, value as u32);
                // The rewritten module still validates (a bug otherwise).
                player_module_text(&text, &name)?;
                files.push(ShaderFile {
                    name: name.clone(),
                    contents: text.into_bytes(),
                });
                listing.push(json!({
                    "file": name, "stages": ["vertex", "fragment"],
                    "entry_points": ["vs_player", "fs_player_straight", "fs_player_premultiplied"],
                    "shading": model,
                }));
            }
        }
    }
    let layout = crate::export_layout::layout_json(lang, &module, listing, &stage_names);
    files.push(ShaderFile {
        name: "layout.json".into(),
        contents: serde_json::to_vec_pretty(&layout)
            .expect("JSON")
            .into_iter()
            .chain(*b"\n")
            .collect(),
    });
    if lang == ShaderLang::GlslEs300 {
        files.push(ShaderFile {
            name: "bindings.txt".into(),
            contents: bindings_txt(&stage_names).into_bytes(),
        });
    }
    files.push(ShaderFile {
        name: "README.md".into(),
        contents: crate::export_layout::readme(lang).into_bytes(),
    });
    Ok(files)
}

/// A stage file's entry in `layout.json`'s `files`.
fn stage_json(stage: &Stage, file: &str) -> Value {
    let (shading, output) = match stage.model {
        Some((model, _)) => (
            Value::from(model),
            Value::from(if stage.entry.ends_with("premultiplied") {
                "premultiplied"
            } else {
                "straight"
            }),
        ),
        None => (Value::Null, Value::Null),
    };
    json!({
        "file": file,
        "stage": match stage.stage { naga::ShaderStage::Vertex => "vertex", _ => "fragment" },
        "entry_point": stage.entry,
        "shading": shading,
        "alpha": output,
    })
}

/// The module text with `SHADING_MODEL`'s default set to `model`.
fn with_model_default(source: &str, model: u32) -> String {
    let from = "override SHADING_MODEL: u32 = 2u;";
    assert!(source.contains(from), "common.wgsl declares `{from}`");
    source.replace(from, &format!("override SHADING_MODEL: u32 = {model}u;"))
}

/// Parses and validates WGSL text `text` (file `name`).
fn player_module_text(text: &str, name: &str) -> Result<(), ExportError> {
    let module = naga::front::wgsl::parse_str(text).map_err(|e| ExportError::Naga {
        what: format!("parse {name}"),
        message: e.emit_to_string(text),
    })?;
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::empty(),
    )
    .validate(&module)
    .map_err(|e| ExportError::Naga {
        what: format!("validate {name}"),
        message: e.emit_to_string(text),
    })?;
    Ok(())
}

/// `bindings.txt`: one line per GLSL name of each stage file, for C hosts to read with
/// `sscanf`: `FILE uniform GROUP BINDING BLOCK_NAME` or
/// `FILE texture GROUP BINDING SAMPLER_NAME SAMPLER_BINDING` (−1: texelFetch only).
fn bindings_txt(stage_names: &[(String, StageNames)]) -> String {
    let mut out = String::from(
        "# trisort export-shaders: the GLSL names of each (group, binding), per stage file.\n\
         # FILE uniform GROUP BINDING BLOCK_NAME\n\
         # FILE texture GROUP BINDING SAMPLER_UNIFORM SAMPLER_BINDING (-1: none, texelFetch)\n",
    );
    for (file, names) in stage_names {
        for (g, b, kind, name, sampler) in &names.entries {
            let _ = match sampler {
                Some(s) => writeln!(out, "{file} {kind} {g} {b} {name} {s}"),
                None if *kind == "texture" => writeln!(out, "{file} {kind} {g} {b} {name} -1"),
                None => writeln!(out, "{file} {kind} {g} {b} {name}"),
            };
        }
    }
    out
}

/// The GLSL names of one stage file, for `layout.json`: per (group, binding), its names.
pub(crate) fn names_of(stage_names: &[(String, StageNames)], group: u32, binding: u32) -> Value {
    let mut out = serde_json::Map::new();
    for (file, names) in stage_names {
        let found: Vec<&String> = names
            .entries
            .iter()
            .filter(|e| {
                e.0 == group && (e.1 == binding || (e.2 == "texture" && e.4 == Some(binding)))
            })
            .map(|e| &e.3)
            .collect();
        if !found.is_empty() {
            out.insert(file.clone(), json!(found));
        }
    }
    Value::Object(out)
}

/// Writes `files` into folder `dir`: into a new sibling folder first, renamed to `dir` once
/// every file is written, so `dir` is never half written. An existing `dir` is replaced
/// whole; an existing file of that name is refused.
pub fn write_export(dir: &Path, files: &[ShaderFile]) -> Result<(), ExportError> {
    if dir.exists() && !dir.is_dir() {
        return Err(ExportError::NotADirectory(dir.to_path_buf()));
    }
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| ExportError::Io { path, source }
    };
    let parent = match dir.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let leaf = dir
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "shaders".into());
    let tmp = parent.join(format!(".{leaf}.tmp-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&tmp);
    std::fs::create_dir_all(&tmp).map_err(io(&tmp))?;
    let written = (|| {
        for f in files {
            let path = tmp.join(&f.name);
            std::fs::write(&path, &f.contents).map_err(io(&path))?;
        }
        if dir.exists() {
            let old = parent.join(format!(".{leaf}.old-{}", std::process::id()));
            std::fs::rename(dir, &old).map_err(io(dir))?;
            std::fs::rename(&tmp, dir).map_err(io(dir))?;
            std::fs::remove_dir_all(&old).map_err(io(&old))?;
        } else {
            std::fs::rename(&tmp, dir).map_err(io(dir))?;
        }
        Ok(())
    })();
    if written.is_err() {
        let _ = std::fs::remove_dir_all(&tmp);
    }
    written
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_language_exports_every_stage() {
        for lang in ShaderLang::ALL {
            let files = export_player_shaders(lang).unwrap();
            let names: Vec<&str> = files.iter().map(|f| f.name.as_str()).collect();
            assert!(
                names.contains(&"layout.json") && names.contains(&"README.md"),
                "{names:?}"
            );
            let stages = files.len() - 2 - (lang == ShaderLang::GlslEs300) as usize;
            assert_eq!(
                stages,
                if lang == ShaderLang::Wgsl { 2 } else { 5 },
                "{names:?}"
            );
        }
    }

    #[test]
    fn glsl_resolves_the_model_and_names_every_binding() {
        let files = export_player_shaders(ShaderLang::GlslEs300).unwrap();
        let text = |name: &str| {
            String::from_utf8(
                files
                    .iter()
                    .find(|f| f.name == name)
                    .unwrap()
                    .contents
                    .clone(),
            )
            .unwrap()
        };
        let pbr = text("pbr_straight.frag");
        assert!(pbr.starts_with("#version 300 es"), "{pbr}");
        assert!(pbr.contains("Lighting_block") && pbr.contains("const uint SHADING_MODEL = 1u;"));
        let bindings = text("bindings.txt");
        for b in [0, 2, 3, 6, 7, 8] {
            assert!(
                bindings.contains(&format!("pbr_straight.frag uniform 0 {b} "))
                    || bindings.contains(&format!("pbr_straight.frag texture 0 {b} ")),
                "binding {b}: {bindings}"
            );
        }
        assert!(bindings.contains("player.vert texture 0 5 "), "{bindings}");
        assert!(bindings.contains("player.vert uniform 0 1 "), "{bindings}");
    }

    #[test]
    fn write_export_replaces_the_folder_whole() {
        let dir = std::env::temp_dir().join(format!("trisort-export-test-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let one = |name: &str| ShaderFile {
            name: name.into(),
            contents: b"x".to_vec(),
        };
        write_export(&dir, &[one("a")]).unwrap();
        write_export(&dir, &[one("b")]).unwrap();
        assert!(!dir.join("a").exists() && dir.join("b").exists());
        std::fs::remove_dir_all(&dir).unwrap();
        let file = std::env::temp_dir().join(format!("trisort-export-file-{}", std::process::id()));
        std::fs::write(&file, b"").unwrap();
        assert!(matches!(
            write_export(&file, &[one("a")]),
            Err(ExportError::NotADirectory(_))
        ));
        std::fs::remove_file(&file).unwrap();
    }
}
