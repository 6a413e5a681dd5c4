//! Why a ground-truth plane was not found: the miss analysis behind `polylidar evaluate`.
//!
//! [`explain_misses`] takes an [`Extraction`] of an organized cloud or mesh, the
//! [`Config`] it ran with, the ground-truth plane label of every vertex and the
//! [`Evaluation`] of the extraction's [`Extraction::plane_labels`] against them, and gives
//! every ground-truth plane that is not correctly found, and every spurious plane, one
//! [`MissCause`]: the first stage of the pipeline that lost it.
//!
//! A ground-truth plane's triangles are the mesh triangles whose three corners carry its
//! label. The stages are checked in pipeline order:
//!
//! 1. no triangle at all ([`MissCause::NoTriangles`]: too few or invalid points);
//! 2. most triangles longer than `lmax` ([`MissCause::DroppedByLmax`]);
//! 3. the plane's normal farther than `norm_thresh` from every dominant normal, without
//!    refinement to find it anyway ([`MissCause::NoDominantNormal`]);
//! 4. most remaining triangles' normals farther than `norm_thresh` from every dominant
//!    normal ([`MissCause::DroppedByNormal`]);
//! 5. split into several planes ([`MissCause::Split`], Hoover's over-segmentation);
//! 6. no plane holds a tenth of its triangles: the regions grown on it were below
//!    `min_triangles` ([`MissCause::RegionTooSmall`]);
//! 7. the plane holding most of it is mostly other planes' points
//!    ([`MissCause::MergedIntoNeighbour`]);
//! 8. otherwise the overlap fell short of the score's threshold on one side
//!    ([`MissCause::LowOverlap`]).

use std::borrow::Cow;
use std::collections::BTreeMap;

use seg_metrics::{Evaluation, PredictedClass, TruthClass};

use crate::{Config, Extraction};

/// Most of a plane's triangles: the share above which a filter is blamed.
const MOST: f64 = 0.5;

/// Why a ground-truth plane was missed (or a predicted plane is spurious).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MissCause {
    /// No mesh triangle has all three corners on the plane.
    NoTriangles,
    /// This share of its triangles have an edge longer than `lmax`.
    DroppedByLmax {
        /// Share of the plane's triangles, 0–1.
        share: f64,
    },
    /// Its least-squares normal is this many degrees from the nearest dominant normal,
    /// more than `norm_thresh` allows, and refinement is off.
    NoDominantNormal {
        /// Angle to the nearest dominant normal, degrees.
        degrees: f64,
    },
    /// This share of its triangles (of those within `lmax`) have normals farther than
    /// `norm_thresh` from every dominant normal.
    DroppedByNormal {
        /// Share, 0–1.
        share: f64,
    },
    /// Split into this many predicted planes, each mostly inside it.
    Split {
        /// Predicted planes.
        pieces: usize,
    },
    /// Its triangles were grouped, but no kept plane holds a tenth of them: the regions
    /// grown on it were below `min_triangles` (or cut small by `z_thresh`).
    RegionTooSmall {
        /// Triangles of the plane in no kept polygon.
        triangles: usize,
    },
    /// The predicted plane holding most of it (this id) is mostly other planes.
    MergedIntoNeighbour {
        /// The predicted plane id.
        predicted: i32,
    },
    /// The best predicted plane overlaps it, but less than the score's threshold of the
    /// ground-truth plane's or of the predicted plane's points.
    LowOverlap {
        /// Share of the ground-truth plane's points in the best predicted plane.
        of_truth: f64,
        /// Share of the best predicted plane's points on the ground-truth plane.
        of_predicted: f64,
    },
    /// A spurious predicted plane: mostly points that belong to no ground-truth plane.
    SpuriousClutter,
    /// A spurious predicted plane: mostly points of this ground-truth plane, but too
    /// few of them for a detection.
    SpuriousPiece {
        /// The ground-truth plane id.
        truth: i32,
    },
}

impl MissCause {
    /// A short name for tables: `lmax`, `no dominant normal`, …
    pub fn name(&self) -> &'static str {
        match self {
            Self::NoTriangles => "no triangles",
            Self::DroppedByLmax { .. } => "dropped by lmax",
            Self::NoDominantNormal { .. } => "no dominant normal near it",
            Self::DroppedByNormal { .. } => "dropped by norm_thresh",
            Self::Split { .. } => "split into pieces",
            Self::RegionTooSmall { .. } => "regions below min_triangles",
            Self::MergedIntoNeighbour { .. } => "merged into a neighbour",
            Self::LowOverlap { .. } => "overlap under the threshold",
            Self::SpuriousClutter => "spurious: clutter",
            Self::SpuriousPiece { .. } => "spurious: piece of a plane",
        }
    }

    /// Whether this explains a spurious predicted plane rather than a missed one.
    pub fn is_spurious(&self) -> bool {
        matches!(self, Self::SpuriousClutter | Self::SpuriousPiece { .. })
    }
}

/// One explained plane.
#[derive(Debug, Clone, PartialEq)]
pub struct Miss {
    /// The ground-truth plane id, or for a spurious plane the predicted plane id.
    pub id: i32,
    /// Its points.
    pub points: usize,
    /// Why.
    pub cause: MissCause,
}

/// Per ground-truth plane not correctly found, and per spurious predicted plane, its
/// cause (see the module docs); ground-truth planes first, by id, then spurious planes.
///
/// `truth` holds the ground-truth plane of every vertex of `extraction.mesh` (−1 for
/// none; of every input pixel for a decimated cloud, see [`Extraction::decimation`]), `evaluation` the scores of [`Extraction::plane_labels`] against it at the
/// overlap threshold `overlap` (Hoover's `T`, 0.8 in the papers).
pub fn explain_misses(
    extraction: &Extraction,
    config: &Config,
    truth: &[i32],
    evaluation: &Evaluation,
    overlap: f64,
) -> Vec<Miss> {
    let stats = TruthStats::collect(extraction, config, truth);
    let predicted = extraction.plane_labels();
    let mut out = Vec::new();
    for region in &evaluation.truth_regions {
        let cause = match region.class {
            TruthClass::Correct { .. } | TruthClass::Ignored => continue,
            TruthClass::OverSegmented => MissCause::Split {
                pieces: evaluation
                    .predicted_regions
                    .iter()
                    .filter(|p| p.class == PredictedClass::OverSegmented { truth: region.id })
                    .count(),
            },
            TruthClass::UnderSegmented { predicted } => {
                MissCause::MergedIntoNeighbour { predicted }
            }
            TruthClass::Missed => stats.cause(region.id, config, overlap, &predicted, truth),
        };
        out.push(Miss {
            id: region.id,
            points: region.points,
            cause,
        });
    }
    for region in &evaluation.predicted_regions {
        if region.class != PredictedClass::Spurious {
            continue;
        }
        let mut by_truth: BTreeMap<i32, usize> = BTreeMap::new();
        for (&p, &t) in predicted.iter().zip(truth) {
            if p == region.id {
                *by_truth.entry(t).or_default() += 1;
            }
        }
        let majority = by_truth
            .iter()
            .max_by_key(|&(t, n)| (*n, std::cmp::Reverse(*t)))
            .map_or(-1, |(&t, _)| t);
        out.push(Miss {
            id: region.id,
            points: region.points,
            cause: if majority < 0 {
                MissCause::SpuriousClutter
            } else {
                MissCause::SpuriousPiece { truth: majority }
            },
        });
    }
    out
}

/// Counts of misses per cause name, in the order causes first appear in `misses`.
pub fn count_causes(misses: &[Miss]) -> Vec<(&'static str, usize)> {
    let mut counts: Vec<(&'static str, usize)> = Vec::new();
    for m in misses {
        match counts.iter_mut().find(|(name, _)| *name == m.cause.name()) {
            Some((_, n)) => *n += 1,
            None => counts.push((m.cause.name(), 1)),
        }
    }
    counts
}

/// What happened to each ground-truth plane's triangles.
#[derive(Debug, Default, Clone)]
struct PlaneTriangles {
    all: usize,
    lmax: usize,
    normal: usize,
    /// Triangles per polygon plane id (−1: in no polygon).
    by_plane: BTreeMap<i32, usize>,
}

struct TruthStats {
    planes: BTreeMap<i32, PlaneTriangles>,
    /// Per ground-truth plane, the angle of its least-squares normal to the nearest
    /// dominant normal, degrees.
    angles: BTreeMap<i32, f64>,
}

impl TruthStats {
    fn collect(extraction: &Extraction, config: &Config, truth: &[i32]) -> Self {
        // A decimated cloud's mesh has a vertex per block: the block's label.
        let truth = match &extraction.decimation {
            Some(d) => Cow::Owned(d.block_labels(truth).unwrap_or_default()),
            None => Cow::Borrowed(truth),
        };
        let mesh = &extraction.mesh;
        let vertices = mesh.vertices();
        let normals = mesh.triangle_normals().unwrap_or(&[]);
        let mut plane_of = vec![-1i32; mesh.num_triangles()];
        for p in &extraction.polygons {
            for &t in &p.triangles {
                plane_of[t as usize] = p.plane_id as i32;
            }
        }
        let nearest = |n: [f64; 3]| {
            extraction
                .dominant_normals
                .iter()
                .map(|d| d[0] * n[0] + d[1] * n[1] + d[2] * n[2])
                .fold(f64::NEG_INFINITY, f64::max)
        };
        let lmax2 = if config.lmax > 0.0 {
            config.lmax * config.lmax
        } else {
            f64::INFINITY
        };
        let mut planes: BTreeMap<i32, PlaneTriangles> = BTreeMap::new();
        for (t, tri) in mesh.triangles().iter().enumerate() {
            let label = truth.get(tri[0] as usize).copied().unwrap_or(-1);
            if label < 0 || tri.iter().any(|&v| truth.get(v as usize) != Some(&label)) {
                continue;
            }
            let stats = planes.entry(label).or_default();
            stats.all += 1;
            let [a, b, c] = tri.map(|v| vertices[v as usize]);
            let len2 = |p: [f64; 3], q: [f64; 3]| (0..3).map(|k| (p[k] - q[k]).powi(2)).sum();
            let longest: f64 = [len2(a, b), len2(b, c), len2(c, a)]
                .into_iter()
                .fold(0.0, f64::max);
            if longest.is_nan() || longest > lmax2 {
                stats.lmax += 1;
                continue;
            }
            if normals
                .get(t)
                .is_none_or(|&n| nearest(n).is_nan() || nearest(n) < config.norm_thresh)
            {
                stats.normal += 1;
            }
            *stats.by_plane.entry(plane_of[t]).or_default() += 1;
        }
        let mut points: BTreeMap<i32, Vec<[f64; 3]>> = BTreeMap::new();
        for (p, &l) in vertices.iter().zip(truth.iter()) {
            if l >= 0 && p.iter().all(|c| c.is_finite()) {
                points.entry(l).or_default().push(*p);
            }
        }
        let angles = points
            .into_iter()
            .filter_map(|(l, pts)| {
                let fit = seg_metrics::fit_plane(&pts)?;
                let cos = nearest(fit.normal).max(nearest(fit.normal.map(|c| -c)));
                Some((l, cos.clamp(-1.0, 1.0).acos().to_degrees()))
            })
            .collect();
        Self { planes, angles }
    }

    fn cause(
        &self,
        id: i32,
        config: &Config,
        overlap_threshold: f64,
        predicted: &[i32],
        truth: &[i32],
    ) -> MissCause {
        let Some(stats) = self.planes.get(&id).filter(|s| s.all > 0) else {
            return MissCause::NoTriangles;
        };
        let share = |n: usize, of: usize| n as f64 / of.max(1) as f64;
        if share(stats.lmax, stats.all) > MOST {
            return MissCause::DroppedByLmax {
                share: share(stats.lmax, stats.all),
            };
        }
        let allowed = config.norm_thresh.clamp(-1.0, 1.0).acos().to_degrees();
        if let Some(&degrees) = self.angles.get(&id)
            && degrees > allowed
            && !config.refine
        {
            return MissCause::NoDominantNormal { degrees };
        }
        let kept = stats.all - stats.lmax;
        if share(stats.normal, kept) > MOST && !config.refine {
            return MissCause::DroppedByNormal {
                share: share(stats.normal, kept),
            };
        }
        let best = stats
            .by_plane
            .iter()
            .filter(|&(&p, _)| p >= 0)
            .max_by_key(|&(&p, &n)| (n, std::cmp::Reverse(p)));
        let Some((&best, _)) = best.filter(|&(_, &n)| share(n, kept) >= 0.1) else {
            return MissCause::RegionTooSmall {
                triangles: stats.by_plane.get(&-1).copied().unwrap_or(0),
            };
        };
        let (mut overlap, mut truth_points, mut predicted_points) = (0usize, 0usize, 0usize);
        for (&p, &t) in predicted.iter().zip(truth) {
            overlap += usize::from(p == best && t == id);
            truth_points += usize::from(t == id);
            predicted_points += usize::from(p == best);
        }
        let of_truth = share(overlap, truth_points);
        let of_predicted = share(overlap, predicted_points);
        if of_truth >= overlap_threshold && of_predicted < overlap_threshold {
            return MissCause::MergedIntoNeighbour { predicted: best };
        }
        MissCause::LowOverlap {
            of_truth,
            of_predicted,
        }
    }
}
