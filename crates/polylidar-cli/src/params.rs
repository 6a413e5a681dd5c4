//! Building the pipeline's parameters: preset, then config file, then flags.

use std::path::Path;

use polylidar::{Config, PRESETS};

use crate::args::{Demo, InputArgs, ParamArgs};
use crate::input::DEMO_SHAPE_POINTS;
use crate::run::CliError;

/// The configuration `args` asks for. Without a preset, the scene demo uses `synpeb-auto`
/// (Laplacian iterations chosen from the measured noise) and the shape demo the 2D
/// paper's α for its point count.
pub fn config(args: &InputArgs) -> Result<Config, CliError> {
    let preset = match (&args.preset, args.demo, &args.input) {
        (Some(name), _, _) => Some(name.as_str()),
        (None, Some(Demo::Scene), None) => Some("synpeb-auto"),
        _ => None,
    };
    let mut config = match preset {
        Some(name) => Config::preset(name).ok_or_else(|| CliError::Preset {
            name: name.to_owned(),
            known: PRESETS.join(", "),
        })?,
        None if args.demo == Some(Demo::Shape) && args.input.is_none() => shape_demo_config(),
        None => Config::default(),
    };
    if let Some(path) = &args.config {
        config = merge_file(config, path)?;
    }
    apply_flags(&mut config, &args.params);
    Ok(config)
}

/// α = 2·√(area / n) for the demo shape, as in the 2D paper's benchmarks.
fn shape_demo_config() -> Config {
    use polylidar::shapes::{demo_shape, paper_alpha};
    Config::new()
        .with_alpha(paper_alpha(&demo_shape(), DEMO_SHAPE_POINTS))
        .with_min_triangles(20)
        .with_min_hole_vertices(6)
}

/// `base` with every field the TOML file sets replaced (tables merged key by key).
fn merge_file(base: Config, path: &Path) -> Result<Config, CliError> {
    let error = |message: String| CliError::Config {
        path: path.to_path_buf(),
        message,
    };
    let text = std::fs::read_to_string(path).map_err(|e| error(e.to_string()))?;
    let file: toml::Table = toml::from_str(&text).map_err(|e| error(e.to_string()))?;
    let mut merged = toml::Table::try_from(&base).map_err(|e| error(e.to_string()))?;
    merge(&mut merged, file);
    merged
        .try_into()
        .map_err(|e: toml::de::Error| error(e.to_string()))
}

fn merge(into: &mut toml::Table, from: toml::Table) {
    for (key, value) in from {
        match (into.get_mut(&key), value) {
            (Some(toml::Value::Table(inner)), toml::Value::Table(table)) => merge(inner, table),
            (_, value) => {
                into.insert(key, value);
            }
        }
    }
}

fn apply_flags(config: &mut Config, flags: &ParamArgs) {
    let ParamArgs {
        alpha,
        lmax,
        min_triangles,
        min_hole_vertices,
        norm_thresh,
        z_thresh,
        up,
        threads,
        no_smoothing,
    } = flags;
    if let Some(v) = alpha {
        config.alpha = *v;
    }
    if let Some(v) = lmax {
        config.lmax = *v;
    }
    if let Some(v) = min_triangles {
        config.min_triangles = *v;
    }
    if let Some(v) = min_hole_vertices {
        config.min_hole_vertices = *v;
    }
    if let Some(v) = norm_thresh {
        config.norm_thresh = *v;
    }
    if let Some(v) = z_thresh {
        config.z_thresh = *v;
    }
    if let Some([x, y, z]) = up.as_deref() {
        config.up = [*x, *y, *z];
    }
    if let Some(v) = threads {
        config.threads = *v;
    }
    if *no_smoothing {
        config.laplacian = None;
        config.bilateral = None;
    }
}
