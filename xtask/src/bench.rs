//! The run context shared by every table: options, machine, fixtures and thread pools.

use std::path::PathBuf;

use crate::data::Fixtures;
use crate::error::{Result, msg};
use crate::machine::Machine;
use crate::timing::Runs;

/// Everything a table needs to know about the run.
#[derive(Debug)]
pub struct Ctx {
    /// `--quick`: fewer runs and sizes.
    pub quick: bool,
    /// Output folder (`docs/bench` by default).
    pub out: PathBuf,
    /// The shared fixtures.
    pub fixtures: Fixtures,
    /// Thread counts for the speed-up chart, ascending.
    pub threads: Vec<usize>,
    /// The machine.
    pub machine: Machine,
}

impl Ctx {
    /// The thread count of the "all cores" rows: the largest of `threads` not above the
    /// core count (at least 1).
    pub fn parallel_threads(&self) -> usize {
        self.threads
            .iter()
            .copied()
            .filter(|&t| t <= self.machine.cores)
            .max()
            .unwrap_or(1)
            .max(1)
    }

    /// `full` runs normally, `quick` with `--quick` (both after `warmup` warm-up runs, one
    /// with `--quick`).
    pub fn runs(&self, warmup: usize, full: usize, quick: usize) -> Runs {
        if self.quick {
            Runs::new(warmup.min(1), quick)
        } else {
            Runs::new(warmup, full)
        }
    }

    /// Runs `f` on a rayon pool of `threads` threads.
    ///
    /// # Errors
    /// The pool cannot start, or `f` fails.
    pub fn on_threads<T: Send>(
        &self,
        threads: usize,
        f: impl FnOnce() -> Result<T> + Send,
    ) -> Result<T> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .map_err(|e| msg(format!("starting {threads} threads: {e}")))?;
        pool.install(f)
    }
}

/// The default thread counts: 1 up to the core count (powers of two beyond 4 cores), and
/// at least 1–4 so that the speed-up chart shows what more threads than cores do.
pub fn default_threads(cores: usize) -> Vec<usize> {
    let mut out: Vec<usize> = (1..=4).collect();
    let mut t = 8;
    while t < cores {
        out.push(t);
        t *= 2;
    }
    if cores > 4 {
        out.push(cores);
    }
    out.sort_unstable();
    out.dedup();
    out
}

/// Parses "1,2,4" into sorted distinct positive counts.
///
/// # Errors
/// Empty list, a zero or a non-number.
pub fn parse_threads(text: &str) -> Result<Vec<usize>> {
    let mut out = Vec::new();
    for part in text.split(',').map(str::trim).filter(|p| !p.is_empty()) {
        let t: usize = part
            .parse()
            .map_err(|_| msg(format!("--threads: `{part}` is not a thread count")))?;
        if t == 0 {
            return Err(msg("--threads: counts start at 1"));
        }
        out.push(t);
    }
    if out.is_empty() {
        return Err(msg("--threads: give at least one count, e.g. 1,2,4"));
    }
    out.sort_unstable();
    out.dedup();
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thread_lists() {
        assert_eq!(default_threads(2), vec![1, 2, 3, 4]);
        assert_eq!(default_threads(16), vec![1, 2, 3, 4, 8, 16]);
        assert_eq!(default_threads(12), vec![1, 2, 3, 4, 8, 12]);
        assert_eq!(parse_threads("4, 1,2,2").unwrap(), vec![1, 2, 4]);
        assert!(parse_threads("0").is_err());
        assert!(parse_threads("a").is_err());
        assert!(parse_threads("").is_err());
    }
}
