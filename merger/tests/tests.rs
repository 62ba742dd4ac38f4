//! The merger's integration tests, one binary: against the independent validator (`merge`),
//! on long synthetic paths (`long`), on long chains (`robustness`) and on frame ranges
//! recorded apart (`shards`).

mod long;
mod merge;
mod robustness;
mod shards;
