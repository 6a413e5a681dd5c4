//! Scores a planar segmentation of a point cloud against ground truth the way Hoover et al.
//! (1996) compare range-image segmentations and the SynPEB benchmark reports them
//! (Polylidar3D paper, §9.3.2, Table 10): correct detections, over- and under-segmentation,
//! missed and spurious planes, the percentages `f` and `k`, and the plane-fit RMSE.
//!
//! Each point carries a ground-truth label and a predicted label (`i32`, −1 = no plane;
//! ids need not be dense). [`evaluate()`] returns an [`Evaluation`]; [`fit_plane`] and
//! [`fit_plane_rmse`] are the least-squares plane fit behind the RMSE.
//!
//! ```
//! use seg_metrics::{EvaluateOptions, evaluate};
//!
//! // Ten points on z = 0 (plane 7) and ten on x = 0 (plane 9); the prediction finds the
//! // first plane but takes only 5 points of the second.
//! let mut points = Vec::new();
//! for i in 0..10 {
//!     points.push([i as f64, (i % 3) as f64, 0.0]);
//! }
//! for i in 0..10 {
//!     points.push([0.0, i as f64, 1.0 + (i % 4) as f64]);
//! }
//! let truth: Vec<i32> = (0..20).map(|i| if i < 10 { 7 } else { 9 }).collect();
//! let predicted: Vec<i32> = (0..20).map(|i| if i < 10 { 0 } else if i < 15 { 1 } else { -1 }).collect();
//!
//! let scores = evaluate(&points, &truth, &predicted, &EvaluateOptions::default())?;
//! assert_eq!((scores.truth_planes, scores.predicted_planes), (2, 2));
//! assert_eq!((scores.correct, scores.missed, scores.spurious), (1, 1, 1));
//! assert_eq!(scores.f, 50.0); // 1 of 2 planes
//! assert_eq!(scores.k, 50.0); // 10 of 20 labelled points
//! assert!(scores.rmse.unwrap() < 1e-9); // both segments are exactly planar
//! assert_eq!(scores.matches[0].truth, 7);
//! assert_eq!(scores.matches[0].predicted, 0);
//! # Ok::<(), seg_metrics::MetricsError>(())
//! ```
//!
//! # Definitions
//!
//! For a ground-truth plane `G` and a predicted segment `S`:
//!
//! - `|G|` = number of points whose ground-truth label is `G` (whatever their predicted
//!   label, −1 included);
//! - `|S|` = number of points whose predicted label is `S` (whatever their ground-truth
//!   label, −1 and ignored planes included);
//! - `O(G, S)` = number of points labelled `G` in the ground truth and `S` in the
//!   prediction.
//!
//! `T` is [`EvaluateOptions::overlap`] (default 0.8, "the standard 80 % threshold
//! described in Hoover et al.", paper §9.3.2); it must lie in (0.5, 1]. "`a` of `b` reaches
//! `T`" means `O ≥ T · b` (inclusive, as in Hoover et al.; compared with a relative
//! tolerance of 1e-12 so that 4 of 5 points meet 0.8). Because `T > ½`, each `S` has at
//! most one `G` holding `T` of `S`, and each `G` at most one `S` holding `T` of `G`.
//!
//! **Candidate instances** (Hoover's definitions):
//!
//! - *Correct detection* of `G` by `S`: `O(G, S) ≥ T·|G|` and `O(G, S) ≥ T·|S|`: at least
//!   80 % of the plane's points and of the segment's points overlap.
//! - *Over-segmentation* of `G`: the set `{S₁ … S_x}` of all segments with
//!   `O(G, Sᵢ) ≥ T·|Sᵢ|` has `x ≥ 2` members, and together they cover
//!   `Σᵢ O(G, Sᵢ) ≥ T·|G|` (one ground-truth plane split into several segments, each lying
//!   mostly inside it). Taking *all* such segments loses nothing: if any subset of two or
//!   more qualifies, the full set does.
//! - *Under-segmentation* of `S`: symmetrically, the set `{G₁ … G_x}` of all planes with
//!   `O(Gᵢ, S) ≥ T·|Gᵢ|` has `x ≥ 2` members and `Σᵢ O(Gᵢ, S) ≥ T·|S|` (several
//!   ground-truth planes merged into one segment).
//!
//! **Exclusive resolution.** Hoover's instances may overlap: a correctly detected pair
//! `(G, S)` can at the same time be part of an over-segmentation of `G` (another small
//! segment lying inside `G`) or of an under-segmentation of `S` (another small plane lying
//! inside `S`). With `T > ½` these are the only overlaps possible. As in the SynPEB
//! evaluation, each such conflict keeps the instance with the largest mean overlap
//! fraction and drops the others:
//!
//! - correct: `(O/|G| + O/|S|) / 2`;
//! - over-segmentation of `G` by `S₁ … S_x`: `(Σᵢ O(G,Sᵢ)/|Sᵢ| + Σᵢ O(G,Sᵢ)/|G|) / (x + 1)`;
//! - under-segmentation of `S` by `G₁ … G_x`: `(Σᵢ O(Gᵢ,S)/|Gᵢ| + Σᵢ O(Gᵢ,S)/|S|) / (x + 1)`;
//!
//! ties (within 1e-12) prefer the correct detection, then the over-segmentation.
//! Candidates not in conflict are kept. Afterwards:
//!
//! - **missed**: a ground-truth plane in no kept instance;
//! - **spurious** (Hoover's "noise"): a predicted segment in no kept instance.
//!
//! So every scored ground-truth plane is exactly one of correct / over-segmented /
//! merged into an under-segmented segment / missed, and every predicted segment exactly one
//! of correct / piece of an over-segmented plane / under-segmented / spurious (see
//! [`TruthRegion`], [`PredictedRegion`]). [`Evaluation::over_segmented`] counts
//! over-segmented *ground-truth planes* and [`Evaluation::under_segmented`] counts
//! under-segmented *predicted segments* (one per Hoover instance).
//!
//! **Scores** (the paper: "f representing the percent of ground truth planes identified,
//! k indicating percent of the point cloud correctly identified, and RMSE quantifying
//! accuracy of each plane fit"):
//!
//! - `f = 100 · correct / truth_planes`;
//! - `k = 100 · Σ_{G correctly detected} |G| / Σ_{G scored} |G|`: the population "all
//!   points" is the points that carry a scored ground-truth label (unlabelled points and
//!   planes below [`EvaluateOptions::min_truth_points`] are left out), and a correctly
//!   detected plane contributes *all* its points, not only the overlap, as in the SynPEB
//!   scoring scripts;
//! - `rmse = sqrt(Σ_S SSE_S / Σ_S |S|)` over *every* predicted segment with at least
//!   [`MIN_RMSE_POINTS`] points, where `SSE_S` is the sum of squared orthogonal distances
//!   of `S`'s points to `S`'s own least-squares plane ([`fit_plane`]); the paper's
//!   "indicating the predicted planes have a good fit", and SynPEB, measure all predicted
//!   planes, not only the correct ones. [`Evaluation::rmse_correct`] restricts the same
//!   pool to correctly detecting segments. Both are `None` when nothing qualifies.
//!   (SynPEB's own scripts measure the error along the sensor ray against each method's
//!   own plane parameters; without a sensor origin or plane parameters we use orthogonal
//!   distances to a refitted plane, which is never larger than the distance to any other
//!   plane.)
//!
//! `f` and `k` are 0 when there is no scored ground-truth plane.
//!
//! **Labels and invalid points.** −1 means "no plane" in either array; any other negative
//! label is an error. A point labelled −1 in the ground truth but not in the prediction
//! counts in its segment's `|S|` (it makes the segment less pure); a point labelled −1 in
//! the prediction but not in the ground truth counts in its plane's `|G|` (it makes the
//! plane less covered). Points with NaN or infinite coordinates (missing returns) are
//! allowed only with −1 in both arrays; otherwise [`evaluate()`] fails with
//! [`MetricsError::NonFinitePoint`] rather than silently dropping them.

#![deny(rustdoc::broken_intra_doc_links)]

mod compact;
mod error;
mod evaluate;
mod plane;

pub use error::{Labels, MetricsError};
pub use evaluate::{
    EvaluateOptions, Evaluation, MIN_RMSE_POINTS, Match, PredictedClass, PredictedRegion,
    TruthClass, TruthRegion, evaluate,
};
pub use plane::{LeastSquaresPlane, fit_plane, fit_plane_rmse};

/// The README's example, compiled and run as a doctest.
#[doc = include_str!("../README.md")]
#[cfg(doctest)]
struct ReadmeDoctest;
