//! The merger's integration tests, one binary: against the independent validator (`merge`),
//! on long synthetic paths (`long`) and on long chains (`robustness`).

mod long;
mod merge;
mod robustness;
