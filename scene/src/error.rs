//! The error type of scene import.

use std::path::PathBuf;

/// Why a glTF file could not be imported. Every message starts with the file it is about.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SceneError {
    /// The file (or a file it references) could not be read.
    #[error("{}: cannot read: {source}", file.display())]
    Io {
        /// The file that could not be read.
        file: PathBuf,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
    /// The file is not valid glTF 2.0: truncated or corrupt container, invalid JSON, or a
    /// document that breaks the specification (dangling indices, node cycles, …).
    #[error("{}: malformed glTF: {problem}", file.display())]
    Malformed {
        /// The glTF file.
        file: PathBuf,
        /// What is wrong.
        problem: String,
    },
    /// A buffer's data is missing, unreadable or shorter than its declared length.
    #[error("{}: buffer {buffer}: {problem}", file.display())]
    Buffer {
        /// The glTF file.
        file: PathBuf,
        /// Buffer index in the file.
        buffer: usize,
        /// What is wrong.
        problem: String,
    },
    /// An accessor points outside its data or has the wrong type for its use.
    #[error("{}: accessor {accessor} ({usage}): {problem}", file.display())]
    Accessor {
        /// The glTF file.
        file: PathBuf,
        /// Accessor index in the file.
        accessor: usize,
        /// What the accessor is used for (mesh, primitive and attribute, or animation).
        usage: String,
        /// What is wrong.
        problem: String,
    },
    /// A base-colour image could not be loaded or decoded.
    #[error("{}: image {image} {name:?}: {problem}", file.display())]
    Image {
        /// The glTF file.
        file: PathBuf,
        /// Image index in the file.
        image: usize,
        /// Image name or URI (may be empty).
        name: String,
        /// What is wrong.
        problem: String,
    },
    /// A vertex position is NaN or infinite.
    #[error(
        "{}: {mesh} primitive {primitive}: accessor {accessor} (POSITION) has a non-finite \
         position at vertex {vertex}",
        file.display()
    )]
    NonFinitePosition {
        /// The glTF file.
        file: PathBuf,
        /// The mesh, as `mesh <index> "<name>"`.
        mesh: String,
        /// Primitive index within the mesh.
        primitive: usize,
        /// Index of the POSITION accessor.
        accessor: usize,
        /// First offending vertex.
        vertex: usize,
    },
    /// A node of the scene is skinned; trisort animates rigid parts only.
    #[error(
        "{}: {node} uses skin {skin}: skinned meshes are not supported (rigid node animation only)",
        file.display()
    )]
    Skinned {
        /// The glTF file.
        file: PathBuf,
        /// The node, as `node <index> "<name>"`.
        node: String,
        /// Skin index.
        skin: usize,
    },
    /// A mesh of the scene has morph targets; trisort animates rigid parts only.
    #[error(
        "{}: {mesh} primitive {primitive} has morph targets: not supported (rigid node \
         animation only)",
        file.display()
    )]
    MorphTargets {
        /// The glTF file.
        file: PathBuf,
        /// The mesh, as `mesh <index> "<name>"`.
        mesh: String,
        /// Primitive index within the mesh.
        primitive: usize,
    },
    /// The file requires (`extensionsRequired`) a glTF extension trisort does not implement.
    #[error("{}: unsupported extension {name}: {hint}", file.display())]
    UnsupportedExtension {
        /// The glTF file.
        file: PathBuf,
        /// The extension's name.
        name: String,
        /// What to do about it.
        hint: String,
    },
    /// The file is valid but uses something trisort cannot import.
    #[error("{}: unsupported: {problem}", file.display())]
    Unsupported {
        /// The glTF file.
        file: PathBuf,
        /// What is unsupported.
        problem: String,
    },
}
