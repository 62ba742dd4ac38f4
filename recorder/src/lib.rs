//! The recorder: GPU depth peeling per frame and per sample into occlusion graphs.
#![deny(missing_docs)]
