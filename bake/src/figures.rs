//! The figures scripts rely on (`--json` of record, merge, bake, inspect; the CLI contract
//! in README.md lists their keys) and the one-line summaries printed beside them.

use serde_json::json;
use trisort_format::{Baked, Environment, Phase, Recording};

/// The raster profile in one line, for summaries: `conformant (±0.001953125 px, corners
/// snapped to 8 sub-pixel bits, depth at the sample)`.
pub fn profile_summary(s: &trisort_format::RecordSettings) -> String {
    let r = &s.robust;
    if !r.conservative {
        return format!("{} (the recorded pattern only)", r.profile.name);
    }
    format!(
        "{} (±{} px, corners snapped to {} sub-pixel bits, depth {})",
        r.profile.name,
        r.tolerance,
        r.profile.bits_text(),
        r.profile.depth_text()
    )
}

/// `--json`'s `raster_profile` (record, merge, bake, inspect): what the bake assumes about
/// the rasterizer that plays it : the profile's `name`, its
/// `tolerance` in pixels, the sub-pixel grids (`subpixel_bits`: `[least, most]`), where depth
/// is taken (`depth_at`), the recorded sample pattern (`size`, `samples`, `sample_locations`:
/// `standard`), whether the recording was `conservative`, and its jittered `patterns`.
pub fn raster_profile_json(s: &trisort_format::RecordSettings) -> serde_json::Value {
    let r = &s.robust;
    json!({
        "name": r.profile.name,
        "tolerance": r.tolerance,
        "subpixel_bits": [r.profile.subpixel_bits_min, r.profile.subpixel_bits_max],
        "depth_at": r.profile.depth_at,
        "size": [s.width, s.height],
        "samples": s.samples,
        "sample_locations": "standard",
        "conservative": r.conservative,
        "patterns": r.patterns,
    })
}

/// The `--json` figures of a recording .
pub fn recording_json(rec: &Recording, seconds: Option<f64>) -> serde_json::Value {
    let g = rec.unique_visible.len();
    let per_frame: Vec<_> = rec
        .frames
        .iter()
        .map(|f| {
            let covered = if rec.phase == Phase::Graphs {
                Some(f.covered.len())
            } else {
                None
            };
            json!({
                "frame": f.frame,
                "visible": f.visible.len(),
                "covered": covered,
                "ignored": covered.map(|c| g - c),
                "edges": f.edges.len(),
                "ties": f.ties.len(),
                "layers": f.layers[0] + f.layers[1],
                "layers_visibility": f.layers[0],
                "layers_graphs": f.layers[1],
                "truncated": f.truncated,
            })
        })
        .collect();
    json!({
        "frames": rec.frames.len(),
        "path_frames": rec.frame_states.len(),
        "phase": format!("{:?}", rec.phase).to_lowercase(),
        "scene_triangles": rec.scene_triangles,
        "unique_visible": g,
        "device": rec.device.adapter,
        "robust": {
            "patterns": rec.settings.robust.patterns,
            "tolerance": rec.settings.robust.tolerance,
            "conservative": rec.settings.robust.conservative,
        },
        "raster_profile": raster_profile_json(&rec.settings),
        "per_frame": per_frame,
        "seconds": seconds,
    })
}

/// Adds `record --json`'s `intersections_split` (pairs of triangles split along their
/// intersection before recording), `intersections_split_across_groups` (those of them of parts
/// that move apart) and `triangles_added` (0 and 0 with `--keep-intersections`).
pub fn add_split_json(v: &mut serde_json::Value, split: Option<&trisort_intersect::SplitReport>) {
    v["intersections_split"] = split
        .map_or(0, |r| r.pairs_split + r.pairs_split_across_groups)
        .into();
    v["intersections_split_across_groups"] =
        split.map_or(0, |r| r.pairs_split_across_groups).into();
    v["triangles_added"] = split.map_or(0, |r| r.triangles_added).into();
    v["intersections_left"] = split.map_or(0, |r| r.pairs_skipped_sliver).into();
}

/// The `--json` figures of a baked file . `seconds` is the measured
/// wall time of the merge: the file's `stats.seconds` stays 0 so that bakes are
/// byte-identical.
pub fn baked_json(b: &Baked, seconds: f64) -> serde_json::Value {
    let s = &b.stats;
    json!({
        "strategy": b.merge.strategy,
        "layout": b.merge.layout,
        "bridge": b.merge.bridge,
        "seeding": b.merge.seeding,
        "depth_only": b.merge.depth_only,
        "segment": b.merge.segment,
        "frames": b.frames.len(),
        "index_triangles": s.index_triangles,
        "source_triangles": s.source_triangles,
        "unique_visible": s.unique_visible,
        "draws_per_frame_mean": s.draws_per_frame_mean,
        "draws_per_frame_max": s.draws_per_frame_max,
        "drawn_not_visible_mean": s.drawn_not_visible_mean,
        "unordered_samples": s.unordered_samples,
        "exact_components": s.exact_components,
        "heuristic_components": s.heuristic_components,
        "heuristic_unordered_samples": s.heuristic_unordered_samples,
        "environment": environment_json(&b.environment),
        "raster_profile": raster_profile_json(&b.settings),
        "seconds": seconds,
    })
}

/// The `environment` of `--json`: its name, level 0's size, levels, bytes of texels and sun
/// (`null` without one; else `direction` towards the light and `color`), and exposure.
pub fn environment_json(e: &Environment) -> serde_json::Value {
    json!({
        "name": e.name,
        "width": e.width,
        "height": e.height,
        "levels": e.levels.len(),
        "bytes": e.texel_bytes(),
        "sun": e.sun.map(|s| json!({"direction": s.direction, "color": s.color})),
        "exposure": e.exposure,
    })
}

/// One human summary of a merge that took `seconds` (wall time, measured by the caller):
/// its figures, then a line naming the raster profile.
pub fn merge_summary(b: &Baked, seconds: f64) -> String {
    let s = &b.stats;
    format!(
        "merged {} frames ({} {}, bridge {}): {} index triangles for |G| = {} ({:.2}x), \
         Σ|V_f| = {}; draws per frame {:.1} mean, {} max; drawn-not-visible {:.0} per frame; \
         {} unordered samples (cycle components: {} solved exactly, {} by heuristic); \
         {:.2} s\nraster profile: {}",
        b.frames.len(),
        b.merge.strategy,
        b.merge.layout,
        b.merge.bridge,
        s.index_triangles,
        s.unique_visible,
        s.index_triangles as f64 / s.unique_visible.max(1) as f64,
        s.source_triangles,
        s.draws_per_frame_mean,
        s.draws_per_frame_max,
        s.drawn_not_visible_mean,
        s.unordered_samples,
        s.exact_components,
        s.heuristic_components,
        seconds,
        profile_summary(&b.settings)
    )
}

/// `inspect --json` of a baked file: its merge figures, rate, material variants (and why
/// `play --variant` refuses any), raster profile, light, device and the edges the merger
/// removed to break depth-order cycles.
pub fn baked_file_json(baked: &Baked) -> serde_json::Value {
    let s = &baked.stats;
    json!({
        "strategy": baked.merge.strategy, "layout": baked.merge.layout,
        "index_triangles": s.index_triangles, "source_triangles": s.source_triangles,
        "unique_visible": s.unique_visible, "draws_per_frame_mean": s.draws_per_frame_mean,
        "draws_per_frame_max": s.draws_per_frame_max, "drawn_not_visible_mean": s.drawn_not_visible_mean,
        "unordered_samples": s.unordered_samples, "seconds": s.seconds,
        "exact_components": s.exact_components, "heuristic_components": s.heuristic_components,
        "heuristic_unordered_samples": s.heuristic_unordered_samples,
        "frames": baked.frames.len(),
        // The path's frame rate (null where the recordings did not store one); the material
        // variants' names (as for a scene), and why `play --variant` refuses any of them.
        "fps": baked.fps,
        "variants": baked.geometry.variants.iter().map(|v| &v.name).collect::<Vec<_>>(),
        "variants_refused": baked.geometry.variants.iter().filter_map(|v| {
            let e = baked.geometry.variant_materials(Some(&v.name)).err()?;
            Some((v.name.clone(), serde_json::Value::from(e.to_string())))
        }).collect::<serde_json::Map<_, _>>(),
        "split_intersections": baked.settings.split_intersections,
        // What the bake assumes about the rasterizer that plays it (record --raster-profile).
        "raster_profile": raster_profile_json(&baked.settings),
        // The light stored in the file (`bake --environment`).
        "environment": environment_json(&baked.environment),
        // The recording device; `mixed: …` (each device with its frames) when the recordings
        // were merged with `merge --allow-mixed-devices`.
        "device": baked.device.adapter, "driver": baked.device.driver,
        // The edges the merger removed to break depth-order cycles, front → back, as scene
        // ids of the recorded scene (the file stores G-local ids): the samples they weigh are
        // the unordered ones.
        "removed_edges": baked.removed_edges.iter().enumerate().flat_map(|(f, edges)| {
            let id = |t: u32| baked.scene_ids.get(t as usize).copied().unwrap_or(t);
            edges.iter().map(move |e| json!({"frame": f, "from": id(e.from), "to": id(e.to), "weight": e.weight}))
        }).collect::<Vec<_>>(),
    })
}

/// The scene's nodes that its animations move, by name.
pub fn animated_nodes(scene: &trisort_scene::Scene) -> std::collections::BTreeSet<&str> {
    let g = &scene.geometry;
    scene
        .animations
        .iter()
        .flat_map(|an| {
            an.channels
                .iter()
                .map(|c| g.nodes[c.node as usize].name.as_str())
        })
        .collect()
}

/// What `record` would split with every node at rest (a path that moves nodes apart splits
/// only within the groups that stay rigid on it).
pub fn split_at_rest(scene: &trisort_scene::Scene) -> trisort_intersect::SplitReport {
    let rest = trisort_format::FrameState {
        camera: trisort_format::Camera {
            view: glam::DMat4::IDENTITY.to_cols_array(),
            yfov: 1.0,
            znear: 0.1,
            zfar: None,
        },
        poses: Vec::new(),
    };
    trisort_intersect::split_intersections(
        &scene.geometry,
        std::slice::from_ref(&rest),
        &trisort_intersect::SplitOptions::default(),
    )
    .report
}

/// `inspect --json` of a scene: counts, materials by alpha mode, animated nodes, bounds,
/// notes, material variants and what `record` would split at rest (`split`).
pub fn scene_json(
    scene: &trisort_scene::Scene,
    split: &trisort_intersect::SplitReport,
) -> serde_json::Value {
    let st = &scene.stats;
    let g = &scene.geometry;
    let count_mode =
        |m: trisort_format::AlphaMode| g.materials.iter().filter(|x| x.alpha_mode == m).count();
    let transmissive = g.materials.iter().filter(|m| m.transmission > 0.0).count();
    let animated = animated_nodes(scene);
    let bounds = scene
        .bounds()
        .map(|(lo, hi)| json!({"min": lo.to_array(), "max": hi.to_array()}));
    let mut v = json!({
        "scene": scene.name,
        "triangles": st.triangles, "zero_area_triangles": st.zero_area_triangles,
        "meshes": st.meshes, "primitives": st.primitives, "nodes": st.nodes,
        "materials": st.materials, "textures": st.textures,
        "animations": st.animations, "cameras": st.cameras,
        "materials_by_alpha_mode": {"opaque": count_mode(trisort_format::AlphaMode::Opaque), "mask": count_mode(trisort_format::AlphaMode::Mask), "blend": count_mode(trisort_format::AlphaMode::Blend)},
        "transmissive_materials": transmissive,
        "animated_nodes": animated,
        "bounds": bounds,
        "notes": scene.notes,
        "variants": scene.variants,
    });
    add_split_json(&mut v, Some(split));
    v
}

/// `play --json`'s `profile_check`: `ok`, `differences` (in words), the `profile` checked
/// against (the bake's `raster_profile`), what the API reported (`api`: `subpixel_bits`,
/// `standard_sample_locations`, null where it cannot say) and what the probe measured
/// (`probe`: `consistent_subpixel_bits`, the coverage steps `x` and `y` in pixels).
pub fn profile_check_json(
    baked: &Baked,
    c: &trisort_gpu::raster_probe::ProfileCheck,
) -> serde_json::Value {
    json!({
        "ok": c.ok,
        "differences": c.differences,
        "profile": raster_profile_json(&baked.settings),
        "api": {
            "subpixel_bits": c.api.subpixel_bits,
            "standard_sample_locations": c.api.standard_sample_locations,
        },
        "probe": {
            "samples": c.probe.samples,
            "consistent_subpixel_bits": c.probe.consistent_bits,
            "x": c.probe.drops[0],
            "y": c.probe.drops[1],
        },
    })
}

/// The clips of a baked file as the `--json` key `clips` lists them (`bake`, `merge`):
/// `[{name, first, frames, fps, path_first}]`, `frames` being the clip's frame count.
pub fn clips_json(baked: &Baked) -> serde_json::Value {
    baked
        .clips
        .iter()
        .map(|c| {
            json!({
                "name": c.name, "first": c.first, "frames": c.count, "fps": c.fps,
                "path_first": c.path_first,
            })
        })
        .collect()
}
