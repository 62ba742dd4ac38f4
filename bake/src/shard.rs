//! Shards: a path cut into balanced frame ranges, one per machine or array task, and the
//! shard a batch scheduler's task is (`--shard I/N` or `auto`).

use crate::BakeError;

/// `bail!`, with the pipeline's error.
macro_rules! bail {
    ($($t:tt)*) => { return Err(BakeError::Shard(format!($($t)*))) };
}

/// `--shard`: a shard index and count, or `auto` (from the batch scheduler's environment).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShardArg {
    /// Shard `.0` of `.1`.
    Fixed(u32, u32),
    /// From `SLURM_ARRAY_TASK_*` or `JOB_COMPLETION_INDEX` + `TRISORT_SHARDS`.
    Auto,
}

/// Parses `I/N` (0 ≤ I < N) or `auto`.
pub fn parse_shard(s: &str) -> Result<ShardArg, BakeError> {
    if s == "auto" {
        return Ok(ShardArg::Auto);
    }
    let bad = || {
        BakeError::Shard(format!(
            "bad shard {s:?}: expected I/N with 0 <= I < N, or auto"
        ))
    };
    let (i, n) = s.split_once('/').ok_or_else(bad)?;
    let (i, n): (u32, u32) = (i.parse().map_err(|_| bad())?, n.parse().map_err(|_| bad())?);
    if n == 0 || i >= n {
        return Err(bad());
    }
    Ok(ShardArg::Fixed(i, n))
}

impl ShardArg {
    /// The shard index and count; `Auto` reads them with `var` (the environment), naming the
    /// variables when they are missing or malformed.
    pub fn resolve(self, var: &dyn Fn(&str) -> Option<String>) -> Result<(u32, u32), BakeError> {
        if let ShardArg::Fixed(i, n) = self {
            return Ok((i, n));
        }
        let shard = |text: String| BakeError::Shard(text);
        let num = |k: &str| -> Result<Option<u32>, BakeError> {
            var(k)
                .map(|v| {
                    v.trim()
                        .parse::<u32>()
                        .map_err(|e| shard(format!("--shard auto: {k}={v:?} is not a number: {e}")))
                })
                .transpose()
        };
        let (i, n, from) = if let Some(id) = num("SLURM_ARRAY_TASK_ID")? {
            let min = num("SLURM_ARRAY_TASK_MIN")?.unwrap_or(0);
            let n = num("SLURM_ARRAY_TASK_COUNT")?.ok_or_else(|| {
                shard(
                    "--shard auto: SLURM_ARRAY_TASK_ID is set but SLURM_ARRAY_TASK_COUNT is not"
                        .into(),
                )
            })?;
            let i = id.checked_sub(min).ok_or_else(|| {
                shard(format!(
                    "--shard auto: SLURM_ARRAY_TASK_ID {id} is below SLURM_ARRAY_TASK_MIN {min}"
                ))
            })?;
            (i, n, "SLURM_ARRAY_TASK_ID/SLURM_ARRAY_TASK_COUNT")
        } else if let Some(i) = num("JOB_COMPLETION_INDEX")? {
            let n = num("TRISORT_SHARDS")?.ok_or_else(|| {
                shard(
                    "--shard auto: JOB_COMPLETION_INDEX is set but TRISORT_SHARDS (the Job's \
                     completions) is not"
                        .into(),
                )
            })?;
            (i, n, "JOB_COMPLETION_INDEX/TRISORT_SHARDS")
        } else {
            bail!(
                "--shard auto: neither SLURM_ARRAY_TASK_ID (a Slurm job array) nor \
                 JOB_COMPLETION_INDEX (a Kubernetes Indexed Job) is set; give --shard I/N"
            );
        };
        if i >= n {
            bail!("--shard auto: shard {i} of {n} ({from}) is out of range");
        }
        Ok((i, n))
    }
}

/// Shard `i` of `n` of a path of `frames` frames: frames `i·frames/n .. (i+1)·frames/n`, so
/// the `n` ranges cover the path in order and their lengths differ by at most one. An error
/// when a shard would be empty (more shards than frames).
pub fn shard_range(i: u32, n: u32, frames: u32) -> Result<std::ops::Range<u32>, BakeError> {
    if n > frames {
        bail!("{n} shards of a {frames}-frame path: some would be empty; use at most {frames}");
    }
    let at = |k: u32| (k as u64 * frames as u64 / n as u64) as u32;
    Ok(at(i)..at(i + 1))
}
