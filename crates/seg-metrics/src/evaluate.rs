//! Scoring a predicted segmentation against ground truth (see the crate docs for the
//! definitions).

use crate::compact::{NONE, compact};
use crate::error::{Labels, MetricsError};
use crate::plane::{Scatter, is_finite};

/// Predicted segments with fewer points than this are left out of [`Evaluation::rmse`] and
/// [`Evaluation::rmse_correct`]: a least-squares plane through three or fewer points has no
/// residual, so such segments would only dilute the error.
pub const MIN_RMSE_POINTS: usize = 4;

/// Relative tolerance on `T · size` when testing `overlap ≥ T · size`, so that a threshold
/// such as 0.8, which is not exact in binary, still accepts 4 of 5 points.
const OVERLAP_TOLERANCE: f64 = 1e-12;

/// Two classification scores closer than this are a tie (resolved in favour of the correct
/// detection, then over-segmentation).
const SCORE_TIE: f64 = 1e-12;

/// Options of [`evaluate`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct EvaluateOptions {
    /// Hoover's overlap threshold `T`, a fraction in (0.5, 1]. Default 0.8, the "standard
    /// 80 % threshold" of the Polylidar3D paper (§9.3.2) and of SynPEB.
    pub overlap: f64,
    /// Ground-truth planes with fewer points than this are ignored: reported as
    /// [`TruthClass::Ignored`], not counted in [`Evaluation::truth_planes`], and their points
    /// count as unlabelled (ground truth −1) for `f` and `k`. They still belong to the
    /// predicted segments they fall in (a predicted segment's size is all of its points).
    /// Default 0: the paper and the SynPEB evaluation drop no ground-truth plane by size.
    pub min_truth_points: usize,
}

impl Default for EvaluateOptions {
    fn default() -> Self {
        Self {
            overlap: 0.8,
            min_truth_points: 0,
        }
    }
}

impl EvaluateOptions {
    /// The defaults: `overlap` 0.8, `min_truth_points` 0.
    pub fn new() -> Self {
        Self::default()
    }

    /// Sets the overlap threshold `T` (a fraction in (0.5, 1]).
    pub fn with_overlap(mut self, overlap: f64) -> Self {
        self.overlap = overlap;
        self
    }

    /// Sets the minimum size of a ground-truth plane that is scored.
    pub fn with_min_truth_points(mut self, min_truth_points: usize) -> Self {
        self.min_truth_points = min_truth_points;
        self
    }
}

/// A correct detection: a ground-truth plane and the predicted segment that found it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Match {
    /// Ground-truth plane id.
    pub truth: i32,
    /// Predicted segment id.
    pub predicted: i32,
    /// Number of points carrying both labels.
    pub overlap: usize,
    /// `overlap` as a fraction of the ground-truth plane's points (≥ `T`).
    pub overlap_truth: f64,
    /// `overlap` as a fraction of the predicted segment's points (≥ `T`).
    pub overlap_predicted: f64,
}

/// What became of one ground-truth plane.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum TruthClass {
    /// Correctly detected by the predicted segment `predicted`.
    Correct {
        /// The predicted segment's id.
        predicted: i32,
    },
    /// Over-segmented: split into several predicted segments, each reported as
    /// [`PredictedClass::OverSegmented`] with this plane's id. Counted once in
    /// [`Evaluation::over_segmented`].
    OverSegmented,
    /// Merged with other ground-truth planes into the under-segmented predicted segment
    /// `predicted` ([`PredictedClass::UnderSegmented`]).
    UnderSegmented {
        /// The predicted segment's id.
        predicted: i32,
    },
    /// In no classification: missed.
    Missed,
    /// Smaller than [`EvaluateOptions::min_truth_points`]; not scored.
    Ignored,
}

/// What became of one predicted segment.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PredictedClass {
    /// A correct detection of ground-truth plane `truth`.
    Correct {
        /// The ground-truth plane's id.
        truth: i32,
    },
    /// One of the pieces of the over-segmented ground-truth plane `truth`
    /// ([`TruthClass::OverSegmented`]).
    OverSegmented {
        /// The ground-truth plane's id.
        truth: i32,
    },
    /// Under-segmented: covers several ground-truth planes, each reported as
    /// [`TruthClass::UnderSegmented`] with this segment's id. Counted once in
    /// [`Evaluation::under_segmented`].
    UnderSegmented,
    /// In no classification: spurious (Hoover's "noise").
    Spurious,
}

/// A ground-truth plane, its size and its classification.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct TruthRegion {
    /// Ground-truth plane id.
    pub id: i32,
    /// Number of points with this ground-truth label.
    pub points: usize,
    /// Its classification.
    pub class: TruthClass,
}

/// A predicted segment, its size and its classification.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct PredictedRegion {
    /// Predicted segment id.
    pub id: i32,
    /// Number of points with this predicted label (whatever their ground truth).
    pub points: usize,
    /// Its classification.
    pub class: PredictedClass,
}

/// The scores of one predicted segmentation (see the crate docs for the definitions).
///
/// Every scored ground-truth plane is exactly one of: correct, over-segmented, part of an
/// under-segmentation, missed; every predicted segment exactly one of: correct, part of an
/// over-segmentation, under-segmented, spurious.
#[derive(Debug, Clone, PartialEq)]
pub struct Evaluation {
    /// Number of scored ground-truth planes (distinct labels ≥ 0 with at least
    /// [`EvaluateOptions::min_truth_points`] points).
    pub truth_planes: usize,
    /// Number of predicted segments (distinct predicted labels ≥ 0).
    pub predicted_planes: usize,
    /// Number of correct detections (ground-truth planes correctly found).
    pub correct: usize,
    /// Number of over-segmented ground-truth planes (Hoover's over-segmentation instances).
    pub over_segmented: usize,
    /// Number of under-segmented predicted segments (Hoover's under-segmentation
    /// instances).
    pub under_segmented: usize,
    /// Number of missed ground-truth planes.
    pub missed: usize,
    /// Number of spurious predicted segments (Hoover's "noise" regions).
    pub spurious: usize,
    /// Percentage of scored ground-truth planes correctly found: `100 · correct /
    /// truth_planes`; 0 when there are none.
    pub f: f64,
    /// Percentage of ground-truth-labelled points that belong to correctly found planes:
    /// `100 · correct_points / labelled_points`; 0 when there are none.
    pub k: f64,
    /// Pooled RMSE of every predicted segment's points to that segment's least-squares
    /// plane, in the points' unit (metres for SynPEB): `sqrt(Σ_s SSE_s / Σ_s n_s)` over
    /// predicted segments with at least [`MIN_RMSE_POINTS`] points. `None` when there is no
    /// such segment.
    pub rmse: Option<f64>,
    /// As [`rmse`](Self::rmse), over the correctly detecting segments only (see
    /// [`matches`](Self::matches)); `None` when none qualifies.
    pub rmse_correct: Option<f64>,
    /// Points carrying a scored ground-truth label: the denominator of `k`.
    pub labelled_points: usize,
    /// Points of correctly found ground-truth planes: the numerator of `k`.
    pub correct_points: usize,
    /// Points behind `rmse` (the `Σ n_s`), for pooling over several scenes.
    pub rmse_points: usize,
    /// Points behind `rmse_correct`.
    pub rmse_correct_points: usize,
    /// The correct detections, by increasing ground-truth id.
    pub matches: Vec<Match>,
    /// Every ground-truth plane (ignored ones too), by increasing id.
    pub truth_regions: Vec<TruthRegion>,
    /// Every predicted segment, by increasing id.
    pub predicted_regions: Vec<PredictedRegion>,
}

/// Overlap of ground-truth plane `t` and predicted segment `p` (compact ids): `o` points.
#[derive(Debug, Clone, Copy)]
struct Pair {
    t: u32,
    p: u32,
    o: usize,
}

/// Maximal runs `start..end` of consecutive points with equal labels in both arrays (of
/// equal length).
fn runs<'a>(first: &'a [i32], second: &'a [i32]) -> impl Iterator<Item = (usize, usize)> + 'a {
    let n = first.len().min(second.len());
    let mut start = 0;
    std::iter::from_fn(move || {
        if start >= n {
            return None;
        }
        let (a, b) = (first[start], second[start]);
        let mut end = start + 1;
        // Eight at a time while whole blocks match (vectorizes), then one at a time.
        while end + 8 <= n
            && first[end..end + 8].iter().all(|&x| x == a)
            && second[end..end + 8].iter().all(|&x| x == b)
        {
            end += 8;
        }
        while end < n && first[end] == a && second[end] == b {
            end += 1;
        }
        let run = (start, end);
        start = end;
        Some(run)
    })
}

/// Coordinate sums of `points`, with two interleaved accumulators.
fn coordinate_sum(points: &[[f64; 3]]) -> [f64; 3] {
    let (mut a, mut b) = ([0.0f64; 3], [0.0f64; 3]);
    let mut pairs = points.chunks_exact(2);
    for pair in &mut pairs {
        for k in 0..3 {
            a[k] += pair[0][k];
            b[k] += pair[1][k];
        }
    }
    for point in pairs.remainder() {
        for k in 0..3 {
            a[k] += point[k];
        }
    }
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// Classes on compact ids.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Tc {
    Correct(u32),
    Over,
    Under(u32),
    Missed,
    Ignored,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Pc {
    Correct(u32),
    Over(u32),
    Under,
    Spurious,
}

/// `overlap ≥ t · size`, up to [`OVERLAP_TOLERANCE`].
#[inline]
fn meets(overlap: usize, size: usize, t: f64) -> bool {
    overlap as f64 * (1.0 + OVERLAP_TOLERANCE) >= t * size as f64
}

/// Scores a predicted planar segmentation of `points` against the ground truth.
///
/// `truth[i]` and `predicted[i]` are the plane ids of point `i`, −1 for "no plane". Ids
/// need not be dense or start at 0. See the crate docs for what is computed.
///
/// # Errors
///
/// - [`MetricsError::InvalidOverlap`] unless `0.5 < options.overlap ≤ 1`;
/// - [`MetricsError::LengthMismatch`] unless the three slices have the same length;
/// - [`MetricsError::InvalidLabel`] for a label below −1 (the first one found, ground
///   truth first);
/// - [`MetricsError::NonFinitePoint`] for a NaN or infinite coordinate on a point that
///   carries a label in either array (the first such point).
///
/// # Performance
///
/// Two passes over the points (sizes, sums and overlap table, then the segments' scatter
/// matrices) after one validating pass over each label array: O(n) for ids below a few
/// times `n`, otherwise O(n + r log r) for `r` runs of equal labels. The overlap table is
/// a dense count matrix when (ground-truth planes × predicted segments) is at most
/// `2n + 65536`, otherwise sorted pair keys (one per run). Runs of points with equal
/// labels (long in organized clouds) are accumulated as a whole. Single-threaded;
/// `cargo run --release -p seg-metrics --example timing` times it (figure in the crate
/// README).
pub fn evaluate(
    points: &[[f64; 3]],
    truth: &[i32],
    predicted: &[i32],
    options: &EvaluateOptions,
) -> Result<Evaluation, MetricsError> {
    let threshold = options.overlap;
    if !(threshold > 0.5 && threshold <= 1.0) {
        return Err(MetricsError::InvalidOverlap { overlap: threshold });
    }
    let n = points.len();
    if truth.len() != n || predicted.len() != n {
        return Err(MetricsError::LengthMismatch {
            points: n,
            truth: truth.len(),
            predicted: predicted.len(),
        });
    }
    let truth_ids = compact(truth, Labels::Truth)?;
    let predicted_ids = compact(predicted, Labels::Predicted)?;
    let (nt, np) = (truth_ids.ids.len(), predicted_ids.ids.len());

    // Pass 1: sizes, coordinate sums of predicted segments, overlap counts. Runs of equal
    // label pairs (long in organized clouds) are accumulated locally and flushed once.
    let mut truth_size = vec![0usize; nt];
    let mut predicted_size = vec![0usize; np];
    let mut predicted_sum = vec![[0.0f64; 3]; np];
    let dense = nt.saturating_mul(np) <= 2 * n + 65_536;
    let mut table = if dense {
        vec![0usize; nt * np]
    } else {
        Vec::new()
    };
    let mut keys: Vec<(u64, usize)> = Vec::new();
    let mut flush = |t: u32, p: u32, count: usize, sum: [f64; 3]| {
        if t != NONE {
            truth_size[t as usize] += count;
        }
        if p != NONE {
            let pu = p as usize;
            predicted_size[pu] += count;
            for (total, part) in predicted_sum[pu].iter_mut().zip(sum) {
                *total += part;
            }
            if t != NONE {
                if dense {
                    table[t as usize * np + pu] += count;
                } else {
                    keys.push((((t as u64) << 32) | p as u64, count));
                }
            }
        }
    };
    for (start, end) in runs(truth, predicted) {
        let (t, p) = (
            truth_ids.get(truth[start]),
            predicted_ids.get(predicted[start]),
        );
        if t == NONE && p == NONE {
            continue;
        }
        let run = &points[start..end];
        let sum = coordinate_sum(run);
        // A non-finite coordinate makes the sum non-finite; only then is the run searched.
        if !(sum[0] + sum[1] + sum[2]).is_finite()
            && let Some(offset) = run.iter().position(|q| !is_finite(q))
        {
            let index = start + offset;
            return Err(MetricsError::NonFinitePoint {
                index,
                truth: truth[index],
                predicted: predicted[index],
            });
        }
        flush(t, p, end - start, sum);
    }

    let scored: Vec<bool> = truth_size
        .iter()
        .map(|&size| size >= options.min_truth_points)
        .collect();
    let mut pairs = Vec::new();
    if dense {
        for (t, row) in table.chunks_exact(np.max(1)).enumerate().take(nt) {
            if !scored[t] {
                continue;
            }
            for (p, &o) in row.iter().enumerate() {
                if o > 0 {
                    pairs.push(Pair {
                        t: t as u32,
                        p: p as u32,
                        o,
                    });
                }
            }
        }
    } else {
        keys.sort_unstable_by_key(|&(key, _)| key);
        for (key, count) in keys {
            let (t, p) = ((key >> 32) as u32, key as u32);
            if !scored[t as usize] {
                continue;
            }
            match pairs.last_mut() {
                Some(last) if (last.t, last.p) == (t, p) => last.o += count,
                _ => pairs.push(Pair { t, p, o: count }),
            }
        }
    }

    let (truth_class, predicted_class) =
        classify(&pairs, &truth_size, &scored, &predicted_size, threshold);

    // Pass 2: scatter matrices of the predicted segments around their means.
    let means: Vec<[f64; 3]> = predicted_sum
        .iter()
        .zip(&predicted_size)
        .map(|(sum, &size)| sum.map(|s| s / size.max(1) as f64))
        .collect();
    let mut scatter = vec![Scatter::default(); np];
    if predicted_size.iter().any(|&size| size >= MIN_RMSE_POINTS) {
        for (start, end) in runs(predicted, predicted) {
            let p = predicted_ids.get(predicted[start]);
            if p != NONE && predicted_size[p as usize] >= MIN_RMSE_POINTS {
                let run = Scatter::of(&points[start..end], &means[p as usize]);
                scatter[p as usize].merge(&run);
            }
        }
    }
    let (mut sse_all, mut n_all, mut sse_correct, mut n_correct) = (0.0, 0usize, 0.0, 0usize);
    for p in 0..np {
        if predicted_size[p] < MIN_RMSE_POINTS {
            continue;
        }
        let sse = scatter[p].residual_sum_of_squares();
        sse_all += sse;
        n_all += predicted_size[p];
        if matches!(predicted_class[p], Pc::Correct(_)) {
            sse_correct += sse;
            n_correct += predicted_size[p];
        }
    }
    let pooled = |sse: f64, count: usize| (count > 0).then(|| (sse / count as f64).sqrt());

    // Reports on original ids.
    let tid = |t: u32| truth_ids.ids[t as usize];
    let pid = |p: u32| predicted_ids.ids[p as usize];
    let truth_regions: Vec<TruthRegion> = (0..nt)
        .map(|t| TruthRegion {
            id: truth_ids.ids[t],
            points: truth_size[t],
            class: match truth_class[t] {
                Tc::Correct(p) => TruthClass::Correct { predicted: pid(p) },
                Tc::Over => TruthClass::OverSegmented,
                Tc::Under(p) => TruthClass::UnderSegmented { predicted: pid(p) },
                Tc::Missed => TruthClass::Missed,
                Tc::Ignored => TruthClass::Ignored,
            },
        })
        .collect();
    let predicted_regions: Vec<PredictedRegion> = (0..np)
        .map(|p| PredictedRegion {
            id: predicted_ids.ids[p],
            points: predicted_size[p],
            class: match predicted_class[p] {
                Pc::Correct(t) => PredictedClass::Correct { truth: tid(t) },
                Pc::Over(t) => PredictedClass::OverSegmented { truth: tid(t) },
                Pc::Under => PredictedClass::UnderSegmented,
                Pc::Spurious => PredictedClass::Spurious,
            },
        })
        .collect();
    let matches: Vec<Match> = pairs
        .iter()
        .filter(|pair| truth_class[pair.t as usize] == Tc::Correct(pair.p))
        .map(|pair| Match {
            truth: tid(pair.t),
            predicted: pid(pair.p),
            overlap: pair.o,
            overlap_truth: pair.o as f64 / truth_size[pair.t as usize] as f64,
            overlap_predicted: pair.o as f64 / predicted_size[pair.p as usize] as f64,
        })
        .collect();

    let count_t = |want: fn(&Tc) -> bool| truth_class.iter().filter(|c| want(c)).count();
    let count_p = |want: fn(&Pc) -> bool| predicted_class.iter().filter(|c| want(c)).count();
    let truth_planes = scored.iter().filter(|&&s| s).count();
    let correct = matches.len();
    let labelled_points: usize = (0..nt).filter(|&t| scored[t]).map(|t| truth_size[t]).sum();
    let correct_points: usize = (0..nt)
        .filter(|&t| matches!(truth_class[t], Tc::Correct(_)))
        .map(|t| truth_size[t])
        .sum();
    let percent = |num: usize, den: usize| {
        if den == 0 {
            0.0
        } else {
            100.0 * num as f64 / den as f64
        }
    };
    Ok(Evaluation {
        truth_planes,
        predicted_planes: np,
        correct,
        over_segmented: count_t(|c| *c == Tc::Over),
        under_segmented: count_p(|c| *c == Pc::Under),
        missed: count_t(|c| *c == Tc::Missed),
        spurious: count_p(|c| *c == Pc::Spurious),
        f: percent(correct, truth_planes),
        k: percent(correct_points, labelled_points),
        rmse: pooled(sse_all, n_all),
        rmse_correct: pooled(sse_correct, n_correct),
        labelled_points,
        correct_points,
        rmse_points: n_all,
        rmse_correct_points: n_correct,
        matches,
        truth_regions,
        predicted_regions,
    })
}

/// Hoover's classification with the exclusive resolution described in the crate docs, on
/// compact ids. `pairs` holds every overlap (> 0 points) of a scored ground-truth plane
/// with a predicted segment.
fn classify(
    pairs: &[Pair],
    truth_size: &[usize],
    scored: &[bool],
    predicted_size: &[usize],
    threshold: f64,
) -> (Vec<Tc>, Vec<Pc>) {
    let (nt, np) = (truth_size.len(), predicted_size.len());
    // host_of_truth[t]: the segment holding ≥ T of plane t (unique since T > 1/2), with
    // the overlap; host_of_predicted[p]: the plane holding ≥ T of segment p.
    let mut host_of_truth = vec![(NONE, 0usize); nt];
    let mut host_of_predicted = vec![NONE; np];
    // Over-segmentation candidates of plane t: segments with ≥ T of their points in t.
    let mut over_count = vec![0usize; nt];
    let mut over_points = vec![0usize; nt];
    let mut over_fraction_sum = vec![0.0f64; nt];
    // Under-segmentation candidates of segment p: planes with ≥ T of their points in p.
    let mut under_count = vec![0usize; np];
    let mut under_points = vec![0usize; np];
    let mut under_fraction_sum = vec![0.0f64; np];
    for &Pair { t, p, o } in pairs {
        let (tu, pu) = (t as usize, p as usize);
        if meets(o, predicted_size[pu], threshold) {
            host_of_predicted[pu] = t;
            over_count[tu] += 1;
            over_points[tu] += o;
            over_fraction_sum[tu] += o as f64 / predicted_size[pu] as f64;
        }
        if meets(o, truth_size[tu], threshold) {
            host_of_truth[tu] = (p, o);
            under_count[pu] += 1;
            under_points[pu] += o;
            under_fraction_sum[pu] += o as f64 / truth_size[tu] as f64;
        }
    }
    // Candidate instances and their scores (mean overlap fraction of the instance).
    let over_score = |t: usize| -> Option<f64> {
        (over_count[t] >= 2 && meets(over_points[t], truth_size[t], threshold)).then(|| {
            (over_fraction_sum[t] + over_points[t] as f64 / truth_size[t] as f64)
                / (over_count[t] + 1) as f64
        })
    };
    let under_score = |p: usize| -> Option<f64> {
        (under_count[p] >= 2 && meets(under_points[p], predicted_size[p], threshold)).then(|| {
            (under_fraction_sum[p] + under_points[p] as f64 / predicted_size[p] as f64)
                / (under_count[p] + 1) as f64
        })
    };
    let mut over_kept: Vec<bool> = (0..nt).map(|t| over_score(t).is_some()).collect();
    let mut under_kept: Vec<bool> = (0..np).map(|p| under_score(p).is_some()).collect();
    let mut correct = vec![false; nt];
    for t in 0..nt {
        let (p, o) = host_of_truth[t];
        if p == NONE || host_of_predicted[p as usize] != t as u32 {
            continue;
        }
        let pu = p as usize;
        let correct_score =
            0.5 * (o as f64 / truth_size[t] as f64 + o as f64 / predicted_size[pu] as f64);
        let over = over_score(t).unwrap_or(f64::NEG_INFINITY);
        let under = under_score(pu).unwrap_or(f64::NEG_INFINITY);
        if correct_score + SCORE_TIE >= over && correct_score + SCORE_TIE >= under {
            correct[t] = true;
            over_kept[t] = false;
            under_kept[pu] = false;
        } else if over + SCORE_TIE >= under {
            under_kept[pu] = false;
        } else {
            over_kept[t] = false;
        }
    }
    let truth_class = (0..nt)
        .map(|t| {
            let host = host_of_truth[t].0;
            if !scored[t] {
                Tc::Ignored
            } else if correct[t] {
                Tc::Correct(host)
            } else if over_kept[t] {
                Tc::Over
            } else if host != NONE && under_kept[host as usize] {
                Tc::Under(host)
            } else {
                Tc::Missed
            }
        })
        .collect();
    let predicted_class = (0..np)
        .map(|p| {
            let host = host_of_predicted[p];
            if host != NONE && correct[host as usize] && host_of_truth[host as usize].0 == p as u32
            {
                Pc::Correct(host)
            } else if under_kept[p] {
                Pc::Under
            } else if host != NONE && over_kept[host as usize] {
                Pc::Over(host)
            } else {
                Pc::Spurious
            }
        })
        .collect();
    (truth_class, predicted_class)
}
