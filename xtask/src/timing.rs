//! Wall-clock measurement: warm-up runs, then timed runs summarised by their median,
//! minimum and maximum.

use std::hint::black_box;
use std::time::Instant;

use crate::error::Result;

/// How many times to run something.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Runs {
    /// Untimed runs first (caches, page faults, thread pools, lazy initialisation).
    pub warmup: usize,
    /// Timed runs.
    pub timed: usize,
}

impl Runs {
    /// `warmup` untimed and `timed` timed runs (at least one).
    pub fn new(warmup: usize, timed: usize) -> Self {
        Self {
            warmup,
            timed: timed.max(1),
        }
    }

    /// "median of N runs after W warm-up runs".
    pub fn describe(&self) -> String {
        format!(
            "median of {} timed runs after {} warm-up run{}",
            self.timed,
            self.warmup,
            if self.warmup == 1 { "" } else { "s" }
        )
    }
}

/// Summary of timed samples, in milliseconds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stats {
    /// Number of samples.
    pub runs: usize,
    /// Median (mean of the two middle samples for an even count).
    pub median: f64,
    /// Fastest sample.
    pub min: f64,
    /// Slowest sample.
    pub max: f64,
}

impl Stats {
    /// Summarises samples in milliseconds; `None` when there are none.
    pub fn from_samples(mut samples: Vec<f64>) -> Option<Self> {
        if samples.is_empty() {
            return None;
        }
        samples.sort_by(f64::total_cmp);
        let n = samples.len();
        let median = if n % 2 == 1 {
            samples[n / 2]
        } else {
            0.5 * (samples[n / 2 - 1] + samples[n / 2])
        };
        Some(Self {
            runs: n,
            median,
            min: samples[0],
            max: samples[n - 1],
        })
    }

    /// "12.3 (11.9–13.0)": median with the range in brackets.
    pub fn cell(&self) -> String {
        format!("{} ({}–{})", ms(self.median), ms(self.min), ms(self.max))
    }
}

/// Times `f`: `runs.warmup` untimed calls, then `runs.timed` timed ones.
///
/// # Errors
/// The first error `f` returns.
pub fn measure<T>(runs: Runs, mut f: impl FnMut() -> Result<T>) -> Result<Stats> {
    for _ in 0..runs.warmup {
        black_box(f()?);
    }
    let mut samples = Vec::with_capacity(runs.timed);
    for _ in 0..runs.timed {
        let start = Instant::now();
        let out = f()?;
        samples.push(start.elapsed().as_secs_f64() * 1e3);
        black_box(out);
    }
    Stats::from_samples(samples).ok_or_else(|| crate::error::msg("no timed runs"))
}

/// Milliseconds with about three significant digits.
pub fn ms(value: f64) -> String {
    let a = value.abs();
    if !value.is_finite() {
        "–".to_owned()
    } else if a >= 100.0 {
        format!("{value:.0}")
    } else if a >= 10.0 {
        format!("{value:.1}")
    } else if a >= 1.0 {
        format!("{value:.2}")
    } else {
        format!("{value:.3}")
    }
}

/// Median of per-run values (for example a pipeline stage's own timing), `None` if empty.
pub fn median_of(values: Vec<f64>) -> Option<f64> {
    Stats::from_samples(values).map(|s| s.median)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stats_of_odd_and_even_counts() {
        let s = Stats::from_samples(vec![3.0, 1.0, 2.0]).unwrap();
        assert_eq!((s.median, s.min, s.max, s.runs), (2.0, 1.0, 3.0, 3));
        let s = Stats::from_samples(vec![4.0, 1.0, 2.0, 3.0]).unwrap();
        assert_eq!(s.median, 2.5);
        assert!(Stats::from_samples(Vec::new()).is_none());
    }

    #[test]
    fn milliseconds_keep_three_digits() {
        assert_eq!(ms(123.456), "123");
        assert_eq!(ms(12.345), "12.3");
        assert_eq!(ms(1.2345), "1.23");
        assert_eq!(ms(0.12345), "0.123");
    }
}
