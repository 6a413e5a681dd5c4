//! One planar segment → a simplified, optionally textured mesh; many segments in parallel.

use std::time::Instant;

use rayon::prelude::*;

use crate::PlanarMeshError;
use crate::frame::fit_frame;
use crate::polygon::{Polygon2, ring_area};
use crate::quadtree::{MAX_DEPTH, Quadtree, auto_depth};
use crate::texture::{Texture, TextureOptions, generate};
use crate::triangulate::{Method, triangulate_segment};
use plane_geom::PlaneFrame;

/// A planar segment: its points (with colours for a texture) and the boundary polygon
/// extracted for it (Polylidar3D's shell and holes), used as the concave hull.
#[derive(Debug, Clone, Copy)]
pub struct Segment<'a> {
    /// The segment's points.
    pub points: &'a [[f64; 3]],
    /// One colour per point, or `None`.
    pub colors: Option<&'a [[u8; 3]]>,
    /// The shell (open or closed ring; either orientation).
    pub shell: &'a [[f64; 3]],
    /// The holes.
    pub holes: &'a [Vec<[f64; 3]>],
}

impl<'a> Segment<'a> {
    /// A segment without colours.
    pub fn new(points: &'a [[f64; 3]], shell: &'a [[f64; 3]], holes: &'a [Vec<[f64; 3]>]) -> Self {
        Self {
            points,
            colors: None,
            shell,
            holes,
        }
    }

    /// Adds one colour per point.
    pub fn with_colors(mut self, colors: &'a [[u8; 3]]) -> Self {
        self.colors = Some(colors);
        self
    }
}

/// The quadtree depth.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Depth {
    /// Per segment: the shallowest depth whose finest cell is at most
    /// [`AUTO_CELL_EDGES`](crate::AUTO_CELL_EDGES) median boundary edge lengths.
    #[default]
    Auto,
    /// This depth for every segment (`2^depth` cells per side, 1 to [`MAX_DEPTH`]).
    Fixed(u32),
}

/// Options of [`simplify`] and [`simplify_all`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct SimplifyOptions {
    /// Triangulation method (default polygon-based).
    pub method: Method,
    /// Quadtree depth (default [`Depth::Auto`]).
    pub depth: Depth,
    /// Interior nodes stay this many finest cells away from every boundary edge (default
    /// 0: the paper's classification, any node not meeting an edge). A little clearance
    /// avoids interior vertices right next to the boundary and the thin triangles between
    /// them.
    pub clearance: f64,
    /// Polygon-based: split every interior node that has smaller neighbours' vertices on
    /// its sides, so that the whole mesh is free of T-joints (more triangles). Default
    /// `false`: as the paper, T-joints stay between interior nodes; nodes touching the
    /// band are split either way, so the band's outline never has one.
    pub conforming: bool,
    /// Texture settings, or `None` for no texture (default).
    pub texture: Option<TextureOptions>,
    /// [`simplify_all`]: segments on rayon's pool (default `true`); `false` runs them one
    /// after the other. The texture's rows use the pool either way.
    pub parallel: bool,
}

impl Default for SimplifyOptions {
    fn default() -> Self {
        Self {
            method: Method::default(),
            depth: Depth::default(),
            clearance: 0.0,
            conforming: false,
            texture: None,
            parallel: true,
        }
    }
}

impl SimplifyOptions {
    /// The defaults: polygon-based, automatic depth, no clearance, no texture, parallel.
    pub fn new() -> Self {
        Self::default()
    }

    /// Sets the triangulation method.
    pub fn with_method(mut self, method: Method) -> Self {
        self.method = method;
        self
    }

    /// Sets the quadtree depth.
    pub fn with_depth(mut self, depth: Depth) -> Self {
        self.depth = depth;
        self
    }

    /// Sets the clearance in finest cells.
    pub fn with_clearance(mut self, clearance: f64) -> Self {
        self.clearance = clearance;
        self
    }

    /// Sets whether the polygon-based interior is split into a conforming mesh.
    pub fn with_conforming(mut self, conforming: bool) -> Self {
        self.conforming = conforming;
        self
    }

    /// Asks for a texture.
    pub fn with_texture(mut self, texture: TextureOptions) -> Self {
        self.texture = Some(texture);
        self
    }

    /// Sets whether segments run in parallel.
    pub fn with_parallel(mut self, parallel: bool) -> Self {
        self.parallel = parallel;
        self
    }

    fn validate(&self) -> Result<(), PlanarMeshError> {
        if let Depth::Fixed(d) = self.depth
            && !(1..=MAX_DEPTH).contains(&d)
        {
            return Err(PlanarMeshError::BadOption {
                name: "depth",
                value: f64::from(d),
                expected: "1 to 16",
            });
        }
        if !(self.clearance.is_finite() && (0.0..=4.0).contains(&self.clearance)) {
            return Err(PlanarMeshError::BadOption {
                name: "clearance",
                value: self.clearance,
                expected: "0 to 4 finest cells",
            });
        }
        match &self.texture {
            Some(t) => t.validate(),
            None => Ok(()),
        }
    }
}

/// Counts and timings of one simplified segment.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PlaneStats {
    /// Points of the segment.
    pub points: usize,
    /// Distinct boundary (shell and hole) vertices, all kept.
    pub boundary_vertices: usize,
    /// Interior vertices: corners of the merged interior nodes.
    pub interior_vertices: usize,
    /// Merged interior nodes.
    pub interior_nodes: usize,
    /// Polygon-based: the first this many triangles are the interior nodes' right
    /// triangles, the rest fill the band; 0 for the other methods.
    pub interior_triangles: usize,
    /// Quadtree depth used (0 for the boundary-only baseline, which builds none).
    pub depth: u32,
    /// Seconds spent on preprocessing and decimation.
    pub decimate_s: f64,
    /// Seconds spent on triangulation.
    pub triangulate_s: f64,
    /// Seconds spent on the texture (0 without).
    pub texture_s: f64,
}

impl PlaneStats {
    /// Vertices kept by the decimation: boundary plus interior.
    pub fn kept_vertices(&self) -> usize {
        self.boundary_vertices + self.interior_vertices
    }
}

/// The simplified mesh of one planar segment.
#[derive(Debug, Clone, PartialEq)]
pub struct PlaneMesh {
    /// The fitted plane; triangles are counter-clockwise about its normal, which is
    /// oriented so that the shell is counter-clockwise too.
    pub frame: PlaneFrame,
    /// Vertices in plane coordinates; the first [`PlaneStats::boundary_vertices`] are the
    /// polygon's distinct ring vertices.
    pub vertices_2d: Vec<[f64; 2]>,
    /// The same vertices in 3D, on the fitted plane.
    pub vertices: Vec<[f64; 3]>,
    /// Triangles, counter-clockwise about [`PlaneFrame::normal`].
    pub triangles: Vec<[u32; 3]>,
    /// The texture, when asked for.
    pub texture: Option<Texture>,
    /// Texture coordinates of every vertex (empty without a texture).
    pub uv: Vec<[f64; 2]>,
    /// Counts and timings.
    pub stats: PlaneStats,
}

/// The segment's polygon in the plane frame, with the frame flipped if needed so that the
/// shell is counter-clockwise.
fn plane_polygon(segment: &Segment<'_>) -> Result<(PlaneFrame, Polygon2), PlanarMeshError> {
    for (what, ring) in std::iter::once(("shell vertex", segment.shell))
        .chain(segment.holes.iter().map(|h| ("hole vertex", h.as_slice())))
    {
        if let Some(index) = ring.iter().position(|p| !p.iter().all(|v| v.is_finite())) {
            return Err(PlanarMeshError::NonFinite {
                what,
                index,
                value: ring[index],
            });
        }
    }
    let mut frame = fit_frame(segment.points)?;
    let project = |frame: &PlaneFrame, ring: &[[f64; 3]]| -> Vec<[f64; 2]> {
        ring.iter().map(|p| frame.project(*p)).collect()
    };
    let mut shell = project(&frame, segment.shell);
    if ring_area(&shell) < 0.0 {
        frame = frame.flipped();
        shell = project(&frame, segment.shell);
    }
    let holes = segment.holes.iter().map(|h| project(&frame, h)).collect();
    let polygon = Polygon2::new(shell, holes)
        .filter(|p| p.area() > 0.0)
        .ok_or_else(|| {
            let ring: Vec<[f64; 2]> = project(&frame, segment.shell);
            let mut distinct = ring.clone();
            distinct.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
            distinct.dedup();
            PlanarMeshError::EmptyShell {
                vertices: distinct.len(),
                area: ring_area(&ring).abs(),
            }
        })?;
    Ok((frame, polygon))
}

impl PlaneMesh {
    /// The triangles' total area in square metres (signed: positive, as they are
    /// counter-clockwise in the plane frame).
    pub fn area(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| self.vertices_2d[v as usize]);
                crate::quality::signed_area(a, b, c)
            })
            .sum()
    }
}

/// Simplifies one planar segment: plane fit and transform, quadtree decimation,
/// triangulation by `options.method`, and the texture when asked for.
///
/// ```
/// use planar_mesh::{Method, SimplifyOptions, Segment, simplify};
///
/// // A 1 m square plane sampled every 1 cm, its outline as the polygon.
/// let points: Vec<[f64; 3]> = (0..101 * 101)
///     .map(|k| [(k % 101) as f64 * 0.01, (k / 101) as f64 * 0.01, 2.0])
///     .collect();
/// let shell: Vec<[f64; 3]> = (0..100).map(|i| [i as f64 * 0.01, 0.0, 2.0])
///     .chain((0..100).map(|i| [1.0, i as f64 * 0.01, 2.0]))
///     .chain((0..100).map(|i| [1.0 - i as f64 * 0.01, 1.0, 2.0]))
///     .chain((0..100).map(|i| [0.0, 1.0 - i as f64 * 0.01, 2.0]))
///     .collect();
/// let mesh = simplify(&Segment::new(&points, &shell, &[]), &SimplifyOptions::new())?;
/// assert!((mesh.area() - 1.0).abs() < 1e-9);
/// // Far fewer triangles than the 20,000 of the full grid.
/// assert!(mesh.triangles.len() < 2_000);
/// # Ok::<(), planar_mesh::PlanarMeshError>(())
/// ```
///
/// # Errors
/// Bad options, too few or non-finite points, points spanning no plane, a shell without
/// area, colours not one per point, a texture asked for without colours.
pub fn simplify(
    segment: &Segment<'_>,
    options: &SimplifyOptions,
) -> Result<PlaneMesh, PlanarMeshError> {
    options.validate()?;
    if let Some(colors) = segment.colors
        && colors.len() != segment.points.len()
    {
        return Err(PlanarMeshError::ColorCount {
            colors: colors.len(),
            points: segment.points.len(),
        });
    }
    if options.texture.is_some() && segment.colors.is_none() {
        return Err(PlanarMeshError::NoColors);
    }
    let start = Instant::now();
    let (frame, polygon) = plane_polygon(segment)?;
    let depth = match options.depth {
        Depth::Auto => auto_depth(&polygon),
        Depth::Fixed(d) => d,
    };
    // The boundary-only baseline decimates everything inside.
    let tree = (options.method != Method::Boundary)
        .then(|| Quadtree::build(&polygon, depth, options.clearance));
    let decimated = Instant::now();
    let tri = triangulate_segment(&polygon, tree.as_ref(), options.method, options.conforming)?;
    let vertices = tri.vertices.iter().map(|q| frame.lift(*q)).collect();
    let triangulated = Instant::now();
    let (texture, uv) = match (&options.texture, segment.colors) {
        (Some(t), Some(colors)) => {
            let points: Vec<[f64; 2]> = segment.points.iter().map(|p| frame.project(*p)).collect();
            let texture = generate(&polygon, &points, colors, t)?;
            let uv = tri.vertices.iter().map(|q| texture.uv(*q)).collect();
            (Some(texture), uv)
        }
        _ => (None, Vec::new()),
    };
    let stats = PlaneStats {
        points: segment.points.len(),
        boundary_vertices: tri.boundary,
        interior_vertices: tree.as_ref().map_or(0, |t| t.vertices.len()),
        interior_nodes: tree.as_ref().map_or(0, |t| t.interior.len()),
        interior_triangles: tri.interior_triangles,
        depth: if tree.is_some() { depth } else { 0 },
        decimate_s: (decimated - start).as_secs_f64(),
        triangulate_s: (triangulated - decimated).as_secs_f64(),
        texture_s: triangulated.elapsed().as_secs_f64(),
    };
    Ok(PlaneMesh {
        frame,
        vertices_2d: tri.vertices,
        vertices,
        triangles: tri.triangles,
        texture,
        uv,
        stats,
    })
}

/// Simplifies every segment, in parallel on rayon's current pool unless
/// `options.parallel` is `false`; results in input order, one per segment (planes are
/// independent: one that fails does not stop the others).
pub fn simplify_all(
    segments: &[Segment<'_>],
    options: &SimplifyOptions,
) -> Vec<Result<PlaneMesh, PlanarMeshError>> {
    if options.parallel {
        // Largest first, so that a big plane does not start last.
        let mut order: Vec<usize> = (0..segments.len()).collect();
        order.sort_by_key(|&i| std::cmp::Reverse(segments[i].points.len()));
        let mut done: Vec<(usize, Result<PlaneMesh, PlanarMeshError>)> = order
            .into_par_iter()
            .with_max_len(1)
            .map(|i| (i, simplify(&segments[i], options)))
            .collect();
        done.sort_by_key(|(i, _)| *i);
        done.into_iter().map(|(_, r)| r).collect()
    } else {
        segments.iter().map(|s| simplify(s, options)).collect()
    }
}
