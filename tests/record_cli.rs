//! `trisort record` through the real binary on real scenes: CarConcept's interior through the
//! glass, kill-and-resume byte identity, determinism.

use std::time::{Duration, Instant};

use trisort_format::{FileKind, Recording};

use crate::support::*;

fn read(path: &std::path::Path) -> Recording {
    trisort_format::read_file(FileKind::Recording, path).unwrap()
}

#[test]
fn car_concept_records_edges_and_interior_through_the_glass() {
    let Some(car) = scene("CarConcept") else {
        return;
    };
    let Some(dir) = gpu_tempdir() else {
        return;
    };
    let v = run_json(
        dir.path(),
        &[
            "record",
            &car,
            "--path",
            "orbit:frames=12,elevation=15",
            "--frames",
            "0..3",
            "--size",
            "128x128",
            "--samples",
            "4",
            "-o",
            "car.rec",
        ],
    );
    assert_eq!(v["frames"], 3);
    let per_frame = v["per_frame"].as_array().unwrap();
    assert!(per_frame.iter().all(|f| f["edges"].as_u64().unwrap() > 0));
    assert!(per_frame.iter().all(|f| f["truncated"] == false));
    let rec = read(&dir.path().join("car.rec"));
    // Interior parts are only visible through the glass (recorded at opacity 0). Ids are
    // those of the recorded scene (split where triangles crossed): classify them with the
    // recording's own geometry of G.
    let g = &rec.geometry;
    let local = |t: u32| {
        rec.unique_visible
            .binary_search(&t)
            .expect("a triangle of G") as u32
    };
    let interior = |t: u32| {
        g.nodes[g.triangle_node(local(t)) as usize]
            .name
            .starts_with("Interior")
    };
    let glass = |t: u32| g.materials[g.triangle_material(local(t)) as usize].transmission > 0.0;
    for f in &rec.frames {
        assert!(
            f.visible.iter().any(|&t| interior(t)),
            "frame {}: no interior triangle visible",
            f.frame
        );
        assert!(
            f.visible.iter().any(|&t| glass(t)),
            "frame {}: no glass visible",
            f.frame
        );
        // Something lies behind the glass: an edge from a glass triangle to an interior one,
        // possibly through other glass.
        assert!(
            f.edges.iter().any(|e| glass(e.from) && interior(e.to)),
            "frame {}: no glass → interior edge",
            f.frame
        );
    }
}

#[test]
fn an_interrupted_recording_resumes_to_identical_bytes() {
    let Some(car) = scene("CarConcept") else {
        return;
    };
    let Some(dir) = gpu_tempdir() else {
        return;
    };
    let args = |out: &'static str| {
        [
            "record",
            car.as_str(),
            "--path",
            "orbit:frames=5",
            "--size",
            "64x64",
            "--samples",
            "4",
            "-o",
            out,
        ]
    };
    // A clean run.
    run(dir.path(), &args("clean.rec"), true);
    // A run killed once some frames are finished.
    let mut child = trisort(dir.path())
        .args(args("resumed.rec"))
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let partial = dir.path().join("resumed.rec.partial");
    let t0 = Instant::now();
    loop {
        let finished = std::fs::read_dir(&partial)
            .map(|d| {
                d.filter(|e| e.as_ref().unwrap().file_name() != "key")
                    .count()
            })
            .unwrap_or(0);
        if finished >= 3 || t0.elapsed() > Duration::from_secs(120) {
            break;
        }
        if child.try_wait().unwrap().is_some() {
            panic!("the recording finished before it could be interrupted");
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(
        !dir.path().join("resumed.rec").exists(),
        "no output file after an interrupted run"
    );
    let out = run(dir.path(), &args("resumed.rec"), true);
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("resuming"),
        "the rerun did not resume"
    );
    assert!(!partial.exists(), "partial folder removed after success");
    let a = std::fs::read(dir.path().join("clean.rec")).unwrap();
    let b = std::fs::read(dir.path().join("resumed.rec")).unwrap();
    assert!(a == b, "resumed recording differs from a clean one");
}

#[test]
fn recordings_are_byte_identical_across_runs_and_thread_counts() {
    let Some(truck) = scene("CesiumMilkTruck") else {
        return;
    };
    let Some(dir) = gpu_tempdir() else {
        return;
    };
    let mut outputs = vec![];
    for threads in ["1", "2"] {
        let out = format!("t{threads}.rec");
        let status = trisort(dir.path())
            .env("RAYON_NUM_THREADS", threads)
            .args([
                "record",
                &truck,
                "--path",
                "gltf",
                "--fps",
                "4",
                "--size",
                "64x48",
                "--samples",
                "4",
                "-o",
                &out,
            ])
            .status()
            .unwrap();
        assert!(status.success());
        outputs.push(std::fs::read(dir.path().join(out)).unwrap());
    }
    assert!(outputs[0] == outputs[1], "recordings differ between runs");
    let rec = read(&dir.path().join("t1.rec"));
    assert!(
        rec.frames.len() >= 4,
        "the truck's 1.25 s animation sampled at 4 fps"
    );
    assert!(
        rec.frame_states
            .windows(2)
            .any(|w| w[0].poses != w[1].poses),
        "wheels move"
    );
}
