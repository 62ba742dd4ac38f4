//! The merger's integration tests, one binary: against the independent validator (`merge`)
//! and on long synthetic paths (`long`).

mod long;
mod merge;
