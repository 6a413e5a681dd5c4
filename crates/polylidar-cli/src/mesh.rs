//! `polylidar mesh`: planes and polygons → simplified, textured meshes (Ma et al. 2013)
//! written as OBJ + MTL + PNG and PLY, with a `--plot` of the textured wireframe.

mod render;

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::{Args, ValueEnum};
use polylidar::io::{CameraSource, DepthCamera};
use polylidar::planar_mesh::{
    Depth, MergedMesh, Method, Packing, Resolution, SimplifyOptions, TextureOptions, export,
};
use polylidar::{Decimation, Extraction, Intrinsics, Polylidar};
use polylidar_io::{ColorImage, Format};

use crate::args::{CameraArgs, InputArgs};
use crate::input::{Input, Loaded, camera, load_with_camera};
use crate::outputs::Outputs;
use crate::params;
use crate::run::{CliError, Outcome, on_input, record_inputs, run_once};

/// Arguments of `polylidar mesh`.
#[derive(Debug, Args)]
pub struct MeshArgs {
    /// The input and the parameters of the plane extraction (as `extract`).
    #[command(flatten)]
    pub input: InputArgs,
    /// The mesh, as Wavefront OBJ; beside it `<name>.mtl`, the texture `<name>.png` (or
    /// `<name>_plane_<k>.png` with `--per-plane`) and `<name>.ply`.
    #[arg(short, long, value_name = "FILE.obj", help_heading = "Mesh")]
    pub output: PathBuf,
    /// Texture the planes from the points' colours: a depth PNG's colour picture
    /// (`--color`, or found beside it: `depth` → `color`/`rgb` in the name, .png/.jpg),
    /// a PCD's `rgb`/`rgba` field, a PLY's vertex colours.
    #[arg(long, help_heading = "Mesh")]
    pub texture: bool,
    /// Triangulation: `polygon` (two right triangles per quadtree node, the band to the
    /// boundary by constrained Delaunay), `point` (constrained Delaunay of all kept
    /// vertices), or `boundary` (boundary vertices only: the paper's baseline).
    #[arg(long, value_enum, default_value_t = MethodArg::Polygon, help_heading = "Mesh")]
    pub method: MethodArg,
    /// Quadtree depth (1–16). Default: per plane, the finest cell between 2 and 4
    /// boundary spacings.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=16), help_heading = "Mesh")]
    pub depth: Option<u32>,
    /// Texels per unit length (per metre for metric input), or `auto`: one per point
    /// spacing. Default: 100 (the paper's).
    #[arg(long, value_name = "R|auto", help_heading = "Mesh")]
    pub resolution: Option<String>,
    /// One PNG per plane instead of one atlas.
    #[arg(long, help_heading = "Mesh")]
    pub per_plane: bool,
    /// Polygon-based: split interior nodes with smaller neighbours so that the mesh has
    /// no T-joints anywhere (more triangles).
    #[arg(long, help_heading = "Mesh")]
    pub conforming: bool,
    /// The colour picture of a depth PNG (8-bit PNG or JPEG of the same size).
    #[arg(long, value_name = "FILE", help_heading = "Mesh")]
    pub color: Option<PathBuf>,
    /// The camera of a depth PNG input (as `extract`).
    #[command(flatten)]
    pub camera: CameraArgs,
    /// Draw the textured mesh with its wireframe into a PNG: from the camera for depth
    /// images, else an oblique orthographic view.
    #[arg(long, value_name = "FILE", help_heading = "Mesh")]
    pub plot: Option<PathBuf>,
    /// Print one JSON object with counts and timings on stdout.
    #[arg(long, help_heading = "Mesh")]
    pub json: bool,
}

/// `--method`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum MethodArg {
    /// Polygon-based triangulation (§IV-B2).
    Polygon,
    /// Point-based triangulation (§IV-B1).
    Point,
    /// Boundary vertices only (the paper's baseline).
    Boundary,
}

impl From<MethodArg> for Method {
    fn from(m: MethodArg) -> Self {
        match m {
            MethodArg::Polygon => Method::Polygon,
            MethodArg::Point => Method::Point,
            MethodArg::Boundary => Method::Boundary,
        }
    }
}

/// What a depth frame brings besides its cloud: the camera, for `--plot`.
struct Frame {
    camera: Option<render::Camera>,
}

/// Runs `polylidar mesh`.
///
/// # Errors
/// Unreadable input or colours, bad parameters, unwritable output.
pub fn mesh(args: &MeshArgs) -> Result<Outcome, CliError> {
    let mut outputs = Outputs::new();
    record_inputs(&mut outputs, &args.input);
    if let Some(path) = &args.color {
        outputs.input("the --color file", path);
    }
    let camera = camera(&args.camera)?;
    if let CameraSource::File(path) = &camera.source {
        outputs.input("the --intrinsics file", path);
    }
    let names = MeshNames::new(&args.output);
    outputs.plan("-o", &args.output)?;
    outputs.plan("-o (.mtl)", &names.mtl)?;
    outputs.plan("-o (.ply)", &names.ply)?;
    if args.texture && !args.per_plane {
        outputs.plan("-o (.png)", &names.texture(Packing::Atlas, 0))?;
    }
    if let Some(plot) = &args.plot {
        outputs.plan("--plot", plot)?;
    }
    let stride = args.input.stride as usize;
    let path = args.input.input.as_deref();
    let (Loaded { input, source, .. }, frame) = load_input(args, &camera, path, stride)?;
    let chosen = params::config_for(&args.input, &input, None)?;
    params::check_kernels(&chosen.config, &input, &source)?;
    let polylidar = Polylidar::new(chosen.config.clone())?;
    let extraction = run_once(&polylidar, &input).map_err(on_input(&source))?;
    let colors = if args.texture {
        Some(colors_for(args, path, stride, &extraction)?)
    } else {
        None
    };
    let options = mesh_options(args)?;
    let started = Instant::now();
    let meshes = extraction
        .planar_meshes(colors.as_deref(), &options)
        .map_err(on_input(&source))?;
    let packing = if args.per_plane {
        Packing::PerPlane
    } else {
        Packing::Atlas
    };
    let merged = meshes.merged(packing);
    let mesh_seconds = started.elapsed().as_secs_f64();
    for (k, why) in &meshes.skipped {
        eprintln!("warning: plane {k} not meshed: {why}");
    }
    stage_mesh(&mut outputs, &names, &meshes, &merged)?;
    if let Some(plot) = &args.plot {
        let textures: Vec<_> = meshes
            .planes
            .iter()
            .map(|(_, m)| m.texture.as_ref())
            .collect();
        let camera = match (&extraction.decimation, frame.camera) {
            (Some(d), Some((k, _, _))) => Some(decimated_camera(k, d)),
            (_, camera) => camera,
        };
        let png = render::render(&merged, &textures, camera, polylidar.config().up).map_err(
            |message| CliError::Write {
                path: plot.clone(),
                message,
            },
        )?;
        outputs.stage("--plot", plot, &png)?;
    }
    let files = outputs.commit()?;
    report(
        args,
        &source,
        &extraction,
        &meshes,
        &merged,
        mesh_seconds,
        &files,
    );
    Ok(Outcome::Done)
}

fn mesh_options(args: &MeshArgs) -> Result<SimplifyOptions, CliError> {
    let mut options = SimplifyOptions::new()
        .with_method(args.method.into())
        .with_conforming(args.conforming);
    if let Some(d) = args.depth {
        options = options.with_depth(Depth::Fixed(d));
    }
    if args.texture {
        let resolution = match args.resolution.as_deref() {
            None => Resolution::default(),
            Some("auto") => Resolution::FromDensity,
            Some(text) => match text.parse::<f64>() {
                Ok(r) if r.is_finite() && r > 0.0 => Resolution::PerUnit(r),
                _ => {
                    return Err(CliError::Unsupported {
                        what: format!("--resolution {text}: texels per unit (> 0) or `auto`"),
                    });
                }
            },
        };
        options = options.with_texture(TextureOptions::new().with_resolution(resolution));
    }
    Ok(options)
}

/// The input, a depth PNG read with `camera` (`--intrinsics`, `--depth-scale`, as
/// `extract`), and for `--plot` the intrinsics of the cloud at the stride's resolution.
fn load_input(
    args: &MeshArgs,
    camera: &DepthCamera,
    path: Option<&Path>,
    stride: usize,
) -> Result<(Loaded, Frame), CliError> {
    let loaded = load_with_camera(path, args.input.demo, stride, args.input.max_memory, camera)?;
    let depth_png = path.filter(|p| polylidar_io::format_of(p) == Some(Format::DepthPng));
    let camera = match (depth_png, &loaded.input) {
        (Some(png), Input::Organized(cloud)) => {
            let k = match &camera.source {
                CameraSource::Pinhole(k) => *k,
                CameraSource::File(file) => {
                    Intrinsics::from(&polylidar_io::read_camera_file(file)?)
                }
                CameraSource::Beside => Intrinsics::from(&polylidar_io::read_camera_file(
                    polylidar_io::metadata_path_for(png)?,
                )?),
            };
            // Every stride-th pixel: the intrinsics shrink by the stride.
            let s = stride as f64;
            Some((
                Intrinsics::new(k.fx / s, k.fy / s, k.ppx / s, k.ppy / s),
                cloud.cols(),
                cloud.rows(),
            ))
        }
        _ => None,
    };
    Ok((loaded, Frame { camera }))
}

/// The camera of a decimated cloud: a point per block of `factor` pixels, at the block's
/// centre.
fn decimated_camera(k: Intrinsics, decimation: &Decimation) -> render::Camera {
    let f = decimation.factor as f64;
    let centre = (f - 1.0) / 2.0;
    let (rows, cols) = decimation.grid();
    (
        Intrinsics::new(
            k.fx / f,
            k.fy / f,
            (k.ppx - centre) / f,
            (k.ppy - centre) / f,
        ),
        cols,
        rows,
    )
}

/// One colour per vertex of the extraction's mesh, from the input's own colours.
fn colors_for(
    args: &MeshArgs,
    path: Option<&Path>,
    stride: usize,
    extraction: &Extraction,
) -> Result<Vec<[u8; 3]>, CliError> {
    let none = |why: &str| CliError::Unsupported {
        what: format!("--texture needs colours: {why}"),
    };
    let path = path.ok_or_else(|| none("the built-in demos have none"))?;
    let colors = match polylidar_io::format_of(path) {
        Some(Format::DepthPng) => {
            let picture = match &args.color {
                Some(c) => c.clone(),
                None => polylidar_io::color_path_for(path)?,
            };
            let image = polylidar_io::read_color_image(&picture)?;
            downsample(&image, stride, &picture)?
        }
        Some(Format::Pcd) => polylidar_io::read_pcd_colors(path)?
            .ok_or_else(|| none("the PCD file has no rgb or rgba field"))?,
        Some(Format::Ply) => polylidar_io::read_ply_colors(path)?
            .ok_or_else(|| none("the PLY file has no red, green, blue vertex properties"))?,
        _ => {
            return Err(none(
                "only depth PNGs (with their colour picture), PCD and PLY files carry them",
            ));
        }
    };
    let colors = match &extraction.decimation {
        Some(d) => d.block_colors(&colors).map_err(|_| {
            none(&format!(
                "{} colours for {} × {} pixels",
                colors.len(),
                d.rows,
                d.cols
            ))
        })?,
        None => colors,
    };
    let vertices = extraction.mesh.num_vertices();
    if colors.len() != vertices {
        return Err(none(&format!(
            "{} colours for {vertices} points of the mesh",
            colors.len()
        )));
    }
    Ok(colors)
}

/// Every `stride`-th row and column of a colour picture, as the depth image's cloud.
fn downsample(image: &ColorImage, stride: usize, path: &Path) -> Result<Vec<[u8; 3]>, CliError> {
    if image.width == 0 || image.height == 0 {
        return Err(CliError::Unsupported {
            what: format!("{}: an empty picture", path.display()),
        });
    }
    Ok((0..image.height)
        .step_by(stride)
        .flat_map(|r| {
            (0..image.width)
                .step_by(stride)
                .map(move |c| image.rgb[r * image.width + c])
        })
        .collect())
}

/// The files of `polylidar mesh -o <name>.obj`: `<name>.mtl`, `<name>.ply` and the
/// texture(s) beside it.
struct MeshNames {
    /// The OBJ file.
    obj: PathBuf,
    /// `<name>`.
    stem: String,
    /// `<name>.mtl`.
    mtl: PathBuf,
    /// `<name>.ply`.
    ply: PathBuf,
}

impl MeshNames {
    fn new(output: &Path) -> Self {
        let stem = output
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "mesh".to_owned());
        Self {
            obj: output.to_path_buf(),
            mtl: output.with_file_name(format!("{stem}.mtl")),
            ply: output.with_file_name(format!("{stem}.ply")),
            stem,
        }
    }

    /// The texture's file name (as the MTL and PLY refer to it) for `plane`.
    fn texture_name(&self, packing: Packing, plane: usize) -> String {
        match packing {
            Packing::Atlas => format!("{}.png", self.stem),
            Packing::PerPlane => format!("{}_plane_{plane}.png", self.stem),
        }
    }

    /// The texture's path for `plane`.
    fn texture(&self, packing: Packing, plane: usize) -> PathBuf {
        self.obj.with_file_name(self.texture_name(packing, plane))
    }
}

/// Stages OBJ, MTL, PNG(s) and PLY ([`Outputs::stage`]).
fn stage_mesh(
    outputs: &mut Outputs,
    names: &MeshNames,
    meshes: &polylidar::PlanarMeshes,
    merged: &MergedMesh,
) -> Result<(), CliError> {
    let packing = merged.packing;
    let mtl_name = format!("{}.mtl", names.stem);
    let obj = export::obj_text(merged, Some(&mtl_name));
    outputs.stage("-o", &names.obj, obj.as_bytes())?;
    let mtl = export::mtl_text(merged, |plane| names.texture_name(packing, plane));
    outputs.stage("-o (.mtl)", &names.mtl, mtl.as_bytes())?;
    if let Some(atlas) = &merged.atlas {
        let png = export::png_bytes(atlas.width, atlas.height, &atlas.rgb)?;
        outputs.stage("-o (.png)", &names.texture(packing, 0), &png)?;
    } else if !merged.uv.is_empty() {
        for (plane, mesh) in &meshes.planes {
            if let Some(t) = &mesh.texture {
                let png = export::png_bytes(t.width, t.height, &t.rgb)?;
                let flag = format!("-o (plane {plane} .png)");
                outputs.stage(&flag, &names.texture(packing, *plane), &png)?;
            }
        }
    }
    let textures: Vec<_> = meshes
        .planes
        .iter()
        .map(|(_, m)| m.texture.as_ref())
        .collect();
    let by_plane: Vec<_> = {
        let mut v = vec![None; meshes.planes.iter().map(|(k, _)| k + 1).max().unwrap_or(0)];
        for ((k, _), t) in meshes.planes.iter().zip(&textures) {
            v[*k] = *t;
        }
        v
    };
    let colors = export::vertex_colors(merged, &by_plane);
    let ply_texture = (packing == Packing::Atlas).then(|| names.texture_name(packing, 0));
    let ply = export::ply_bytes(merged, ply_texture.as_deref(), &colors);
    outputs.stage("-o (.ply)", &names.ply, &ply)
}

fn report(
    args: &MeshArgs,
    source: &str,
    extraction: &Extraction,
    meshes: &polylidar::PlanarMeshes,
    merged: &MergedMesh,
    mesh_seconds: f64,
    files: &[PathBuf],
) {
    let points: usize = meshes.planes.iter().map(|(_, m)| m.stats.points).sum();
    let kept: usize = meshes
        .planes
        .iter()
        .map(|(_, m)| m.stats.kept_vertices())
        .sum();
    let full: usize = meshes
        .planes
        .iter()
        .map(|(k, _)| extraction.polygons[*k].triangles.len())
        .sum();
    let texels: usize = meshes
        .planes
        .iter()
        .filter_map(|(_, m)| m.texture.as_ref())
        .map(|t| t.width as usize * t.height as usize)
        .sum();
    if args.json {
        let value = serde_json::json!({
            "input": source,
            "method": format!("{:?}", args.method).to_lowercase(),
            "planes": meshes.planes.len(),
            "skipped": meshes.skipped.iter().map(|(k, e)| serde_json::json!({"plane": k, "reason": e.to_string()})).collect::<Vec<_>>(),
            "planar_points": points,
            "kept_vertices": kept,
            "triangles": merged.triangles.len(),
            "segment_triangles": full,
            "texels": texels,
            "decimate_factor": extraction.decimation.as_ref().map_or(1, |d| d.factor),
            "extract_ms": 1e3 * extraction.diagnostics.timings.total().as_secs_f64(),
            "mesh_ms": 1e3 * meshes.seconds,
            "mesh_and_merge_ms": 1e3 * mesh_seconds,
            "files": files.iter().map(|f| f.display().to_string()).collect::<Vec<_>>(),
        });
        println!("{value}");
        return;
    }
    let pct = |a: usize, b: usize| 100.0 * a as f64 / b.max(1) as f64;
    println!(
        "{source}: {} planes meshed ({} skipped)",
        meshes.planes.len(),
        meshes.skipped.len()
    );
    if let Some(d) = &extraction.decimation {
        let (rows, cols) = d.grid();
        println!(
            "  decimated {0} × {0}: planes of the {cols} × {rows} grid, each vertex \
             coloured by its block",
            d.factor
        );
    }
    println!(
        "  vertices kept {kept} of {points} planar points ({:.1} %), triangles {} of {full} ({:.1} %)",
        pct(kept, points),
        merged.triangles.len(),
        pct(merged.triangles.len(), full)
    );
    if texels > 0 {
        println!("  texture {texels} texels");
    }
    println!(
        "  {:.1} ms after plane extraction ({:.1} ms meshing{})",
        1e3 * mesh_seconds,
        1e3 * meshes.seconds,
        if texels > 0 { " and texturing" } else { "" }
    );
    for f in files {
        println!("  wrote {}", f.display());
    }
}
