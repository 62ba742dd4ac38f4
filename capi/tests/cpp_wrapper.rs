//! The C++ wrapper (`include/trisort.hpp`) through its example (examples/cpp/example.cpp):
//! built with g++ against the static library next to this test binary, once per error mode
//! (exceptions; `TRISORT_HPP_NO_EXCEPTIONS`, `trisort::expected`), C++17 with `-Wall -Wextra
//! -Werror -pedantic`, and run on a hand-built baked file. Every figure, the frame's draws, the
//! sum of the indices they draw and the matrices it prints must equal what the C API gives for
//! the same file; a missing file and a frame out of range fail with a message naming them.
//! The header must also compile with `-fno-exceptions` in the expected mode and, where g++
//! knows C++23, with `std::expected` in both modes.
//!
//! Skips when g++ is missing, unless `CI` is set (then it fails).

use std::collections::HashMap;
use std::ffi::CString;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::ptr::null_mut;

use trisort_capi::ffi::*;
use trisort_format::container::encode;
use trisort_format::{Baked, FileKind};

/// The repository root (the example and the header are found from it).
fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap()
}

/// Whether g++ is here; CI requires it.
fn gxx() -> bool {
    let ok = Command::new("g++").arg("--version").output().is_ok();
    if !ok {
        assert!(
            std::env::var_os("CI").is_none(),
            "g++ is missing: install it (Debian: apt-get install g++)"
        );
        eprintln!("skipping: g++ is missing");
    }
    ok
}

/// g++ on the example with `flags`; the output is the compiler's.
fn gxx_example(flags: &[&str], out: &[&str]) -> Output {
    Command::new("g++")
        .args(["-Wall", "-Wextra", "-Werror", "-pedantic", "-I"])
        .arg(root().join("capi/include"))
        .args(flags)
        .arg(root().join("examples/cpp/example.cpp"))
        .args(out)
        .output()
        .expect("run g++")
}

fn assert_built(out: &Output, what: &str) {
    assert!(
        out.status.success(),
        "g++ failed ({what}):\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Builds the example into `dir` in C++17 with the static library, as examples/cpp/README.md
/// says, with `-DTRISORT_HPP_NO_EXCEPTIONS` when `expected`.
fn build(dir: &Path, expected: bool) -> PathBuf {
    let exe = dir.join(if expected { "expected" } else { "exceptions" });
    let mut flags = vec!["-std=c++17"];
    if expected {
        flags.push("-DTRISORT_HPP_NO_EXCEPTIONS");
    }
    let lib = trisort_testkit::capi_static_library();
    let out = gxx_example(
        &flags,
        &[
            lib.to_str().unwrap(),
            "-lpthread",
            "-ldl",
            "-lm",
            "-o",
            exe.to_str().unwrap(),
        ],
    );
    assert_built(&out, &format!("{flags:?}"));
    exe
}

/// Whether g++ takes `-std=c++23`.
fn knows_cxx23() -> bool {
    Command::new("g++")
        .args(["-std=c++23", "-x", "c++", "-fsyntax-only", "-"])
        .stdin(std::process::Stdio::null())
        .output()
        .is_ok_and(|o| o.status.success())
}

/// The C API tests' hand-built file (`baked::sample`), recorded at 24 fps, as a bundle of
/// two clips (`api::two_clips`: "intro" at 24 fps and "door-open" with no rate).
fn sample() -> Baked {
    let mut b = crate::api::two_clips();
    b.fps = Some(24.0);
    b
}

/// What the example must print for `frame` of the file at `path`, read through the C API.
fn expected_report(path: &Path, frame: u32) -> Vec<(&'static str, String)> {
    let c = CString::new(path.to_str().unwrap()).unwrap();
    let mut h = null_mut();
    assert_eq!(
        unsafe { trisort_open_path(c.as_ptr(), &mut h) },
        TrisortStatus::Ok
    );
    let mut info = TrisortInfo::default();
    assert_eq!(unsafe { trisort_info(h, &mut info) }, TrisortStatus::Ok);
    let get = |f: &mut dyn FnMut(*mut u32, usize, *mut usize) -> TrisortStatus| {
        let mut len = 0;
        assert_eq!(f(null_mut(), 0, &mut len), TrisortStatus::Ok);
        let mut v = vec![0u32; len];
        assert_eq!(f(v.as_mut_ptr(), len, &mut len), TrisortStatus::Ok);
        v
    };
    let indices = get(&mut |o, c, l| unsafe { trisort_indices_u32(h, true, o, c, l) });
    let mut len = 0;
    let s = unsafe { trisort_frame_draws(h, frame, true, null_mut(), 0, &mut len) };
    assert_eq!(s, TrisortStatus::Ok);
    let mut draws = vec![TrisortDrawIndexedIndirectArgs::default(); len];
    let s = unsafe { trisort_frame_draws(h, frame, true, draws.as_mut_ptr(), len, &mut len) };
    assert_eq!(s, TrisortStatus::Ok);
    let drawn = || {
        draws.iter().flat_map(|d| {
            &indices[d.first_index as usize..(d.first_index + d.index_count) as usize]
        })
    };
    let sum: u64 = drawn().map(|&i| u64::from(i)).sum();
    let matrix = |m: [f32; 16]| {
        m.iter()
            .map(|v| v.to_string())
            .collect::<Vec<_>>()
            .join(" ")
    };
    let mut view = [0f32; 16];
    assert_eq!(
        unsafe { trisort_frame_view(h, frame, view.as_mut_ptr()) },
        TrisortStatus::Ok
    );
    let aspect = f64::from(info.width) / f64::from(info.height);
    let projection = |depth: u32| {
        let mut p = [0f32; 16];
        let s = unsafe { trisort_frame_projection(h, frame, aspect, depth, p.as_mut_ptr()) };
        assert_eq!(s, TrisortStatus::Ok);
        matrix(p)
    };
    let mut fps = 0.0;
    assert_eq!(unsafe { trisort_fps(h, &mut fps) }, TrisortStatus::Ok);
    let gpu = gpu_lines(h, frame);
    let report = vec![
        ("frames", info.frame_count.to_string()),
        (
            "image",
            format!("{}x{}, {} samples", info.width, info.height, info.samples),
        ),
        ("vertices", format!("{0} (copied {0})", info.vertex_count)),
        ("triangles", info.triangle_count.to_string()),
        ("index triangles", info.index_triangle_count.to_string()),
        ("draws", info.draw_count.to_string()),
        ("nodes", info.node_count.to_string()),
        (
            "materials",
            format!("{0} (copied {0})", info.material_count),
        ),
        ("fits u16", "yes".into()),
        ("u16 indices equal", "yes".into()),
        ("fps", fps.to_string()),
        ("variants", "0".into()),
        ("index buffer", format!("{} indices", indices.len())),
        ("frame", frame.to_string()),
        ("frame draws", draws.len().to_string()),
        (
            "first draw",
            format!("{} {}", draws[0].first_index, draws[0].index_count),
        ),
        ("frame indices", drawn().count().to_string()),
        ("frame index sum", sum.to_string()),
        ("frame ranges equal draws", "yes".into()),
        ("view", matrix(view)),
        ("projection zero to one", projection(0)),
        ("projection minus one to one", projection(1)),
        ("node matrices", info.node_count.to_string()),
        ("gpu frame uniform", gpu[0].clone()),
        ("gpu lighting uniform", gpu[1].clone()),
        ("gpu texels", gpu[2].clone()),
        ("gpu srgb array", gpu[3].clone()),
        ("gpu environment", gpu[4].clone()),
        ("clips", clips_line(h)),
        ("last clip found", "1".into()),
    ];
    unsafe { trisort_close(h) };
    report
}

/// Values copied out by a two-call `trisort_gpu_*` function.
fn copied<T: Default + Clone>(
    f: &mut dyn FnMut(*mut T, usize, *mut usize) -> TrisortStatus,
) -> Vec<T> {
    let mut len = 0;
    assert_eq!(f(null_mut(), 0, &mut len), TrisortStatus::Ok);
    let mut v = vec![T::default(); len];
    assert_eq!(f(v.as_mut_ptr(), len, &mut len), TrisortStatus::Ok);
    v
}

/// The example's `gpu …` lines for frame `frame` of the file open as `h`, read through the
/// C API (what the player uploads: uniforms, data textures, texture arrays, environment).
fn gpu_lines(h: *const TrisortBaked, frame: u32) -> [String; 5] {
    let sum = |v: &[u8]| v.iter().map(|&b| u64::from(b)).sum::<u64>();
    let frame_uniform =
        copied(&mut |o, c, l| unsafe { trisort_gpu_frame_uniform(h, frame, 0, 0, o, c, l) });
    let lighting = copied(&mut |o, c, l| unsafe {
        trisort_gpu_lighting_uniform(h, TRISORT_SHADING_PBR, TRISORT_TONE_MAP_NEUTRAL, 0, o, c, l)
    });
    let materials = copied(&mut |o, c, l| unsafe { trisort_gpu_material_texels(h, 0, o, c, l) });
    let nodes = copied(&mut |o, c, l| unsafe { trisort_gpu_node_texels(h, o, c, l) });
    let mut srgb = TrisortGpuTexture::default();
    let s = unsafe { trisort_gpu_texture_array(h, TRISORT_TEXTURE_ARRAY_SRGB, 0, &mut srgb) };
    assert_eq!(s, TrisortStatus::Ok);
    let level0 = copied(&mut |o, c, l| unsafe {
        trisort_gpu_texture_array_level(h, TRISORT_TEXTURE_ARRAY_SRGB, 0, 0, 0, o, c, l)
    });
    let mut env = TrisortGpuTexture::default();
    assert_eq!(
        unsafe { trisort_gpu_environment(h, 0, &mut env) },
        TrisortStatus::Ok
    );
    let env0 = copied(&mut |o, c, l| unsafe { trisort_gpu_environment_level(h, 0, 0, o, c, l) });
    [
        format!("{} bytes, sum {}", frame_uniform.len(), sum(&frame_uniform)),
        format!("{} bytes, sum {}", lighting.len(), sum(&lighting)),
        format!(
            "{} material floats, {} node floats",
            materials.len(),
            nodes.len()
        ),
        format!(
            "{}x{}, {} layers, {} levels; level 0: {} bytes, sum {}",
            srgb.width,
            srgb.height,
            srgb.layers,
            srgb.levels,
            level0.len(),
            sum(&level0)
        ),
        format!(
            "{}x{}, {} levels; level 0: {} halves",
            env.width,
            env.height,
            env.levels,
            env0.len()
        ),
    ]
}

/// The example's `clips` line for the file open as `h`, read through the C API: the count,
/// then per clip `'NAME' FIRST+COUNT @FPS` (`@none` without a rate).
fn clips_line(h: *const TrisortBaked) -> String {
    let mut n = 0;
    assert_eq!(unsafe { trisort_clip_count(h, &mut n) }, TrisortStatus::Ok);
    let mut line = n.to_string();
    for k in 0..n {
        let mut buf = [0u8; 80];
        let mut len = 0;
        let s = unsafe { trisort_clip_name(h, k, buf.as_mut_ptr().cast(), 80, &mut len) };
        assert_eq!(s, TrisortStatus::Ok);
        let (mut first, mut count, mut fps) = (0, 0, 0.0);
        let s = unsafe { trisort_clip_frames(h, k, &mut first, &mut count) };
        assert_eq!(s, TrisortStatus::Ok);
        let fps = match unsafe { trisort_clip_fps(h, k, &mut fps) } {
            TrisortStatus::Ok => fps.to_string(),
            TrisortStatus::Absent => "none".into(),
            s => panic!("trisort_clip_fps: {s:?}"),
        };
        let name = std::str::from_utf8(&buf[..len]).unwrap();
        line += &format!(" '{name}' {first}+{count} @{fps}");
    }
    line
}

/// The `key: value` lines of the example's output.
fn parse(stdout: &str) -> HashMap<String, String> {
    stdout
        .lines()
        .filter_map(|l| l.split_once(": "))
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect()
}

/// The `TRISORT_ABI_VERSION` of the header the example is compiled with.
fn header_abi() -> u32 {
    let header = std::fs::read_to_string(root().join("capi/include/trisort.h")).unwrap();
    header
        .lines()
        .find_map(|l| l.strip_prefix("#define TRISORT_ABI_VERSION "))
        .and_then(|v| v.trim().parse().ok())
        .expect("trisort.h defines TRISORT_ABI_VERSION")
}

/// A printed matrix's 16 floats (as `%.9g`: each the f32 it was).
fn floats(s: &str) -> Vec<f32> {
    s.split(' ').map(|v| v.parse().unwrap()).collect()
}

#[test]
fn cpp_example_prints_what_the_c_api_reads_in_both_error_modes() {
    if !gxx() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let file = d.join("sample.baked");
    let baked = sample();
    baked.check_structure().unwrap();
    std::fs::write(&file, encode(FileKind::Baked, &baked)).unwrap();

    // Both builds, and the compile-only checks of the other language modes, at once.
    let cxx23 = knows_cxx23();
    let (exes, checks) = std::thread::scope(|s| {
        let exes: Vec<_> = [false, true]
            .map(|expected| s.spawn(move || build(d, expected)))
            .into_iter()
            .collect();
        let mut syntax: Vec<Vec<&str>> = vec![vec![
            "-std=c++17",
            "-fno-exceptions",
            "-DTRISORT_HPP_NO_EXCEPTIONS",
        ]];
        if cxx23 {
            syntax.push(vec!["-std=c++23"]);
            syntax.push(vec!["-std=c++23", "-DTRISORT_HPP_NO_EXCEPTIONS"]);
        }
        let checks: Vec<_> = syntax
            .into_iter()
            .map(|flags| {
                s.spawn(move || {
                    let out = gxx_example(&flags, &["-fsyntax-only"]);
                    (flags, out)
                })
            })
            .collect();
        (
            exes.into_iter()
                .map(|t| t.join().unwrap())
                .collect::<Vec<_>>(),
            checks
                .into_iter()
                .map(|t| t.join().unwrap())
                .collect::<Vec<_>>(),
        )
    });
    for (flags, out) in &checks {
        assert_built(out, &format!("{flags:?}"));
    }

    for (exe, mode) in exes.iter().zip(["exceptions", "expected"]) {
        for frame in [0u32, 1] {
            let out = Command::new(exe)
                .arg(&file)
                .arg(frame.to_string())
                .output()
                .unwrap();
            let stdout = String::from_utf8_lossy(&out.stdout);
            assert!(
                out.status.success(),
                "{mode} example failed on frame {frame}:\n{stdout}\n{}",
                String::from_utf8_lossy(&out.stderr)
            );
            if frame == 1 {
                eprintln!("{mode} example, frame 1:\n{stdout}");
            }
            let got = parse(&stdout);
            assert_eq!(got["mode"], mode);
            assert_eq!(
                got["abi"],
                format!("library {}, header {}", trisort_abi_version(), header_abi())
            );
            assert_eq!(got["file"], file.to_str().unwrap());
            for (key, want) in expected_report(&file, frame) {
                let have = got
                    .get(key)
                    .unwrap_or_else(|| panic!("no {key:?}:\n{stdout}"));
                if key == "view" || key.starts_with("projection") {
                    assert_eq!(floats(have), floats(&want), "{mode} frame {frame}: {key}");
                } else {
                    assert_eq!(have, &want, "{mode} frame {frame}: {key}\n{stdout}");
                }
            }
            // The failure it shows on purpose names the file and the problem.
            let missing = format!("{}.missing", file.display());
            let line = &got["missing file"];
            assert!(
                line.starts_with("io: ") && line.contains(&missing),
                "{mode}: {line}"
            );
        }

        // Failures: exit status 1 with a message naming what failed.
        let missing = d.join("no-such.baked");
        let out = Command::new(exe).arg(&missing).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{mode}: {err}");
        assert!(
            err.contains("error (io)") && err.contains(missing.to_str().unwrap()),
            "{mode}: {err}"
        );
        let out = Command::new(exe).arg(&file).arg("7").output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{mode}: {err}");
        assert!(
            err.contains("error (out of range)") && err.contains("frame 7"),
            "{mode}: {err}"
        );
    }
}
