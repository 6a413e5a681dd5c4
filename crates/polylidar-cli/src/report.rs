//! The `--json` report and the human summary.
//!
//! The JSON shape is a stable interface for scripts (documented in `docs/cli-json.md`):
//! `{"input": {...}, "counts": {...}, "timings_ms": {"<stage>": ms, ..., "total": ms}}`.

use std::time::Duration;

use polylidar::{Counts, Timings};
use seg_metrics::Evaluation;
use serde_json::{Map, Value, json};

use crate::input::Input;

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

/// Median stage timings in milliseconds as a JSON object, `total` last.
pub fn timings_json(runs: &[Timings]) -> Value {
    let timings: Map<String, Value> = median_timings(runs)
        .into_iter()
        .map(|(k, v)| (k, json!((v * 1e3).round() / 1e3)))
        .collect();
    Value::Object(timings)
}

/// The scores of a segmentation against ground truth.
pub fn metrics_json(e: &Evaluation) -> Value {
    json!({
        "truth_planes": e.truth_planes,
        "predicted_planes": e.predicted_planes,
        "f": e.f,
        "k": e.k,
        "rmse": e.rmse,
        "rmse_correct": e.rmse_correct,
        "correct": e.correct,
        "over_segmented": e.over_segmented,
        "under_segmented": e.under_segmented,
        "missed": e.missed,
        "spurious": e.spurious,
    })
}

fn input_json(source: &str, input: &Input, runs: usize) -> Value {
    let mut value =
        json!({ "source": source, "kind": input.kind(), "points": input.len(), "runs": runs });
    if let Some((rows, cols)) = input.grid() {
        value["rows"] = json!(rows);
        value["cols"] = json!(cols);
    }
    value
}

/// The one-line JSON object printed by `--json`; `metrics` only for inputs with ground
/// truth (the scene demo).
pub fn json(
    source: &str,
    input: &Input,
    counts: &Counts,
    runs: &[Timings],
    score: Option<&Evaluation>,
) -> String {
    let mut value = json!({
        "input": input_json(source, input, runs.len()),
        "counts": counts,
        "timings_ms": timings_json(runs),
    });
    if let Some(e) = score {
        value["metrics"] = metrics_json(e);
    }
    value.to_string()
}

/// A short human-readable summary for stderr.
pub fn summary(
    source: &str,
    input: &Input,
    counts: &Counts,
    runs: &[Timings],
    score: Option<&Evaluation>,
) -> String {
    let timings: Vec<String> = median_timings(runs)
        .into_iter()
        .map(|(k, v)| format!("{k} {v:.2} ms"))
        .collect();
    let planes = if counts.dominant_normals > 0 {
        format!("{} dominant normals, ", counts.dominant_normals)
    } else {
        String::new()
    };
    let mut text = format!(
        "{source}: {} points ({}) → {} triangles, {} kept, {planes}{} regions ({} too small), {} polygons, {} holes ({} dropped)",
        input.len(),
        input.kind(),
        counts.triangles,
        counts.triangles_kept,
        counts.regions,
        counts.regions_too_small,
        counts.polygons,
        counts.holes,
        counts.holes_too_small,
    );
    if counts.postprocessed_polygons + counts.postprocess_dropped > 0 {
        text.push_str(&format!(
            ", {} after post-processing ({} dropped)",
            counts.postprocessed_polygons, counts.postprocess_dropped
        ));
    }
    if let Some(e) = score {
        text.push_str(&format!(
            "\n  against ground truth: f {:.1} % of {} planes found, k {:.1} % of points, {} over-, {} under-segmented, {} missed, {} spurious",
            e.f, e.truth_planes, e.k, e.over_segmented, e.under_segmented, e.missed, e.spurious
        ));
    }
    text.push_str(&format!("\n  {}", timings.join(", ")));
    text
}
