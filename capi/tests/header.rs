//! The checked-in `include/trisort.h` must equal a fresh cbindgen generation (CI runs this).
//! `TRISORT_BLESS=1 cargo test -p trisort-capi header` rewrites it.

use std::path::Path;

fn generate() -> String {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let config = cbindgen::Config::from_file(dir.join("cbindgen.toml")).expect("cbindgen.toml");
    let mut out = Vec::new();
    cbindgen::Builder::new()
        .with_config(config)
        // The header's functions come in the order of these files (`[fn] sort_by = "None"`).
        .with_src(dir.join("src/ffi/types.rs"))
        .with_src(dir.join("src/ffi/boundary.rs"))
        .with_src(dir.join("src/ffi/baked.rs"))
        .with_src(dir.join("src/ffi/materials.rs"))
        .with_src(dir.join("src/ffi/playback.rs"))
        .with_src(dir.join("src/ffi/environment.rs"))
        .with_src(dir.join("src/ffi/gpu_data.rs"))
        .with_src(dir.join("src/ffi/order.rs"))
        // The ORDER file's types (`TrisortOrderRange`, `TrisortOrderSource`).
        .with_src(dir.join("../format/src/order.rs"))
        .generate()
        .expect("cbindgen generates the header")
        .write(&mut out);
    String::from_utf8(out).expect("UTF-8 header")
}

/// `include/trisort_export.h`: libtrisort_export's one addition (trisort-capi-export).
fn generate_export() -> String {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("export");
    let config = cbindgen::Config::from_file(dir.join("cbindgen.toml")).expect("cbindgen.toml");
    let mut out = Vec::new();
    cbindgen::Builder::new()
        .with_config(config)
        .with_src(dir.join("src/lib.rs"))
        .generate()
        .expect("cbindgen generates the export header")
        .write(&mut out);
    String::from_utf8(out).expect("UTF-8 header")
}

fn check_current(name: &str, fresh: &str) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("include")
        .join(name);
    if std::env::var_os("TRISORT_BLESS").is_some() {
        std::fs::write(&path, fresh).unwrap();
    }
    let checked_in = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        checked_in == fresh,
        "{} differs from a fresh cbindgen generation: run \
         `TRISORT_BLESS=1 cargo test -p trisort-capi header` and commit it",
        path.display()
    );
}

#[test]
fn header_is_current() {
    check_current("trisort.h", &generate());
    check_current("trisort_export.h", &generate_export());
}

/// The header reads as C: no Rust intra-doc links or paths, no undefined "module
/// conventions", and the conventions it refers to are written at its top.
#[test]
fn header_documents_itself_in_c_terms() {
    for (name, h) in [
        ("trisort.h", generate()),
        ("trisort_export.h", generate_export()),
    ] {
        for rust in ["[`", "Option<", "module conventions", "Self", "crate::"] {
            assert!(!h.contains(rust), "{name} contains Rust wording `{rust}`");
        }
        // A Rust path to one of the API's own types (`TrisortStatus::Ok`); C++ and Vulkan
        // names (`trisort::trisort`, `VkPhysicalDeviceLimits::…`) are fine.
        for (i, _) in h.match_indices("::") {
            let word = h[..i]
                .rsplit(|c: char| !c.is_alphanumeric())
                .next()
                .unwrap();
            assert!(
                !(word.starts_with("Trisort") || word.starts_with("Order")),
                "{name} names a Rust path: {word}::"
            );
        }
    }
    let h = generate();
    for convention in [
        "The copy convention (out, cap, len)",
        "column major",
        "Threads.",
        "Lifetimes.",
        "uint32_t",
        "right handed, +Y up, metres",
    ] {
        assert!(h.contains(convention), "trisort.h lacks `{convention}`");
    }
    // Every enum argument is a uint32_t: no function takes a C enum by value.
    for line in h
        .lines()
        .filter(|l| l.contains('(') || l.starts_with("    "))
    {
        for e in ["TrisortDepthRange ", "TrisortMode ", "TrisortAlphaMode "] {
            assert!(
                !line.trim_start().starts_with(e),
                "an enum taken by value: {line}"
            );
        }
    }
    assert!(generate_export().contains(" trisort_export_order("));
    assert!(
        !h.contains(" trisort_export_order("),
        "export_order is libtrisort_export's"
    );
}

#[test]
fn header_declares_the_abi_version_and_every_entry_point() {
    let h = generate();
    assert!(h.contains("#define TRISORT_ABI_VERSION 6"), "{h}");
    assert!(h.contains("#define TRISORT_FORMAT_VERSION 7"), "{h}");
    // Taken as uint32_t, so no function names the enum: its values must still be there.
    assert!(
        h.contains("TRISORT_DEPTH_RANGE_MINUS_ONE_TO_ONE = 1"),
        "{h}"
    );
    for f in [
        "trisort_abi_version",
        "trisort_format_version",
        "trisort_version_string",
        "trisort_last_error",
        "trisort_open_path",
        "trisort_open_bytes",
        "trisort_close",
        "trisort_info",
        "trisort_indices_u16",
        "trisort_indices_u32",
        "trisort_frame_ranges",
        "trisort_frame_draws",
        "trisort_vertices",
        "trisort_frame_view",
        "trisort_frame_projection",
        "trisort_frame_node_matrices",
        "trisort_materials",
        "trisort_texture",
        "trisort_texture_info",
        "trisort_texture_level",
        "trisort_order_open_path",
        "trisort_order_triangles",
        "trisort_fps",
        "trisort_environment_info",
        "trisort_environment_name",
        "trisort_environment_level",
        "trisort_variant_count",
        "trisort_variant_name",
        "trisort_variant_materials",
        "trisort_raster_profile",
        "trisort_check_device",
        "trisort_gpu_frame_uniform",
        "trisort_gpu_lighting_uniform",
        "trisort_gpu_material_texels",
        "trisort_gpu_node_texels",
        "trisort_gpu_texture_array",
        "trisort_gpu_texture_array_level",
        "trisort_gpu_environment",
        "trisort_gpu_environment_level",
        "trisort_clip_count",
        "trisort_clip_name",
        "trisort_clip_frames",
        "trisort_clip_fps",
        "trisort_clip_find",
    ] {
        assert!(h.contains(&format!(" {f}(")), "{f} missing from the header");
    }
}
