//! The 2D post-processing of one polygon: sanitise, simplify, repair, buffer out, buffer
//! in, filter by area, check validity.

use geo::algorithm::bool_ops::FillRule;
use geo::algorithm::buffer::{BufferStyle, LineJoin};
use geo::{Area, BooleanOps, Buffer, ConvexHull, Coord, LineString, MultiPolygon, OpType, Polygon};

use crate::config::{BufferJoin, PostprocessConfig};
use crate::diagnostics::{DropReason, PostDiagnostics};
use crate::simplify::{SimplifyScratch, simplify_polygon};
use crate::valid::{ValidityScratch, check_valid, fast_valid};

/// Reusable buffers of one worker.
#[derive(Debug, Default)]
pub(crate) struct Scratch {
    valid: ValidityScratch,
    simplify: SimplifyScratch,
}

/// Runs the whole pipeline on `polygon` (input number `source`), recording what happened
/// in `diag`. Every polygon returned is valid for `geo::Validation`, has a
/// counter-clockwise shell and clockwise holes.
pub(crate) fn process_polygon(
    polygon: &Polygon<f64>,
    config: &PostprocessConfig,
    source: u32,
    diag: &mut PostDiagnostics,
    scratch: &mut Scratch,
) -> Vec<Polygon<f64>> {
    diag.input_polygons += 1;
    let polygon = match sanitize(polygon, diag) {
        Ok(p) => p,
        Err(reason) => {
            diag.drop_invalid(source, reason);
            return Vec::new();
        }
    };
    if config.min_area > 0.0 && area_bound(&polygon, config) < config.min_area {
        diag.dropped_by_area += 1;
        return Vec::new();
    }
    // The paper's order: simplify first, the rings as they are, even where they cross;
    // what is then not valid is repaired, on rings often ten times shorter.
    let parts = if config.alpha > 0.0 {
        let simple = simplify_polygon(&polygon, config.alpha, &mut scratch.simplify);
        if fast_valid(&simple, &mut scratch.valid) {
            vec![simple]
        } else {
            if fast_valid(&polygon, &mut scratch.valid) {
                diag.repaired_after_simplify += 1;
            } else {
                diag.repaired_inputs += 1;
            }
            repair(&simple).0
        }
    } else if fast_valid(&polygon, &mut scratch.valid) {
        vec![polygon]
    } else {
        diag.repaired_inputs += 1;
        repair(&polygon).0
    };
    if parts.is_empty() {
        diag.drop_invalid(source, DropReason::NoAreaAfterRepair);
        return Vec::new();
    }
    let mut shape = MultiPolygon(parts);
    if config.beta_pos > 0.0 && !shape.0.is_empty() {
        shape = shape.buffer_with_style(buffer_style(config.beta_pos, config.buffer_join));
    }
    if config.beta_neg > 0.0 && !shape.0.is_empty() {
        // Buffering inwards only takes area away: an input below γ as a whole now can give
        // no part of γ, so it is dropped without the costlier of the two buffers.
        if config.min_area > 0.0 && shape.unsigned_area() < config.min_area {
            diag.dropped_by_area += 1;
            return Vec::new();
        }
        shape = shape.buffer_with_style(buffer_style(-config.beta_neg, config.buffer_join));
    }
    shape.0.retain(|p| !p.exterior().0.is_empty());
    if shape.0.is_empty() {
        diag.vanished += 1;
        return Vec::new();
    }
    let mut out = Vec::with_capacity(shape.0.len());
    for part in shape.0 {
        if part.unsigned_area() < config.min_area {
            diag.dropped_by_area += 1;
            continue;
        }
        let part = finish(part, config.min_hole_area, diag);
        match check_valid(&part, &mut scratch.valid) {
            Ok(()) => out.push(part),
            Err(detail) => {
                diag.drop_invalid(source, DropReason::InvalidAfterProcessing { detail });
            }
        }
    }
    diag.output_polygons += out.len() as u32;
    out
}

/// An upper bound on the area of every part post-processing can make of `polygon`, for
/// dropping at once what cannot reach `min_area` (most polygons of a depth frame, and the
/// buffers are the expensive steps). The convex hull `H` of the shell contains the
/// polygon, its simplification (Ramer–Douglas–Peucker keeps a subset of the vertices) and
/// its repair (the region inside the shell); the outward buffer reaches at most `r` from
/// it, so it stays inside `H` grown by `r`, whose area is
/// `area(H) + perimeter(H) · r + π r²` (Steiner's formula for convex sets); the inward
/// buffer only removes area.
fn area_bound(polygon: &Polygon<f64>, config: &PostprocessConfig) -> f64 {
    let hull = polygon.exterior().convex_hull();
    let ring = &hull.exterior().0;
    let perimeter: f64 = ring
        .windows(2)
        .map(|w| (w[1].x - w[0].x).hypot(w[1].y - w[0].y))
        .sum();
    let r = config.beta_pos * buffer_reach(config.buffer_join);
    let bound = hull.unsigned_area() + perimeter * r + std::f64::consts::PI * r * r;
    // Rounding in the buffers' arithmetic is far below this margin.
    bound * (1.0 + 1e-9) + f64::EPSILON
}

/// How far an outward buffer of distance 1 with `join` reaches from the polygon at most:
/// 1 for bevels, the circumscribed arc's vertices for round joins, the longest miter kept
/// for miter joins (angles clamped as the offsetter clamps them).
fn buffer_reach(join: BufferJoin) -> f64 {
    use std::f64::consts::PI;
    match join {
        BufferJoin::Round { max_angle } => {
            1.0 / (max_angle.clamp(0.01 * PI, 0.25 * PI) / 2.0).cos()
        }
        BufferJoin::Miter { min_angle } => {
            1.0 / (min_angle.clamp(0.01 * PI, 0.99 * PI) / 2.0).sin()
        }
        BufferJoin::Bevel => 1.0,
    }
}

/// Checks coordinates, removes repeated consecutive vertices, closes rings, removes holes
/// without area.
fn sanitize(
    polygon: &Polygon<f64>,
    diag: &mut PostDiagnostics,
) -> Result<Polygon<f64>, DropReason> {
    let finite = |ls: &LineString<f64>| ls.0.iter().all(|c| c.x.is_finite() && c.y.is_finite());
    if !finite(polygon.exterior()) || !polygon.interiors().iter().all(finite) {
        return Err(DropReason::NonFiniteCoordinate);
    }
    let (shell, distinct_vertices) = clean_ring(polygon.exterior());
    if distinct_vertices < 3 {
        return Err(DropReason::DegenerateShell { distinct_vertices });
    }
    let mut holes = Vec::with_capacity(polygon.interiors().len());
    for hole in polygon.interiors() {
        let (ring, distinct) = clean_ring(hole);
        if distinct < 3 {
            diag.degenerate_holes_removed += 1;
        } else {
            holes.push(ring);
        }
    }
    Ok(Polygon::new(shell, holes))
}

/// The ring without consecutive repeated vertices, closed; and its vertex count.
fn clean_ring(ring: &LineString<f64>) -> (LineString<f64>, usize) {
    let mut coords: Vec<Coord<f64>> = Vec::with_capacity(ring.0.len() + 1);
    for &c in &ring.0 {
        if coords.last() != Some(&c) {
            coords.push(c);
        }
    }
    while coords.len() > 1 && coords.first() == coords.last() {
        coords.pop();
    }
    let distinct = coords.len();
    if let Some(&first) = coords.first() {
        coords.push(first);
    }
    (LineString(coords), distinct)
}

/// Rebuilds a valid multipolygon covering the region inside the shell (non-zero winding,
/// so every loop of a self-intersecting shell counts as inside) minus the region inside
/// any hole (each hole oriented counter-clockwise first, so overlapping holes unite).
pub(crate) fn repair(polygon: &Polygon<f64>) -> MultiPolygon<f64> {
    let shell = Polygon::new(polygon.exterior().clone(), Vec::new());
    let holes = MultiPolygon(
        polygon
            .interiors()
            .iter()
            .map(|h| {
                let mut ring = h.clone();
                if signed_ring_area(&ring.0) < 0.0 {
                    ring.0.reverse();
                }
                Polygon::new(ring, Vec::new())
            })
            .collect(),
    );
    let mut out = shell.boolean_op_with_fill_rule(&holes, OpType::Difference, FillRule::NonZero);
    out.0.retain(|p| p.exterior().0.len() >= 4);
    out
}

fn buffer_style(distance: f64, join: BufferJoin) -> BufferStyle<f64> {
    let join = match join {
        BufferJoin::Round { max_angle } => LineJoin::Round(max_angle),
        BufferJoin::Miter { min_angle } => LineJoin::Miter(min_angle),
        BufferJoin::Bevel => LineJoin::Bevel,
    };
    BufferStyle::new(distance).line_join(join)
}

/// Drops holes smaller than `min_hole_area` and orients the shell counter-clockwise and
/// the holes clockwise.
fn finish(part: Polygon<f64>, min_hole_area: f64, diag: &mut PostDiagnostics) -> Polygon<f64> {
    let (mut shell, holes) = part.into_inner();
    if signed_ring_area(&shell.0) < 0.0 {
        shell.0.reverse();
    }
    let mut kept = Vec::with_capacity(holes.len());
    for mut hole in holes {
        let a = signed_ring_area(&hole.0);
        if a.abs() < min_hole_area {
            diag.holes_dropped_by_area += 1;
            continue;
        }
        if a > 0.0 {
            hole.0.reverse();
        }
        kept.push(hole);
    }
    Polygon::new(shell, kept)
}

/// Signed area of a closed ring (positive = counter-clockwise), shoelace around the
/// first vertex.
pub(crate) fn signed_ring_area(ring: &[Coord<f64>]) -> f64 {
    let Some(&o) = ring.first() else {
        return 0.0;
    };
    let mut twice = 0.0;
    for w in ring.windows(2) {
        twice += (w[0].x - o.x) * (w[1].y - o.y) - (w[1].x - o.x) * (w[0].y - o.y);
    }
    0.5 * twice
}
