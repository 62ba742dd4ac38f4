//! The merger: per-frame occlusion graphs into one sorted triangle list and a sliding window.
#![deny(missing_docs)]
