//! What the surface function draws (real renders on the test GPU): each map of the PBR model
//! changes pixels, the environment, exposure and tone map are used, and `--shading basic`
//! draws one view-space light plus ambient, ignoring every map.

use trisort_format::{Baked, Environment, Material, Sun, Texture, TextureSlot};
use trisort_gpu::{Gpu, Shading, ToneMap};
use trisort_player::headless::{HeadlessConfig, HeadlessRenderer};
use trisort_player::Mode;
use trisort_testkit::gpu;

use crate::support::{lit, pixel, quads, srgb8, SIZE};

/// [`quads`] with the red and green quads invisible (blend, alpha 0) and the blue quad (the
/// whole view in frame 1) grey, dielectric, half rough, with uv (both sets) running over
/// [0, 1]² across the view (x right, y down) and a +X tangent, under a dim uniform environment
/// and a bright sun from the upper right front.
pub(crate) fn textured() -> Baked {
    let mut b = quads();
    let g = &mut b.geometry;
    for m in &mut g.materials[..2] {
        m.base_color[3] = 0.0;
    }
    g.materials[2] = Material {
        base_color: [0.5, 0.5, 0.5, 1.0],
        metallic: 0.0,
        roughness: 0.5,
        ..Default::default()
    };
    for v in g.vertices.iter_mut().filter(|v| v.material == 2) {
        // The view spans x, y ∈ [−1.1, 1.1] at the quad's depth.
        v.uv = [
            (v.position[0] / 1.1 + 1.0) / 2.0,
            (1.0 - v.position[1] / 1.1) / 2.0,
        ];
        v.uv1 = v.uv;
        v.tangent = [1.0, 0.0, 0.0, 1.0];
    }
    let mut env = Environment::uniform(0.2);
    env.sun = Some(Sun {
        direction: [0.4, 0.5, 1.0],
        color: [2.0, 2.0, 2.0],
    });
    b.environment = env;
    b
}

/// A `size`² linear or sRGB texture of one colour, with its mip chain.
pub(crate) fn flat_texture(rgba: [u8; 4], size: u32, srgb: bool) -> Texture {
    with_chain(Texture {
        name: String::new(),
        width: size,
        height: size,
        rgba8: rgba.repeat((size * size) as usize),
        srgb,
        mips: Vec::new(),
        blocks: None,
    })
}

/// `t` with the mip chain the importer makes from its level 0 (after a test edits it).
pub(crate) fn with_chain(t: Texture) -> Texture {
    trisort_scene::mips::texture_with_mips(
        t.name,
        t.width,
        t.height,
        t.rgba8,
        t.srgb,
        trisort_scene::mips::MAX_SIZE,
    )
    .0
}

/// The slot of texture `texture` on uv set 0, untransformed.
pub(crate) fn slot(texture: u32) -> Option<TextureSlot> {
    Some(TextureSlot {
        texture,
        tex_coord: 0,
        transform: Default::default(),
    })
}

/// Frame 1 of `baked` (the grey quad over the whole view) at 4× in blend mode.
fn render(gpu: &Gpu, baked: &Baked, shading: Shading, tone_map: ToneMap) -> Vec<u8> {
    let config = HeadlessConfig {
        samples: 4,
        mode: Mode::Blend,
        shading,
        tone_map,
        ..HeadlessConfig::recorded(baked)
    };
    HeadlessRenderer::new(gpu, baked, &config)
        .expect("renderer")
        .render(1)
        .expect("frame")
        .rgba8
}

pub(crate) fn pbr(gpu: &Gpu, baked: &Baked) -> Vec<u8> {
    render(gpu, baked, Shading::Pbr, ToneMap::Neutral)
}

/// The largest channel difference of two images.
pub(crate) fn max_diff(a: &[u8], b: &[u8]) -> u8 {
    a.iter().zip(b).map(|(x, y)| x.abs_diff(*y)).max().unwrap()
}

/// `baked` changed by `change`.
pub(crate) fn with(baked: &Baked, change: impl FnOnce(&mut Baked)) -> Baked {
    let mut b = baked.clone();
    change(&mut b);
    b
}

#[test]
fn every_map_of_the_pbr_model_changes_pixels() {
    let Some(gpu) = gpu() else { return };
    let plain = textured();
    let base = pbr(&gpu, &plain);
    // The quad is lit: not the background, not black, not saturated.
    let centre = pixel(&base, SIZE / 2, SIZE / 2);
    assert!(centre.iter().all(|&c| c > 20 && c < 250), "{centre:?}");
    let metal = with(&plain, |b| {
        b.geometry.materials[2].metallic = 1.0;
        b.geometry.materials[2].roughness = 1.0;
    });
    let glowing = with(&plain, |b| {
        b.geometry.materials[2].emissive = [1.0, 1.0, 1.0]
    });
    // A rough base under a sun behind the camera: the smooth coat's highlight is in view.
    let rough = with(&plain, |b| {
        b.geometry.materials[2].roughness = 1.0;
        if let Some(sun) = &mut b.environment.sun {
            sun.direction = [0.02, 0.03, 1.0];
        }
    });
    // Each map against the same material without it.
    let cases: Vec<(&str, &Baked, Baked)> = vec![
        (
            "normal map (tilted to -X)",
            &plain,
            with(&plain, |b| {
                b.geometry.textures = vec![flat_texture([38, 128, 218, 255], 4, false)];
                b.geometry.materials[2].normal_texture = slot(0);
            }),
        ),
        (
            "metallic-roughness texture (smooth metal)",
            &metal,
            with(&metal, |b| {
                b.geometry.textures = vec![flat_texture([0, 20, 255, 255], 4, false)];
                b.geometry.materials[2].metallic_roughness_texture = slot(0);
            }),
        ),
        (
            "emissive texture (red)",
            &glowing,
            with(&glowing, |b| {
                b.geometry.textures = vec![flat_texture([255, 0, 0, 255], 4, true)];
                b.geometry.materials[2].emissive_texture = slot(0);
            }),
        ),
        (
            "occlusion texture (dark)",
            &plain,
            with(&plain, |b| {
                b.geometry.textures = vec![flat_texture([30, 0, 0, 255], 4, false)];
                b.geometry.materials[2].occlusion_texture = slot(0);
            }),
        ),
        (
            "clearcoat",
            &rough,
            with(&rough, |b| {
                b.geometry.materials[2].clearcoat = 1.0;
                b.geometry.materials[2].clearcoat_roughness = 0.05;
            }),
        ),
        (
            "base-colour texture on uv set 1, scaled by its transform",
            &plain,
            with(&plain, |b| {
                let mut t = flat_texture([255, 255, 255, 255], 8, true);
                // A black left half: the transform's scale of 2 repeats it twice.
                for (i, px) in t.rgba8.chunks_mut(4).enumerate() {
                    if i % 8 < 4 {
                        px[..3].copy_from_slice(&[0, 0, 0]);
                    }
                }
                b.geometry.textures = vec![with_chain(t)];
                let m = &mut b.geometry.materials[2];
                m.base_color_texture = Some(0);
                m.base_color_tex_coord = 1;
                m.base_color_transform.scale = [2.0, 1.0];
            }),
        ),
    ];
    for (name, without, mapped) in &cases {
        let d = max_diff(&pbr(&gpu, mapped), &pbr(&gpu, without));
        assert!(d >= 8, "{name}: the image changes by only {d}/255");
    }
    // The colour texture through its transform: uv.x 0.125 and 0.625 map to the black halves
    // of two repeats, 0.375 and 0.875 to the white ones.
    let image = pbr(&gpu, &cases[5].2);
    let row = SIZE / 2;
    let at = |u: f32| pixel(&image, (u * SIZE as f32) as u32, row);
    for u in [0.125, 0.625] {
        for w in [0.375, 0.875] {
            assert!(at(u)[1] + 40 < at(w)[1], "{:?} {:?}", at(u), at(w));
        }
    }
}

#[test]
fn light_comes_from_the_environment_exposure_and_tone_map() {
    let Some(gpu) = gpu() else { return };
    let plain = textured();
    let base = pbr(&gpu, &plain);
    let brighter = with(&plain, |b| b.environment.exposure = 2.0);
    let sunless = with(&plain, |b| b.environment.sun = None);
    let tinted = with(&plain, |b| {
        // Irradiance from +Y only (the quad faces +Z: half of that reaches it).
        b.environment.sh[2] = [0.0, 0.0, 1.0];
    });
    for (name, b) in [
        ("exposure 2", &brighter),
        ("no sun", &sunless),
        ("SH", &tinted),
    ] {
        let d = max_diff(&pbr(&gpu, b), &base);
        assert!(d >= 8, "{name}: the image changes by only {d}/255");
    }
    let aces = render(&gpu, &plain, Shading::Pbr, ToneMap::Aces);
    assert!(max_diff(&aces, &base) >= 4, "ACES draws as Neutral does");
}

#[test]
fn basic_shading_draws_the_old_model_and_ignores_the_maps() {
    let Some(gpu) = gpu() else { return };
    let plain = textured();
    let mapped = with(&plain, |b| {
        b.geometry.textures = vec![
            flat_texture([38, 128, 218, 255], 4, false),
            flat_texture([255, 0, 0, 255], 4, true),
        ];
        let m = &mut b.geometry.materials[2];
        m.normal_texture = slot(0);
        m.metallic_roughness_texture = slot(0);
        m.emissive_texture = slot(1);
        m.clearcoat = 1.0;
        b.environment.exposure = 3.0;
    });
    let old = render(&gpu, &plain, Shading::Basic, ToneMap::Neutral);
    assert_eq!(
        render(&gpu, &mapped, Shading::Basic, ToneMap::Neutral),
        old,
        "basic shading ignores maps, clearcoat and the environment"
    );
    assert_eq!(
        render(&gpu, &plain, Shading::Basic, ToneMap::Aces),
        old,
        "basic shading has no tone map"
    );
    // One view-space light plus ambient.
    let want = srgb8(lit([0.5, 0.5, 0.5, 1.0])[..3].try_into().unwrap());
    for (x, y) in [(2, 2), (SIZE / 2, SIZE / 2), (SIZE - 3, SIZE - 3)] {
        let got = pixel(&old, x, y);
        assert!(
            got.iter().zip(want).all(|(a, b)| a.abs_diff(b) <= 1),
            "({x}, {y}): {got:?}, want {want:?}"
        );
    }
    assert!(max_diff(&pbr(&gpu, &plain), &old) >= 8);
}

#[test]
fn colour_textures_use_their_stored_mips_and_alpha_stays_at_level_0() {
    let Some(gpu) = gpu() else { return };
    // Level 0 white, every smaller level black: what shows tells which level was sampled.
    let mut t = flat_texture([255, 255, 255, 255], 16, true);
    for level in &mut t.mips {
        for px in level.chunks_mut(4) {
            px[..3].copy_from_slice(&[0, 0, 0]);
        }
    }
    let textured = |repeat: f32| {
        with(&textured(), |b| {
            b.geometry.textures = vec![t.clone()];
            let m = &mut b.geometry.materials[2];
            m.base_color = [1.0; 4];
            m.base_color_texture = Some(0);
            m.base_color_transform.scale = [repeat, repeat];
        })
    };
    let centre = |image: &[u8]| pixel(image, SIZE / 2, SIZE / 2);
    // 16 texels over 32 pixels: magnified, level 0.
    let near = textured(1.0);
    // 16 × 16 texels over 32 pixels: 8 texels a pixel, level 3.
    let far = textured(16.0);
    let (n, f) = (centre(&pbr(&gpu, &near)), centre(&pbr(&gpu, &far)));
    assert!(n.iter().all(|&c| c > 100), "magnified: {n:?}");
    assert!(f.iter().all(|&c| c < 30), "minified: {f:?}");
    // The basic model colours with `surface_base`, the level-0 texel that decides alpha.
    let basic = render(&gpu, &far, Shading::Basic, ToneMap::Neutral);
    let b = centre(&basic);
    assert!(b.iter().all(|&c| c > 100), "basic: {b:?}");
}

/// [`textured`] with every map at once (normal, metallic-roughness, occlusion, emissive, a
/// base-colour checker on uv set 1 through a rotating transform) and clearcoat: both texture
/// arrays hold layers of different sizes.
pub fn every_map() -> Baked {
    with(&textured(), |b| {
        let mut checker = flat_texture([255, 255, 255, 255], 8, true);
        for (i, px) in checker.rgba8.chunks_mut(4).enumerate() {
            if (i % 8 + i / 8) % 2 == 0 {
                px[..3].copy_from_slice(&[200, 40, 0]);
            }
        }
        let checker = with_chain(checker);
        b.geometry.textures = vec![
            flat_texture([90, 160, 220, 255], 4, false),
            flat_texture([0, 90, 200, 255], 2, false),
            flat_texture([255, 120, 0, 255], 4, true),
            checker,
            flat_texture([140, 0, 0, 255], 16, false),
        ];
        let m = &mut b.geometry.materials[2];
        m.normal_texture = slot(0);
        m.metallic_roughness_texture = slot(1);
        m.emissive_texture = slot(2);
        m.emissive = [0.5, 0.5, 0.5];
        m.base_color_texture = Some(3);
        m.base_color_tex_coord = 1;
        m.base_color_transform.rotation = 0.4;
        m.base_color_transform.offset = [0.1, 0.2];
        m.occlusion_texture = slot(4);
        m.clearcoat = 0.7;
        m.clearcoat_roughness = 0.2;
    })
}

#[test]
fn a_small_texture_in_a_larger_layer_repeats_without_the_rest_of_the_layer() {
    let Some(gpu) = gpu() else { return };
    let untextured = with(&textured(), |b| {
        b.geometry.materials[2].base_color = [1.0; 4];
        // A larger texture in the same (sRGB) array makes the layers 16²: the white 4² one
        // fills a corner of each level.
        b.geometry.textures = vec![
            flat_texture([255, 255, 255, 255], 4, true),
            flat_texture([0, 0, 0, 255], 16, true),
        ];
    });
    let plain = pbr(&gpu, &untextured);
    // About 7 and 30 repeats over the view, off the pixel grid: linear filtering at level 0
    // and the footprints of coarser levels cross the corner's edges at every repeat.
    for repeat in [7.3, 29.7] {
        let tiled = with(&untextured, |b| {
            let m = &mut b.geometry.materials[2];
            m.base_color_texture = Some(0);
            m.base_color_transform.scale = [repeat, repeat];
            m.base_color_transform.offset = [0.37, 0.21];
        });
        let d = max_diff(&pbr(&gpu, &tiled), &plain);
        assert!(
            d <= 2,
            "{repeat} repeats: {d}/255 from the untextured white"
        );
    }
}

#[test]
fn glass_shows_what_it_reflects_not_its_base_colour() {
    let Some(gpu) = gpu() else { return };
    // The grey quad as smooth dielectric glass at opacity 0.35 over the background.
    let glass = |rgb: [f32; 3]| {
        with(&textured(), |b| {
            b.settings.glass_opacity = 0.35;
            let m = &mut b.geometry.materials[2];
            m.base_color = [rgb[0], rgb[1], rgb[2], 1.0];
            m.metallic = 0.0;
            m.roughness = 0.1;
            m.transmission = 1.0;
        })
    };
    let white = pbr(&gpu, &glass([1.0, 1.0, 1.0]));
    let red = pbr(&gpu, &glass([1.0, 0.0, 0.0]));
    // Transmission replaces the diffuse lobe: the base colour does not show (a diffuse white
    // glass drew a veil of its own colour over what lies behind it).
    assert!(max_diff(&white, &red) <= 1, "{}", max_diff(&white, &red));
    // The same surface opaque does show its diffuse colour.
    let opaque = |rgb: [f32; 3]| with(&glass(rgb), |b| b.geometry.materials[2].transmission = 0.0);
    let shown = max_diff(
        &pbr(&gpu, &opaque([1.0, 1.0, 1.0])),
        &pbr(&gpu, &opaque([1.0, 0.0, 0.0])),
    );
    assert!(shown > 40, "{shown}");
    // Reflection reaches the screen at full strength: the glass quad is brighter than the
    // background blended with the glass's reflection scaled down by its opacity would be,
    // and a brighter environment makes it brighter.
    let dim = pbr(
        &gpu,
        &with(&glass([1.0; 3]), |b| {
            b.environment = Environment::uniform(0.05);
        }),
    );
    let centre = |img: &[u8]| pixel(img, SIZE / 2, SIZE / 2);
    assert!(
        centre(&white)[0] > centre(&dim)[0],
        "{:?} vs {:?}",
        centre(&white),
        centre(&dim)
    );
}
