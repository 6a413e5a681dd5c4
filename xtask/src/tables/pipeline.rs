//! Timing the whole 3D pipeline on an organized cloud, stage by stage.

use std::hint::black_box;
use std::time::Instant;

use polylidar::{Extraction, OrganizedPointCloud, Polylidar};

use crate::error::Result;
use crate::timing::{Runs, Stats, median_of, ms};

/// The stage names of `Timings` for organized clouds, in pipeline order, with the column
/// titles the tables use.
pub const STAGES: [(&str, &str); 6] = [
    ("laplacian", "Laplacian"),
    ("mesh", "mesh"),
    ("bilateral", "bilateral"),
    ("fastga", "FastGA"),
    ("planes_polygons", "planes + polygons"),
    ("postprocess", "polygon filtering"),
];

/// Medians of every stage and of the whole call, and the last result.
pub struct PipelineStats {
    /// Median per stage of [`STAGES`] (`None`: the stage did not run).
    pub stages: Vec<Option<f64>>,
    /// Wall-clock time of `extract_organized` (includes work between the stages).
    pub wall: Stats,
    /// The last run's result.
    pub last: Extraction,
}

impl PipelineStats {
    /// The median of `stage`, if it ran.
    pub fn stage(&self, stage: &str) -> Option<f64> {
        STAGES
            .iter()
            .position(|(s, _)| *s == stage)
            .and_then(|k| self.stages[k])
    }

    /// Cells for the stages of [`STAGES`] ("–" where a stage did not run).
    pub fn stage_cells(&self) -> Vec<String> {
        self.stages
            .iter()
            .map(|s| s.map_or_else(|| "–".to_owned(), ms))
            .collect()
    }
}

/// Runs `extract_organized` `runs` times (after the warm-up) and summarises the stages.
///
/// # Errors
/// The pipeline's error.
pub fn time_pipeline(
    polylidar: &Polylidar,
    cloud: &OrganizedPointCloud,
    runs: Runs,
) -> Result<PipelineStats> {
    let mut last = None;
    for _ in 0..runs.warmup {
        drop(last.take());
        last = Some(black_box(polylidar.extract_organized(cloud)?));
    }
    let mut per_stage: Vec<Vec<f64>> = vec![Vec::new(); STAGES.len()];
    let mut wall = Vec::with_capacity(runs.timed);
    for _ in 0..runs.timed {
        // Drop the previous result first, as a frame-by-frame caller does, so that its
        // memory is free for this run (keeping it makes every run fault in fresh pages).
        drop(last.take());
        let start = Instant::now();
        let extraction = polylidar.extract_organized(cloud)?;
        wall.push(start.elapsed().as_secs_f64() * 1e3);
        for (k, (stage, _)) in STAGES.iter().enumerate() {
            if let Some(d) = extraction.diagnostics.timings.get(stage) {
                per_stage[k].push(d.as_secs_f64() * 1e3);
            }
        }
        last = Some(extraction);
    }
    let wall = Stats::from_samples(wall).ok_or_else(|| crate::error::msg("no timed runs"))?;
    let last = last.ok_or_else(|| crate::error::msg("no runs"))?;
    Ok(PipelineStats {
        stages: per_stage.into_iter().map(median_of).collect(),
        wall,
        last,
    })
}
