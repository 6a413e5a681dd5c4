//! Table 10u: the unorganized 3D path (`Polylidar::extract_unorganized`) on the Table 10
//! scenes sampled as unorganized clouds — each scan with its grid dropped and its points
//! shuffled, and four scans of one room merged — scored against the organized path on
//! the same scenes; and its speed on real airborne LiDAR and a million-point room.

use std::fmt::Write as _;
use std::time::Instant;

use polylidar::{Config, Extraction, Polylidar};
use seg_metrics::{EvaluateOptions, Evaluation, evaluate};
use synthscan::{Noise, UnorganizedCloud};

use crate::bench::Ctx;
use crate::data::{LabelledCloud, SYNTHETIC_RADIAL_SIGMA};
use crate::error::{Result, msg};
use crate::report::{PAPER_HARDWARE, Section, Table};
use crate::tables::accuracy::{mean, preset_pipeline, run_frame, suite_seeds};

/// The scores, size, smoothing passes and time of one cloud.
struct Scored {
    eval: Evaluation,
    points: f64,
    passes: u32,
    ms: f64,
}

use crate::timing::{measure, ms};

/// Tangential noise of the scenes, as Table 10's key row.
const MDEG: f64 = 1.0;

/// Runs Table 10u.
///
/// # Errors
/// Pipeline, scoring, scene or fixture errors.
pub fn run(ctx: &Ctx) -> Result<Section> {
    let threads = ctx.parallel_threads();
    let organized = preset_pipeline(ctx, "synpeb-auto")?;
    let seeds = suite_seeds(ctx);
    let radial = SYNTHETIC_RADIAL_SIGMA;
    let views = synthscan::VIEWS.len();
    let mut table = Table::new([
        "data",
        "path",
        "frames",
        "points",
        "f [%]",
        "k [%]",
        "n_s",
        "smoothing passes",
        "time (median)",
    ]);
    for radial in [radial, 0.0] {
        let scene_name = format!("SynPEB-like, {MDEG} mdeg, radial {} mm", radial * 1e3);
        let path = "3D, `room`";
        let mut organized_rows = Vec::new();
        let mut single = Vec::new();
        let mut merged = Vec::new();
        for &seed in &seeds {
            let (scene, sensor) = synthscan::synpeb_like(seed)?;
            let scan = scene.scan(&sensor, &Noise::new(radial, MDEG, seed))?;
            let cloud = scan.to_unorganized(synthscan::VIEWS[0].0, seed);
            let points = scan.num_valid() as f64;
            let frame = LabelledCloud {
                cloud: polylidar::OrganizedPointCloud::new(scan.rows, scan.cols, scan.points)?,
                labels: scan.labels,
            };
            let scored = run_frame(&organized, &frame)?;
            organized_rows.push(Scored {
                eval: scored.eval,
                points,
                passes: scored.iterations,
                ms: scored.ms,
            });
            let viewpoint = Some(cloud.viewpoints[0]);
            single.push(run_cloud(&room(threads, viewpoint)?, &cloud)?);
            let (scene, sensors) = synthscan::synpeb_like_views(seed, views)?;
            let cloud = scene.scan_views(&sensors, &Noise::new(radial, MDEG, seed), seed)?;
            merged.push(run_cloud(&room(threads, None)?, &cloud)?);
        }
        table.row(score_row(
            &scene_name,
            "organized, `synpeb-auto`",
            &organized_rows,
        ));
        table.row(score_row(
            &format!("{scene_name}, unorganized (shuffled)"),
            path,
            &single,
        ));
        table.row(score_row(
            &format!("{scene_name}, {views} views merged"),
            path,
            &merged,
        ));
    }

    // Speed on real airborne LiDAR, from loaded points.
    let mut speed = Table::new([
        "data",
        "points",
        "threads",
        "time (median, range)",
        "planes",
    ]);
    let runs = ctx.runs(2, 9, 3);
    let mut notes = String::new();
    match ctx.fixtures.path("lidar/autzen_trim.laz") {
        Some(path) => {
            let points = polylidar_io::read_las(&path)?.points;
            let unit =
                polylidar_io::read_las_unit(&path)?.unwrap_or(polylidar_io::LengthUnit::Metre);
            for t in [1, threads.max(1)] {
                let config = polylidar::scale::convert_lengths(
                    &Config::preset("aerial").ok_or_else(|| msg("no aerial preset"))?,
                    1.0 / unit.metres(),
                )
                .with_threads(t);
                let polylidar = Polylidar::new(config)?;
                let mut planes = 0;
                let stats = measure(runs, || {
                    let e = polylidar.extract_unorganized(&points, None)?;
                    planes = e.polygons.len();
                    Ok(e)
                })?;
                speed.row(vec![
                    "`lidar/autzen_trim.laz`, `aerial`".to_owned(),
                    points.len().to_string(),
                    t.to_string(),
                    stats.cell(),
                    planes.to_string(),
                ]);
            }
        }
        None => {
            let _ = writeln!(notes, "* `lidar/autzen_trim.laz` is missing: row skipped.");
        }
    }
    // A million-point room: the four merged views of the first scene.
    let (scene, sensors) = synthscan::synpeb_like_views(seeds[0], views)?;
    let cloud = scene.scan_views(&sensors, &Noise::new(radial, MDEG, seeds[0]), seeds[0])?;
    for (name, polylidar) in [
        ("`room`", room(threads, None)?),
        ("`room`, voxel 2 cm", room_voxel(threads, 0.02)?),
    ] {
        let mut planes = 0;
        let stats = measure(ctx.runs(1, 5, 2), || {
            let e = polylidar.extract_unorganized(&cloud.points, None)?;
            planes = e.polygons.len();
            Ok(e)
        })?;
        speed.row(vec![
            format!("synthetic room, {views} views merged, {name}"),
            cloud.points.len().to_string(),
            threads.to_string(),
            stats.cell(),
            planes.to_string(),
        ]);
    }

    let mut body = String::new();
    let _ = writeln!(
        body,
        "The unorganized 3D path (`Polylidar::extract_unorganized`, preset `room`: PCA \
         normals of the 12 nearest neighbours, FastGA on the normals taken both ways, per \
         direction the agreeing points split into neighbour-connected pieces and triangulated \
         along it, planar segmentation, labels by best fit) on the scenes of Table 10 \
 (`synthscan::synpeb_like`, seeds {}–{}, {} frames, {MDEG} mdeg tangential and {} mm \
         radial noise, and noise-free), scored like Table 10 (Hoover et al., 80 % overlap; f = % of planes \
         found, k = % of points in found planes, n_s = spurious planes per frame). \
         The preset smooths the points over their 12 nearest neighbours as many passes \
         as its model predicts from each cloud's noise (`smoothing = \"auto\"`, \
         `polylidar::predict_smoothing_passes`; the mean count run is in the table; \
         organized rows: the Laplacian passes of `iterations = \"auto\"`). \
         \"organized\" is the organized path on the same scans; \"unorganized (shuffled)\" \
         the same scans with the image grid dropped, invalid pixels removed and the points \
         shuffled (`ScanResult::to_unorganized`; normals turned towards the sensor); \
         \"{views} views merged\" four 500 × 500 scans of each room from its four sides \
         (`synthscan::synpeb_like_views`, `Scene::scan_views`, about a million points; \
         normals turned up, walls by a fixed side). {threads} threads; time = median \
         wall-clock of one extraction from loaded points, ms.\n",
        seeds.first().copied().unwrap_or(1),
        seeds.last().copied().unwrap_or(1),
        seeds.len(),
        radial * 1e3
    );
    body.push_str(&table.render());
    let _ = writeln!(
        body,
        "\n### Speed\n\nFrom loaded points to polygons and labels, {}. Autzen: the `aerial` \
         preset in the file's US survey feet.\n",
        runs.describe()
    );
    body.push_str(&speed.render());
    let _ = writeln!(body, "\n{notes}\n{PAPER_HARDWARE}");
    Ok(Section {
        file: "table10u_unorganized.md",
        title: "Table 10u — unorganized clouds, planes in every direction".to_owned(),
        body,
    })
}

/// The `room` preset on `threads` threads, normals turned towards `viewpoint` if given.
fn room(threads: usize, viewpoint: Option<[f64; 3]>) -> Result<Polylidar> {
    let mut config = Config::preset("room")
        .ok_or_else(|| msg("no room preset"))?
        .with_threads(threads);
    if let Some(section) = &mut config.unorganized {
        section.viewpoint = viewpoint;
    }
    Ok(Polylidar::new(config)?)
}

/// The `room` preset with voxel downsampling.
fn room_voxel(threads: usize, voxel: f64) -> Result<Polylidar> {
    let mut config = Config::preset("room")
        .ok_or_else(|| msg("no room preset"))?
        .with_threads(threads);
    if let Some(section) = &mut config.unorganized {
        section.voxel = voxel;
    }
    Ok(Polylidar::new(config)?)
}

/// Extracts and scores one unorganized cloud.
fn run_cloud(polylidar: &Polylidar, cloud: &UnorganizedCloud) -> Result<Scored> {
    let start = Instant::now();
    let extraction = polylidar.extract_unorganized(&cloud.points, None)?;
    let ms = start.elapsed().as_secs_f64() * 1e3;
    Ok(Scored {
        eval: score(cloud, &extraction)?,
        points: cloud.points.len() as f64,
        passes: extraction.diagnostics.counts.laplacian_iterations,
        ms,
    })
}

fn score(cloud: &UnorganizedCloud, extraction: &Extraction) -> Result<Evaluation> {
    Ok(evaluate(
        &cloud.points,
        &cloud.labels,
        &extraction.plane_labels(),
        &EvaluateOptions::default(),
    )?)
}

/// A row: means over the frames, median time.
fn score_row(data: &str, path: &str, scored: &[Scored]) -> Vec<String> {
    let m =
        |f: &dyn Fn(&Evaluation) -> f64| format!("{:.1}", mean(scored.iter().map(|s| f(&s.eval))));
    let mut times: Vec<f64> = scored.iter().map(|s| s.ms).collect();
    times.sort_by(f64::total_cmp);
    vec![
        data.to_owned(),
        path.to_owned(),
        scored.len().to_string(),
        format!("{:.0}", mean(scored.iter().map(|s| s.points))),
        m(&|e| e.f),
        m(&|e| e.k),
        m(&|e| e.spurious as f64),
        format!("{:.1}", mean(scored.iter().map(|s| f64::from(s.passes)))),
        times
            .get(times.len() / 2)
            .map_or_else(|| "–".to_owned(), |&t| ms(t)),
    ]
}
