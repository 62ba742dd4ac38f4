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
        .with_src(dir.join("src/ffi/order.rs"))
        // The ORDER file's types (`TrisortOrderRange`, `TrisortOrderSource`).
        .with_src(dir.join("../format/src/order.rs"))
        .generate()
        .expect("cbindgen generates the header")
        .write(&mut out);
    String::from_utf8(out).expect("UTF-8 header")
}

#[test]
fn header_is_current() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("include/trisort.h");
    let fresh = generate();
    if std::env::var_os("TRISORT_BLESS").is_some() {
        std::fs::write(&path, &fresh).unwrap();
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
fn header_declares_the_abi_version_and_every_entry_point() {
    let h = generate();
    assert!(h.contains("#define TRISORT_ABI_VERSION 4"), "{h}");
    for f in [
        "trisort_abi_version",
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
        "trisort_export_order",
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
    ] {
        assert!(h.contains(&format!(" {f}(")), "{f} missing from the header");
    }
}
