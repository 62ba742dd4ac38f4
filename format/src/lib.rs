//! trisort's shared data model and file types.
//!
//! Every pipeline stage speaks these types: the scene importer and the procedural car fill a
//! [`Geometry`], the `paths` crate produces one [`FrameState`] per frame, the recorder writes a
//! [`Recording`], the merger turns it into a [`Baked`] file, and the player and the validator
//! read that file. This crate has no GPU, glTF or graph dependencies, so the player and the
//! validator can depend on it alone.
//!
//! Triangle ids: a *scene triangle id* is the index of a triangle in the full scene's
//! [`Geometry::triangles`]. Recordings speak scene ids. A Baked file stores only the triangles
//! of G (the triangles visible at least once), in ascending scene id; a *G-local id* is an index
//! into that list, and [`Baked::scene_ids`] maps it back.
#![deny(missing_docs)]

pub mod baked;
pub mod blocks;
pub mod camera;
pub mod clip;
pub mod container;
pub mod environment;
pub mod geometry;
pub mod gpu_layout;
pub mod legacy;
pub mod options;
pub mod order;
pub mod presorted;
pub mod recording;
pub mod structure;

pub use baked::{Baked, DrawIndexedIndirectArgs, FrameWindow, MatrixCell, MergeInfo, MergeStats};
pub use blocks::{BlockFormat, TextureBlocks};
pub use camera::{world_transforms, Camera, FrameState, NodePose};
pub use clip::Clip;
#[cfg(not(target_arch = "wasm32"))]
pub use container::write_file_atomic;
pub use container::{read_file, FileKind, FormatError, Stored, FORMAT_VERSION};
pub use environment::{Environment, Sun};
pub use geometry::{
    AlphaMode, Geometry, Material, MaterialVariant, Node, Texture, TextureSlot, TextureTransform,
    VariantError, Vertex,
};
pub use options::{
    Bridge, Choice, Choosable, DeviceBackend, DeviceLimits, Layout, Mode, OptionValue,
    ParseOptionError, Seeding, Shading, Strategy, ToneMap,
};
pub use presorted::{
    OutsideError, PlaneTest, Polyhedron, PresortStats, Presorted, PresortedCopy, Segment,
};
pub use recording::{
    DepthAt, DeviceInfo, Edge, FrameRecord, Phase, ProfileName, RasterProfile, RecordSettings,
    Recording, Robust, SettingsError,
};
pub use structure::{Part, StructureError};

/// The version of the trisort tool that wrote a file (stored in every file).
pub const TOOL_VERSION: &str = env!("CARGO_PKG_VERSION");

/// A 32-byte content hash (BLAKE3), used for scene, path and recording identities.
pub type Hash = [u8; 32];

/// Hashes bytes with BLAKE3.
pub fn hash_bytes(bytes: &[u8]) -> Hash {
    *blake3::hash(bytes).as_bytes()
}

/// Formats a hash as lowercase hex (for JSON output and file names).
pub fn hash_hex(hash: &Hash) -> String {
    hash.iter().map(|b| format!("{b:02x}")).collect()
}
