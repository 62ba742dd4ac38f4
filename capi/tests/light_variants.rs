//! ABI 3's additions on files baked by the real `trisort` binary: the environment (figures,
//! name, every prefiltered level), the frame rate, and material variants (CarConcept's three
//! `KHR_materials_variants` tables), each equal to what `trisort_format::read_file` reads from
//! the same file; a stored-less frame rate, an unknown variant and a variant that changes
//! visibility are refused with their status and a message naming the file and the variant;
//! null pointers and short buffers are handled.

use std::ffi::{c_char, CString};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::ptr::{null, null_mut};
use std::sync::OnceLock;

use trisort_capi::ffi::*;
use trisort_format::{container, read_file, AlphaMode, Baked, FileKind, Material};

use crate::api::last_error;

/// The `trisort` binary of this build (target/<profile>/trisort), built once first so that it
/// is current: `cargo test -p trisort-capi` does not build other packages' binaries.
fn trisort_binary() -> &'static Path {
    static BIN: OnceLock<PathBuf> = OnceLock::new();
    BIN.get_or_init(build_trisort)
}

fn build_trisort() -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    let profile_dir = exe.parent().unwrap().parent().unwrap().to_path_buf();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).parent().unwrap();
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let mut build = Command::new(cargo);
    build
        .current_dir(root)
        .args(["build", "--quiet", "--bin", "trisort"]);
    match profile_dir.file_name().and_then(|n| n.to_str()) {
        Some("debug") | None => {}
        Some(profile) => {
            build.args(["--profile", profile]);
        }
    }
    let out = build.output().expect("run cargo build --bin trisort");
    assert!(
        out.status.success(),
        "cargo build --bin trisort failed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let bin = profile_dir.join("trisort");
    assert!(bin.is_file(), "{} is missing", bin.display());
    bin
}

/// Bakes with the real binary in `dir` (`trisort bake ARGS`), expecting success.
fn bake(dir: &Path, args: &[&str]) {
    let out = Command::new(trisort_binary())
        .current_dir(dir)
        .arg("bake")
        .args(args)
        .output()
        .expect("run trisort");
    assert!(
        out.status.success(),
        "trisort bake {} failed:\n{}",
        args.join(" "),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A temporary directory for a test that bakes (which needs a GPU), or `None` to skip.
fn gpu_tempdir() -> Option<tempfile::TempDir> {
    trisort_testkit::gpu().map(|_| tempfile::tempdir().unwrap())
}

/// Opens `path` through the C API.
fn open(path: &Path) -> *mut TrisortBaked {
    let c = CString::new(path.to_str().unwrap()).unwrap();
    let mut h = null_mut();
    let s = unsafe { trisort_open_path(c.as_ptr(), &mut h) };
    assert_eq!(s, TrisortStatus::Ok, "{}", last_error());
    h
}

/// A NUL-terminated string copied out by `f(out, cap, len)` after asking its length, checking
/// on the way that a buffer one byte short (no room for the NUL) is refused untouched.
fn string(f: impl Fn(*mut c_char, usize, *mut usize) -> TrisortStatus) -> String {
    let mut len = usize::MAX;
    assert_eq!(f(null_mut(), 0, &mut len), TrisortStatus::Ok);
    let mut buf = vec![0x55u8; len + 1];
    let mut len2 = 0;
    let s = f(buf.as_mut_ptr().cast(), len, &mut len2);
    assert_eq!(s, TrisortStatus::BufferTooSmall);
    assert!(last_error().contains(&format!("{} needed", len + 1)));
    assert_eq!(len2, len);
    assert!(buf.iter().all(|&b| b == 0x55), "nothing copied");
    assert_eq!(
        f(buf.as_mut_ptr().cast(), len + 1, null_mut()),
        TrisortStatus::Ok
    );
    assert_eq!(buf[len], 0, "NUL-terminated");
    buf.truncate(len);
    String::from_utf8(buf).unwrap()
}

/// The material table `trisort_variant_materials` copies for `name` (null: the default).
fn variant_table(
    h: *mut TrisortBaked,
    name: Option<&str>,
) -> Result<Vec<TrisortMaterial>, TrisortStatus> {
    let c = name.map(|n| CString::new(n).unwrap());
    let p = c.as_ref().map_or(null(), |c| c.as_ptr());
    let mut len = 0;
    let s = unsafe { trisort_variant_materials(h, p, null_mut(), 0, &mut len) };
    if s != TrisortStatus::Ok {
        return Err(s);
    }
    let mut table = vec![TrisortMaterial::default(); len];
    let s = unsafe { trisort_variant_materials(h, p, table.as_mut_ptr(), len, &mut len) };
    assert_eq!(s, TrisortStatus::Ok);
    Ok(table)
}

/// The default materials through `trisort_materials`.
fn materials(h: *mut TrisortBaked) -> Vec<TrisortMaterial> {
    let mut len = 0;
    unsafe { trisort_materials(h, null_mut(), 0, &mut len) };
    let mut m = vec![TrisortMaterial::default(); len];
    let s = unsafe { trisort_materials(h, m.as_mut_ptr(), len, &mut len) };
    assert_eq!(s, TrisortStatus::Ok);
    m
}

/// The fields of `c` a variant changes, against the Rust side's material `r`.
fn assert_material(c: &TrisortMaterial, r: &Material, what: &str) {
    assert_eq!(c.base_color, r.base_color, "{what}");
    assert_eq!(c.emissive, r.emissive, "{what}");
    assert_eq!(
        (c.metallic, c.roughness),
        (r.metallic, r.roughness),
        "{what}"
    );
    assert_eq!(
        c.base_color_texture,
        r.base_color_texture.map_or(-1, |t| t as i32),
        "{what}"
    );
    let mode = match r.alpha_mode {
        AlphaMode::Opaque => TrisortAlphaMode::Opaque,
        AlphaMode::Mask => TrisortAlphaMode::Mask,
        AlphaMode::Blend => TrisortAlphaMode::Blend,
    };
    assert_eq!(
        (c.alpha_mode, c.double_sided),
        (mode, r.double_sided),
        "{what}"
    );
    assert_eq!(c.transmission, r.transmission, "{what}");
    assert_eq!(
        c.normal.texture,
        r.normal_texture.as_ref().map_or(-1, |s| s.texture as i32),
        "{what}"
    );
}

#[test]
fn the_environment_and_frame_rate_of_a_demo_bake_are_what_the_rust_reader_reads() {
    let Some(dir) = gpu_tempdir() else { return };
    let d = dir.path();
    // The built-in studio (with a sun), and an .hdr sky (without one).
    let common = [
        "demo:2000",
        "--path",
        "orbit:frames=2,degrees=20",
        "--size",
        "32x32",
        "--samples",
        "1",
        "--fps",
        "24",
    ];
    bake(d, &[&common[..], &["-o", "studio.baked"]].concat());
    write_sky(&d.join("sky.hdr"));
    bake(
        d,
        &[
            &common[..],
            &["-o", "sky.baked", "--environment", "sky.hdr"],
        ]
        .concat(),
    );
    for (file, name, sun) in [
        ("studio.baked", "studio", true),
        ("sky.baked", "sky.hdr", false),
    ] {
        let path = d.join(file);
        let b: Baked = read_file(FileKind::Baked, &path).unwrap();
        let h = open(&path);

        check_environment(h, file, name, sun, &b);
        check_fps_and_no_variants(h, file, &b);
        unsafe { trisort_close(h) };
    }

    let (h, b) = open_without_fps(d);
    check_raster_profile(h, &b);
    check_null_pointers(h);
}

/// The environment of the file `file` (handle `h`, read as `b`) as the C API copies it: its
/// figures, `name`, a sun exactly when `sun`, and every prefiltered level.
fn check_environment(h: *mut TrisortBaked, file: &str, name: &str, sun: bool, b: &Baked) {
    let e = &b.environment;
    let mut info = TrisortEnvironmentInfo::default();
    assert_eq!(
        unsafe { trisort_environment_info(h, &mut info) },
        TrisortStatus::Ok
    );
    assert_eq!((info.width, info.height), (e.width, e.height));
    assert_eq!(info.level_count as usize, e.levels.len());
    assert!(info.level_count > 1, "{file}: prefiltered levels");
    assert_eq!(info.sh, e.sh);
    assert_ne!(info.sh[0], [0.0; 3], "{file}: some light");
    assert_eq!(info.exposure, e.exposure);
    assert_eq!(info.has_sun, sun, "{file}");
    assert_eq!(e.sun.is_some(), sun, "{file}");
    match e.sun {
        Some(s) => {
            assert_eq!((info.sun_direction, info.sun_color), (s.direction, s.color));
            assert_ne!(info.sun_color, [0.0; 3]);
        }
        None => assert_eq!((info.sun_direction, info.sun_color), ([0.0; 3], [0.0; 3])),
    }
    let got = string(|o, c, l| unsafe { trisort_environment_name(h, o, c, l) });
    assert_eq!((got.as_str(), e.name.as_str()), (name, name));

    for (k, level) in e.levels.iter().enumerate() {
        let (mut w, mut ht, mut len) = (0, 0, 0);
        let s = unsafe {
            trisort_environment_level(h, k as u32, &mut w, &mut ht, null_mut(), 0, &mut len)
        };
        assert_eq!(s, TrisortStatus::Ok);
        let want = ((e.width >> k).max(1), (e.height >> k).max(1));
        assert_eq!((w, ht), want, "{file} level {k}");
        assert_eq!(len, 4 * (w * ht) as usize);
        assert_eq!(len, level.len());
        let mut texels = vec![0xbeefu16; len];
        let s = unsafe {
            trisort_environment_level(
                h,
                k as u32,
                null_mut(),
                null_mut(),
                texels.as_mut_ptr(),
                len - 1,
                &mut len,
            )
        };
        assert_eq!(s, TrisortStatus::BufferTooSmall);
        assert!(texels.iter().all(|&t| t == 0xbeef), "nothing copied");
        let s = unsafe {
            trisort_environment_level(
                h,
                k as u32,
                null_mut(),
                null_mut(),
                texels.as_mut_ptr(),
                len,
                null_mut(),
            )
        };
        assert_eq!(s, TrisortStatus::Ok);
        assert_eq!(&texels, level, "{file} level {k}");
    }
    let past = info.level_count;
    let mut len = 0;
    let s = unsafe {
        trisort_environment_level(h, past, null_mut(), null_mut(), null_mut(), 0, &mut len)
    };
    assert_eq!(s, TrisortStatus::OutOfRange);
    let msg = last_error();
    assert!(
        msg.contains(file) && msg.contains(&format!("level {past}")),
        "{msg}"
    );
}

/// The frame rate (24) and, the demo having none, the variants of the file `file`.
fn check_fps_and_no_variants(h: *mut TrisortBaked, file: &str, b: &Baked) {
    let mut fps = -1.0;
    assert_eq!(unsafe { trisort_fps(h, &mut fps) }, TrisortStatus::Ok);
    assert_eq!(Some(fps), b.fps);
    assert_eq!(fps, 24.0);
    assert_eq!(last_error(), "");

    // No variants in the demo: the count is 0, the default table is the materials', and
    // any name is unknown, naming the file and the name.
    let mut count = 9;
    assert_eq!(
        unsafe { trisort_variant_count(h, &mut count) },
        TrisortStatus::Ok
    );
    assert_eq!(count, 0);
    assert_eq!(variant_table(h, None).unwrap(), materials(h));
    assert_eq!(variant_table(h, Some("Gold")), Err(TrisortStatus::Absent));
    let msg = last_error();
    assert!(
        msg.contains(file) && msg.contains("\"Gold\"") && msg.contains("no variants"),
        "{msg}"
    );
    let mut len = 0;
    let s = unsafe { trisort_variant_name(h, 0, null_mut(), 0, &mut len) };
    assert_eq!(s, TrisortStatus::OutOfRange);
    assert!(last_error().contains("variant 0"), "{}", last_error());
}

/// Opens `studio.baked` of `d` without its stored frame rate (as from recordings that did not
/// know it) and checks the frame rate's refusal; returns the handle and the file.
fn open_without_fps(d: &Path) -> (*mut TrisortBaked, Baked) {
    // The distinct status, 0 in `*out`, and a message naming the file.
    let mut b: Baked = read_file(FileKind::Baked, &d.join("studio.baked")).unwrap();
    b.fps = None;
    let bytes = container::encode(FileKind::Baked, &b);
    let mut h = null_mut();
    let s = unsafe { trisort_open_bytes(bytes.as_ptr(), bytes.len(), &mut h) };
    assert_eq!(s, TrisortStatus::Ok, "{}", last_error());
    let mut fps = -1.0;
    assert_eq!(unsafe { trisort_fps(h, &mut fps) }, TrisortStatus::Absent);
    assert_eq!(fps, 0.0);
    let msg = last_error();
    assert!(
        msg.contains("<bytes>") && msg.contains("frame rate"),
        "{msg}"
    );
    (h, b)
}

/// The raster profile the file was baked for (the default: conformant), and a host's device
/// checked against it: lavapipe-like figures pass; 4 sub-pixel bits, non-standard locations or
/// another sample count each give the mismatch status, named in the message.
fn check_raster_profile(h: *mut TrisortBaked, b: &Baked) {
    let mut p = TrisortRasterProfile::default();
    assert_eq!(
        unsafe { trisort_raster_profile(h, &mut p) },
        TrisortStatus::Ok
    );
    assert_eq!(p.name, TRISORT_PROFILE_CONFORMANT);
    assert_eq!((p.subpixel_bits_min, p.subpixel_bits_max), (8, 8));
    assert!(p.depth_at_sample && p.conservative && p.patterns == 1);
    assert_eq!(p.tolerance, b.settings.robust.tolerance);
    let device = |bits, standard, samples| TrisortDeviceRaster {
        subpixel_bits: bits,
        standard_sample_locations: standard,
        samples,
    };
    let check = |d: TrisortDeviceRaster| unsafe { trisort_check_device(h, &d) };
    let samples = b.settings.samples;
    assert_eq!(check(device(8, 1, samples)), TrisortStatus::Ok);
    assert_eq!(
        check(device(0, -1, samples)),
        TrisortStatus::Ok,
        "unknown: not a difference"
    );
    assert_eq!(check(device(4, 1, samples)), TrisortStatus::ProfileMismatch);
    let msg = last_error();
    assert!(
        msg.contains("<bytes>") && msg.contains("4 bits") && msg.contains("`conformant` asks 8"),
        "{msg}"
    );
    assert_eq!(check(device(8, 0, samples)), TrisortStatus::ProfileMismatch);
    assert!(last_error().contains("non-standard sample locations"));
    assert_eq!(
        check(device(8, 1, 5 - samples)),
        TrisortStatus::ProfileMismatch
    );
    assert!(last_error().contains("sample count"));
    assert_eq!(
        unsafe { trisort_check_device(h, null()) },
        TrisortStatus::NullArgument
    );
    assert_eq!(
        unsafe { trisort_raster_profile(h, null_mut()) },
        TrisortStatus::NullArgument
    );
}

/// Null handles and outputs are refused; closes `h`.
fn check_null_pointers(h: *mut TrisortBaked) {
    let mut fps = -1.0;
    let mut info = TrisortEnvironmentInfo::default();
    let mut n = 0u32;
    let mut len = 0usize;
    unsafe {
        assert_eq!(trisort_fps(null(), &mut fps), TrisortStatus::NullArgument);
        assert_eq!(trisort_fps(h, null_mut()), TrisortStatus::NullArgument);
        assert_eq!(
            trisort_environment_info(null(), &mut info),
            TrisortStatus::NullArgument
        );
        assert_eq!(
            trisort_environment_info(h, null_mut()),
            TrisortStatus::NullArgument
        );
        assert_eq!(
            trisort_environment_name(h, null_mut(), 0, null_mut()),
            TrisortStatus::NullArgument
        );
        assert_eq!(
            trisort_environment_name(null(), null_mut(), 0, &mut len),
            TrisortStatus::NullArgument
        );
        assert_eq!(
            trisort_environment_level(h, 0, null_mut(), null_mut(), null_mut(), 0, null_mut()),
            TrisortStatus::NullArgument
        );
        assert_eq!(
            trisort_variant_count(h, null_mut()),
            TrisortStatus::NullArgument
        );
        assert_eq!(
            trisort_variant_count(null(), &mut n),
            TrisortStatus::NullArgument
        );
        assert_eq!(
            trisort_variant_materials(null(), null(), null_mut(), 0, &mut len),
            TrisortStatus::NullArgument
        );
        trisort_close(h);
    }
}

/// Writes a 16 × 8 equirectangular Radiance HDR image, bright above and dim below.
fn write_sky(path: &Path) {
    let (w, h) = (16usize, 8usize);
    let mut out = format!("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y {h} +X {w}\n").into_bytes();
    for y in 0..h {
        // Flat (not run-length encoded) RGBE: 3.0 above (mantissa 192, exponent 2), 0.25 below.
        let texel: [u8; 4] = if y < h / 2 {
            [192, 192, 192, 130]
        } else {
            [128, 128, 128, 127]
        };
        for _ in 0..w {
            out.extend_from_slice(&texel);
        }
    }
    std::fs::write(path, out).unwrap();
}

#[test]
fn car_concept_variants_are_what_the_rust_reader_reads_and_refusals_name_the_variant() {
    let Some(car) = trisort_testkit::scene_path("CarConcept/CarConcept.glb") else {
        return;
    };
    let Some(dir) = gpu_tempdir() else { return };
    let d = dir.path();
    bake(
        d,
        &[
            car.to_str().unwrap(),
            "--path",
            "orbit:frames=1",
            "--size",
            "32x32",
            "--samples",
            "1",
            "--keep-intersections",
            "-o",
            "car.baked",
        ],
    );
    let path = d.join("car.baked");
    let b: Baked = read_file(FileKind::Baked, &path).unwrap();
    let g = &b.geometry;
    assert_eq!(g.variants.len(), 3, "CarConcept has three variants");
    let h = open(&path);
    let mut count = 0;
    assert_eq!(
        unsafe { trisort_variant_count(h, &mut count) },
        TrisortStatus::Ok
    );
    assert_eq!(count as usize, g.variants.len());
    let default = materials(h);
    assert_eq!(variant_table(h, None).unwrap(), default);
    let mut changed = 0;
    for (k, v) in g.variants.iter().enumerate() {
        let name = string(|o, c, l| unsafe { trisort_variant_name(h, k as u32, o, c, l) });
        assert_eq!(name, v.name);
        let table = variant_table(h, Some(&name)).unwrap();
        let rust = g.variant_materials(Some(&name)).unwrap();
        assert_eq!(table.len(), g.materials.len());
        for (slot, (c, r)) in table.iter().zip(&rust).enumerate() {
            assert_material(c, r, &format!("{name} slot {slot}"));
            // Slot `slot` shows material `v.materials[slot]` under the variant.
            assert_eq!(
                *c, default[v.materials[slot] as usize],
                "{name} slot {slot}"
            );
        }
        changed += table.iter().zip(&default).filter(|(a, b)| a != b).count();
    }
    assert!(changed > 0, "some variant changes some material");
    assert_eq!(variant_table(h, Some("Chrome")), Err(TrisortStatus::Absent));
    let msg = last_error();
    for part in [
        "car.baked",
        "\"Chrome\"",
        &format!("{:?}", g.variants[0].name),
    ] {
        assert!(msg.contains(part), "{part} missing from: {msg}");
    }
    let bad = CString::new(vec![0xffu8, 0xfe]).unwrap();
    let mut len = 0;
    let s = unsafe { trisort_variant_materials(h, bad.as_ptr(), null_mut(), 0, &mut len) };
    assert_eq!(s, TrisortStatus::Unsupported);
    assert!(last_error().contains("UTF-8"), "{}", last_error());
    let mut short = vec![TrisortMaterial::default(); default.len() - 1];
    let name = CString::new(g.variants[1].name.clone()).unwrap();
    let s = unsafe {
        trisort_variant_materials(h, name.as_ptr(), short.as_mut_ptr(), short.len(), &mut len)
    };
    assert_eq!((s, len), (TrisortStatus::BufferTooSmall, default.len()));
    assert!(
        short.iter().all(|m| *m == TrisortMaterial::default()),
        "nothing copied"
    );
    unsafe { trisort_close(h) };

    // The same file with a variant that puts a material of another alpha mode or sidedness
    // in a slot: refused, as the player refuses it, naming the file, the variant and the slot.
    let (slot, other) = (0..g.materials.len())
        .flat_map(|a| (0..g.materials.len()).map(move |b| (a, b)))
        .find(|&(a, o)| {
            let (x, y) = (&g.materials[a], &g.materials[o]);
            x.alpha_mode != y.alpha_mode || x.double_sided != y.double_sided
        })
        .expect("CarConcept has materials of different alpha modes or sidedness");
    let mut forged = b.clone();
    forged.geometry.variants[2].materials[slot] = other as u32;
    let variant = forged.geometry.variants[2].name.clone();
    let rust = forged
        .geometry
        .variant_materials(Some(&variant))
        .unwrap_err();
    let forged_path = d.join("forged.baked");
    container::write_file_atomic(FileKind::Baked, &forged_path, &forged).unwrap();
    let h = open(&forged_path);
    assert_eq!(
        variant_table(h, Some(&variant)),
        Err(TrisortStatus::Unsupported)
    );
    let msg = last_error();
    assert_eq!(msg, format!("{}: {rust}", forged_path.display()));
    assert!(
        msg.contains(&format!("{variant:?}")) && msg.contains(&format!("material {slot}")),
        "{msg}"
    );
    // The other variants still apply.
    assert!(variant_table(h, Some(&g.variants[1].name)).is_ok());
    unsafe { trisort_close(h) };
}
