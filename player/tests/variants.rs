//! Material variants at play time (`KHR_materials_variants`): `set_variant` draws exactly what a file
//! whose materials are the variant's draws, switches back, and refuses (leaving the table as it
//! was) a variant that is unknown or that changes what decides visibility.

use trisort_format::{AlphaMode, Baked, Material, MaterialVariant, VariantError};
use trisort_player::{HeadlessConfig, HeadlessRenderer, Mode, PlayerError};

use crate::support::*;

/// [`quads`] with a variant "Warm" that recolours red (same alpha) and turns the opaque blue
/// yellow, and a variant "Veiled" that makes the blue quad blended.
fn with_variants() -> Baked {
    let mut b = quads();
    let g = &mut b.geometry;
    let m = |name: &str, base_color: [f32; 4], alpha_mode| Material {
        name: name.into(),
        base_color,
        alpha_mode,
        ..Material::default()
    };
    g.materials[2].name = "blue".into();
    g.materials
        .push(m("orange", [1.0, 0.5, 0.0, 0.5], AlphaMode::Blend)); // 3
    g.materials
        .push(m("yellow", [1.0, 1.0, 0.0, 1.0], AlphaMode::Opaque)); // 4
    g.materials
        .push(m("blue veil", [0.0, 0.0, 1.0, 1.0], AlphaMode::Blend)); // 5
    g.variants = vec![
        MaterialVariant {
            name: "Warm".into(),
            materials: vec![3, 1, 4, 3, 4, 5],
        },
        MaterialVariant {
            name: "Veiled".into(),
            materials: vec![0, 1, 5, 3, 4, 5],
        },
    ];
    b.check_structure().unwrap();
    b
}

fn frames(r: &HeadlessRenderer) -> Vec<Vec<u8>> {
    (0..r.player().frame_count())
        .map(|f| r.render(f).unwrap().rgba8)
        .collect()
}

#[test]
fn a_variant_draws_what_a_file_with_its_materials_draws_and_switches_back() {
    let Some(gpu) = trisort_testkit::gpu() else {
        return;
    };
    let baked = with_variants();
    for mode in [Mode::Blend, Mode::Saturate] {
        let config = HeadlessConfig {
            mode,
            // `lit` is the basic model's colour.
            shading: trisort_gpu::Shading::Basic,
            ..HeadlessConfig::recorded(&baked)
        };
        let r = HeadlessRenderer::new(&gpu, &baked, &config).unwrap();
        assert_eq!(r.player().variant_names(), ["Warm", "Veiled"]);
        let default = frames(&r);
        r.set_variant(Some("Warm")).unwrap();
        let warm = frames(&r);
        let mut recoloured = baked.clone();
        recoloured.geometry.materials = baked.geometry.variant_materials(Some("Warm")).unwrap();
        let expected = frames(&HeadlessRenderer::new(&gpu, &recoloured, &config).unwrap());
        assert_eq!(warm, expected, "{mode}");
        assert_ne!(warm, default, "{mode}");
        // Frame 1's background quad is yellow now (red and green blend over it).
        let (x, y) = (SIZE - 2, SIZE - 2);
        let yellow = lit([1.0, 1.0, 0.0, 1.0]);
        let want = [yellow[0], yellow[1], yellow[2]];
        assert_pixel(&warm[1], (x, y), want, 1, "yellow behind");

        // Refused: the table stays as it was.
        let err = r.set_variant(Some("Veiled")).unwrap_err();
        let PlayerError::Variant(VariantError::ChangesVisibility { slot, field, .. }) = &err else {
            panic!("{err:?}");
        };
        assert_eq!((*slot, *field), (2, "alpha mode"));
        let text = err.to_string();
        assert!(
            text.contains("\"Veiled\"") && text.contains("\"blue veil\""),
            "{text}"
        );
        let err = r.set_variant(Some("Cold")).unwrap_err();
        assert!(
            err.to_string()
                .contains("the file's variants are \"Warm\", \"Veiled\""),
            "{err}"
        );
        assert_eq!(
            frames(&r),
            warm,
            "{mode}: a refused variant changed the table"
        );

        r.set_variant(None).unwrap();
        assert_eq!(frames(&r), default, "{mode}");
    }
}
