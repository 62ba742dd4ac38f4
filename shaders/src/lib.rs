//! WGSL shared by the recorder, the player and the reference.
#![deny(missing_docs)]
