//! 2D paper Tables III–VI and Fig. 7: time (split into triangulation, shape extraction and
//! polygon extraction) and L² error against the number of points sampled in the shapes of
//! `../shared/fixtures/shapes`.

use std::fmt::Write as _;

use geo_types::MultiPolygon;
use polylidar::output::to_multipolygon;
use polylidar::{Config, Polylidar};
use synthscan::shapes::{
    convexity, l2_error, multipolygon_from_geojson, paper_alpha, sample_uniform,
};

use crate::bench::Ctx;
use crate::chart::{Axis, Chart, PALETTE, Series, log_ticks};
use crate::data::FIXTURES_NAME;
use crate::error::{Result, msg};
use crate::report::{Section, Table, percent};
use crate::tables::fastga::thousands;
use crate::timing::{Runs, Stats, measure, median_of, ms};

/// The 2D paper's point counts (Fig. 7).
const FULL_SIZES: [usize; 6] = [2_000, 4_000, 8_000, 16_000, 32_000, 64_000];
const QUICK_SIZES: [usize; 3] = [2_000, 16_000, 64_000];

/// One measurement: a shape at one point count.
struct Point {
    n: usize,
    alpha: f64,
    /// Medians of the pipeline's stages on one thread (triangulation, shape, polygons).
    split: [f64; 3],
    one: Stats,
    parallel: Stats,
    l2: f64,
    polygons: usize,
    holes: usize,
}

/// Runs the 2D tables and charts.
///
/// # Errors
/// Unreadable shapes or a pipeline error.
pub fn run(ctx: &Ctx) -> Result<Section> {
    let shapes = ctx.fixtures.shapes();
    if shapes.is_empty() {
        return Err(msg(format!("no shapes in {FIXTURES_NAME}/shapes")));
    }
    let sizes: &[usize] = if ctx.quick { &QUICK_SIZES } else { &FULL_SIZES };
    let runs = ctx.runs(2, 20, 3);
    let parallel = ctx.parallel_threads();

    let mut results = Vec::new();
    for (name, path) in &shapes {
        let truth = multipolygon_from_geojson(&std::fs::read_to_string(path)?)?;
        let mut points = Vec::new();
        for &n in sizes {
            eprintln!("  shapes: {name} {n}");
            points.push(measure_shape(&truth, n, runs, parallel)?);
        }
        results.push((name.clone(), convexity(&truth), points));
    }

    let mut body = String::new();
    let _ = writeln!(
        body,
        "`Polylidar::extract_2d` on points sampled uniformly inside each shape of \
         `{FIXTURES_NAME}/shapes` (`shapes::sample_uniform`, fixed seed), with α = 2·√(area / n) \
         as in the 2D paper (Table II) and `min_triangles` 1. The split columns are the medians \
         of the pipeline's own timings on one thread: triangulation (`mesh`: Delaunay and \
         half-edge mesh), shape extraction (`regions`: α filter and region growing) and polygon \
         extraction (`polygons`). Totals are wall-clock: {}, median (min–max) in ms. L² error = \
         area of the symmetric difference between the truth and the polygons, over the \
         truth's area. The 2D paper ran 10 random samples per size; we time one sample \
         {} times.\n",
        runs.describe(),
        runs.timed
    );

    // Table VI: the stage split on caholes at 64k.
    if let Some((_, _, pts)) = results.iter().find(|(n, _, _)| n == "caholes")
        && let Some(p) = pts.iter().find(|p| p.n == 64_000)
    {
        let mut t = Table::new([
            "California with holes, 64,000 points",
            "triangulation",
            "shape extraction",
            "polygon extraction",
            "total",
        ]);
        t.row([
            "ours, 1 thread (stage medians; wall median)".to_owned(),
            ms(p.split[0]),
            ms(p.split[1]),
            ms(p.split[2]),
            ms(p.one.median),
        ]);
        t.row([
            format!("ours, {parallel} threads (wall median)"),
            String::new(),
            String::new(),
            String::new(),
            ms(p.parallel.median),
        ]);
        for (who, a, b, c, total) in [
            (
                "paper: Polylidar (C++, Delaunator)",
                "36.0",
                "4.4",
                "1.0",
                "41.4",
            ),
            ("paper: CGAL α-shape", "44.5", "154.0", "–", "198.5"),
            ("paper: Spatialite", "234.2", "135.3", "10788.7", "11158.1"),
        ] {
            t.row([who, a, b, c, total]);
        }
        let _ = writeln!(
            body,
            "## Table VI — stage split on California with holes, 64k points\n\n\
             Paper: mean of 30 runs on the authors' machine.\n\n{}",
            t.render()
        );
    }

    // Fig. 7 style: every shape and size.
    let _ = writeln!(body, "## Time and L² error vs point count (Fig. 7 style)\n");
    for (name, cv, pts) in &results {
        let mut t = Table::new([
            "points",
            "α",
            "triangulation",
            "shape",
            "polygons",
            "total, 1 thread",
            &format!("total, {parallel} threads"),
            "L² error",
            "polygons / holes",
        ]);
        for p in pts {
            t.row([
                thousands(p.n),
                format!("{:.4}", p.alpha),
                ms(p.split[0]),
                ms(p.split[1]),
                ms(p.split[2]),
                p.one.cell(),
                p.parallel.cell(),
                percent(p.l2),
                format!("{} / {}", p.polygons, p.holes),
            ]);
        }
        let _ = writeln!(body, "### `{name}` (convexity {cv:.2})\n\n{}", t.render());
    }

    // Tables III–V: the paper's aggregate figures next to our nearest rows.
    let at = |n: usize| -> Vec<&Point> {
        results
            .iter()
            .filter_map(|(_, _, pts)| pts.iter().find(|p| p.n == n))
            .collect()
    };
    let mut t = Table::new([
        "paper table",
        "its input",
        "paper: L² mean",
        "paper: time mean",
        "ours, nearest",
    ]);
    let summary = |pts: &[&Point]| -> String {
        if pts.is_empty() {
            return "(size not run)".to_owned();
        }
        let l2: Vec<f64> = pts.iter().map(|p| p.l2).collect();
        let time: Vec<f64> = pts.iter().map(|p| p.one.median).collect();
        format!(
            "{} shapes at {} points: L² {}–{}, time {}–{} ms (1 thread)",
            pts.len(),
            thousands(pts[0].n),
            percent(l2.iter().copied().fold(f64::INFINITY, f64::min)),
            percent(l2.iter().copied().fold(0.0, f64::max)),
            ms(time.iter().copied().fold(f64::INFINITY, f64::min)),
            ms(time.iter().copied().fold(0.0, f64::max)),
        )
    };
    t.row([
        "III".to_owned(),
        "11 RGBD floor point sets, 83,184 points on average".to_owned(),
        "2.2 %".to_owned(),
        "47.9 ms".to_owned(),
        summary(&at(64_000)),
    ]);
    t.row([
        "IV".to_owned(),
        "26 capital letters, 2,000 points each".to_owned(),
        "12.8 %".to_owned(),
        "1.2 ms".to_owned(),
        summary(&at(2_000)),
    ]);
    t.row([
        "V".to_owned(),
        "19,600 random polygons, 8,000 points: high / mid / low convexity".to_owned(),
        "4.4 / 8.0 / 15.5 %".to_owned(),
        "4.6 / 4.6 / 4.7 ms".to_owned(),
        summary(&at(8_000)),
    ]);
    let _ = writeln!(
        body,
        "## Tables III–V — the paper's aggregates beside our nearest rows\n\nThe paper's \
         inputs (RGBD floors, letters, random polygons) are not in the fixtures; the rows \
         give the scale of its figures next to ours at the same point count.\n\n{}",
        t.render()
    );

    write_charts(ctx, &results)?;
    let _ = writeln!(
        body,
        "## Charts\n\n![time vs points](shapes_2d_time.png)\n\n*Total time (1 thread, median) \
         against the number of points, log–log; dashed lines are the shapes with holes.*\n\n\
         ![L² error vs points](shapes_2d_error.png)\n\n*L² error against the number of \
         points.*\n\n{}",
        crate::report::PAPER_HARDWARE
    );
    Ok(Section {
        file: "shapes_2d.md",
        title: "2D paper Tables III–VI — concave hulls of the shape fixtures".to_owned(),
        body,
    })
}

/// Samples `n` points in `truth` and times the pipeline on 1 and `parallel` threads.
fn measure_shape(
    truth: &MultiPolygon<f64>,
    n: usize,
    runs: Runs,
    parallel: usize,
) -> Result<Point> {
    let points = sample_uniform(truth, n, 42 + n as u64)?;
    let alpha = paper_alpha(truth, n);
    let config = Config::new().with_alpha(alpha).with_min_triangles(1);
    let one = Polylidar::new(config.clone().with_threads(1))?;
    let many = Polylidar::new(config.with_threads(parallel))?;
    let mut stages: [Vec<f64>; 3] = Default::default();
    let mut last = None;
    let one_stats = measure(runs, || {
        let e = one.extract_2d(&points)?;
        for (k, stage) in ["mesh", "regions", "polygons"].iter().enumerate() {
            if let Some(d) = e.diagnostics.timings.get(stage) {
                stages[k].push(d.as_secs_f64() * 1e3);
            }
        }
        last = Some(e.polygons.clone());
        Ok(e)
    })?;
    let parallel_stats = measure(runs, || Ok(many.extract_2d(&points)?))?;
    let polygons = last.ok_or_else(|| msg("no run"))?;
    let found = to_multipolygon(&polygons);
    let split = stages.map(|s| median_of(s).unwrap_or(f64::NAN));
    Ok(Point {
        n,
        alpha,
        split,
        one: one_stats,
        parallel: parallel_stats,
        l2: l2_error(truth, &found),
        polygons: polygons.len(),
        holes: polygons.iter().map(|p| p.holes.len()).sum(),
    })
}

/// Time and error charts, one line per shape (holes dashed, same colour as the outline).
fn write_charts(ctx: &Ctx, results: &[(String, f64, Vec<Point>)]) -> Result<()> {
    let bases: Vec<&str> = {
        let mut b: Vec<&str> = results
            .iter()
            .map(|(n, _, _)| n.strip_suffix("holes").unwrap_or(n))
            .collect();
        b.dedup();
        b
    };
    let series = |value: &dyn Fn(&Point) -> f64| -> Vec<Series> {
        results
            .iter()
            .map(|(name, _, pts)| {
                let base = name.strip_suffix("holes").unwrap_or(name);
                let k = bases.iter().position(|b| *b == base).unwrap_or(0);
                Series {
                    label: name.clone(),
                    points: pts.iter().map(|p| (p.n as f64, value(p))).collect(),
                    color: PALETTE[k % PALETTE.len()],
                    dashed: name.ends_with("holes"),
                }
            })
            .collect()
    };
    let sizes: Vec<f64> = results
        .first()
        .map(|(_, _, pts)| pts.iter().map(|p| p.n as f64).collect())
        .unwrap_or_default();
    let time_series = series(&|p: &Point| p.one.median);
    let (lo, hi) = bounds(&time_series);
    Chart {
        title: "2D: TIME VS POINTS (1 THREAD)".to_owned(),
        x: Axis {
            label: "POINTS".to_owned(),
            log: true,
            ticks: sizes.clone(),
        },
        y: Axis {
            label: "TIME (MS)".to_owned(),
            log: true,
            ticks: log_ticks(lo, hi),
        },
        series: time_series,
    }
    .save(&ctx.out.join("shapes_2d_time.png"))?;
    let error_series = series(&|p: &Point| 100.0 * p.l2);
    let (lo, hi) = bounds(&error_series);
    Chart {
        title: "2D: L2 ERROR VS POINTS".to_owned(),
        x: Axis {
            label: "POINTS".to_owned(),
            log: true,
            ticks: sizes,
        },
        y: Axis {
            label: "L2 ERROR (%)".to_owned(),
            log: true,
            ticks: log_ticks(lo, hi),
        },
        series: error_series,
    }
    .save(&ctx.out.join("shapes_2d_error.png"))
}

/// Range of the y values, widened to 1-2-5 steps.
fn bounds(series: &[Series]) -> (f64, f64) {
    let ys = series.iter().flat_map(|s| s.points.iter().map(|p| p.1));
    let lo = ys
        .clone()
        .filter(|y| *y > 0.0)
        .fold(f64::INFINITY, f64::min);
    let hi = ys.fold(0.0, f64::max);
    if !lo.is_finite() || hi <= 0.0 {
        return (0.1, 1.0);
    }
    crate::chart::log_bounds(lo, hi)
}
