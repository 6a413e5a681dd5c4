//! Building the pipeline's parameters: preset (metres, converted into the input's unit),
//! then config file, then flags, then lengths nobody gave derived from the data.

use std::path::Path;

use polylidar::scale::{alpha_for_spacing, convert_lengths, lmax_for_spacing};
use polylidar::{Config, DecimateFactor, Preset, SmoothingBackend};
use polylidar_io::LengthUnit;

use crate::args::{Demo, InputArgs, Mode, ParamArgs};
use crate::input::{DEMO_SHAPE_POINTS, Input};
use crate::run::CliError;

/// Where the unit of the input's coordinates came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UnitSource {
    /// `--units`.
    Flag,
    /// The LAS/LAZ header.
    Header,
    /// Nothing said: metres assumed.
    Assumed,
}

/// The parameters chosen for one input, and how.
#[derive(Debug, Clone)]
pub struct Chosen {
    /// The configuration to run.
    pub config: Config,
    /// The preset it started from.
    pub preset: Option<String>,
    /// The unit of the input's coordinates (and of every length of `config`).
    pub unit: LengthUnit,
    /// Where `unit` came from.
    pub unit_source: UnitSource,
    /// The median nearest-neighbour spacing, when it was measured (2D and 2.5D input).
    pub spacing: Option<f64>,
    /// Lines for the summary on how lengths were chosen, e.g.
    /// `lmax 4.1 ft (from spacing 1.0 ft)`.
    pub notes: Vec<String>,
}

/// Which length parameters the config file or a flag set explicitly.
#[derive(Debug, Clone, Copy, Default)]
struct Explicit {
    alpha: bool,
    lmax: bool,
    min_triangles: bool,
}

/// The configuration `args` asks for, with a preset's lengths in `--units` (metres when
/// not given); nothing is derived from data. Used where the input is organized (scores
/// against ground truth), so the organized inputs' default preset applies.
pub fn config(args: &InputArgs) -> Result<Config, CliError> {
    let unit = args.units.unwrap_or(LengthUnit::Metre);
    Ok(layered(args, unit, true)?.0)
}

/// The preset `args` selects: `--preset`; else `synpeb-auto` for the scene demo; else,
/// when neither `--preset` nor `--config` is given and the input is `organized`, the
/// adaptive detector for its sensor: `rgbd-auto` for a depth image (`.png`),
/// `synpeb-auto` for any other organized cloud (a range scan). Other inputs have no
/// default preset: their lengths are derived from the data ([`config_for`]).
pub fn preset_name(args: &InputArgs, organized: bool) -> Option<PresetChoice<'_>> {
    match (&args.preset, args.demo, &args.input) {
        (Some(name), _, _) => Some(PresetChoice::Asked(name)),
        (None, Some(Demo::Scene), None) => Some(PresetChoice::Asked("synpeb-auto")),
        (None, None, Some(path)) if organized && args.config.is_none() => {
            let depth_image = path
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("png"));
            Some(if depth_image {
                PresetChoice::Default("rgbd-auto", "depth images")
            } else {
                PresetChoice::Default("synpeb-auto", "organized clouds")
            })
        }
        _ => None,
    }
}

/// A preset and why it was chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PresetChoice<'a> {
    /// Named by `--preset` (or implied by a demo).
    Asked(&'a str),
    /// The default for a kind of input, named by the second field (no `--preset` and no
    /// `--config` given).
    Default(&'a str, &'static str),
}

impl<'a> PresetChoice<'a> {
    /// The preset's name.
    pub fn name(self) -> &'a str {
        match self {
            Self::Asked(name) | Self::Default(name, _) => name,
        }
    }
}

/// Preset (converted from metres into `unit`), config file, flags; and which lengths the
/// file or the flags set. `organized` says whether the input is organized (its default
/// preset, [`preset_name`]).
fn layered(
    args: &InputArgs,
    unit: LengthUnit,
    organized: bool,
) -> Result<(Config, Explicit), CliError> {
    let mut explicit = Explicit::default();
    let mut config = match preset_name(args, organized).map(PresetChoice::name) {
        Some(name) => {
            let preset: Preset = name.parse().map_err(|_| CliError::Preset {
                name: name.to_owned(),
                known: Preset::all()
                    .iter()
                    .map(|p| p.name())
                    .collect::<Vec<_>>()
                    .join(", "),
            })?;
            convert_lengths(&preset.config(), 1.0 / unit.metres())
        }
        None if args.demo == Some(Demo::Shape) && args.input.is_none() => {
            explicit.alpha = true;
            shape_demo_config()
        }
        None => Config::default(),
    };
    if let Some(path) = &args.config {
        let (merged, keys) = merge_file(config, path)?;
        config = merged;
        explicit.alpha |= keys.iter().any(|k| k == "alpha");
        explicit.lmax |= keys.iter().any(|k| k == "lmax");
        explicit.min_triangles |= keys.iter().any(|k| k == "min_triangles");
    }
    apply_flags(&mut config, &args.params)?;
    explicit.alpha |= args.params.alpha.is_some();
    explicit.lmax |= args.params.lmax.is_some();
    explicit.min_triangles |= args.params.min_triangles.is_some();
    Ok((config, explicit))
}

/// Takes the unorganized 3D path ([`polylidar::Config::unorganized`]) or the 2.5D one as
/// `--mode` says (`auto`: 3D when the file stores normals or the preset asks for it).
fn apply_mode(args: &InputArgs, config: &mut Config) -> Result<(), CliError> {
    let three_d = match args.mode {
        Mode::ThreeD => true,
        Mode::TwoAndHalfD => false,
        Mode::Auto => {
            config.unorganized.is_some()
                || match args.input.as_deref() {
                    Some(path) => polylidar::unorganized::file_has_normals(path)?,
                    None => false,
                }
        }
    };
    if three_d {
        config.unorganized.get_or_insert_with(Default::default);
    } else {
        config.unorganized = None;
    }
    Ok(())
}

/// The parameters for a loaded `input` whose file declares `header_unit`.
///
/// Lengths are in the input's unit: `--units`, else the LAS/LAZ header's, else metres.
/// For 2D and 2.5D input the median nearest-neighbour spacing `s` is measured, and the
/// length filters neither the config file nor a flag set are derived from it:
///
/// * 2D: `alpha` = 4.2 · s (the 2D paper's α for a uniform sample), unless a preset's
///   `lmax` is kept (raised to at least 4 · s);
/// * 2.5D: `lmax` = 4 · s, or the preset's if that is longer; `alpha` stays the
///   preset's (0: off).
pub fn config_for(
    args: &InputArgs,
    input: &Input,
    header_unit: Option<LengthUnit>,
) -> Result<Chosen, CliError> {
    let (unit, unit_source) = match (args.units, header_unit) {
        (Some(u), _) => (u, UnitSource::Flag),
        (None, Some(u)) => (u, UnitSource::Header),
        (None, None) => (LengthUnit::Metre, UnitSource::Assumed),
    };
    let organized = matches!(input, Input::Organized(_));
    let (mut config, explicit) = layered(args, unit, organized)?;
    if matches!(input, Input::Cloud(_)) {
        apply_mode(args, &mut config)?;
    }
    let choice = preset_name(args, organized);
    let preset = choice.map(|c| c.name().to_owned());
    let mut notes = Vec::new();
    if let Some(PresetChoice::Default(name, inputs)) = choice {
        notes.push(format!(
            "{name}: the default for {inputs} (--preset to choose another)"
        ));
    }
    let spacing = match input {
        Input::Points2d(points) => Some(polylidar::scale::median_spacing_2d(points)?),
        Input::Cloud(points) if config.unorganized.is_some() => {
            Some(polylidar::unorganized::median_spacing(points)?)
        }
        Input::Cloud(points) => Some(polylidar::scale::median_spacing_25d(points, config.up)?),
        _ => None,
    };
    let derive = match input {
        Input::Points2d(_) => !(explicit.alpha || explicit.lmax),
        _ => !explicit.lmax,
    };
    let from = |s: f64| format!("from spacing {}", length(s, unit));
    if let Some(s) = spacing.filter(|_| derive) {
        match input {
            Input::Points2d(_) if config.lmax > 0.0 => {
                let floor = lmax_for_spacing(s);
                if config.lmax < floor {
                    notes.push(format!(
                        "lmax {} (the preset's {} raised to 4 × spacing {})",
                        length(floor, unit),
                        length(config.lmax, unit),
                        length(s, unit)
                    ));
                    config.lmax = floor;
                }
            }
            Input::Points2d(_) => {
                config.alpha = alpha_for_spacing(s);
                notes.push(format!(
                    "alpha {} ({})",
                    length(config.alpha, unit),
                    from(s)
                ));
            }
            _ => {
                let derived = lmax_for_spacing(s);
                if config.lmax >= derived {
                    notes.push(format!(
                        "lmax {} (the preset's; spacing {})",
                        length(config.lmax, unit),
                        length(s, unit)
                    ));
                } else if config.lmax > 0.0 {
                    notes.push(format!(
                        "lmax {} (the preset's {} raised to 4 × spacing {})",
                        length(derived, unit),
                        length(config.lmax, unit),
                        length(s, unit)
                    ));
                    config.lmax = derived;
                } else {
                    config.lmax = derived;
                    notes.push(format!("lmax {} ({})", length(derived, unit), from(s)));
                }
            }
        }
    }
    if let (Input::Cloud(points), Some(s)) = (input, spacing)
        && preset.is_none()
        && config.unorganized.is_none()
        && !explicit.min_triangles
        && let Some((n, area)) =
            polylidar::scale::min_triangles_for_extent(points, config.up, s, config.min_triangles)
        && n > config.min_triangles
    {
        config.min_triangles = n;
        notes.push(format!(
            "min_triangles {n} (regions of {} {}², 1/10,000 of the extent)",
            significant(area),
            unit.symbol()
        ));
    }
    Ok(Chosen {
        config,
        preset,
        unit,
        unit_source,
        spacing,
        notes,
    })
}

/// Refuses a smoothing kernel wider than an organized input's image (`source` names the
/// input): the filters leave the pixels within `kernel / 2` of the edge as they are, so
/// such a kernel smooths nothing. The Laplacian works on the `rows × cols` pixels, the
/// bilateral filter on the `(rows − 1) × (cols − 1)` cells between them.
///
/// # Errors
/// [`CliError::Unsupported`] naming the input, the kernel, the image and what to do.
pub fn check_kernels(config: &Config, input: &Input, source: &str) -> Result<(), CliError> {
    let Input::Organized(cloud) = input else {
        return Ok(());
    };
    let (rows, cols) = (cloud.rows(), cloud.cols());
    let filters = [
        (
            "laplacian.kernel",
            config.laplacian.map(|l| l.kernel),
            rows,
            cols,
            "pixels",
        ),
        (
            "bilateral.kernel",
            config.bilateral.map(|b| b.kernel),
            rows.saturating_sub(1),
            cols.saturating_sub(1),
            "cells",
        ),
    ];
    for (field, kernel, r, c, what) in filters {
        if let Some(k) = kernel
            && (k as usize > r || k as usize > c)
        {
            // The largest odd kernel that still smooths something.
            let fits = r.min(c).saturating_sub(1 - r.min(c) % 2);
            let remedy = if fits >= 3 {
                format!("use a kernel of at most {fits} (in --config) or --no-smoothing")
            } else {
                "the image is too small to smooth; use --no-smoothing".to_owned()
            };
            return Err(CliError::Unsupported {
                what: format!(
                    "{source}: {field} {k} is wider than the image's {r} × {c} {what}, so \
                     nothing would be smoothed; {remedy}"
                ),
            });
        }
    }
    Ok(())
}

/// A length with 3 significant digits and its unit: `4.07 ft`.
pub fn length(value: f64, unit: LengthUnit) -> String {
    format!("{} {unit}", significant(value))
}

/// `value` with 3 significant digits, without trailing zeros.
pub fn significant(value: f64) -> String {
    if value == 0.0 || !value.is_finite() {
        return value.to_string();
    }
    let digits = (2 - value.abs().log10().floor() as i32).max(0) as usize;
    let text = format!("{value:.digits$}");
    if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.').to_owned()
    } else {
        text
    }
}

/// α = 2·√(area / n) for the demo shape, as in the 2D paper's benchmarks.
fn shape_demo_config() -> Config {
    use synthscan::shapes::{demo_shape, paper_alpha};
    Config::new()
        .with_alpha(paper_alpha(&demo_shape(), DEMO_SHAPE_POINTS))
        .with_min_triangles(20)
        .with_min_hole_vertices(6)
}

/// `base` with every field the TOML file sets replaced (tables merged key by key), and
/// the top-level keys the file sets.
fn merge_file(base: Config, path: &Path) -> Result<(Config, Vec<String>), CliError> {
    let error = |message: String| CliError::Config {
        path: path.to_path_buf(),
        message,
    };
    let text = std::fs::read_to_string(path).map_err(|e| error(e.to_string()))?;
    let file: toml::Table = toml::from_str(&text).map_err(|e| error(e.to_string()))?;
    let keys = file.keys().cloned().collect();
    let mut merged = toml::Table::try_from(&base).map_err(|e| error(e.to_string()))?;
    merge(&mut merged, file);
    let config = merged
        .try_into()
        .map_err(|e: toml::de::Error| error(e.to_string()))?;
    Ok((config, keys))
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

fn apply_flags(config: &mut Config, flags: &ParamArgs) -> Result<(), CliError> {
    let ParamArgs {
        alpha,
        lmax,
        min_triangles,
        min_area,
        min_hole_vertices,
        norm_thresh,
        z_thresh,
        up,
        threads,
        no_smoothing,
        decimate,
        gpu,
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
    if let Some(v) = min_area {
        config.min_area = *v;
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
    match up.as_deref() {
        None => {}
        Some(&[x, y, z]) => config.up = [x, y, z],
        Some(other) => {
            return Err(CliError::Unsupported {
                what: format!(
                    "--up needs three numbers (`--up 0,0,1` or `--up 0 0 1`), got {}",
                    other.len()
                ),
            });
        }
    }
    if let Some(v) = threads {
        config.threads = *v;
    }
    if *no_smoothing {
        config.laplacian = None;
        config.bilateral = None;
    }
    match *decimate {
        None => {}
        Some(DecimateFactor::Fixed(1)) => config.decimate = None,
        Some(factor) => {
            config.decimate = Some(config.decimate.unwrap_or_default().with_factor(factor));
        }
    }
    if *gpu {
        if !cfg!(feature = "gpu") {
            return Err(CliError::Unsupported {
                what: "--gpu needs a polylidar built with the `gpu` feature (`cargo install \
                       polylidar-cli --features gpu`, or `cargo run -p polylidar-cli \
                       --features gpu` in the workspace)"
                    .to_owned(),
            });
        }
        *config = config.clone().with_smoothing_backend(SmoothingBackend::Gpu);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn significant_keeps_three_digits() {
        assert_eq!(significant(2.952755), "2.95");
        assert_eq!(significant(0.0123456), "0.0123");
        assert_eq!(significant(1234.6), "1235");
        assert_eq!(significant(4.0), "4");
        assert_eq!(significant(0.0), "0");
    }
}
