//! Every composed shader parses and validates with naga (no GPU needed) and has every
//! `{{NAME}}` placeholder filled.

#[test]
fn every_shader_validates() {
    let all = trisort_gpu::all();
    assert!(!all.is_empty());
    for (name, source) in all {
        let left = trisort_gpu::shader_source::placeholders(&source);
        assert!(
            left.is_empty(),
            "{name}: placeholders left unfilled: {left:?}"
        );
        let module = naga::front::wgsl::parse_str(&source)
            .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(&source)));
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::all(),
        )
        .validate(&module)
        .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(&source)));
    }
}

/// The assembly refuses a placeholder left without a value, so a shader can never reach the
/// GPU with `{{NAME}}` text in it.
#[test]
#[should_panic(expected = "placeholder `{{GROUP}}` is unfilled")]
fn an_unfilled_placeholder_is_caught() {
    trisort_gpu::compose(&[], "@group({{GROUP}}) @binding(0) var<uniform> x: f32;");
}

#[test]
fn a_broken_shader_is_caught() {
    let source = trisort_gpu::compose(&[], "fn broken() -> f32 { return undefined_thing; }");
    assert!(naga::front::wgsl::parse_str(&source).is_err());
}

/// Every WGSL file of the repository lies in the top-level `shaders/` (grouped by stage:
/// `common/`, `record/`, `play/`, `reference/`), and each reaches the validation above: its
/// text is part of at least one composed shader of `trisort_gpu::all()` (a new file that no
/// composition uses fails here).
#[test]
fn every_wgsl_file_is_validated() {
    let all = trisort_gpu::all();
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("the workspace root")
        .to_path_buf();
    let shaders = root.join("shaders");
    let mut files = 0;
    for path in wgsl_files(&root) {
        assert!(
            path.starts_with(&shaders),
            "{} lies outside shaders/: every WGSL file lives there",
            path.display()
        );
        files += 1;
        let text = std::fs::read_to_string(&path).expect("readable WGSL");
        // Lines with a `{{NAME}}` placeholder are filled in by the assembly: every other line
        // must appear in one composed shader.
        let placeholder = |l: &str| !trisort_gpu::shader_source::placeholders(l).is_empty();
        let lines: Vec<&str> = text
            .lines()
            .filter(|l| !l.trim().is_empty() && !placeholder(l))
            .collect();
        assert!(
            all.iter().any(|(_, s)| lines.iter().all(|l| s.contains(l))),
            "{} is in no shader of trisort_gpu::all()",
            path.display()
        );
    }
    assert!(
        files >= 19,
        "found only {files} WGSL files in {}",
        shaders.display()
    );
}

/// The `.wgsl` files under `dir`, skipping build output, dependencies and hidden folders.
fn wgsl_files(dir: &std::path::Path) -> Vec<std::path::PathBuf> {
    let mut out = Vec::new();
    let mut todo = vec![dir.to_path_buf()];
    while let Some(d) = todo.pop() {
        for entry in std::fs::read_dir(&d).expect("a readable folder") {
            let path = entry.expect("directory entry").path();
            let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
            if path.is_dir() {
                if !(name.starts_with('.') || name == "target" || name == "node_modules") {
                    todo.push(path);
                }
            } else if path.extension().is_some_and(|e| e == "wgsl") {
                out.push(path);
            }
        }
    }
    out.sort();
    out
}
