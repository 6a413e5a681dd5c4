//! The `--json` report and the human summary.
//!
//! The JSON shape is a stable interface for scripts (documented in `docs/cli-json.md`):
//! `{"input": {...}, "counts": {...}, "timings_ms": {"<stage>": ms, ..., "total": ms}}`.

use std::time::Duration;

use polylidar::{Counts, Timings};
use serde_json::{Map, Value, json};

use crate::run::Input;

/// Median per stage over the runs, in the first run's stage order, then the median total.
fn median_timings(runs: &[Timings]) -> Vec<(String, f64)> {
    let median = |mut v: Vec<f64>| -> f64 {
        v.sort_by(f64::total_cmp);
        let n = v.len();
        if n == 0 {
            0.0
        } else if n % 2 == 1 {
            v[n / 2]
        } else {
            0.5 * (v[n / 2 - 1] + v[n / 2])
        }
    };
    let ms = |d: Duration| d.as_secs_f64() * 1e3;
    let mut out: Vec<(String, f64)> = runs
        .first()
        .map(|t| t.stages())
        .unwrap_or(&[])
        .iter()
        .map(|(stage, _)| {
            let values = runs.iter().filter_map(|t| t.get(stage)).map(ms).collect();
            ((*stage).to_owned(), median(values))
        })
        .collect();
    out.push((
        "total".to_owned(),
        median(runs.iter().map(|t| ms(t.total())).collect()),
    ));
    out
}

/// The one-line JSON object printed by `--json`.
pub fn json(source: &str, input: &Input, counts: &Counts, runs: &[Timings]) -> String {
    let timings: Map<String, Value> = median_timings(runs)
        .into_iter()
        .map(|(k, v)| (k, json!((v * 1e3).round() / 1e3)))
        .collect();
    json!({
        "input": { "source": source, "kind": input.kind(), "points": input.len(), "runs": runs.len() },
        "counts": counts,
        "timings_ms": timings,
    })
    .to_string()
}

/// A short human-readable summary for stderr.
pub fn summary(source: &str, input: &Input, counts: &Counts, runs: &[Timings]) -> String {
    let timings: Vec<String> = median_timings(runs)
        .into_iter()
        .map(|(k, v)| format!("{k} {v:.2} ms"))
        .collect();
    format!(
        "{source}: {} points ({}) → {} triangles, {} kept, {} regions ({} too small), {} polygons, {} holes ({} dropped)\n  {}",
        input.len(),
        input.kind(),
        counts.triangles,
        counts.triangles_kept,
        counts.regions,
        counts.regions_too_small,
        counts.polygons,
        counts.holes,
        counts.holes_too_small,
        timings.join(", ")
    )
}
