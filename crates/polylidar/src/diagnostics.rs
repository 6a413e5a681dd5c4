//! Per-stage counts and timings, so a user can see where triangles, regions and holes went.

use std::time::{Duration, Instant};

use serde::Serialize;

/// What each stage kept and dropped. Serialized with these field names by the CLI's
/// `--json` output.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct Counts {
    /// Input points.
    pub points: usize,
    /// Points left out of the triangulation because an equal point was already in it.
    pub duplicate_points: usize,
    /// Triangles in the mesh.
    pub triangles: usize,
    /// Triangles dropped because their normal is too far from `up` (2.5D).
    pub dropped_normal: usize,
    /// Triangles dropped by the `lmax` test (3D: of those near enough to a dominant
    /// normal, which is tested first).
    pub dropped_lmax: usize,
    /// Triangles dropped by the α test.
    pub dropped_alpha: usize,
    /// Triangles that passed every test.
    pub triangles_kept: usize,
    /// Edge-connected regions of kept triangles.
    pub regions: usize,
    /// Regions dropped for having fewer than `min_triangles` triangles.
    pub regions_too_small: usize,
    /// Polygons returned.
    pub polygons: usize,
    /// Holes returned.
    pub holes: usize,
    /// Holes dropped for having fewer than `min_hole_vertices` vertices.
    pub holes_too_small: usize,
    /// 3D: dominant plane normals used for segmentation.
    pub dominant_normals: usize,
    /// 3D with refinement: triangles absorbed into a neighbouring plane's region.
    pub absorbed: usize,
    /// 3D with refinement: planes grown without a dominant normal.
    pub free_planes: usize,
    /// 3D with refinement: regions merged into a neighbour on the same plane.
    pub merged: usize,
    /// Polygons after post-processing (a polygon may split into several or vanish).
    pub postprocessed_polygons: usize,
    /// Polygons dropped by post-processing (area below γ, or not repairable).
    pub postprocess_dropped: usize,
    /// Rotating scans ([`crate::Polylidar::extract_scan`]): points left out by
    /// `keep_every` and the field of view.
    pub scan_thinned: usize,
    /// Rotating scans: points dropped as beam outliers.
    pub beam_outliers: usize,
    /// 3D organized clouds: missing pixels filled ([`crate::Config::fill_missing`]).
    pub filled: usize,
    /// 3D organized clouds decimated by [`crate::Config::decimate`]: the valid points of
    /// the coarser grid the pipeline ran on (0: not decimated).
    pub decimated_points: usize,
    /// 3D clouds: Laplacian passes run (the configured count, or the one predicted for
    /// `iterations = "auto"`; on the unorganized path the point-smoothing passes of
    /// `unorganized.smoothing`); 0 without smoothing.
    pub laplacian_iterations: u32,
}

/// Wall-clock time per pipeline stage, in execution order.
///
/// Stage names: `decimate` (organized clouds: blocks of pixels merged), `fill` (organized
/// clouds: missing returns filled), `outliers` (rotating scans: beams, thinning, beam outliers), `range_image`
/// (rotating scans rebuilt as range images), `mesh` (triangulation or meshing, normals included), `laplacian`
/// (with `iterations = "auto"`, the noise estimate too), `bilateral` (smoothing), `fastga` (dominant normals: integration and peaks), `regions`
/// (2D / 2.5D triangle filtering and region growing), `polygons` (2D / 2.5D boundary
/// following), `planes_polygons` (3D group assignment, region growing and polygon
/// extraction, overlapped), `postprocess`. Stages that did not run are absent.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Timings {
    stages: Vec<(&'static str, Duration)>,
}

impl Timings {
    /// The stages and their durations, in order.
    pub fn stages(&self) -> &[(&'static str, Duration)] {
        &self.stages
    }

    /// The duration of a stage, if it ran.
    pub fn get(&self, stage: &str) -> Option<Duration> {
        self.stages
            .iter()
            .find(|(s, _)| *s == stage)
            .map(|(_, d)| *d)
    }

    /// The sum of all stages.
    pub fn total(&self) -> Duration {
        self.stages.iter().map(|(_, d)| *d).sum()
    }

    /// Puts the stages of `earlier` before these.
    pub(crate) fn prepend(&mut self, mut earlier: Timings) {
        earlier.stages.append(&mut self.stages);
        self.stages = earlier.stages;
    }

    /// Records `duration` under `stage`.
    pub(crate) fn record(&mut self, stage: &'static str, duration: Duration) {
        self.stages.push((stage, duration));
    }

    /// Runs `f`, recording its duration under `stage`.
    pub(crate) fn time<T>(&mut self, stage: &'static str, f: impl FnOnce() -> T) -> T {
        let start = Instant::now();
        let out = f();
        self.stages.push((stage, start.elapsed()));
        out
    }
}

/// Counts and timings of one pipeline run.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Diagnostics {
    /// What each stage kept and dropped.
    pub counts: Counts,
    /// How long each stage took.
    pub timings: Timings,
}
