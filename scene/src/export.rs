//! glTF export of a scene.
