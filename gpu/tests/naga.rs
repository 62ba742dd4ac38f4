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
