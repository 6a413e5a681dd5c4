//! Scoring an extraction against ground-truth labels with `seg-metrics` (Hoover et al.,
//! 80 % overlap), as the SynPEB benchmark does.

use polylidar::{Config, Extraction, Polylidar};
use seg_metrics::{EvaluateOptions, Evaluation, evaluate};

use crate::bench::Ctx;
use crate::data::LabelledCloud;
use crate::error::{Result, msg};

/// The pipeline of preset `name` on the context's parallel thread count.
///
/// # Errors
/// An unknown preset or a pipeline that cannot start.
pub fn preset_pipeline(ctx: &Ctx, name: &str) -> Result<Polylidar> {
    let config = Config::preset(name)
        .ok_or_else(|| msg(format!("no {name} preset")))?
        .with_threads(ctx.parallel_threads());
    Ok(Polylidar::new(config)?)
}

/// The scene seeds of an accuracy suite: 1–20, or 1–2 with `--quick`.
pub fn suite_seeds(ctx: &Ctx) -> Vec<u64> {
    if ctx.quick {
        (1..=2).collect()
    } else {
        (1..=20).collect()
    }
}

/// Scores the predicted plane of every pixel (`Extraction::point_labels`) against the
/// frame's labels, on the frame's raw (unsmoothed) points.
///
/// # Errors
/// Mismatched sizes or labels `seg-metrics` rejects.
pub fn score(frame: &LabelledCloud, extraction: &Extraction) -> Result<Evaluation> {
    let predicted = extraction.plane_labels();
    Ok(evaluate(
        frame.cloud.points(),
        &frame.labels,
        &predicted,
        &EvaluateOptions::default(),
    )?)
}
