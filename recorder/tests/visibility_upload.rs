//! The recorder uploads only what decides visibility (`SceneGpu::for_visibility`: no linear
//! metallic-roughness, normal or occlusion maps) and records exactly what the full upload
//! records: byte-identical `Recording`s, both made in this process, on the demo car given
//! linear maps and on a real scene, plain, robust and conservative, at 4× and 1× MSAA.

use trisort_format::{FrameState, Texture, TextureSlot};
use trisort_gpu::scene_gpu::{SceneGpu, View};
use trisort_recorder::Internals;
use trisort_scene::Scene;

use crate::compact_readback::{assert_internals_keep_recording, shared_scene, variants};

/// Records two frames of `scene`'s orbit with the visibility-only and the full upload, for
/// every settings of [`variants`], and asserts the bytes agree.
fn record_both(gpu: &trisort_gpu::Gpu, scene: &Scene) {
    for settings in variants() {
        let full = Internals {
            full_texture_upload: true,
            ..Internals::default()
        };
        assert_internals_keep_recording(
            gpu,
            scene,
            settings,
            (Internals::default(), full),
            "leaving out the linear maps",
        );
    }
}

/// The demo car with a linear normal and metallic-roughness map on every material (it has
/// none of its own), so the visibility upload has something to leave out.
fn demo_car_with_linear_maps() -> Scene {
    let mut scene = trisort_scene::demo_car(20_000);
    let g = &mut scene.geometry;
    let pattern: Vec<u8> = (0..16 * 16 * 4).map(|i| (i * 53 % 251) as u8).collect();
    let (maps, _) =
        trisort_scene::mips::texture_with_mips("maps".into(), 16, 16, pattern, false, 1024);
    let slot = Some(TextureSlot {
        texture: g.textures.len() as u32,
        tex_coord: 0,
        transform: Default::default(),
    });
    g.textures.push(maps);
    for m in &mut g.materials {
        m.normal_texture = slot;
        m.metallic_roughness_texture = slot;
    }
    g.check_structure().expect("valid geometry");
    scene
}

/// The first frame of `scene`'s orbit.
fn first_frame(scene: &Scene) -> Vec<FrameState> {
    let timeline = trisort_paths::load("orbit", scene, &Default::default()).expect("orbit path");
    timeline.frames[..1].to_vec()
}

/// Texture bytes on the GPU of `scene` uploaded as a player does and for visibility (first
/// frame).
fn texture_bytes(gpu: &trisort_gpu::Gpu, scene: &Scene) -> (u64, u64) {
    let (device, queue, g, f) = (
        &gpu.device,
        &gpu.queue,
        &scene.geometry,
        &first_frame(scene),
    );
    (
        SceneGpu::new(device, queue, g, f, view()).texture_bytes(),
        SceneGpu::for_visibility(device, queue, g, f, view()).texture_bytes(),
    )
}

fn view() -> View {
    View {
        width: 64,
        height: 64,
        samples: 4,
        glass_opacity: 0.35,
    }
}

#[test]
fn the_visibility_upload_records_the_demo_car_with_linear_maps_as_the_full_one() {
    let Some(gpu) = trisort_testkit::gpu() else {
        return;
    };
    let scene = demo_car_with_linear_maps();
    // Not vacuous: the linear map is left out.
    let g = &scene.geometry;
    let (full, visibility) = texture_bytes(&gpu, &scene);
    let maps = g.textures.last().unwrap().byte_len();
    // Less the white texel left in its place (two layers of it on GL).
    assert!(
        visibility + maps <= full + 8 && full > visibility,
        "{full} vs {visibility} ({maps} in the maps)"
    );
    record_both(&gpu, &scene);
}

#[test]
fn a_linear_base_colour_texture_is_uploaded_for_visibility() {
    let Some(gpu) = trisort_testkit::gpu() else {
        return;
    };
    // The plate's colour texture stored linear: `surface_base` samples it in the linear
    // array, so that array is uploaded whole.
    let mut scene = demo_car_with_linear_maps();
    let plate = scene
        .geometry
        .materials
        .iter()
        .find_map(|m| m.base_color_texture)
        .expect("the demo car's plate is textured") as usize;
    scene.geometry.textures[plate].srgb = false;
    let (full, visibility) = texture_bytes(&gpu, &scene);
    assert_eq!(visibility, full);
}

#[test]
fn the_visibility_upload_records_a_real_scene_as_the_full_one() {
    let Some(gpu) = trisort_testkit::gpu() else {
        return;
    };
    let Some(scene) = shared_scene("GlassVaseFlowers/GlassVaseFlowers.glb") else {
        return;
    };
    record_both(&gpu, &scene);
}

/// CarConcept's linear maps are most of its texture memory; the recorder leaves them out.
/// Prints both figures (`cargo test -p trisort-recorder --test tests car_concept -- --nocapture`).
#[test]
fn the_visibility_upload_of_car_concept_leaves_out_its_linear_maps() {
    let Some(gpu) = trisort_testkit::gpu() else {
        return;
    };
    let Some(scene) = shared_scene("CarConcept/CarConcept.glb") else {
        return;
    };
    let g = &scene.geometry;
    let (full, visibility) = texture_bytes(&gpu, &scene);
    let linear: u64 = g
        .textures
        .iter()
        .filter(|t| !t.srgb)
        .map(Texture::byte_len)
        .sum();
    eprintln!(
        "CarConcept texture bytes on the GPU: full upload {full}, visibility upload \
         {visibility}, saved {} ({linear} bytes of linear textures in the file)",
        full - visibility
    );
    assert!(visibility + linear <= full + 8, "{full} vs {visibility}");
}
