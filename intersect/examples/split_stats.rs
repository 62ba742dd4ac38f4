//! Prints what `split_intersections` does to a scene: the report, the time, and (with
//! `--verify`) the crossing pairs left in the output.
//!
//! ```sh
//! cargo run --release -p trisort-intersect --example split_stats -- SCENE [--path SPEC] \
//!     [--min-fraction F] [--both-sides] [--keep-t-junctions] [--verify]
//! ```
//!
//! `SCENE` is a `.glb`/`.gltf` file or `demo[:TRIANGLES]`; `--path` any path spec of
//! `trisort_paths::load` (a TOML file, `gltf`, `orbit:…`) or `demo` (the demo car's default
//! path, `trisort_paths::demo_default`); without it the scene is
//! taken at its rest pose (one rigid group).

use std::path::Path;
use std::process::ExitCode;
use std::time::Instant;

use trisort_intersect::{find_intersections, split_intersections, SplitOptions};

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("split_stats: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run() -> Result<(), String> {
    let mut args = std::env::args().skip(1);
    let mut scene_spec = None;
    let mut path_spec = None;
    let mut options = SplitOptions::default();
    let mut verify = false;
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--path" => path_spec = Some(args.next().ok_or("--path needs a value")?),
            "--min-fraction" => {
                let v = args.next().ok_or("--min-fraction needs a value")?;
                options.min_piece_area_fraction =
                    v.parse().map_err(|e| format!("--min-fraction {v}: {e}"))?;
            }
            "--verify" => verify = true,
            "--keep-t-junctions" => options.close_t_junctions = false,
            "--both-sides" => options.cut_both_sides = true,
            _ if scene_spec.is_none() && !arg.starts_with("--") => scene_spec = Some(arg),
            _ => return Err(format!("unexpected argument {arg:?}")),
        }
    }
    let scene_spec = scene_spec.ok_or("usage: split_stats SCENE [--path SPEC] [--verify]")?;

    let start = Instant::now();
    let scene = match scene_spec.strip_prefix("demo") {
        Some(rest) if rest.is_empty() || rest.starts_with(':') => {
            let n = match rest.strip_prefix(':') {
                Some(n) => n.parse().map_err(|e| format!("{scene_spec}: {e}"))?,
                None => trisort_scene::DEFAULT_TRIANGLES,
            };
            trisort_scene::demo_car(n)
        }
        _ => trisort_scene::load(Path::new(&scene_spec)).map_err(|e| e.to_string())?,
    };
    let frames = match &path_spec {
        Some(spec) if spec == "demo" => trisort_paths::demo_default(&scene).frames,
        Some(spec) => {
            trisort_paths::load(spec, &scene, &Default::default())
                .map_err(|e| e.to_string())?
                .frames
        }
        None => Vec::new(),
    };
    let loaded = start.elapsed().as_secs_f64();

    let start = Instant::now();
    let split = split_intersections(&scene.geometry, &frames, &options);
    let seconds = start.elapsed().as_secs_f64();
    let r = &split.report;
    println!("scene               {}", scene.name);
    println!("frames              {}", frames.len());
    println!("triangles in        {}", scene.geometry.triangles.len());
    println!("triangles out       {}", split.geometry.triangles.len());
    println!("groups              {}", r.groups);
    println!("candidate pairs     {}", r.candidate_pairs);
    println!("pairs split         {}", r.pairs_split);
    println!("pairs skipped       {} (sliver)", r.pairs_skipped_sliver);
    println!("pairs below prec.   {}", r.pairs_below_precision);
    println!("triangles split     {}", r.triangles_split);
    println!("triangles added     {}", r.triangles_added);
    println!("rounds              {}", r.rounds);
    println!("neighbours split    {}", r.neighbours_split);
    println!("t-junctions left    {}", r.t_junctions_left);
    println!("load s              {loaded:.2}");
    println!("split s             {seconds:.2}");
    println!("threads             {}", rayon::current_num_threads());
    if verify {
        let start = Instant::now();
        let left = find_intersections(&split.geometry, &frames);
        let unexplained = left
            .pairs
            .iter()
            .map(|&[a, b]| [split.origin[a as usize], split.origin[b as usize]])
            .filter(|&[a, b]| split.skipped.binary_search(&[a.min(b), a.max(b)]).is_err())
            .count();
        println!("crossing pairs left {}", left.pairs.len());
        println!("  not in skipped    {unexplained}");
        println!("verify s            {:.2}", start.elapsed().as_secs_f64());
    }
    Ok(())
}
