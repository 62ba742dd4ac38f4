//! trisort-intersect's integration tests, one binary with a module per subject.

mod cases;
mod common;
mod groups;
mod scenes;
