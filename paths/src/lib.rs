//! Camera and animation paths: the frame timeline (see the crate README section in the project README).
#![deny(missing_docs)]
