//! The tables, one module each, and the index (`README.md`) that lists them.

mod accuracy;
mod fastga;
mod kitti;
mod pipeline;
mod planar_mesh;
mod realsense;
mod rgbd_accuracy;
mod rgbd_frames;
mod scaling;
mod shapes2d;
mod smoothing;
mod synpeb_accuracy;
mod synpeb_timing;
mod unorganized;

use std::fmt::Write as _;

use crate::bench::Ctx;
use crate::error::{Result, msg};
use crate::report::{Section, write};

/// One table: its key, the other names `--only` accepts, its file and its runner.
pub struct TableSpec {
    /// Name for `--only`.
    pub key: &'static str,
    /// Other accepted names (paper table numbers).
    pub aliases: &'static [&'static str],
    /// Files it writes (markdown first).
    pub files: &'static [&'static str],
    /// Runs the table.
    pub run: fn(&Ctx) -> Result<Section>,
}

/// Every table, in the order they run (timing tables first).
pub const ALL: &[TableSpec] = &[
    TableSpec {
        key: "fastga",
        aliases: &["2", "table2"],
        files: &["table02_fastga.md"],
        run: fastga::run,
    },
    TableSpec {
        key: "smoothing",
        aliases: &["12", "13", "table12", "table13"],
        files: &["table12_13_smoothing.md"],
        run: smoothing::run,
    },
    TableSpec {
        key: "realsense",
        aliases: &["8", "table8"],
        files: &["table08_realsense.md"],
        run: realsense::run,
    },
    TableSpec {
        key: "kitti",
        aliases: &["kitti-range", "velodyne", "t4", "t5"],
        files: &["table05_kitti.md"],
        run: kitti::run,
    },
    TableSpec {
        key: "shapes",
        aliases: &["2d", "3", "4", "5", "6", "iii", "iv", "v", "vi"],
        files: &["shapes_2d.md", "shapes_2d_time.png", "shapes_2d_error.png"],
        run: shapes2d::run,
    },
    TableSpec {
        key: "scaling",
        aliases: &["21", "fig21"],
        files: &["scaling_threads.md", "scaling_threads.png"],
        run: scaling::run,
    },
    TableSpec {
        key: "synpeb-timing",
        aliases: &["11", "table11"],
        files: &["table11_synpeb_timing.md"],
        run: synpeb_timing::run,
    },
    TableSpec {
        key: "synpeb-accuracy",
        aliases: &["10", "table10"],
        files: &["table10_synpeb_accuracy.md"],
        run: synpeb_accuracy::run,
    },
    TableSpec {
        key: "planar-mesh",
        aliases: &["ma", "ma2013", "mesh", "i", "ii"],
        files: &["planar_mesh.md", "planar_mesh_angles.png"],
        run: planar_mesh::run,
    },
    TableSpec {
        key: "rgbd-accuracy",
        aliases: &["10b"],
        files: &["table10b_rgbd_accuracy.md"],
        run: rgbd_accuracy::run,
    },
    TableSpec {
        key: "unorganized",
        aliases: &["10u", "table10u"],
        files: &["table10u_unorganized.md"],
        run: unorganized::run,
    },
];

/// The tables `--only` names (all without it), in run order.
///
/// # Errors
/// An unknown name.
pub fn select(only: Option<&str>) -> Result<Vec<&'static TableSpec>> {
    let Some(only) = only else {
        return Ok(ALL.iter().collect());
    };
    let mut keep = Vec::new();
    for name in only
        .split(',')
        .map(|s| s.trim().to_lowercase())
        .filter(|s| !s.is_empty())
    {
        let name = name.trim_start_matches("table").trim().to_owned();
        let found = ALL
            .iter()
            .position(|t| t.key == name || t.aliases.contains(&name.as_str()))
            .ok_or_else(|| {
                msg(format!(
                    "--only: unknown table `{name}`; use {}",
                    ALL.iter().map(|t| t.key).collect::<Vec<_>>().join(", ")
                ))
            })?;
        keep.push(found);
    }
    keep.sort_unstable();
    keep.dedup();
    Ok(keep.into_iter().map(|k| &ALL[k]).collect())
}

/// Writes `README.md` in the output folder: the machine, how to reproduce, and the
/// tables and charts present there.
///
/// # Errors
/// File-system errors.
pub fn write_index(ctx: &Ctx) -> Result<()> {
    let mut s = String::new();
    let m = &ctx.machine;
    let _ = writeln!(s, "# Benchmarks\n");
    let _ = writeln!(
        s,
        "Timing and accuracy tables in the style of the Polylidar3D paper (Castagno & Atkins, \
         2020) and the Polylidar 2D paper, measured on polylidar-rs by `cargo xtask bench`. \
         Every table names the machine, thread counts, run counts and the load average while \
         it ran, and puts the paper's figure beside ours for context.\n"
    );
    let _ = writeln!(s, "## Machine of the last run\n");
    let _ = writeln!(s, "* CPU: {}", m.cpu);
    let _ = writeln!(s, "* cores (available parallelism): {}", m.cores);
    if let Some(g) = m.memory_gib {
        let _ = writeln!(s, "* memory: {g:.0} GiB");
    }
    let _ = writeln!(s, "* OS: {}", m.os);
    let _ = writeln!(s, "* compiler: {} (release profile)", m.rustc);
    let _ = writeln!(
        s,
        "* date: {}{}\n",
        m.date,
        if ctx.quick { " (`--quick` run)" } else { "" }
    );
    let _ = writeln!(
        s,
        "The paper's figures come from different hardware (AMD Ryzen 9 3900X, 12 cores, \
         4.2 GHz; NVIDIA RTX 2070 Super) and from C++/Python code; compare trends and ratios, \
         not absolute times. On a shared machine whose load average exceeds 1 the timings are \
         noisy; each table says so in its header when that happened. `--only` republishes some \
         tables and leaves the others: each table's header names the machine and date it was \
         measured on, and cloud machines of one name differ (the CPU line gives family, model \
         and vector extension; an AVX2 machine takes 1.4–1.7 times as long for the \
         bilateral filter as an AVX-512 one, and about as long for the other stages: see \
         `amd-epyc-avx2/`), so compare timings within a table.\n"
    );
    let _ = writeln!(s, "## Results\n");
    for spec in ALL {
        let mut any = false;
        for file in spec.files {
            let path = ctx.out.join(file);
            if !path.is_file() {
                continue;
            }
            any = true;
            if file.ends_with(".md") {
                let title = std::fs::read_to_string(&path)
                    .ok()
                    .and_then(|t| {
                        t.lines()
                            .next()
                            .map(|l| l.trim_start_matches('#').trim().to_owned())
                    })
                    .unwrap_or_else(|| (*file).to_owned());
                let _ = writeln!(s, "* [{title}]({file})");
            } else {
                let _ = writeln!(s, "  * chart: [{file}]({file})");
            }
        }
        if !any {
            let _ = writeln!(
                s,
                "* `{}`: not generated yet (`cargo xtask bench --only {}`)",
                spec.key, spec.key
            );
        }
    }
    other_machines(ctx, &mut s);
    let _ = writeln!(
        s,
        "\n## Reproduce\n\n```sh\ncargo xtask bench            # everything: about 4 minutes \
         on 2 cores\ncargo xtask bench --quick    # fewer runs and sizes: under a minute\n\
         cargo xtask bench --only fastga,smoothing --threads 1,2,4\ncargo run -p xtask \
         --release --features gpu -- bench   # adds GPU smoothing rows where an adapter \
         exists\n```\n\nGPU rows appear in a build with `--features gpu` where wgpu finds an \
         adapter; each table names the adapter, and marks a software one (Mesa's lavapipe) \
         as not GPU speed.\n\n\
         The real data come from `../shared/fixtures` next to the workspace (`--fixtures DIR` \
         to point elsewhere); tables whose fixtures are missing say so. The synthetic \
         SynPEB-like suite is generated by the `synthscan` crate and needs no files."
    );
    write(&ctx.out.join("README.md"), &s)
}

/// Lists the runs kept in sub-folders of the output folder (tables measured on other
/// machines, such as a GPU's), each by its `README.md`'s title.
fn other_machines(ctx: &Ctx, s: &mut String) {
    let Ok(entries) = std::fs::read_dir(&ctx.out) else {
        return;
    };
    let mut runs: Vec<(String, String)> = entries
        .filter_map(|e| {
            let dir = e.ok()?.path();
            let text = std::fs::read_to_string(dir.join("README.md")).ok()?;
            let title = text
                .lines()
                .next()?
                .trim_start_matches('#')
                .trim()
                .to_owned();
            let name = dir.file_name()?.to_str()?.to_owned();
            Some((name, title))
        })
        .collect();
    if runs.is_empty() {
        return;
    }
    runs.sort();
    let _ = writeln!(s, "\n## Other machines\n");
    for (name, title) in runs {
        let _ = writeln!(s, "* [{title}]({name}/README.md)");
    }
}
