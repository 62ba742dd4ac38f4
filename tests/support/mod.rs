//! Harness for tests that run the real `trisort` binary: a temp directory per test and, on
//! failure, the command, its directory and its stderr.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The binary under test.
pub fn bin() -> PathBuf {
    PathBuf::from(env!("CARGO_BIN_EXE_trisort"))
}

/// A command for the binary with the environment tests need.
pub fn trisort(dir: &Path) -> Command {
    let mut c = Command::new(bin());
    c.current_dir(dir);
    if std::env::var_os("XDG_RUNTIME_DIR").is_none() {
        c.env("XDG_RUNTIME_DIR", std::env::temp_dir());
    }
    c
}

/// Runs and returns the output, panicking with the command, directory and stderr if the exit
/// status is not `expect_success`.
///
/// With `TRISORT_TEST_TIMES=FILE` each run appends a line to FILE: seconds, the test (its
/// thread's name) and the command, to find where the suite spends its time.
pub fn run(dir: &Path, args: &[&str], expect_success: bool) -> Output {
    let started = std::time::Instant::now();
    let out = trisort(dir).args(args).output().expect("spawn trisort");
    if let Some(log) = std::env::var_os("TRISORT_TEST_TIMES") {
        log_time(Path::new(&log), started.elapsed().as_secs_f64(), args);
    }
    if out.status.success() != expect_success {
        panic!(
            "trisort {} (in {}) exited with {:?}, expected {}\n--- stdout\n{}\n--- stderr\n{}",
            args.join(" "),
            dir.display(),
            out.status.code(),
            if expect_success { "success" } else { "failure" },
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
    }
    out
}

/// Appends one timing line to `log` (best effort: a diagnostic, not part of any check).
fn log_time(log: &Path, seconds: f64, args: &[&str]) {
    use std::io::Write;
    let test = std::thread::current().name().unwrap_or("?").to_string();
    if let Ok(mut f) = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(log)
    {
        let _ = writeln!(f, "{seconds:.2}\t{test}\ttrisort {}", args.join(" "));
    }
}

/// The arguments of a command line written as one string, split at whitespace:
/// `args("play car.baked --frames 0..1")`. For literal arguments; pass paths, which may hold
/// spaces, as arguments of their own.
pub fn args(line: &str) -> Vec<&str> {
    line.split_whitespace().collect()
}

/// The arguments of `trisort bake SCENE --path PATH --size SIZE --samples SAMPLES -o OUT`, in
/// that order; add options after them.
pub fn bake_args<'a>(
    scene: &'a str,
    path: &'a str,
    size: &'a str,
    samples: &'a str,
    out: &'a str,
) -> Vec<&'a str> {
    vec![
        "bake",
        scene,
        "--path",
        path,
        "--size",
        size,
        "--samples",
        samples,
        "-o",
        out,
    ]
}

/// Runs with `--json` appended and parses stdout.
pub fn run_json(dir: &Path, args: &[&str]) -> serde_json::Value {
    let mut a = args.to_vec();
    a.push("--json");
    let out = run(dir, &a, true);
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "bad JSON from trisort {}: {e}\n{}",
            a.join(" "),
            String::from_utf8_lossy(&out.stdout)
        )
    })
}

/// A shared scene file, or `None` to skip (unless TRISORT_REQUIRE_SCENES=1).
pub fn scene(name: &str) -> Option<String> {
    trisort_testkit::scene_path(&format!("{name}/{name}.glb")).map(|p| p.display().to_string())
}

/// Whether GPU tests can run here; panics when a GPU is required (CI) but missing.
pub fn gpu_available() -> bool {
    trisort_testkit::gpu().is_some()
}

/// A fresh temporary directory for a test that needs a GPU, or `None` to skip the test where
/// [`gpu_available`] finds none (it panics instead when a GPU is required).
pub fn gpu_tempdir() -> Option<tempfile::TempDir> {
    gpu_available().then(|| tempfile::tempdir().unwrap())
}
