//! Counts of what post-processing kept, changed and dropped, and why.

use std::fmt;

/// Why an input polygon, or one output part of it, was dropped as unusable.
#[derive(Debug, Clone, PartialEq)]
pub enum DropReason {
    /// A coordinate is NaN or infinite.
    NonFiniteCoordinate,
    /// The shell has fewer than three distinct vertices.
    DegenerateShell {
        /// Distinct consecutive vertices found.
        distinct_vertices: usize,
    },
    /// The plane given with a 3D polygon has a non-finite or zero normal, or a
    /// non-finite centroid or offset.
    BadPlane,
    /// Repairing the polygon left nothing with positive area (e.g. all vertices on one
    /// line, or a shell that cancels itself out).
    NoAreaAfterRepair,
    /// A processed polygon failed `geo::Validation` (a defect in a geometry routine; the
    /// polygon is dropped instead of being returned invalid).
    InvalidAfterProcessing {
        /// The first reason `geo::Validation` gave.
        detail: String,
    },
}

impl fmt::Display for DropReason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DropReason::NonFiniteCoordinate => write!(f, "a coordinate is NaN or infinite"),
            DropReason::DegenerateShell { distinct_vertices } => write!(
                f,
                "the shell has {distinct_vertices} distinct vertices, a polygon needs at least 3"
            ),
            DropReason::BadPlane => write!(f, "the plane has a non-finite or zero normal"),
            DropReason::NoAreaAfterRepair => {
                write!(f, "nothing with positive area is left after repair")
            }
            DropReason::InvalidAfterProcessing { detail } => {
                write!(f, "a processed polygon is invalid: {detail}")
            }
        }
    }
}

/// One dropped polygon: which input it came from and why.
#[derive(Debug, Clone, PartialEq)]
pub struct DroppedPolygon {
    /// Index of the input polygon.
    pub source: u32,
    /// Why it was dropped.
    pub reason: DropReason,
}

/// What post-processing did, summed over the inputs of one call.
///
/// Area counts are per output *part*: buffering can split one input into several parts,
/// each filtered on its own.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PostDiagnostics {
    /// Input polygons seen.
    pub input_polygons: u32,
    /// Polygons returned.
    pub output_polygons: u32,
    /// Inputs that were invalid (self-intersecting, touching or crossing rings, holes
    /// outside the shell, …) and, still so after simplification, were repaired.
    pub repaired_inputs: u32,
    /// Valid inputs that simplification made invalid, repaired.
    pub repaired_after_simplify: u32,
    /// Inputs of which nothing was left after simplification and buffering (e.g. eroded
    /// away by β_neg).
    pub vanished: u32,
    /// Parts dropped because their area was below γ (`min_area`), and inputs dropped
    /// before processing because no part of them could reach it (counted once each).
    pub dropped_by_area: u32,
    /// Holes dropped because their area was below δ (`min_hole_area`).
    pub holes_dropped_by_area: u32,
    /// Holes removed because they had fewer than three distinct vertices (no area).
    pub degenerate_holes_removed: u32,
    /// Inputs or parts dropped as unusable; `dropped` says which and why.
    pub dropped_invalid: u32,
    /// One entry per `dropped_invalid`, in input order.
    pub dropped: Vec<DroppedPolygon>,
}

impl PostDiagnostics {
    /// Adds `other`'s counts to these and appends its dropped list.
    pub fn merge(&mut self, other: &PostDiagnostics) {
        self.input_polygons += other.input_polygons;
        self.output_polygons += other.output_polygons;
        self.repaired_inputs += other.repaired_inputs;
        self.repaired_after_simplify += other.repaired_after_simplify;
        self.vanished += other.vanished;
        self.dropped_by_area += other.dropped_by_area;
        self.holes_dropped_by_area += other.holes_dropped_by_area;
        self.degenerate_holes_removed += other.degenerate_holes_removed;
        self.dropped_invalid += other.dropped_invalid;
        self.dropped.extend(other.dropped.iter().cloned());
    }

    pub(crate) fn drop_invalid(&mut self, source: u32, reason: DropReason) {
        self.dropped_invalid += 1;
        self.dropped.push(DroppedPolygon { source, reason });
    }
}
