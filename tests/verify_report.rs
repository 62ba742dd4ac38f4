//! `verify --report DIR` (the HTML sign-off report) and `verify --clip NAME`, on a small demo
//! bake made a two-clip file (clip `a`: frame 0, clip `b`: frames 1 and 2) whose frame 1 is
//! forged (its front-most draw dropped: a hole). The report is read back by headless Chromium
//! (scripts/report-dom.mjs, playwright-core) and checked against `verify --json`: the forged
//! frame failed and first, every figure as JSON has it, every thumbnail decoded, no request
//! leaving the file.

use std::path::Path;

use serde_json::Value;
use trisort_format::{Baked, Clip, FileKind};

use crate::support::*;

const SCENE: &str = "demo:400";

/// The two-clip file: an honest 3-frame bake (48×32) with its clips replaced by `a` (frame 0)
/// and `b` (frames 1, 2), and a copy `forged.baked` whose frame 1 lost its front-most draw.
/// The recording beside the bake is not used: these checks compare images only (`--scene`).
fn two_clips(dir: &Path) {
    run(
        dir,
        &args(&format!(
            "bake {SCENE} --path orbit:frames=3,degrees=60 --size 48x32 -o one.baked"
        )),
        true,
    );
    let mut baked: Baked =
        trisort_format::read_file(FileKind::Baked, &dir.join("one.baked")).unwrap();
    let main = baked.clips[0].clone();
    assert_eq!((main.first, main.count), (0, 3), "{main:?}");
    baked.clips = vec![
        Clip {
            name: "a".into(),
            count: 1,
            ..main.clone()
        },
        Clip {
            name: "b".into(),
            first: 1,
            count: 2,
            path_first: 1,
            ..main
        },
    ];
    trisort_format::write_file_atomic(FileKind::Baked, &dir.join("two.baked"), &baked).unwrap();
    let mut forged = baked.clone();
    let w = forged.frames[1];
    assert!(w.count >= 2, "frame 1 has {} draws", w.count);
    forged.draws.remove(w.first as usize);
    forged.frames[1].count -= 1;
    for later in &mut forged.frames[2..] {
        later.first -= 1;
    }
    forged.stats.draws_per_frame_max = forged.frames.iter().map(|w| w.count).max().unwrap();
    forged.stats.draws_per_frame_mean =
        forged.frames.iter().map(|w| w.count as f64).sum::<f64>() / forged.frames.len() as f64;
    trisort_format::write_file_atomic(FileKind::Baked, &dir.join("forged.baked"), &forged).unwrap();
}

/// The report page as Chromium reads it (scripts/report-dom.mjs). `None` (a skip) when
/// playwright-core or Chromium is missing outside CI (`CI` set: a failure;
/// scripts/ensure-web.sh --browser-only installs both).
fn report_dom(page: &Path) -> Option<Value> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let missing = if !root.join("web/test/node_modules/playwright-core").is_dir() {
        Some("playwright-core (bash scripts/ensure-web.sh --browser-only)")
    } else if !Path::new("/usr/bin/chromium").is_file() {
        Some("/usr/bin/chromium (bash scripts/ensure-web.sh --browser-only)")
    } else {
        None
    };
    if let Some(what) = missing {
        if std::env::var_os("CI").is_some() || std::env::var_os("TRISORT_REQUIRE_BROWSER").is_some()
        {
            panic!("the report's browser check needs {what}");
        }
        eprintln!("skipping the report's browser check: {what} is missing");
        return None;
    }
    let out = std::process::Command::new("node")
        .arg(root.join("scripts/report-dom.mjs"))
        .arg(page)
        .output()
        .expect("node");
    assert!(
        out.status.success(),
        "report-dom.mjs: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    Some(serde_json::from_slice(&out.stdout).unwrap())
}

/// A figure of `verify --json` as the report prints it.
fn figure(v: &Value) -> String {
    match v {
        Value::Null => "-".into(),
        Value::Number(n) if n.is_f64() => format!("{:.1}", n.as_f64().unwrap()),
        other => other.to_string(),
    }
}

#[test]
fn the_html_report_shows_the_forged_frame_failed_and_first() {
    let Some(dir) = gpu_tempdir() else { return };
    let d = dir.path();
    two_clips(d);
    let out = run(
        d,
        &[
            "verify",
            "forged.baked",
            "--scene",
            SCENE,
            "--json",
            "--report",
            "report",
            "--junit",
            "forged.xml",
        ],
        false,
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(
        out.status.code(),
        Some(3),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: Value = serde_json::from_str(&stdout).unwrap();
    let frames = v["frames"].as_array().unwrap();
    let clips: Vec<(u64, &str)> = frames
        .iter()
        .map(|f| (f["frame"].as_u64().unwrap(), f["clip"].as_str().unwrap()))
        .collect();
    assert_eq!(clips, [(0, "a"), (1, "b"), (2, "b")]);
    let failed: Vec<u64> = frames
        .iter()
        .filter(|f| f["ok"] == false)
        .map(|f| f["frame"].as_u64().unwrap())
        .collect();
    assert_eq!(failed, [1], "{v}");
    assert!(
        frames[1]["hole_pixels"].as_u64().unwrap() > 0,
        "{}",
        frames[1]
    );
    // JUnit: the clip in each frame's class name.
    let xml = std::fs::read_to_string(d.join("forged.xml")).unwrap();
    assert!(
        xml.contains("classname=\"trisort.verify.forged.a\" name=\"frame 0\""),
        "{xml}"
    );
    assert!(
        xml.contains("classname=\"trisort.verify.forged.b\" name=\"frame 2\""),
        "{xml}"
    );

    let html = std::fs::read_to_string(d.join("report/index.html")).unwrap();
    let hash = trisort_format::hash_bytes(&std::fs::read(d.join("forged.baked")).unwrap());
    let hex: String = hash.iter().map(|b| format!("{b:02x}")).collect();
    assert!(
        html.contains(&hex),
        "the baked file's BLAKE3 is not in the report"
    );
    assert!(!html.contains("<script") && !html.contains("http://") && !html.contains("https://"));
    if let Some(dom) = report_dom(&d.join("report/index.html")) {
        check_page(&dom, frames, &hex);
    }
}

/// The forged file's report as Chromium shows it against `verify --json`'s `frames` and the
/// baked file's BLAKE3 `hex`.
fn check_page(dom: &Value, frames: &[Value], hex: &str) {
    assert_eq!(dom["verdict"]["ok"], "false", "{dom}");
    assert_eq!(dom["baked_hash"], hex);
    assert_eq!(dom["scripts"], 0);
    assert_eq!(
        dom["requests"],
        serde_json::json!([]),
        "the report fetched something"
    );
    assert_eq!(dom["console_errors"], serde_json::json!([]));
    assert!(
        dom["raster_profile"]
            .as_str()
            .unwrap()
            .starts_with("conformant"),
        "{dom}"
    );
    assert!(dom["legend"].as_str().unwrap().contains("holes"));
    // Worst first: the forged frame, then the honest ones by frame.
    let rows = dom["frames"].as_array().unwrap();
    let order: Vec<u64> = rows.iter().map(|r| r["frame"].as_u64().unwrap()).collect();
    assert_eq!(order, [1, 0, 2], "{dom}");
    for row in rows {
        let f = frames.iter().find(|f| f["frame"] == row["frame"]).unwrap();
        let verdict = if f["ok"] == true { "pass" } else { "fail" };
        assert_eq!(row["verdict"], verdict, "{row}");
        assert_eq!(row["clip"], f["clip"], "{row}");
        let cells = &row["cells"];
        for key in [
            "pixels_differing",
            "pixels_differing_ordered",
            "max_channel_diff",
            "max_channel_diff_ordered",
            "unordered_samples",
            "hole_pixels",
            "order_error_pixels",
            "psnr",
        ] {
            assert_eq!(
                cells[key],
                figure(&f[key]).as_str(),
                "frame {}: {key}",
                f["frame"]
            );
        }
        let images = row["images"].as_array().unwrap();
        let classes: Vec<&str> = images
            .iter()
            .map(|i| i["class"].as_str().unwrap())
            .collect();
        assert_eq!(classes, ["player", "reference", "difference"], "{row}");
        for i in images {
            assert_eq!(i["inline"], true, "{i}");
            assert_eq!(
                (i["natural_width"].as_u64(), i["natural_height"].as_u64()),
                (Some(48), Some(32)),
                "{i}"
            );
        }
    }
    let clip_rows: Vec<(String, String, String, String)> = dom["clips"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| {
            let s = |k: &str| c[k].as_str().unwrap().to_string();
            (s("clip"), s("verdict"), s("checked"), s("failed"))
        })
        .collect();
    let row = |c: &str, v: &str, n: &str, f: &str| (c.into(), v.into(), n.into(), f.into());
    assert_eq!(
        clip_rows,
        [row("a", "pass", "1", "0"), row("b", "fail", "2", "1")]
    );
}

#[test]
fn verify_clip_checks_that_clips_frames_only() {
    let Some(dir) = gpu_tempdir() else { return };
    let d = dir.path();
    two_clips(d);
    let frames = |extra: &str| -> Vec<(u64, String)> {
        let v = run_json(
            d,
            &args(&format!("verify two.baked --scene {SCENE} {extra}")),
        );
        assert_eq!(v["ok"], true, "{v}");
        v["frames"]
            .as_array()
            .unwrap()
            .iter()
            .map(|f| {
                (
                    f["frame"].as_u64().unwrap(),
                    f["clip"].as_str().unwrap().into(),
                )
            })
            .collect()
    };
    let b = |f: u64| (f, "b".to_string());
    assert_eq!(frames("--clip b"), [b(1), b(2)]);
    // --frames counts within the clip.
    assert_eq!(frames("--clip b --frames 1..2"), [b(2)]);
    assert_eq!(frames("--clip a"), [(0, "a".to_string())]);
    // Frames drawn elsewhere for one clip are named within it, as `play --clip` writes them.
    run(d, &args("play two.baked --clip b --out-dir b-frames"), true);
    assert!(d.join("b-frames/frame-00001.png").is_file());
    assert_eq!(frames("--clip b --frames-dir b-frames"), [b(1), b(2)]);
    let out = run(
        d,
        &args(&format!(
            "verify two.baked --scene {SCENE} --clip b --frames 0..3"
        )),
        false,
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("clip \"b\""), "{err}");
    let out = run(
        d,
        &args(&format!("verify two.baked --scene {SCENE} --clip c")),
        false,
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("no clip named \"c\"") && err.contains("a, b"),
        "{err}"
    );
}
