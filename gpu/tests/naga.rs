//! Every composed shader parses and validates with naga (no GPU needed).

#[test]
fn every_shader_validates() {
    let all = trisort_gpu::all();
    assert!(!all.is_empty());
    for (name, source) in all {
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

#[test]
fn a_broken_shader_is_caught() {
    let source = trisort_gpu::compose(&[], "fn broken() -> f32 { return undefined_thing; }");
    assert!(naga::front::wgsl::parse_str(&source).is_err());
}

/// Every WGSL file of the crate's shader folder reaches the validation above: each file's text
/// is part of at least one composed shader of `trisort_gpu::all()` (a new file that no
/// composition uses fails here).
#[test]
fn every_wgsl_file_is_validated() {
    let all = trisort_gpu::all();
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src/wgsl");
    let mut files = 0;
    for entry in std::fs::read_dir(&dir).expect("gpu/src/wgsl") {
        let path = entry.expect("directory entry").path();
        if path.extension().is_none_or(|e| e != "wgsl") {
            continue;
        }
        files += 1;
        let text = std::fs::read_to_string(&path).expect("readable WGSL");
        // Placeholders (runs of capitals such as PREV_IDS_TYPE or UNDER) are filled in before
        // composition: every other line must appear in one composed shader.
        let placeholder = |l: &str| {
            l.split(|c: char| !(c.is_ascii_uppercase() || c == '_'))
                .any(|run| run.len() >= 5)
        };
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
        files >= 11,
        "found only {files} WGSL files in {}",
        dir.display()
    );
}
