//! Scoring an extraction against ground-truth labels with `seg-metrics` (Hoover et al.,
//! 80 % overlap), as the SynPEB benchmark does.

use std::time::Instant;

use polylidar::{Config, Extraction, Polylidar};
use seg_metrics::{EvaluateOptions, Evaluation, evaluate};

use crate::bench::Ctx;
use crate::data::{LabelledCloud, truth_plane_rmse};
use crate::error::{Result, msg};
use crate::timing::{median_of, ms};

/// The scores, time and noise of one frame.
pub struct Scored {
    /// The Hoover scores.
    pub eval: Evaluation,
    /// Wall-clock of the extraction, ms.
    pub ms: f64,
    /// Ground-truth plane-fit RMSE of the frame (its noise), metres.
    pub noise: Option<f64>,
    /// Laplacian passes the pipeline ran.
    pub iterations: u32,
}

/// Extracts and scores one frame.
///
/// # Errors
/// Pipeline or scoring errors.
pub fn run_frame(polylidar: &Polylidar, frame: &LabelledCloud) -> Result<Scored> {
    let start = Instant::now();
    let extraction = polylidar.extract_organized(&frame.cloud)?;
    let ms = start.elapsed().as_secs_f64() * 1e3;
    Ok(Scored {
        eval: score(frame, &extraction)?,
        ms,
        noise: truth_plane_rmse(frame),
        iterations: extraction.diagnostics.counts.laplacian_iterations,
    })
}

/// The columns [`score_cells`] fills.
pub const SCORE_COLUMNS: [&str; 8] = [
    "f [%]",
    "k [%]",
    "RMSE [mm]",
    "n_o",
    "n_u",
    "n_m",
    "n_s",
    "time (median)",
];

/// Mean of the values (0 for none).
pub fn mean(values: impl Iterator<Item = f64>) -> f64 {
    let (sum, n) = values.fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    if n == 0 { 0.0 } else { sum / n as f64 }
}

/// The mean of the values in millimetres, one decimal, or `–` without values.
pub fn mean_mm(values: impl Iterator<Item = f64>) -> String {
    let values: Vec<f64> = values.collect();
    if values.is_empty() {
        "–".to_owned()
    } else {
        format!("{:.1}", 1e3 * mean(values.into_iter()))
    }
}

/// Planes per frame, as the mean over the frames.
pub fn planes_per_frame(scored: &[Scored]) -> String {
    format!(
        "{:.1}",
        mean(scored.iter().map(|s| s.eval.truth_planes as f64))
    )
}

/// The [`SCORE_COLUMNS`] of a row: means over the frames, median time.
pub fn score_cells(scored: &[Scored]) -> Vec<String> {
    let m =
        |f: &dyn Fn(&Evaluation) -> f64| format!("{:.1}", mean(scored.iter().map(|s| f(&s.eval))));
    vec![
        m(&|e| e.f),
        m(&|e| e.k),
        mean_mm(scored.iter().filter_map(|s| s.eval.rmse)),
        m(&|e| e.over_segmented as f64),
        m(&|e| e.under_segmented as f64),
        m(&|e| e.missed as f64),
        m(&|e| e.spurious as f64),
        median_of(scored.iter().map(|s| s.ms).collect()).map_or_else(|| "–".to_owned(), ms),
    ]
}

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
