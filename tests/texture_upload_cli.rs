//! Issue 34: a baked file's block-compressed textures on the GPU. `play` samples the blocks
//! where the device has the format's compression feature (BC on lavapipe) and says how it
//! uploaded each texture array (`--json` `texture_upload`); `play --decode-textures` uploads
//! their decoded RGBA8 texels instead, as a device without the feature does. `inspect`
//! budgets both: `gpu_bytes.textures` at the compressed size, `textures_decoded` decoded.

use crate::support::*;

/// The largest channel difference of two PNGs of the same size.
fn max_diff(a: &std::path::Path, b: &std::path::Path) -> u8 {
    let a = image::open(a).unwrap().to_rgba8();
    let b = image::open(b).unwrap().to_rgba8();
    assert_eq!(a.dimensions(), b.dimensions());
    a.as_raw()
        .iter()
        .zip(b.as_raw())
        .map(|(x, y)| x.abs_diff(*y))
        .max()
        .unwrap()
}

#[test]
fn play_samples_bc7_blocks_and_inspect_budgets_them_both_ways() {
    let Some(dir) = gpu_tempdir() else {
        return;
    };
    let d = dir.path();
    let bake =
        "bake demo:400 --path orbit:frames=3,degrees=60 --size 48x32 --textures bc7 -o x.baked";
    run(d, &args(bake), true);
    let inspect = run_json(d, &["inspect", "x.baked"]);
    let budget = &inspect["gpu_bytes"];
    let textures = budget["textures"].as_u64().unwrap();
    let decoded = budget["textures_decoded"].as_u64().unwrap();
    assert!(textures < decoded, "{budget}");
    let arrays = &budget["tiers"]["storage"]["texture_arrays"];
    assert_eq!(arrays["srgb"]["format"], "bc7", "{arrays}");
    assert_eq!(budget["assumes"]["texture_compression"][0], "bc");
    let native = run_json(d, &["play", "x.baked", "--out-dir", "native"]);
    let plain = run_json(
        d,
        &[
            "play",
            "x.baked",
            "--decode-textures",
            "--out-dir",
            "decoded",
        ],
    );
    assert_eq!(plain["texture_upload"]["srgb"], "rgba8 (decoded from bc7)");
    assert_eq!(plain["gpu_bytes_allocated"]["textures"], decoded, "{plain}");
    // On lavapipe (CI's device) BC is native; a device without it decodes.
    let upload = native["texture_upload"]["srgb"].as_str().unwrap();
    let allocated = native["gpu_bytes_allocated"]["textures"].as_u64().unwrap();
    match upload {
        "bc7" => assert_eq!(allocated, textures, "{native}"),
        _ => assert_eq!(allocated, decoded, "{native}"),
    }
    eprintln!("demo car: texture bytes {allocated} as {upload}, {decoded} decoded");
    // The same texels: frames equal but for sRGB conversion's last bit (lavapipe converts
    // BC7 sRGB texels to linear a step of 8 bits apart from RGBA8 ones now and then).
    for f in 0..3 {
        let name = format!("frame-{f:05}.png");
        let diff = max_diff(
            &d.join("native").join(&name),
            &d.join("decoded").join(&name),
        );
        assert!(
            diff <= 1,
            "frame {f}: native and decoded BC7 differ by {diff}/255"
        );
    }
    // `play --window --decode-textures`: tests/window_cli.rs (under Xvfb).
}

/// `bake --textures etc2|bc7`: the file stores blocks (smaller textures, `--json` `textures`
/// says how much and the colour error), and `verify --scene --recording` stays exact in the
/// three compositing modes: the reference draws the file's decoded texels once their alpha
/// (where it decides visibility) is checked against the scene's, and the graph check accepts
/// the recording's RGBA8 texture in place of the blocks on the same terms.
#[test]
fn compressed_bakes_verify_exact_in_every_mode() {
    let Some(dir) = gpu_tempdir() else {
        return;
    };
    let d = dir.path();
    for format in ["etc2", "bc7"] {
        let file = format!("{format}.baked");
        let bake = format!(
            "bake demo:400 --path orbit:frames=3,degrees=60 --size 48x32 --textures {format} \
             -o {file}"
        );
        let baked = run_json(d, &args(&bake));
        let t = &baked["textures"];
        assert_eq!(t["format"], format, "{t}");
        assert_eq!(t["compressed"], t["count"], "{t}");
        assert!(t["kept_rgba8"].as_array().unwrap().is_empty(), "{t}");
        let (rgba8, stored) = (
            t["rgba8_bytes"].as_u64().unwrap(),
            t["stored_bytes"].as_u64().unwrap(),
        );
        // ETC2 without alpha is 4 bits a texel, BC7 8: an eighth or a quarter, plus the
        // whole blocks of the 2×2 and 1×1 levels.
        let ratio = if format == "etc2" { 8 } else { 4 };
        assert!(
            stored * ratio < rgba8 + 64 * ratio,
            "{format}: {stored} of {rgba8} bytes"
        );
        let stored_as = t["per_texture"][0]["stored"].as_str().unwrap();
        assert!(stored_as.starts_with(format), "{t}");
        for mode in ["blend", "depth", "saturate"] {
            let v = run_json(
                d,
                &[
                    "verify",
                    &file,
                    "--scene",
                    "demo:400",
                    "--recording",
                    &format!("{file}.rec"),
                    "--mode",
                    mode,
                ],
            );
            assert_eq!(v["ok"], true, "{format} {mode}: {}", v["problems"]);
            assert_eq!(v["textures"]["format"], format, "{v}");
            assert_eq!(v["textures"]["compressed"], t["compressed"], "{v}");
        }
    }
    // rgba8 is the default and stores no blocks: verify has nothing to report on them.
    run(
        d,
        &args("bake demo:400 --path orbit:frames=3,degrees=60 --size 48x32 -o plain.baked"),
        true,
    );
    let v = run_json(d, &["verify", "plain.baked", "--scene", "demo:400"]);
    assert_eq!(v["ok"], true);
    assert!(v["textures"].is_null(), "{v}");
    // A format trisort does not offer is refused by name, before any work.
    let out = run(
        d,
        &args("bake demo:400 --path demo --textures basis -o b.baked"),
        false,
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("unknown texture format \"basis\""), "{err}");
    assert!(!d.join("b.baked").exists());
}
