//! Ma et al. 2013 ("Planar simplification and texturing of dense point cloud maps"):
//! Table I (planar points kept by the quadtree decimation), Table II (triangles against
//! the full triangulation of the segments), the skinny-triangle shares and angle
//! distribution of Fig. 8, and Table III (time of decimation + triangulation + texture,
//! serial and on N threads), on the shared RGB-D frames and the coloured fragment.

use std::fmt::Write as _;

use polylidar::planar_mesh::{Method, PlaneMesh, SimplifyOptions, TextureOptions, quality};
use polylidar::{Config, DepthOptions, Extraction, Intrinsics, OrganizedPointCloud, Polylidar};

use crate::bench::Ctx;
use crate::chart::{Axis, Chart, PALETTE, Series, linear_ticks};
use crate::data::FIXTURES_NAME;
use crate::error::{Result, msg};
use crate::report::{Section, Table};
use crate::timing::{measure, ms};

/// One input: its name, the planes Polylidar found, and one colour per mesh vertex.
struct Dataset {
    name: String,
    points: usize,
    extraction: Extraction,
    colors: Vec<[u8; 3]>,
    /// A 640 × 480 frame (the speed target applies).
    frame: bool,
}

/// PrimeSense intrinsics of the ICL-NUIM and TUM frames (`rgbd/camera_primesense.json`).
const PRIMESENSE: [f64; 4] = [525.0, 525.0, 319.5, 239.5];

/// The fragment's 2.5D parameters, as `polylidar extract` derives them: lmax 4 × its
/// median point spacing (3.44 mm), regions of at least 1/10,000 of its extent.
const FRAGMENT_LMAX: f64 = 0.0138;
const FRAGMENT_MIN_TRIANGLES: usize = 78;

/// The methods compared, with their names in the tables.
const METHODS: [(Method, bool, &str); 4] = [
    (Method::Boundary, false, "boundary only"),
    (Method::Point, false, "point-based"),
    (Method::Polygon, false, "polygon-based"),
    (Method::Polygon, true, "polygon-based, conforming"),
];

fn load(ctx: &Ctx, notes: &mut String) -> Result<Vec<Dataset>> {
    let mut out = Vec::new();
    let preset = |name: &str| -> Result<Polylidar> {
        let config = Config::preset(name).ok_or_else(|| msg(format!("no {name} preset")))?;
        Ok(Polylidar::new(config)?)
    };
    let organized = [
        ("synpeb-auto", preset("synpeb-auto")?),
        ("rgbd", preset("rgbd")?),
    ];
    for (file, scale) in [
        ("rgbd/icl_living_depth_00000.png", 0.001),
        ("rgbd/icl_living_depth_00004.png", 0.001),
        ("rgbd/tum_depth.png", 0.0002),
    ] {
        let Some(path) = ctx.fixtures.path(file) else {
            let _ = writeln!(notes, "* `{file}` is missing: row skipped.");
            continue;
        };
        let depth = polylidar_io::read_depth_png(&path)?;
        let color = polylidar_io::read_color_image(polylidar_io::color_path_for(&path)?)?;
        let [fx, fy, cx, cy] = PRIMESENSE;
        let options = DepthOptions::new(Intrinsics::new(fx, fy, cx, cy)).with_depth_scale(scale);
        let cloud = OrganizedPointCloud::from_depth_image(
            &depth.data,
            depth.height,
            depth.width,
            &options,
        )?;
        for (preset, polylidar) in &organized {
            let extraction = polylidar.extract_organized(&cloud)?;
            // A decimated frame's mesh has a vertex per block: its colour the block's.
            let (colors, name) = match &extraction.decimation {
                Some(d) => (
                    d.block_colors(&color.rgb)?,
                    format!(
                        "{}, `{preset}` (decimated by {})",
                        file.trim_start_matches("rgbd/"),
                        d.factor
                    ),
                ),
                None => (
                    color.rgb.clone(),
                    format!("{}, `{preset}`", file.trim_start_matches("rgbd/")),
                ),
            };
            out.push(Dataset {
                name,
                points: cloud.num_valid(),
                extraction,
                colors,
                frame: (depth.width, depth.height) == (640, 480),
            });
        }
    }
    match ctx.fixtures.path("rgbd/living_fragment.pcd") {
        Some(path) => {
            let cloud = polylidar_io::read_pcd(&path)?;
            let colors = polylidar_io::read_pcd_colors(&path)?
                .ok_or_else(|| msg("living_fragment.pcd has no colours"))?;
            let config = Config::new()
                .with_lmax(FRAGMENT_LMAX)
                .with_min_triangles(FRAGMENT_MIN_TRIANGLES)
                .with_norm_thresh(0.9);
            let extraction = Polylidar::new(config)?.extract_25d(&cloud.points)?;
            out.push(Dataset {
                name: "living_fragment.pcd".to_owned(),
                points: cloud.points.len(),
                extraction,
                colors,
                frame: false,
            });
        }
        None => {
            let _ = writeln!(
                notes,
                "* `rgbd/living_fragment.pcd` is missing: row skipped."
            );
        }
    }
    Ok(out)
}

fn meshes(d: &Dataset, options: &SimplifyOptions) -> Result<Vec<PlaneMesh>> {
    let colors = options.texture.is_some().then_some(d.colors.as_slice());
    let m = d.extraction.planar_meshes(colors, options)?;
    Ok(m.planes.into_iter().map(|(_, p)| p).collect())
}

fn pct(a: usize, b: usize) -> String {
    format!("{:.1} %", 100.0 * a as f64 / b.max(1) as f64)
}

/// Runs the tables.
///
/// # Errors
/// Unreadable fixtures or a pipeline error.
pub fn run(ctx: &Ctx) -> Result<Section> {
    let mut notes = String::new();
    let data = load(ctx, &mut notes)?;
    if data.is_empty() {
        return Err(msg(format!("no RGB-D fixture in {FIXTURES_NAME}/rgbd")));
    }
    let mut body = String::new();
    let _ = writeln!(
        body,
        "Each plane Polylidar3D finds (ICL-NUIM and TUM frames: `extract_organized` with the \
         `synpeb-auto` preset, the best of the range-scanner and paper presets on Kinect \
         frames (Table 10b), and with the paper's `rgbd` preset, which decimates these frames \
         by 2 first, so that each vertex stands for a block of 2 × 2 pixels and carries its \
         mean colour; `living_fragment.pcd`: `extract_25d` with z up, lmax {FRAGMENT_LMAX} m, \
         at least {FRAGMENT_MIN_TRIANGLES} triangles) is simplified by \
         `Extraction::planar_meshes` (crate `planar-mesh`): its points are the vertices of its \
         triangles, its concave hull the extracted polygon with holes, the quadtree depth \
         automatic (finest cell 2–4 boundary spacings). The paper's figures are for four \
         Kintinuous maps of 0.9–5.6 million points on a 2013 six-core CPU.\n"
    );

    // Table I and II.
    let mut t1 = Table::new([
        "dataset",
        "points",
        "planes",
        "planar points",
        "kept vertices",
        "kept %",
    ]);
    let mut t2 = Table::new([
        "dataset",
        "full triangulation",
        "boundary only",
        "point-based",
        "polygon-based",
        "polygon-based, conforming",
    ]);
    let mut angles: Vec<Vec<f64>> = vec![Vec::new(); METHODS.len()];
    let mut skinny = [(0usize, 0usize); METHODS.len()];
    let mut right_isosceles = (0usize, 0usize);
    for d in &data {
        let mut row2 = vec![d.name.clone()];
        let full: usize = d
            .extraction
            .polygons
            .iter()
            .map(|p| p.triangles.len())
            .sum();
        row2.push(full.to_string());
        for (k, (method, conforming, _)) in METHODS.iter().enumerate() {
            let options = SimplifyOptions::new()
                .with_method(*method)
                .with_conforming(*conforming);
            let planes = meshes(d, &options)?;
            let triangles: usize = planes.iter().map(|p| p.triangles.len()).sum();
            row2.push(format!("{triangles} ({})", pct(triangles, full)));
            for p in &planes {
                for t in &p.triangles {
                    let [a, b, c] = t.map(|v| p.vertices_2d[v as usize]);
                    let three = quality::angles_deg(a, b, c);
                    let min = three.iter().copied().fold(f64::INFINITY, f64::min);
                    skinny[k].0 += usize::from(min < quality::SKINNY_DEG);
                    skinny[k].1 += 1;
                    if *method == Method::Polygon && !*conforming {
                        let mut s = three;
                        s.sort_by(f64::total_cmp);
                        let near = |x: f64, y: f64| (x - y).abs() < 0.5;
                        right_isosceles.0 += usize::from(near(s[0], 45.0) && near(s[2], 90.0));
                        right_isosceles.1 += 1;
                    }
                    angles[k].extend(three);
                }
            }
            if *method == Method::Point {
                let planar: usize = planes.iter().map(|p| p.stats.points).sum();
                let kept: usize = planes.iter().map(|p| p.stats.kept_vertices()).sum();
                t1.row([
                    d.name.clone(),
                    d.points.to_string(),
                    planes.len().to_string(),
                    planar.to_string(),
                    kept.to_string(),
                    pct(kept, planar),
                ]);
            }
        }
        t2.row(row2);
    }
    for (name, planar, ours) in [
        ("paper: data 1", 540_230, 47_457),
        ("paper: data 2", 708_653, 84_711),
        ("paper: data 3", 1_303_012, 43_257),
        ("paper: data 4", 2_430_743, 76_624),
    ] {
        t1.row([
            name.to_owned(),
            String::new(),
            String::new(),
            planar.to_string(),
            ours.to_string(),
            pct(ours, planar),
        ]);
    }
    for (name, gpt, point, polygon) in [
        ("paper: data 1 (GPT)", 1_020_241, 85_653, 76_367),
        ("paper: data 2 (GPT)", 1_350_004, 161_270, 130_642),
        ("paper: data 3 (GPT)", 2_293_599, 79_988, 66_413),
        ("paper: data 4 (GPT)", 4_665_067, 143_396, 118_275),
    ] {
        t2.row([
            name.to_owned(),
            gpt.to_string(),
            String::new(),
            format!("{point} ({})", pct(point, gpt)),
            format!("{polygon} ({})", pct(polygon, gpt)),
            String::new(),
        ]);
    }
    let _ = writeln!(
        body,
        "## Table I — planar points kept by the decimation\n\nKept vertices: every boundary \
         vertex plus the corners of the merged interior quadtree nodes (the same for the \
         point- and polygon-based triangulations, which add none). Paper: ≈ 10 % of the \
         planar points (3–12 %).\n"
    );
    body.push_str(&t1.render());
    let _ = writeln!(
        body,
        "\n## Table II — triangles against the full triangulation\n\n\"Full triangulation\": \
         the triangles of the planes' segments in Polylidar's mesh (one per pixel half for \
         the frames), the counterpart of the paper's GPT mesh of the non-decimated segments. \
         Paper: both methods need no more than 10 % of it.\n"
    );
    body.push_str(&t2.render());

    // Skinny triangles and Fig. 8.
    let mut t3 = Table::new([
        "triangulation",
        "triangles",
        "skinny (min angle < 15°)",
        "paper",
    ]);
    for (k, (_, _, name)) in METHODS.iter().enumerate() {
        let paper = match k {
            0 => "28 %",
            1 | 2 => "10 %",
            _ => "—",
        };
        t3.row([
            (*name).to_owned(),
            skinny[k].1.to_string(),
            pct(skinny[k].0, skinny[k].1),
            paper.to_owned(),
        ]);
    }
    let _ = writeln!(
        body,
        "\n## Skinny triangles (§VI-A, Fig. 8)\n\nOver all planes of all datasets above. \
         Polygon-based: {} of its triangles are isosceles right triangles (paper: ≈ 80 %).\n",
        pct(right_isosceles.0, right_isosceles.1)
    );
    body.push_str(&t3.render());
    let chart = angle_chart(&angles);
    chart.save(&ctx.out.join("planar_mesh_angles.png"))?;
    let _ = writeln!(
        body,
        "\n![Angle distribution](planar_mesh_angles.png)\n\nThe distribution of all \
         triangle angles in 5° bins centred on multiples of 5°, each method's normalised to sum to 1 (Fig. 8 of the \
         paper).\n"
    );

    // Table III.
    timing_table(ctx, &data, &mut body)?;
    body.push_str(&notes);
    Ok(Section {
        file: "planar_mesh.md",
        title: "Ma et al. 2013, Tables I–III and Fig. 8 — planar simplification and texturing"
            .to_owned(),
        body,
    })
}

fn angle_chart(angles: &[Vec<f64>]) -> Chart {
    // Bins centred on multiples of 5° (so right angles fall at 90, not at a bin edge).
    let bins = 37usize;
    let mut top: f64 = 0.0;
    let series = METHODS
        .iter()
        .zip(angles)
        .enumerate()
        .map(|(k, ((_, _, name), a))| {
            let mut counts = vec![0usize; bins];
            for &x in a {
                counts[((x / 5.0).round() as usize).min(bins - 1)] += 1;
            }
            let n = a.len().max(1) as f64;
            let points: Vec<(f64, f64)> = counts
                .iter()
                .enumerate()
                .map(|(b, &c)| (5.0 * b as f64, c as f64 / n))
                .collect();
            top = points.iter().map(|p| p.1).fold(top, f64::max);
            Series {
                label: name.trim_start_matches("polygon-based, ").to_uppercase(),
                points,
                color: PALETTE[k % PALETTE.len()],
                dashed: k == 3,
            }
        })
        .collect();
    Chart {
        title: "TRIANGLE ANGLES OF THE PLANAR MESHES (FIG. 8)".to_owned(),
        x: Axis {
            label: "ANGLE (DEGREES)".to_owned(),
            log: false,
            ticks: (0..=6).map(|k| f64::from(k) * 30.0).collect(),
        },
        y: Axis {
            label: "SHARE OF ANGLES".to_owned(),
            log: false,
            ticks: linear_ticks(top.max(0.01)),
        },
        series,
    }
}

fn timing_table(ctx: &Ctx, data: &[Dataset], body: &mut String) -> Result<()> {
    let runs = ctx.runs(2, 15, 4);
    let parallel = ctx.parallel_threads();
    let mut header = vec!["configuration".to_owned()];
    header.extend(data.iter().map(|d| d.name.clone()));
    let mut table = Table::new(header);
    let texture = TextureOptions::new();
    let rows: [(&str, Method, bool, usize); 6] = [
        ("serial point-based", Method::Point, false, 1),
        ("serial polygon-based", Method::Polygon, false, 1),
        ("serial polygon-based (texture)", Method::Polygon, true, 1),
        ("N threads point-based", Method::Point, false, parallel),
        ("N threads polygon-based", Method::Polygon, false, parallel),
        (
            "N threads polygon-based (texture)",
            Method::Polygon,
            true,
            parallel,
        ),
    ];
    let mut frame_textured = Vec::new();
    for (name, method, textured, threads) in rows {
        let mut options = SimplifyOptions::new()
            .with_method(method)
            .with_parallel(threads > 1);
        if textured {
            options = options.with_texture(texture);
        }
        let mut row = vec![name.replace("N threads", &format!("{threads} threads"))];
        for d in data {
            let stats = ctx.on_threads(threads, || measure(runs, || meshes(d, &options)))?;
            if textured && threads == parallel && d.frame {
                frame_textured.push((d.name.clone(), stats.median));
            }
            row.push(stats.cell());
        }
        table.row(row);
    }
    let _ = writeln!(
        body,
        "## Table III — time of decimation + triangulation + texture\n\nWall time of \
         `Extraction::planar_meshes` after plane extraction (gathering each plane's points \
         and colours, plane fit, decimation, triangulation, texture at 100 texels per metre; \
         not the merge or the files), in ms: {}. Serial rows run the planes one after the \
         other on one thread; the others run them on a rayon pool of that many threads \
         (largest plane first; texture rows in parallel within a plane). The paper's \
         Table III gives seconds for whole maps (serial polygon-based with texture: 8.3, \
         10.0, 20.3, 41.4 s; 1 segmentation + 5 triangulation threads: 4.7, 3.5, 8.7, \
         16.2 s).\n",
        runs.describe()
    );
    body.push_str(&table.render());
    if !frame_textured.is_empty() {
        let _ = writeln!(
            body,
            "\nSpeed target (issue 17): all planes of a 640 × 480 frame simplified and \
             textured in at most 15 ms on 2 threads after plane extraction. Measured on {} \
             threads: {}.\n",
            parallel,
            frame_textured
                .iter()
                .map(|(n, t)| format!(
                    "{n} {} ms{}",
                    ms(*t),
                    if *t <= 15.0 { " (met)" } else { " (not met)" }
                ))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    Ok(())
}
