//! Table 10b: f, k, RMSE and error counts of the `rgbd` preset, the adaptive `rgbd-auto`
//! decimated and not, and, for comparison, the range scanners' `synpeb-auto` on the
//! synthetic RGB-D suite:
//! `synthscan::rgbd_like` rooms scanned by a Kinect v1 and a RealSense D435 model, each
//! at full and half resolution.

use std::fmt::Write as _;

use polylidar::{Config, DecimateConfig, Polylidar};
use synthscan::{DepthCameraKind, DepthModel};

use crate::bench::Ctx;
use crate::data::{LabelledCloud, rgbd_frame, rgbd_frame_with, truth_plane_rmse};
use crate::error::{Result, msg};
use crate::report::{Section, Table};
use crate::tables::accuracy::{
    SCORE_COLUMNS, Scored, mean, mean_mm, planes_per_frame, preset_pipeline, run_frame,
    score_cells, suite_seeds,
};

/// The presets scored, in row order per camera.
const PRESETS: [&str; 3] = ["rgbd", "synpeb-auto", "rgbd-auto"];

/// The width of the paper's RealSense frames after the SDK's decimation by 2 (424 × 240
/// sampled, 212 × 120 processed; §8.2, Table 6).
pub const PAPER_COLUMNS: u32 = 212;

/// The `rgbd` preset on the paper's working grid: frames decimated to about
/// [`PAPER_COLUMNS`] columns, on `threads` threads.
///
/// # Errors
/// None in practice: the preset exists.
pub fn paper_grid(threads: usize) -> Result<Config> {
    Ok(Config::preset("rgbd")
        .ok_or_else(|| msg("no rgbd preset"))?
        .with_threads(threads)
        .with_decimate(Some(
            DecimateConfig::default().with_target_columns(PAPER_COLUMNS),
        )))
}

/// Runs Table 10b.
///
/// # Errors
/// Pipeline, scoring or scene errors.
pub fn run(ctx: &Ctx) -> Result<Section> {
    let threads = ctx.parallel_threads();
    let mut pipelines = Vec::new();
    for name in PRESETS {
        pipelines.push((format!("`{name}`"), preset_pipeline(ctx, name)?));
    }
    // The adaptive preset stays at full resolution; decimating it as `rgbd` does is the
    // user's choice of speed over accuracy, measured here.
    let config = Config::preset("rgbd-auto")
        .ok_or_else(|| msg("no rgbd-auto preset"))?
        .with_threads(threads)
        .with_decimate(Some(DecimateConfig::default()));
    pipelines.push((
        "`rgbd-auto`, `decimate = auto`".to_owned(),
        Polylidar::new(config)?,
    ));
    // The paper's own working grid: its D435i frames were decimated to 212 columns by the
    // RealSense SDK.
    pipelines.push((
        format!("`rgbd`, decimated to {PAPER_COLUMNS} columns"),
        Polylidar::new(paper_grid(threads)?)?,
    ));
    let seeds = suite_seeds(ctx);

    let mut table = Table::new(
        [
            "camera",
            "preset",
            "frames",
            "planes / frame",
            "valid [%]",
            "noise [mm]",
        ]
        .into_iter()
        .chain(SCORE_COLUMNS),
    );
    for kind in DepthCameraKind::ALL {
        let frames = seeds
            .iter()
            .map(|&seed| rgbd_frame(seed, kind))
            .collect::<Result<Vec<LabelledCloud>>>()?;
        let valid = mean(frames.iter().map(|f| {
            let n = f.labels.len().max(1) as f64;
            100.0 * f.labels.iter().filter(|&&l| l >= 0).count() as f64 / n
        }));
        let noise = mean_mm(frames.iter().filter_map(truth_plane_rmse));
        for (name, polylidar) in &pipelines {
            let scored = frames
                .iter()
                .map(|frame| run_frame(polylidar, frame))
                .collect::<Result<Vec<Scored>>>()?;
            table.row(row(kind.name(), name, &scored, valid, &noise));
        }
        // The same rooms without sensor errors: what the geometry alone costs.
        let (_, rgbd) = &pipelines[0];
        let ideal = seeds
            .iter()
            .map(|&seed| rgbd_frame_with(seed, kind, DepthModel::ideal()))
            .collect::<Result<Vec<LabelledCloud>>>()?;
        let scored = ideal
            .iter()
            .map(|frame| run_frame(rgbd, frame))
            .collect::<Result<Vec<Scored>>>()?;
        table.row(row(
            kind.name(),
            "`rgbd`, error-free depth",
            &scored,
            100.0,
            "0.0",
        ));
    }

    let (kinect, d435) = (DepthModel::kinect_v1(), DepthModel::d435());
    let mut body = String::new();
    let _ = writeln!(
        body,
        "Accuracy of `Polylidar::extract_organized` on synthetic RGB-D frames, with \
         `Config::preset(\"rgbd\")` (the paper's RealSense parameters, Table 7, chosen for \
         the D435i's 424 × 240 depth decimated to 212 × 120: the preset decimates to about \
         424 columns, the full-resolution frames by 2, \
         `Config::decimate`, and scored per input pixel), the \
         adaptive detector for depth cameras `Config::preset(\"rgbd-auto\")` (Laplacian passes \
         from the measured noise, growing with range; refinement) and the range scanners' \
         `Config::preset(\"synpeb-auto\")` (the same with one pass count per frame), and \
         `rgbd-auto` decimated as `rgbd` is (`Config::decimate`, 640 × 480 and 848 × 480 by \
         2: the speed it buys and the accuracy it costs), and `rgbd` on the paper's own \
         working grid (its D435i frames, sampled at 424 × 240, were decimated by 2 to \
         212 × 120 by the RealSense SDK, Table 6: here every frame is decimated to about \
         {PAPER_COLUMNS} columns, by 3 at 640 × 480 and 4 at 848 × 480), on \
         {threads} threads, scored by \
         `seg-metrics` like Table 10 (Hoover et al., 80 % overlap: f = % of ground-truth \
         planes correctly found, k = % of labelled points in correctly found planes, RMSE of \
         every predicted segment's raw points to its own least-squares plane, and the mean \
         number per frame of over-segmented (n_o), under-segmented (n_u), missed (n_m) and \
         spurious (n_s) planes). Every ground-truth plane with at least one pixel counts.\n\n\
         Frames: `synthscan::rgbd_like(seed, camera)` for seeds {}–{} ({} frames per row): a \
         furnished room (4–5.5 × 3.2–4.5 m; cabinets, desks, an open shelf, boxes and a \
         leaning board) seen from 0.8–1.6 m high, pitched down 10–30°, scanned by \
         `Scene::scan_depth` with the camera's `DepthModel`. Kinect v1: 640 × 480, fx 525 px, \
         depth noise σ = {:.2}·z² mm (z in m), disparity in 1/8 px at f·B = {:.1} px·m, range {}–{} m. \
         D435: 848 × 480, fx 425 px, σ = {:.2}·z² mm (Intel's 0.08 px sub-pixel RMS), \
         disparity in 1/32 px at f·B = {:.2} px·m, range {}–{} m. Both round depth to 1 mm \
         and drop returns at grazing incidence, within 1 px of depth jumps (half of them) and \
         in the baseline shadow of near objects. The half-resolution cameras see the same \
         rooms from the same poses with half the focal length and the same metric noise. \
         \"valid\" is the share of pixels with depth, \"noise\" the RMS distance of the \
         points to their ground-truth plane's least-squares fit (planes of ≥ 50 points). \
         Rows \"error-free depth\" scan the same rooms with `DepthModel::ideal()` (no noise, \
         quantisation or missing returns): what the scene's geometry alone costs (decimated, \
         the `rgbd` preset then finds fewer of the small planes than at full resolution, \
         with min_triangles counted on the coarser grid). Time: \
         median wall-clock of one extraction per frame.\n",
        seeds.first().copied().unwrap_or(1),
        seeds.last().copied().unwrap_or(1),
        seeds.len(),
        kinect.sigma_quadratic * 1e3,
        kinect.disparity_focal * kinect.baseline,
        kinect.min_depth,
        kinect.max_depth,
        d435.sigma_quadratic * 1e3,
        d435.disparity_focal * d435.baseline,
        d435.min_depth,
        d435.max_depth,
    );
    body.push_str(&table.render());
    let _ = writeln!(
        body,
        "\nThe paper reports no RGB-D accuracy (its RealSense results are qualitative, §9.3.1), so there is no \
         paper row; the rooms imitate indoor RGB-D scenes but are not real frames. Targets \
         for this suite (issue 15): f ≥ 60, k ≥ 85 required; f ≥ 75, k ≥ 90 wanted."
    );
    Ok(Section {
        file: "table10b_rgbd_accuracy.md",
        title: "Table 10b — plane segmentation accuracy on synthetic RGB-D frames".to_owned(),
        body,
    })
}

/// A row of means over the frames.
fn row(camera: &str, preset: &str, scored: &[Scored], valid: f64, noise: &str) -> Vec<String> {
    let mut cells = vec![
        camera.to_owned(),
        preset.to_owned(),
        scored.len().to_string(),
        planes_per_frame(scored),
        format!("{valid:.1}"),
        noise.to_owned(),
    ];
    cells.extend(score_cells(scored));
    cells
}
