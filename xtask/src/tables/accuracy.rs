//! Scoring an extraction against ground-truth labels with `seg-metrics` (Hoover et al.,
//! 80 % overlap), as the SynPEB benchmark does.

use polylidar::Extraction;
use seg_metrics::{EvaluateOptions, Evaluation, evaluate};

use crate::data::LabelledCloud;
use crate::error::Result;

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
