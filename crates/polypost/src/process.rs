//! The public entry points: one polygon or many, in 2D or on a plane in 3D.

use geo::{Coord, LineString, Polygon};
use rayon::prelude::*;

use crate::PostError;
use crate::config::PostprocessConfig;
use crate::diagnostics::{DropReason, PostDiagnostics};
use crate::pipeline::{Scratch, process_polygon};
use crate::plane::{Plane, PlaneFrame, norm};
use plane_geom::Polygon3;

/// A processed 2D polygon and the input it came from.
#[derive(Debug, Clone, PartialEq)]
pub struct SourcedPolygon2 {
    /// Index of the input polygon.
    pub source: u32,
    /// The polygon: valid for `geo::Validation`, shell counter-clockwise, holes clockwise,
    /// rings closed (as `geo` requires).
    pub polygon: Polygon<f64>,
}

/// A processed 3D polygon and the input it came from.
#[derive(Debug, Clone, PartialEq)]
pub struct SourcedPolygon3 {
    /// Index of the input polygon (and of its plane).
    pub source: u32,
    /// The polygon, on the input's plane; valid in the plane's 2D frame.
    pub polygon: Polygon3,
}

/// Result of 2D post-processing: polygons ordered by `source`, and what happened.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Output2 {
    /// Output polygons, grouped by source in input order; an input may give zero, one or
    /// several (a multipolygon).
    pub polygons: Vec<SourcedPolygon2>,
    /// Counts and drop reasons.
    pub diagnostics: PostDiagnostics,
}

/// Result of 3D post-processing: polygons ordered by `source`, and what happened.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Output3 {
    /// Output polygons, grouped by source in input order; an input may give zero, one or
    /// several (a multipolygon).
    pub polygons: Vec<SourcedPolygon3>,
    /// Counts and drop reasons.
    pub diagnostics: PostDiagnostics,
}

impl Output2 {
    /// The polygons that came from input `source`.
    pub fn of_source(&self, source: u32) -> &[SourcedPolygon2] {
        let lo = self.polygons.partition_point(|p| p.source < source);
        let hi = self.polygons.partition_point(|p| p.source <= source);
        &self.polygons[lo..hi]
    }
}

impl Output3 {
    /// The polygons that came from input `source`.
    pub fn of_source(&self, source: u32) -> &[SourcedPolygon3] {
        let lo = self.polygons.partition_point(|p| p.source < source);
        let hi = self.polygons.partition_point(|p| p.source <= source);
        &self.polygons[lo..hi]
    }
}

/// Post-processes polygons with a checked [`PostprocessConfig`].
///
/// Every polygon returned is valid for `geo::Validation` (in its plane's 2D frame for 3D
/// input). Inputs that are invalid are repaired first; inputs that cannot be made valid are
/// dropped and reported in [`PostDiagnostics`], never returned.
///
/// The `*_many` methods process polygons in parallel on the current rayon thread pool
/// (run them inside `ThreadPool::install` to choose the thread count); the result is
/// identical whatever the number of threads.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PostProcessor {
    config: PostprocessConfig,
}

impl PostProcessor {
    /// A processor for `config`.
    ///
    /// # Errors
    /// As [`PostprocessConfig::validate`].
    pub fn new(config: PostprocessConfig) -> Result<Self, PostError> {
        config.validate()?;
        Ok(Self { config })
    }

    /// The configuration in use.
    pub fn config(&self) -> &PostprocessConfig {
        &self.config
    }

    /// Post-processes one 2D polygon (coordinates in metres, e.g. from the 2D pipeline);
    /// the outputs have `source` 0.
    pub fn process_2d(&self, polygon: &Polygon<f64>) -> Output2 {
        let mut diagnostics = PostDiagnostics::default();
        let polygons = self.one_2d(polygon, 0, &mut diagnostics, &mut Scratch::default());
        Output2 {
            polygons,
            diagnostics,
        }
    }

    /// Post-processes many 2D polygons in parallel; output `source` is the input index.
    ///
    /// # Errors
    /// [`PostError::TooManyPolygons`] for more than `u32::MAX` inputs.
    pub fn process_many_2d(&self, polygons: &[Polygon<f64>]) -> Result<Output2, PostError> {
        check_count(polygons.len())?;
        let vertices = |p: &Polygon<f64>| {
            p.exterior().0.len() + p.interiors().iter().map(|h| h.0.len()).sum::<usize>()
        };
        let per_input = largest_first(
            polygons.len(),
            |i| vertices(&polygons[i]),
            |scratch, i| {
                let mut d = PostDiagnostics::default();
                let out = self.one_2d(&polygons[i], i as u32, &mut d, scratch);
                (out, d)
            },
        );
        let mut out = Output2::default();
        for (polys, d) in per_input {
            out.polygons.extend(polys);
            out.diagnostics.merge(&d);
        }
        Ok(out)
    }

    /// Post-processes one 3D polygon on `plane`: its points are projected orthogonally
    /// onto the plane's [`PlaneFrame`], processed in 2D and lifted back onto the plane.
    /// The outputs have `source` 0.
    pub fn process_3d(&self, polygon: &Polygon3, plane: &Plane) -> Output3 {
        let mut diagnostics = PostDiagnostics::default();
        let polygons = self.one_3d(polygon, plane, 0, &mut diagnostics, &mut Scratch::default());
        Output3 {
            polygons,
            diagnostics,
        }
    }

    /// Post-processes `polygons[i]` on `planes[i]` for every `i`, in parallel; output
    /// `source` is the input index.
    ///
    /// # Errors
    /// [`PostError::LengthMismatch`] if the slices differ in length,
    /// [`PostError::TooManyPolygons`] for more than `u32::MAX` inputs.
    pub fn process_many_3d(
        &self,
        polygons: &[Polygon3],
        planes: &[Plane],
    ) -> Result<Output3, PostError> {
        if polygons.len() != planes.len() {
            return Err(PostError::LengthMismatch {
                polygons: polygons.len(),
                planes: planes.len(),
            });
        }
        check_count(polygons.len())?;
        let vertices = |p: &Polygon3| p.shell.len() + p.holes.iter().map(Vec::len).sum::<usize>();
        let per_input = largest_first(
            polygons.len(),
            |i| vertices(&polygons[i]),
            |scratch, i| {
                let mut d = PostDiagnostics::default();
                let out = self.one_3d(&polygons[i], &planes[i], i as u32, &mut d, scratch);
                (out, d)
            },
        );
        let mut out = Output3::default();
        for (polys, d) in per_input {
            out.polygons.extend(polys);
            out.diagnostics.merge(&d);
        }
        Ok(out)
    }

    fn one_2d(
        &self,
        polygon: &Polygon<f64>,
        source: u32,
        diag: &mut PostDiagnostics,
        scratch: &mut Scratch,
    ) -> Vec<SourcedPolygon2> {
        process_polygon(polygon, &self.config, source, diag, scratch)
            .into_iter()
            .map(|polygon| SourcedPolygon2 { source, polygon })
            .collect()
    }

    fn one_3d(
        &self,
        polygon: &Polygon3,
        plane: &Plane,
        source: u32,
        diag: &mut PostDiagnostics,
        scratch: &mut Scratch,
    ) -> Vec<SourcedPolygon3> {
        if !plane_is_usable(plane) {
            diag.input_polygons += 1;
            diag.drop_invalid(source, DropReason::BadPlane);
            return Vec::new();
        }
        let frame = plane.frame();
        let flat = project(polygon, &frame);
        process_polygon(&flat, &self.config, source, diag, scratch)
            .into_iter()
            .map(|p| SourcedPolygon3 {
                source,
                polygon: lift(&p, &frame),
            })
            .collect()
    }
}

/// `run(scratch, i)` for every input `i < count` in parallel, the costliest first
/// (`cost(i)`: its vertices), with the results in input order. A frame's polygons differ
/// in cost a hundredfold (the buffers' cost grows faster than their vertex count): the
/// largest left to the end would keep one worker busy while the others wait. Each input
/// is processed on its own, so the order changes no result.
fn largest_first<T: Send>(
    count: usize,
    cost: impl Fn(usize) -> usize,
    run: impl Fn(&mut Scratch, usize) -> T + Sync,
) -> Vec<T> {
    let mut order: Vec<usize> = (0..count).collect();
    order.sort_by_key(|&i| std::cmp::Reverse(cost(i)));
    // One input per task: rayon otherwise runs a few neighbours of the order in one
    // task, which no other worker can take over.
    let mut done: Vec<(usize, T)> = order
        .into_par_iter()
        .with_max_len(1)
        .map_init(Scratch::default, |scratch, i| (i, run(scratch, i)))
        .collect();
    done.sort_unstable_by_key(|&(i, _)| i);
    done.into_iter().map(|(_, t)| t).collect()
}

fn check_count(n: usize) -> Result<(), PostError> {
    if u32::try_from(n).is_err() {
        return Err(PostError::TooManyPolygons { count: n });
    }
    Ok(())
}

fn plane_is_usable(plane: &Plane) -> bool {
    let n = norm(plane.normal);
    n.is_finite()
        && (n - 1.0).abs() < 1e-6
        && plane.offset.is_finite()
        && plane.centroid.iter().all(|c| c.is_finite())
}

/// The polygon's rings projected into the frame (closing point added as `geo` wants).
fn project(polygon: &Polygon3, frame: &PlaneFrame) -> Polygon<f64> {
    let ring = |r: &[[f64; 3]]| {
        LineString(
            r.iter()
                .map(|&p| {
                    let q = frame.project(p);
                    Coord { x: q[0], y: q[1] }
                })
                .collect(),
        )
    };
    Polygon::new(
        ring(&polygon.shell),
        polygon.holes.iter().map(|h| ring(h)).collect(),
    )
}

/// The 2D polygon lifted onto the frame's plane, rings open.
fn lift(polygon: &Polygon<f64>, frame: &PlaneFrame) -> Polygon3 {
    let ring = |r: &LineString<f64>| -> Vec<[f64; 3]> {
        let open = &r.0[..r.0.len().saturating_sub(1)];
        open.iter().map(|c| frame.lift([c.x, c.y])).collect()
    };
    Polygon3 {
        shell: ring(polygon.exterior()),
        holes: polygon.interiors().iter().map(ring).collect(),
    }
}
