//! The `--json` report and the human summary.
//!
//! The JSON shape is a stable interface for scripts (documented in `docs/cli-json.md`):
//! `{"input": {...}, "counts": {...}, "timings_ms": {"<stage>": ms, ..., "total": ms}}`.

use std::time::Duration;

use polylidar::explain::Explanation;
use polylidar::{Counts, Timings};
use seg_metrics::Evaluation;
use serde_json::{Map, Value, json};

use crate::input::Input;
use crate::params::{Chosen, UnitSource, length, significant};

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

/// Everything a report of one `extract` shows.
pub struct Run<'a> {
    /// The input path or the demo's name.
    pub source: &'a str,
    /// The data.
    pub input: &'a Input,
    /// The parameters and how they were chosen.
    pub chosen: &'a Chosen,
    /// The first run's counts.
    pub counts: &'a Counts,
    /// Every run's timings.
    pub runs: &'a [Timings],
    /// Scores against ground truth (the scene demo).
    pub score: Option<&'a Evaluation>,
    /// Why the result is empty, if it is.
    pub explanation: &'a Explanation,
}

fn parameters_json(run: &Run<'_>) -> Value {
    let c = run.chosen;
    let config = &c.config;
    let source = match c.unit_source {
        UnitSource::Flag => "flag",
        UnitSource::Header => "header",
        UnitSource::Assumed => "assumed",
    };
    let mut value = json!({
        "preset": c.preset,
        "unit": c.unit.symbol(),
        "unit_source": source,
        "spacing": c.spacing,
        "alpha": config.alpha,
        "lmax": config.lmax,
        "min_triangles": config.min_triangles,
        "min_hole_vertices": config.min_hole_vertices,
        "norm_thresh": config.norm_thresh,
        "z_thresh": config.z_thresh,
        "derived": c.notes,
    });
    if run.counts.laplacian_iterations > 0 || config.laplacian.is_some() {
        value["laplacian_iterations"] = json!(run.counts.laplacian_iterations);
    }
    value
}

fn explanation_json(e: &Explanation) -> Value {
    let findings: Vec<Value> = e
        .findings
        .iter()
        .map(|f| {
            json!({
                "stage": f.stage,
                "parameter": f.parameter,
                "dropped": f.dropped,
                "of": f.of,
                "current": f.current,
                "suggested": f.suggested,
                "hint": f.hint,
            })
        })
        .collect();
    json!({ "empty": e.empty, "findings": findings })
}

/// The one-line JSON object printed by `--json`; `metrics` only for inputs with ground
/// truth (the scene demo).
pub fn json(run: &Run<'_>) -> String {
    let mut value = json!({
        "input": input_json(run.source, run.input, run.runs.len()),
        "parameters": parameters_json(run),
        "counts": run.counts,
        "explanation": explanation_json(run.explanation),
        "timings_ms": timings_json(run.runs),
    });
    if let Some(e) = run.score {
        value["metrics"] = metrics_json(e);
    }
    value.to_string()
}

/// `n` and the noun, singular for one: `1 hole`, `3 holes`.
pub fn count(n: usize, one: &str, many: &str) -> String {
    format!("{n} {}", if n == 1 { one } else { many })
}

/// A short human-readable summary for stderr.
pub fn summary(run: &Run<'_>) -> String {
    let counts = run.counts;
    let timings: Vec<String> = median_timings(run.runs)
        .into_iter()
        .map(|(k, v)| format!("{k} {v:.2} ms"))
        .collect();
    let planes = if counts.dominant_normals > 0 {
        format!(
            "{}, ",
            count(
                counts.dominant_normals,
                "dominant normal",
                "dominant normals"
            )
        )
    } else {
        String::new()
    };
    let mut text = format!(
        "{}: {} ({}) → {}, {} kept, {planes}{} ({} too small), {}, {} ({} dropped)",
        run.source,
        count(run.input.len(), "point", "points"),
        run.input.kind(),
        count(counts.triangles, "triangle", "triangles"),
        counts.triangles_kept,
        count(counts.regions, "region", "regions"),
        counts.regions_too_small,
        count(counts.polygons, "polygon", "polygons"),
        count(counts.holes, "hole", "holes"),
        counts.holes_too_small,
    );
    if counts.postprocessed_polygons + counts.postprocess_dropped > 0 {
        text.push_str(&format!(
            ", {} after post-processing ({} dropped)",
            counts.postprocessed_polygons, counts.postprocess_dropped
        ));
    }
    text.push_str(&format!("\n  parameters: {}", parameters_line(run)));
    if let Some(e) = run.score {
        text.push_str(&format!(
            "\n  against ground truth: f {:.1} % of {} found, k {:.1} % of points, {} over-, {} under-segmented, {} missed, {} spurious",
            e.f,
            count(e.truth_planes, "plane", "planes"),
            e.k,
            e.over_segmented,
            e.under_segmented,
            e.missed,
            e.spurious
        ));
    }
    text.push_str(&format!("\n  {}", timings.join(", ")));
    text
}

/// `preset rooftop (metres → ft, from the LAS header); lmax 4.07 ft (from spacing …)`.
fn parameters_line(run: &Run<'_>) -> String {
    let c = run.chosen;
    let unit = match c.unit_source {
        UnitSource::Flag => format!("{} (--units)", c.unit),
        UnitSource::Header => format!("{} (LAS header)", c.unit),
        UnitSource::Assumed if matches!(run.input, Input::Cloud(_)) => {
            "m (assumed; --units ft if the data is in feet)".to_owned()
        }
        UnitSource::Assumed => "m (assumed)".to_owned(),
    };
    let mut parts = vec![match &c.preset {
        Some(name) => format!("preset {name}, lengths in {unit}"),
        None => format!("no preset, lengths in {unit}"),
    }];
    parts.extend(c.notes.iter().cloned());
    let config = &c.config;
    let is_3d = matches!(run.input, Input::Organized(_) | Input::Mesh { .. });
    let mut set = Vec::new();
    if !is_3d && config.alpha > 0.0 && !c.notes.iter().any(|n| n.starts_with("alpha")) {
        set.push(format!("alpha {}", length(config.alpha, c.unit)));
    }
    if config.lmax > 0.0 && !c.notes.iter().any(|n| n.starts_with("lmax")) {
        set.push(format!("lmax {}", length(config.lmax, c.unit)));
    }
    set.push(format!("min_triangles {}", config.min_triangles));
    if !matches!(run.input, Input::Points2d(_)) {
        set.push(format!("norm_thresh {}", config.norm_thresh));
    }
    if is_3d && config.z_thresh > 0.0 {
        set.push(format!("z_thresh {}", length(config.z_thresh, c.unit)));
    }
    parts.push(set.join(", "));
    if let (Input::Organized(cloud), Some(d)) = (run.input, &config.decimate) {
        let factor = d.factor_for(cloud.rows(), cloud.cols());
        if factor > 1 {
            parts.push(format!(
                "decimated {factor} × {factor} to {} points",
                run.counts.decimated_points
            ));
        }
    }
    if matches!(run.input, Input::Organized(_)) {
        match config.laplacian {
            Some(l) => parts.push(format!(
                "Laplacian {} ({})",
                count(run.counts.laplacian_iterations as usize, "pass", "passes"),
                match (l.iterations, l.range_exponent > 0.0) {
                    (polylidar::LaplacianIterations::Auto, false) => {
                        "chosen from the measured noise"
                    }
                    (polylidar::LaplacianIterations::Auto, true) => {
                        "chosen from the measured noise, at the median range; more farther away"
                    }
                    (polylidar::LaplacianIterations::Fixed(_), false) => "fixed",
                    (polylidar::LaplacianIterations::Fixed(_), true) => {
                        "fixed at the median range; more farther away"
                    }
                }
            )),
            None => parts.push("no Laplacian".to_owned()),
        }
        let on_gpu = |b: polylidar::SmoothingBackend| b == polylidar::SmoothingBackend::Gpu;
        if config.laplacian.is_some_and(|l| on_gpu(l.backend))
            || config.bilateral.is_some_and(|b| on_gpu(b.backend))
        {
            parts.push("smoothing on the GPU".to_owned());
        }
        if config.fill_missing.is_some() {
            parts.push(format!(
                "{} filled",
                count(run.counts.filled, "missing return", "missing returns")
            ));
        }
    }
    parts.join("; ")
}

/// Why the result is empty, for stderr, with the flags to try.
pub fn explanation_text(run: &Run<'_>, strict: bool) -> String {
    let unit = run.chosen.unit;
    let mut text = String::from("nothing, or nearly nothing, was found");
    if run.explanation.findings.is_empty() {
        text.push_str(
            ": no single stage dropped most of the data; see the counts above and try another --preset",
        );
    }
    for f in &run.explanation.findings {
        let value = |v: f64| match f.parameter {
            "lmax" | "alpha" => length(v, unit),
            "postprocess.min_area" => format!("{} {unit}²", significant(v)),
            _ => significant(v),
        };
        text.push_str(&format!(
            "\n  {}: {} dropped {} of {} — {}",
            f.stage, f.parameter, f.dropped, f.of, f.hint
        ));
        let flag = match f.parameter {
            "lmax" | "alpha" | "min_triangles" | "norm_thresh" => {
                Some(format!("--{}", f.parameter.replace('_', "-")))
            }
            _ => None,
        };
        match (f.suggested, flag) {
            (Some(s), Some(flag)) => text.push_str(&format!(
                "\n    now {}; try {flag} {}",
                value(f.current),
                significant(s)
            )),
            (Some(s), None) => text.push_str(&format!(
                "\n    now {}; try {} (in a --config file)",
                value(f.current),
                value(s)
            )),
            (None, _) => text.push_str(&format!("\n    now {}", value(f.current))),
        }
    }
    if !strict {
        text.push_str("\n  (exit code 0; --strict makes this exit code 3)");
    }
    text
}
