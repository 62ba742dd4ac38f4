//! The merger's integration tests, one binary: against the independent validator (`merge`),
//! on long synthetic paths (`long`), on long chains (`robustness`) and on frame ranges
//! recorded apart (`shards`).

mod long;
mod merge;
mod robustness;
mod shards;

use trisort_format::{Baked, Environment, Recording};
use trisort_merger::{MergeError, MergeOptions};

/// [`trisort_merger::merge`], lit by a uniform environment: these tests look at the draws,
/// which the light does not change.
fn merge(recordings: &[Recording], opts: &MergeOptions) -> Result<Baked, MergeError> {
    trisort_merger::merge(recordings, opts).map(|m| m.lit(Environment::uniform(1.0)))
}
