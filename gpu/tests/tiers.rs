//! The data-texture tier's size check ([`Bindings::check_fits`]): what fits WebGL2's minimum
//! texture size and what is refused with the reason, without a device.

use trisort_format::{Geometry, Node};
use trisort_gpu::scene_gpu::DATA_WIDTH;
use trisort_gpu::Bindings;

fn scene_with_nodes(n: usize) -> Geometry {
    let node = Node {
        name: String::new(),
        parent: None,
        rest: glam::DMat4::IDENTITY.to_cols_array(),
    };
    Geometry {
        nodes: vec![node; n],
        ..Geometry::default()
    }
}

#[test]
fn the_texture_tier_refuses_more_node_rows_than_the_device_has() {
    let limits = wgpu::Limits::downlevel_webgl2_defaults();
    let max = limits.max_texture_dimension_2d as usize;
    // 4 texels a node: exactly `max` rows of matrices fit, one more frame does not.
    let nodes = 16;
    let frames_that_fit = max * DATA_WIDTH as usize / (nodes * 4);
    let g = scene_with_nodes(nodes);
    assert_eq!(
        Bindings::Textures.check_fits(&limits, &g, frames_that_fit),
        Ok(())
    );
    let err = Bindings::Textures
        .check_fits(&limits, &g, frames_that_fit + 1)
        .unwrap_err();
    assert!(
        err.contains(&format!("{} rows", max + 1)) && err.contains(&format!("allows {max}")),
        "{err}"
    );
    // The storage tier has no such limit.
    assert_eq!(
        Bindings::Storage.check_fits(&limits, &g, frames_that_fit * 10),
        Ok(())
    );
}

#[test]
fn the_texture_tier_needs_data_width_texels_a_row() {
    let mut limits = wgpu::Limits::downlevel_webgl2_defaults();
    limits.max_texture_dimension_2d = DATA_WIDTH - 1;
    let err = Bindings::Textures
        .check_fits(&limits, &scene_with_nodes(1), 1)
        .unwrap_err();
    assert!(err.contains(&DATA_WIDTH.to_string()), "{err}");
}
