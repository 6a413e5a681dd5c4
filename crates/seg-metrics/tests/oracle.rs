//! `evaluate` against a brute-force reimplementation of the definitions (maps of pairs,
//! subset enumeration for Hoover's instances, pairwise conflict resolution, SVD plane fits),
//! on small random labelings; invariance under relabelling and reordering; a large sparse
//! labeling; noisy planes scored perfectly.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::collections::{BTreeMap, BTreeSet};

use nalgebra::DMatrix;
use proptest::prelude::*;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use seg_metrics::{EvaluateOptions, Evaluation, PredictedClass, TruthClass, evaluate};

/// What the oracle expects.
#[derive(Debug)]
struct Expected {
    truth_planes: usize,
    predicted_planes: usize,
    correct: usize,
    over_segmented: usize,
    under_segmented: usize,
    missed: usize,
    spurious: usize,
    f: f64,
    k: f64,
    rmse: Option<f64>,
    rmse_correct: Option<f64>,
    truth: BTreeMap<i32, TruthClass>,
    predicted: BTreeMap<i32, PredictedClass>,
}

#[derive(Debug, Clone)]
enum Instance {
    Correct { plane: i32, segment: i32 },
    Over { plane: i32, pieces: Vec<i32> },
    Under { segment: i32, planes: Vec<i32> },
}

impl Instance {
    fn planes(&self) -> Vec<i32> {
        match self {
            Instance::Correct { plane, .. } | Instance::Over { plane, .. } => vec![*plane],
            Instance::Under { planes, .. } => planes.clone(),
        }
    }
    fn segments(&self) -> Vec<i32> {
        match self {
            Instance::Correct { segment, .. } | Instance::Under { segment, .. } => vec![*segment],
            Instance::Over { pieces, .. } => pieces.clone(),
        }
    }
    fn rank(&self) -> u8 {
        match self {
            Instance::Correct { .. } => 0,
            Instance::Over { .. } => 1,
            Instance::Under { .. } => 2,
        }
    }
}

/// Does any subset of at least two of `overlaps` sum to `T · size` or more?
fn some_subset_reaches(
    overlaps: &[usize],
    size: usize,
    reaches: &dyn Fn(usize, usize) -> bool,
) -> bool {
    let k = overlaps.len();
    assert!(k <= 20, "oracle subset enumeration too large");
    (0u32..1 << k).any(|mask| {
        mask.count_ones() >= 2
            && reaches(
                (0..k)
                    .filter(|i| mask & (1 << i) != 0)
                    .map(|i| overlaps[i])
                    .sum(),
                size,
            )
    })
}

/// Sum of squared orthogonal residuals to the least-squares plane, by SVD of the centred
/// coordinates.
fn svd_sse(points: &[[f64; 3]]) -> f64 {
    let n = points.len();
    let mean: Vec<f64> = (0..3)
        .map(|a| points.iter().map(|p| p[a]).sum::<f64>() / n as f64)
        .collect();
    let m = DMatrix::from_fn(n, 3, |r, c| points[r][c] - mean[c]);
    let s = m.svd(false, false).singular_values;
    let smallest = s.iter().copied().fold(f64::INFINITY, f64::min);
    if n < 3 { 0.0 } else { smallest * smallest }
}

fn brute(
    points: &[[f64; 3]],
    truth: &[i32],
    predicted: &[i32],
    (t_num, t_den): (u64, u64),
    min_truth: usize,
) -> Expected {
    let reaches = |o: usize, size: usize| o as u64 * t_den >= t_num * size as u64;
    let mut plane_size: BTreeMap<i32, usize> = BTreeMap::new();
    let mut segment_size: BTreeMap<i32, usize> = BTreeMap::new();
    let mut overlap: BTreeMap<(i32, i32), usize> = BTreeMap::new();
    let mut segment_points: BTreeMap<i32, Vec<[f64; 3]>> = BTreeMap::new();
    for i in 0..points.len() {
        if truth[i] >= 0 {
            *plane_size.entry(truth[i]).or_default() += 1;
        }
        if predicted[i] >= 0 {
            *segment_size.entry(predicted[i]).or_default() += 1;
            segment_points
                .entry(predicted[i])
                .or_default()
                .push(points[i]);
        }
        if truth[i] >= 0 && predicted[i] >= 0 {
            *overlap.entry((truth[i], predicted[i])).or_default() += 1;
        }
    }
    let planes: Vec<i32> = plane_size
        .iter()
        .filter(|&(_, &size)| size >= min_truth)
        .map(|(&g, _)| g)
        .collect();
    let segments: Vec<i32> = segment_size.keys().copied().collect();
    let o = |g: i32, s: i32| overlap.get(&(g, s)).copied().unwrap_or(0);
    let (gs, ss) = (|g: i32| plane_size[&g], |s: i32| segment_size[&s]);

    let mut instances: Vec<(Instance, f64)> = Vec::new();
    for &g in &planes {
        for &s in &segments {
            let ov = o(g, s);
            if ov > 0 && reaches(ov, gs(g)) && reaches(ov, ss(s)) {
                let score = (ov as f64 / gs(g) as f64 + ov as f64 / ss(s) as f64) / 2.0;
                instances.push((
                    Instance::Correct {
                        plane: g,
                        segment: s,
                    },
                    score,
                ));
            }
        }
    }
    for &g in &planes {
        let pieces: Vec<i32> = segments
            .iter()
            .copied()
            .filter(|&s| o(g, s) > 0 && reaches(o(g, s), ss(s)))
            .collect();
        let overlaps: Vec<usize> = pieces.iter().map(|&s| o(g, s)).collect();
        if some_subset_reaches(&overlaps, gs(g), &reaches) {
            let total: usize = overlaps.iter().sum();
            let score = (pieces
                .iter()
                .map(|&s| o(g, s) as f64 / ss(s) as f64)
                .sum::<f64>()
                + total as f64 / gs(g) as f64)
                / (pieces.len() + 1) as f64;
            instances.push((Instance::Over { plane: g, pieces }, score));
        }
    }
    for &s in &segments {
        let merged: Vec<i32> = planes
            .iter()
            .copied()
            .filter(|&g| o(g, s) > 0 && reaches(o(g, s), gs(g)))
            .collect();
        let overlaps: Vec<usize> = merged.iter().map(|&g| o(g, s)).collect();
        if some_subset_reaches(&overlaps, ss(s), &reaches) {
            let total: usize = overlaps.iter().sum();
            let score = (merged
                .iter()
                .map(|&g| o(g, s) as f64 / gs(g) as f64)
                .sum::<f64>()
                + total as f64 / ss(s) as f64)
                / (merged.len() + 1) as f64;
            instances.push((
                Instance::Under {
                    segment: s,
                    planes: merged,
                },
                score,
            ));
        }
    }
    // Kept: beats every instance it shares a region with.
    let shares = |a: &Instance, b: &Instance| {
        a.planes().iter().any(|g| b.planes().contains(g))
            || a.segments().iter().any(|s| b.segments().contains(s))
    };
    let beats = |(a, sa): &(Instance, f64), (b, sb): &(Instance, f64)| {
        *sa > *sb + 1e-12 || ((sa - sb).abs() <= 1e-12 && a.rank() < b.rank())
    };
    let kept: Vec<Instance> = (0..instances.len())
        .filter(|&i| {
            (0..instances.len()).all(|j| {
                i == j
                    || !shares(&instances[i].0, &instances[j].0)
                    || beats(&instances[i], &instances[j])
            })
        })
        .map(|i| instances[i].0.clone())
        .collect();

    let mut truth_classes = BTreeMap::new();
    let mut predicted_classes = BTreeMap::new();
    for instance in &kept {
        let mut put_t = |g: i32, class: TruthClass| {
            assert!(
                truth_classes.insert(g, class).is_none(),
                "plane {g} in two instances"
            );
        };
        match instance {
            Instance::Correct { plane, segment } => put_t(
                *plane,
                TruthClass::Correct {
                    predicted: *segment,
                },
            ),
            Instance::Over { plane, .. } => put_t(*plane, TruthClass::OverSegmented),
            Instance::Under { segment, planes } => {
                for &g in planes {
                    put_t(
                        g,
                        TruthClass::UnderSegmented {
                            predicted: *segment,
                        },
                    );
                }
            }
        }
        let mut put_s = |s: i32, class: PredictedClass| {
            assert!(
                predicted_classes.insert(s, class).is_none(),
                "segment {s} in two instances"
            );
        };
        match instance {
            Instance::Correct { plane, segment } => {
                put_s(*segment, PredictedClass::Correct { truth: *plane })
            }
            Instance::Over { plane, pieces } => {
                for &s in pieces {
                    put_s(s, PredictedClass::OverSegmented { truth: *plane });
                }
            }
            Instance::Under { segment, .. } => put_s(*segment, PredictedClass::UnderSegmented),
        }
    }
    for &g in plane_size.keys() {
        let class = if planes.contains(&g) {
            TruthClass::Missed
        } else {
            TruthClass::Ignored
        };
        truth_classes.entry(g).or_insert(class);
    }
    for &s in &segments {
        predicted_classes
            .entry(s)
            .or_insert(PredictedClass::Spurious);
    }

    let correct_planes: Vec<i32> = kept
        .iter()
        .filter_map(|i| match i {
            Instance::Correct { plane, .. } => Some(*plane),
            _ => None,
        })
        .collect();
    let correct_segments: BTreeSet<i32> = kept
        .iter()
        .filter_map(|i| match i {
            Instance::Correct { segment, .. } => Some(*segment),
            _ => None,
        })
        .collect();
    let labelled: usize = planes.iter().map(|&g| gs(g)).sum();
    let correct_points: usize = correct_planes.iter().map(|&g| gs(g)).sum();
    let pct = |a: usize, b: usize| {
        if b == 0 {
            0.0
        } else {
            100.0 * a as f64 / b as f64
        }
    };
    let pool = |only_correct: bool| {
        let (mut sse, mut n) = (0.0, 0usize);
        for (s, pts) in &segment_points {
            if pts.len() >= 4 && (!only_correct || correct_segments.contains(s)) {
                sse += svd_sse(pts);
                n += pts.len();
            }
        }
        (n > 0).then(|| (sse / n as f64).sqrt())
    };
    let count_t = |f: fn(&TruthClass) -> bool| truth_classes.values().filter(|c| f(c)).count();
    let count_p =
        |f: fn(&PredictedClass) -> bool| predicted_classes.values().filter(|c| f(c)).count();
    Expected {
        truth_planes: planes.len(),
        predicted_planes: segments.len(),
        correct: correct_planes.len(),
        over_segmented: count_t(|c| *c == TruthClass::OverSegmented),
        under_segmented: count_p(|c| *c == PredictedClass::UnderSegmented),
        missed: count_t(|c| *c == TruthClass::Missed),
        spurious: count_p(|c| *c == PredictedClass::Spurious),
        f: pct(correct_planes.len(), planes.len()),
        k: pct(correct_points, labelled),
        rmse: pool(false),
        rmse_correct: pool(true),
        truth: truth_classes,
        predicted: predicted_classes,
    }
}

fn close(a: Option<f64>, b: Option<f64>) -> bool {
    match (a, b) {
        (None, None) => true,
        (Some(a), Some(b)) => (a - b).abs() <= 1e-9 * (1.0 + a.abs().max(b.abs())),
        _ => false,
    }
}

fn check_against_oracle(
    points: &[[f64; 3]],
    truth: &[i32],
    predicted: &[i32],
    threshold: (u64, u64),
    min_truth: usize,
) -> Result<Evaluation, TestCaseError> {
    let options = EvaluateOptions::new()
        .with_overlap(threshold.0 as f64 / threshold.1 as f64)
        .with_min_truth_points(min_truth);
    let got = evaluate(points, truth, predicted, &options).unwrap();
    let want = brute(points, truth, predicted, threshold, min_truth);
    let got_truth: BTreeMap<i32, TruthClass> =
        got.truth_regions.iter().map(|r| (r.id, r.class)).collect();
    let got_predicted: BTreeMap<i32, PredictedClass> = got
        .predicted_regions
        .iter()
        .map(|r| (r.id, r.class))
        .collect();
    prop_assert_eq!(&got_truth, &want.truth);
    prop_assert_eq!(&got_predicted, &want.predicted);
    prop_assert_eq!(
        (
            got.truth_planes,
            got.predicted_planes,
            got.correct,
            got.over_segmented
        ),
        (
            want.truth_planes,
            want.predicted_planes,
            want.correct,
            want.over_segmented
        )
    );
    prop_assert_eq!(
        (got.under_segmented, got.missed, got.spurious),
        (want.under_segmented, want.missed, want.spurious)
    );
    prop_assert!((got.f - want.f).abs() < 1e-12, "f {} vs {}", got.f, want.f);
    prop_assert!((got.k - want.k).abs() < 1e-12, "k {} vs {}", got.k, want.k);
    prop_assert!(
        close(got.rmse, want.rmse),
        "rmse {:?} vs {:?}",
        got.rmse,
        want.rmse
    );
    prop_assert!(
        close(got.rmse_correct, want.rmse_correct),
        "rmse_correct {:?} vs {:?}",
        got.rmse_correct,
        want.rmse_correct
    );
    // Bookkeeping identities.
    let in_under = got_truth
        .values()
        .filter(|c| matches!(c, TruthClass::UnderSegmented { .. }))
        .count();
    let in_over = got_predicted
        .values()
        .filter(|c| matches!(c, PredictedClass::OverSegmented { .. }))
        .count();
    prop_assert_eq!(
        got.truth_planes,
        got.correct + got.over_segmented + in_under + got.missed
    );
    prop_assert_eq!(
        got.predicted_planes,
        got.correct + in_over + got.under_segmented + got.spurious
    );
    prop_assert_eq!(got.matches.len(), got.correct);
    for m in &got.matches {
        prop_assert_eq!(
            got_truth[&m.truth],
            TruthClass::Correct {
                predicted: m.predicted
            }
        );
        prop_assert!(m.overlap_truth >= options.overlap - 1e-12);
        prop_assert!(m.overlap_predicted >= options.overlap - 1e-12);
    }
    Ok(got)
}

const SPARSE_IDS: [i32; 8] = [0, 3, 17, 1000, 65_536, 1 << 24, i32::MAX - 1, i32::MAX];

/// Ground-truth class of a selector: −1 (unlabelled), three large planes, two small ones.
const CLASS_OF: [i32; 16] = [-1, -1, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 3, 4];

/// A random labeling that produces every class and every conflict: each ground-truth class
/// has a base segment (shared bases merge planes) and two 10 % pieces that may go to other
/// segments (splits, and small fragments next to a correct detection); 5 % label noise;
/// optional sparse ids and invalid (NaN) points where both labels are −1.
fn labeling() -> impl Strategy<Value = (Vec<[f64; 3]>, Vec<i32>, Vec<i32>)> {
    (0usize..90)
        .prop_flat_map(|n| {
            (
                proptest::collection::vec((0usize..16, 0u8..10, 0u8..20, -1i32..7), n),
                proptest::collection::vec(-1i32..7, 6),
                proptest::collection::vec((any::<bool>(), -1i32..7), 12),
                proptest::collection::vec(proptest::array::uniform3(-5.0f64..5.0), n),
                any::<(bool, bool, bool)>(),
            )
        })
        .prop_map(
            |(per_point, base, pieces, points, (sparse_t, sparse_p, nans))| {
                let mut truth = Vec::with_capacity(per_point.len());
                let mut predicted = Vec::with_capacity(per_point.len());
                for &(class, piece, noise, noise_label) in &per_point {
                    let t = CLASS_OF[class];
                    let row = (t + 1) as usize;
                    let p = match piece {
                        0..=7 => base[row],
                        _ => match pieces[row * 2 + (piece - 8) as usize] {
                            (true, other) => other,
                            (false, _) => base[row],
                        },
                    };
                    truth.push(t);
                    predicted.push(if noise == 0 { noise_label } else { p });
                }
                let relabel = |l: i32, sparse: bool| {
                    if l < 0 || !sparse {
                        l
                    } else {
                        SPARSE_IDS[l as usize]
                    }
                };
                let truth: Vec<i32> = truth.iter().map(|&l| relabel(l, sparse_t)).collect();
                let predicted: Vec<i32> = predicted.iter().map(|&l| relabel(l, sparse_p)).collect();
                let points = points
                    .iter()
                    .enumerate()
                    .map(|(i, &p)| {
                        if nans && truth[i] < 0 && predicted[i] < 0 && i % 2 == 0 {
                            [f64::NAN, p[1], p[2]]
                        } else {
                            p
                        }
                    })
                    .collect();
                (points, truth, predicted)
            },
        )
}

fn threshold() -> impl Strategy<Value = (u64, u64)> {
    prop_oneof![
        Just((4, 5)),
        Just((3, 4)),
        Just((2, 3)),
        Just((9, 10)),
        Just((51, 100)),
        Just((1, 1)),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn matches_the_brute_force_oracle(
        (points, truth, predicted) in labeling(),
        threshold in threshold(),
        min_truth in 0usize..4,
    ) {
        check_against_oracle(&points, &truth, &predicted, threshold, min_truth)?;
    }

    #[test]
    fn invariant_under_relabelling_and_reordering(
        (points, truth, predicted) in labeling(),
        truth_ids in Just(SPARSE_IDS.to_vec()).prop_shuffle(),
        predicted_ids in Just(SPARSE_IDS.to_vec()).prop_shuffle(),
        order_seed in any::<u64>(),
    ) {
        let options = EvaluateOptions::default();
        let base = evaluate(&points, &truth, &predicted, &options).unwrap();
        // Relabel densely first (ids may already be sparse), then through the shuffles.
        let dense = |labels: &[i32]| -> (Vec<i32>, Vec<i32>) {
            let ids: Vec<i32> = labels.iter().copied().filter(|&l| l >= 0).collect::<BTreeSet<_>>().into_iter().collect();
            (labels.iter().map(|&l| if l < 0 { -1 } else { ids.binary_search(&l).unwrap() as i32 }).collect(), ids)
        };
        let (truth_dense, truth_original) = dense(&truth);
        let (predicted_dense, predicted_original) = dense(&predicted);
        let mut order: Vec<usize> = (0..points.len()).collect();
        let mut rng = ChaCha8Rng::seed_from_u64(order_seed);
        for i in (1..order.len()).rev() {
            order.swap(i, rng.random_range(0..=i));
        }
        let map_t = |l: i32| if l < 0 { -1 } else { truth_ids[l as usize] };
        let map_p = |l: i32| if l < 0 { -1 } else { predicted_ids[l as usize] };
        let points2: Vec<[f64; 3]> = order.iter().map(|&i| points[i]).collect();
        let truth2: Vec<i32> = order.iter().map(|&i| map_t(truth_dense[i])).collect();
        let predicted2: Vec<i32> = order.iter().map(|&i| map_p(predicted_dense[i])).collect();
        let moved = evaluate(&points2, &truth2, &predicted2, &options).unwrap();

        prop_assert_eq!(
            (base.truth_planes, base.predicted_planes, base.correct, base.over_segmented, base.under_segmented, base.missed, base.spurious),
            (moved.truth_planes, moved.predicted_planes, moved.correct, moved.over_segmented, moved.under_segmented, moved.missed, moved.spurious)
        );
        prop_assert_eq!(base.f, moved.f);
        prop_assert_eq!(base.k, moved.k);
        prop_assert!(close(base.rmse, moved.rmse));
        prop_assert!(close(base.rmse_correct, moved.rmse_correct));
        // The same pairs, through the id maps.
        let to_new_t = |id: i32| map_t(truth_original.binary_search(&id).unwrap() as i32);
        let to_new_p = |id: i32| map_p(predicted_original.binary_search(&id).unwrap() as i32);
        let base_pairs: BTreeSet<(i32, i32, usize)> = base.matches.iter().map(|m| (to_new_t(m.truth), to_new_p(m.predicted), m.overlap)).collect();
        let moved_pairs: BTreeSet<(i32, i32, usize)> = moved.matches.iter().map(|m| (m.truth, m.predicted, m.overlap)).collect();
        prop_assert_eq!(base_pairs, moved_pairs);
        let base_classes: BTreeMap<i32, PredictedClass> = base.predicted_regions.iter().map(|r| {
            let class = match r.class {
                PredictedClass::Correct { truth } => PredictedClass::Correct { truth: to_new_t(truth) },
                PredictedClass::OverSegmented { truth } => PredictedClass::OverSegmented { truth: to_new_t(truth) },
                other => other,
            };
            (to_new_p(r.id), class)
        }).collect();
        let moved_classes: BTreeMap<i32, PredictedClass> = moved.predicted_regions.iter().map(|r| (r.id, r.class)).collect();
        prop_assert_eq!(base_classes, moved_classes);
    }
}

/// Many planes and segments (the sparse pair table), against the oracle.
#[test]
fn large_sparse_labeling_matches_the_oracle() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let n = 4000;
    let mut truth = Vec::with_capacity(n);
    let mut predicted = Vec::with_capacity(n);
    let mut points = Vec::with_capacity(n);
    for i in 0..n {
        let plane = (i / 8) as i32; // 500 planes of 8 points
        truth.push(if rng.random_range(0..20) == 0 {
            -1
        } else {
            plane * 3 + 1
        });
        let segment = match plane % 6 {
            0 | 1 => plane,                         // correct (mostly)
            2 => 1000 + plane * 2 + (i % 2) as i32, // over: two pieces
            3 | 4 => 5000 + plane / 6,              // under: planes 3 and 4 merged
            _ => -1,                                // missed
        };
        let noise = rng.random_range(0..15) == 0;
        predicted.push(if noise {
            rng.random_range(0..600) * 7
        } else {
            segment
        });
        points.push([
            rng.random::<f64>(),
            rng.random::<f64>(),
            0.01 * rng.random::<f64>(),
        ]);
    }
    let options = EvaluateOptions::default();
    let got = evaluate(&points, &truth, &predicted, &options).unwrap();
    assert!(
        got.truth_planes * got.predicted_planes > 2 * n + 65_536,
        "not the sparse path: {} × {}",
        got.truth_planes,
        got.predicted_planes
    );
    assert!(got.correct > 100 && got.over_segmented > 20 && got.under_segmented > 20);
    assert!(got.missed > 50 && got.spurious > 50);
    check_against_oracle(&points, &truth, &predicted, (4, 5), 0).unwrap();
    check_against_oracle(&points, &truth, &predicted, (2, 3), 5).unwrap();
}

/// Standard normal samples (Box–Muller).
fn gaussian(rng: &mut ChaCha8Rng) -> f64 {
    let u1 = 1.0 - rng.random::<f64>();
    let u2 = rng.random::<f64>();
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

#[test]
fn perfect_prediction_of_noisy_planes() {
    let sigma = 0.01;
    let mut rng = ChaCha8Rng::seed_from_u64(42);
    // Three planes (floor, tilted wall, slanted roof), 20,000 points each, noise σ along
    // the normal, plus 5,000 unlabelled clutter points left unpredicted.
    let planes: [([f64; 3], [f64; 3], [f64; 3]); 3] = [
        ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
        ([0.0, 5.0, 0.0], [0.6, 0.8, 0.0], [0.0, 0.0, 1.0]),
        ([2.0, 2.0, 3.0], [1.0, 0.0, 0.0], [0.0, 0.6, 0.8]),
    ];
    let (mut points, mut truth) = (Vec::new(), Vec::new());
    for (id, (origin, u, v)) in planes.iter().enumerate() {
        let normal = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        for _ in 0..20_000 {
            let (a, b, e) = (
                4.0 * rng.random::<f64>(),
                3.0 * rng.random::<f64>(),
                sigma * gaussian(&mut rng),
            );
            points.push([0, 1, 2].map(|k| origin[k] + a * u[k] + b * v[k] + e * normal[k]));
            truth.push(10 * id as i32 + 5);
        }
    }
    for _ in 0..5_000 {
        points.push([
            10.0 * rng.random::<f64>(),
            10.0 * rng.random::<f64>(),
            10.0 * rng.random::<f64>(),
        ]);
        truth.push(-1);
    }
    let e = evaluate(&points, &truth, &truth, &EvaluateOptions::default()).unwrap();
    assert_eq!((e.f, e.k), (100.0, 100.0));
    assert_eq!((e.correct, e.missed, e.spurious), (3, 0, 0));
    let rmse = e.rmse.unwrap();
    assert!(
        (rmse - sigma).abs() < 0.03 * sigma,
        "rmse {rmse} vs σ {sigma}"
    );
    assert_eq!(e.rmse, e.rmse_correct);
    for region in &e.truth_regions {
        let own: Vec<[f64; 3]> = (0..points.len())
            .filter(|&i| truth[i] == region.id)
            .map(|i| points[i])
            .collect();
        let single = seg_metrics::fit_plane_rmse(&own).unwrap();
        assert!(
            (single - sigma).abs() < 0.05 * sigma,
            "plane {}: {single}",
            region.id
        );
        let fit = seg_metrics::fit_plane(&own).unwrap();
        assert!(((svd_sse(&own) / own.len() as f64).sqrt() - fit.rmse).abs() < 1e-12);
    }
}
