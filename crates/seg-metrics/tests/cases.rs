//! Hand-made segmentations, one per classification and conflict, plus bad input.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use seg_metrics::{
    EvaluateOptions, Evaluation, Labels, MetricsError, PredictedClass, TruthClass, evaluate,
};

/// Concatenates runs of `(label, count)`.
fn runs(parts: &[(i32, usize)]) -> Vec<i32> {
    parts
        .iter()
        .flat_map(|&(label, count)| std::iter::repeat_n(label, count))
        .collect()
}

/// Points on the plane z = 0 (positions do not matter for the classification).
fn flat(n: usize) -> Vec<[f64; 3]> {
    (0..n)
        .map(|i| [(i % 17) as f64, (i / 17) as f64, 0.0])
        .collect()
}

fn score(truth: &[i32], predicted: &[i32]) -> Evaluation {
    assert_eq!(truth.len(), predicted.len(), "test labels must line up");
    evaluate(
        &flat(truth.len()),
        truth,
        predicted,
        &EvaluateOptions::default(),
    )
    .unwrap()
}

fn truth_class(e: &Evaluation, id: i32) -> TruthClass {
    e.truth_regions.iter().find(|r| r.id == id).unwrap().class
}

fn predicted_class(e: &Evaluation, id: i32) -> PredictedClass {
    e.predicted_regions
        .iter()
        .find(|r| r.id == id)
        .unwrap()
        .class
}

/// (correct, over, under, missed, spurious)
fn counts(e: &Evaluation) -> (usize, usize, usize, usize, usize) {
    (
        e.correct,
        e.over_segmented,
        e.under_segmented,
        e.missed,
        e.spurious,
    )
}

#[test]
fn identical_labelings_are_all_correct() {
    let truth = runs(&[(4, 10), (-1, 3), (9, 20)]);
    let e = score(&truth, &truth);
    assert_eq!(counts(&e), (2, 0, 0, 0, 0));
    assert_eq!((e.truth_planes, e.predicted_planes), (2, 2));
    assert_eq!((e.f, e.k), (100.0, 100.0));
    assert_eq!((e.labelled_points, e.correct_points), (30, 30));
    assert_eq!(e.matches.len(), 2);
    assert_eq!((e.matches[0].truth, e.matches[0].predicted), (4, 4));
    assert_eq!(e.matches[1].overlap, 20);
    assert_eq!(e.matches[1].overlap_truth, 1.0);
    assert_eq!(e.matches[1].overlap_predicted, 1.0);
    assert!(e.rmse.unwrap() < 1e-12);
    assert_eq!(e.rmse_points, 30);
    assert_eq!(e.rmse_correct_points, 30);
}

#[test]
fn correct_detection_threshold_is_inclusive() {
    // Plane 1 (10 points): 8 in segment 5, 2 unpredicted; segment 5 also takes 2
    // unlabelled points: 8/10 of both.
    let truth = runs(&[(1, 8), (1, 2), (-1, 2)]);
    let predicted = runs(&[(5, 8), (-1, 2), (5, 2)]);
    let e = score(&truth, &predicted);
    assert_eq!(counts(&e), (1, 0, 0, 0, 0));
    assert_eq!(truth_class(&e, 1), TruthClass::Correct { predicted: 5 });
    assert_eq!(predicted_class(&e, 5), PredictedClass::Correct { truth: 1 });
    assert_eq!(e.matches[0].overlap_truth, 0.8);
    assert_eq!(e.matches[0].overlap_predicted, 0.8);
    // k counts the whole plane, not only the overlap.
    assert_eq!(e.k, 100.0);

    // One point fewer in the overlap: 7/10 of the plane, 7/9 of the segment.
    let truth = runs(&[(1, 7), (1, 3), (-1, 2)]);
    let predicted = runs(&[(5, 7), (-1, 3), (5, 2)]);
    let e = score(&truth, &predicted);
    assert_eq!(counts(&e), (0, 0, 0, 1, 1));
    assert_eq!((e.f, e.k), (0.0, 0.0));
    assert!(e.matches.is_empty());
}

#[test]
fn unlabelled_points_make_a_segment_impure() {
    // The whole plane lies in segment 2, but so do 3 unlabelled points: 10/13 < 0.8.
    let truth = runs(&[(0, 10), (-1, 3)]);
    let predicted = runs(&[(2, 13)]);
    let e = score(&truth, &predicted);
    assert_eq!(counts(&e), (0, 0, 0, 1, 1));
    // With T = 0.75 it is correct.
    let e = evaluate(
        &flat(13),
        &truth,
        &predicted,
        &EvaluateOptions::new().with_overlap(0.75),
    )
    .unwrap();
    assert_eq!(counts(&e), (1, 0, 0, 0, 0));
}

#[test]
fn over_segmentation() {
    // Plane 3 split into halves 10 and 11.
    let truth = runs(&[(3, 20)]);
    let predicted = runs(&[(10, 10), (11, 10)]);
    let e = score(&truth, &predicted);
    assert_eq!(counts(&e), (0, 1, 0, 0, 0));
    assert_eq!(truth_class(&e, 3), TruthClass::OverSegmented);
    assert_eq!(
        predicted_class(&e, 10),
        PredictedClass::OverSegmented { truth: 3 }
    );
    assert_eq!(
        predicted_class(&e, 11),
        PredictedClass::OverSegmented { truth: 3 }
    );
    assert_eq!((e.f, e.k), (0.0, 0.0));
}

#[test]
fn over_segmentation_needs_enough_coverage() {
    // Pieces covering 4 + 3 of 10 points (70 %): no over-segmentation.
    let truth = runs(&[(3, 10)]);
    let predicted = runs(&[(10, 4), (11, 3), (-1, 3)]);
    let e = score(&truth, &predicted);
    assert_eq!(counts(&e), (0, 0, 0, 1, 2));
    // A piece with too many foreign points does not take part: segment 11 holds 4 points
    // of plane 3 and 2 of plane 8 (4/6 < 0.8), which leaves segment 10 as the only piece.
    let truth = runs(&[(3, 5), (3, 4), (8, 2), (8, 20), (3, 1)]);
    let predicted = runs(&[(10, 5), (11, 4), (11, 2), (12, 20), (-1, 1)]);
    let e = score(&truth, &predicted);
    assert_eq!(truth_class(&e, 3), TruthClass::Missed);
    assert_eq!(predicted_class(&e, 10), PredictedClass::Spurious);
    assert_eq!(predicted_class(&e, 11), PredictedClass::Spurious);
    assert_eq!(truth_class(&e, 8), TruthClass::Correct { predicted: 12 });
}

#[test]
fn under_segmentation() {
    // Planes 1 and 2 merged into segment 7.
    let truth = runs(&[(1, 10), (2, 10)]);
    let predicted = runs(&[(7, 20)]);
    let e = score(&truth, &predicted);
    assert_eq!(counts(&e), (0, 0, 1, 0, 0));
    assert_eq!(predicted_class(&e, 7), PredictedClass::UnderSegmented);
    assert_eq!(
        truth_class(&e, 1),
        TruthClass::UnderSegmented { predicted: 7 }
    );
    assert_eq!(
        truth_class(&e, 2),
        TruthClass::UnderSegmented { predicted: 7 }
    );
    // Too many unlabelled points in the merged segment: (10 + 10) / 26 < 0.8.
    let truth = runs(&[(1, 10), (2, 10), (-1, 6)]);
    let predicted = runs(&[(7, 26)]);
    let e = score(&truth, &predicted);
    assert_eq!(counts(&e), (0, 0, 0, 2, 1));
}

#[test]
fn missed_and_spurious() {
    // Plane 0 never predicted; segment 4 on unlabelled points only.
    let truth = runs(&[(0, 10), (-1, 10)]);
    let predicted = runs(&[(-1, 10), (4, 10)]);
    let e = score(&truth, &predicted);
    assert_eq!(counts(&e), (0, 0, 0, 1, 1));
    assert_eq!(truth_class(&e, 0), TruthClass::Missed);
    assert_eq!(predicted_class(&e, 4), PredictedClass::Spurious);
    // A plane scattered over three segments, none with 80 % of it and none inside it.
    let truth = runs(&[(0, 30), (5, 30)]);
    let predicted = runs(&[(1, 10), (2, 10), (3, 10), (1, 10), (2, 10), (3, 10)]);
    let e = score(&truth, &predicted);
    assert_eq!(counts(&e), (0, 0, 0, 2, 3));
}

#[test]
fn over_segmentation_beats_a_weaker_correct_detection() {
    // Plane 0 (100 points): segment 1 holds 90 of them and nothing else, segment 2 the
    // other 10. Correct (0, 1) scores (0.9 + 1) / 2 = 0.95, the over-segmentation
    // (1 + 1 + 1) / 3 = 1.
    let truth = runs(&[(0, 100)]);
    let predicted = runs(&[(1, 90), (2, 10)]);
    let e = score(&truth, &predicted);
    assert_eq!(counts(&e), (0, 1, 0, 0, 0));
    assert_eq!(
        predicted_class(&e, 1),
        PredictedClass::OverSegmented { truth: 0 }
    );
}

#[test]
fn correct_detection_beats_a_weaker_over_segmentation() {
    // Plane 0 (100): segment 1 = 95 of its points (fm 1, fg 0.95: score 0.975); segment 2 =
    // 4 of its points + 1 unlabelled (fm 0.8); over score (1 + 0.8 + 0.99) / 3 = 0.93.
    // The leftover piece is then in no kept instance: spurious.
    let truth = runs(&[(0, 95), (0, 4), (-1, 1), (0, 1)]);
    let predicted = runs(&[(1, 95), (2, 4), (2, 1), (-1, 1)]);
    let e = score(&truth, &predicted);
    assert_eq!(counts(&e), (1, 0, 0, 0, 1));
    assert_eq!(truth_class(&e, 0), TruthClass::Correct { predicted: 1 });
    assert_eq!(predicted_class(&e, 2), PredictedClass::Spurious);
}

#[test]
fn under_segmentation_against_correct_detection() {
    // Segment 0 (100) = plane 1 (90) + plane 2 (10): under (1 + 1 + 1) / 3 beats correct
    // (1 + 0.9) / 2.
    let truth = runs(&[(1, 90), (2, 10)]);
    let predicted = runs(&[(0, 100)]);
    let e = score(&truth, &predicted);
    assert_eq!(counts(&e), (0, 0, 1, 0, 0));
    // Segment 0 (100) = plane 1 (95, all of it) + 4 of plane 2's 5 points + 1 unlabelled:
    // correct (1 + 0.95) / 2 = 0.975 beats under (1 + 0.8 + 0.99) / 3 = 0.93; plane 2 is
    // then missed.
    let truth = runs(&[(1, 95), (2, 4), (-1, 1), (2, 1)]);
    let predicted = runs(&[(0, 95), (0, 4), (0, 1), (-1, 1)]);
    let e = score(&truth, &predicted);
    assert_eq!(counts(&e), (1, 0, 0, 1, 0));
    assert_eq!(truth_class(&e, 2), TruthClass::Missed);
}

#[test]
fn ties_prefer_the_correct_detection() {
    // Plane 0 (200): segment 1 = 160 of its points only (correct: (0.8 + 1) / 2 = 0.9),
    // segment 2 = 20 of its points + 5 unlabelled (fm 0.8); over: (1 + 0.8 + 0.9) / 3 = 0.9.
    let truth = runs(&[(0, 160), (0, 20), (-1, 5), (0, 20)]);
    let predicted = runs(&[(1, 160), (2, 20), (2, 5), (-1, 20)]);
    let e = score(&truth, &predicted);
    assert_eq!(counts(&e), (1, 0, 0, 0, 1));
}

#[test]
fn mixed_scene() {
    // 0: correct (seg 100); 1: over-segmented (101, 102); 2 and 3: merged into 103;
    // 4: missed; 105: spurious; unlabelled background partly unpredicted.
    let truth = runs(&[
        (0, 50),
        (1, 20),
        (1, 20),
        (2, 15),
        (3, 15),
        (4, 12),
        (-1, 9),
        (-1, 30),
    ]);
    let predicted = runs(&[
        (100, 50),
        (101, 20),
        (102, 20),
        (103, 15),
        (103, 15),
        (-1, 12),
        (105, 9),
        (-1, 30),
    ]);
    let e = score(&truth, &predicted);
    assert_eq!((e.truth_planes, e.predicted_planes), (5, 5));
    assert_eq!(counts(&e), (1, 1, 1, 1, 1));
    assert_eq!(e.f, 20.0);
    assert_eq!(e.labelled_points, 132);
    assert_eq!(e.correct_points, 50);
    assert!((e.k - 100.0 * 50.0 / 132.0).abs() < 1e-12);
    assert_eq!(truth_class(&e, 4), TruthClass::Missed);
    assert_eq!(predicted_class(&e, 105), PredictedClass::Spurious);
    assert_eq!(
        truth_class(&e, 3),
        TruthClass::UnderSegmented { predicted: 103 }
    );
}

#[test]
fn small_truth_planes_can_be_ignored() {
    // Plane 9 has 3 points, inside segment 1 with plane 0's 20: ignored, it is just
    // foreign points in segment 1 (20/23 ≥ 0.8: correct).
    let truth = runs(&[(0, 20), (9, 3)]);
    let predicted = runs(&[(1, 23)]);
    let options = EvaluateOptions::new().with_min_truth_points(5);
    let e = evaluate(&flat(23), &truth, &predicted, &options).unwrap();
    assert_eq!(e.truth_planes, 1);
    assert_eq!(counts(&e), (1, 0, 0, 0, 0));
    assert_eq!(truth_class(&e, 9), TruthClass::Ignored);
    assert_eq!((e.labelled_points, e.k), (20, 100.0));
    // Without the minimum, planes 0 and 9 are merged into segment 1, which wins over the
    // correct detection of plane 0 ((1 + 1 + 1) / 3 > (1 + 20/23) / 2).
    let e = score(&truth, &predicted);
    assert_eq!(counts(&e), (0, 0, 1, 0, 0));
}

#[test]
fn empty_prediction_misses_everything() {
    let truth = runs(&[(0, 10), (1, 10), (-1, 5), (2, 4)]);
    let predicted = vec![-1; truth.len()];
    let e = score(&truth, &predicted);
    assert_eq!(counts(&e), (0, 0, 0, 3, 0));
    assert_eq!((e.f, e.k), (0.0, 0.0));
    assert_eq!(e.predicted_planes, 0);
    assert!(e.rmse.is_none() && e.rmse_correct.is_none());
    assert!(
        e.truth_regions
            .iter()
            .all(|r| r.class == TruthClass::Missed)
    );
}

#[test]
fn no_truth_and_no_points() {
    let e = evaluate(&[], &[], &[], &EvaluateOptions::default()).unwrap();
    assert_eq!((e.truth_planes, e.predicted_planes), (0, 0));
    assert_eq!((e.f, e.k), (0.0, 0.0));
    assert!(e.rmse.is_none());
    // Prediction only: all spurious, f = k = 0 by convention.
    let predicted = runs(&[(3, 6)]);
    let e = score(&[-1; 6], &predicted);
    assert_eq!(counts(&e), (0, 0, 0, 0, 1));
    assert_eq!((e.f, e.k), (0.0, 0.0));
    assert!(e.rmse.is_some());
}

#[test]
fn rmse_pools_segments_with_enough_points() {
    // Segment 0: 4 points alternating z = ±0.1 on a square (plane fit error: the best
    // plane is z = 0 → 0.1). Segment 1: three points (left out). Segment 2: eight points
    // with z = ±0.2 in a checkerboard on a 4 × 2 grid.
    let mut points = vec![
        [0.0, 0.0, 0.1],
        [1.0, 0.0, -0.1],
        [1.0, 1.0, 0.1],
        [0.0, 1.0, -0.1],
    ];
    points.extend([[5.0, 0.0, 3.0], [6.0, 0.0, 9.0], [5.0, 1.0, -4.0]]);
    for i in 0..8 {
        let (x, y) = ((i % 4) as f64, (i / 4) as f64);
        let z = if (i % 4 + i / 4) % 2 == 0 { 0.2 } else { -0.2 };
        points.push([x + 10.0, y, z]);
    }
    let predicted = runs(&[(0, 4), (1, 3), (2, 8)]);
    let truth = predicted.clone();
    let e = evaluate(&points, &truth, &predicted, &EvaluateOptions::default()).unwrap();
    let expected = ((4.0 * 0.01 + 8.0 * 0.04) / 12.0f64).sqrt();
    assert_eq!(e.rmse_points, 12);
    assert!((e.rmse.unwrap() - expected).abs() < 1e-12, "{:?}", e.rmse);
    assert_eq!(e.rmse, e.rmse_correct);
    // The plane fit itself agrees.
    let fit = seg_metrics::fit_plane_rmse(&points[..4]).unwrap();
    assert!((fit - 0.1).abs() < 1e-12);
}

#[test]
fn non_finite_points_need_no_labels() {
    let mut points = flat(12);
    points[3] = [f64::NAN, 0.0, 0.0];
    points[7] = [0.0, f64::INFINITY, 0.0];
    let mut truth = runs(&[(0, 12)]);
    let mut predicted = runs(&[(0, 12)]);
    for i in [3, 7] {
        truth[i] = -1;
        predicted[i] = -1;
    }
    let e = evaluate(&points, &truth, &predicted, &EvaluateOptions::default()).unwrap();
    assert_eq!(counts(&e), (1, 0, 0, 0, 0));
    // Labelled in one array only: refused, naming the point.
    predicted[7] = 0;
    assert_eq!(
        evaluate(&points, &truth, &predicted, &EvaluateOptions::default()),
        Err(MetricsError::NonFinitePoint {
            index: 7,
            truth: -1,
            predicted: 0
        })
    );
    predicted[7] = -1;
    truth[3] = 0;
    assert_eq!(
        evaluate(&points, &truth, &predicted, &EvaluateOptions::default()),
        Err(MetricsError::NonFinitePoint {
            index: 3,
            truth: 0,
            predicted: -1
        })
    );
}

#[test]
fn non_finite_point_inside_a_long_run_is_found() {
    let truth = runs(&[(4, 40)]);
    for (index, bad) in [
        (0, [f64::NAN, 0.0, 0.0]),
        (23, [0.0, 0.0, f64::NEG_INFINITY]),
        (39, [f64::INFINITY, 1.0, 1.0]),
    ] {
        let mut points = flat(40);
        points[index] = bad;
        assert_eq!(
            evaluate(&points, &truth, &truth, &EvaluateOptions::default()),
            Err(MetricsError::NonFinitePoint {
                index,
                truth: 4,
                predicted: 4
            })
        );
    }
    // +∞ and −∞ in one run cancel to NaN in the sum; still found.
    let mut points = flat(40);
    points[5][1] = f64::INFINITY;
    points[6][1] = f64::NEG_INFINITY;
    assert_eq!(
        evaluate(&points, &truth, &truth, &EvaluateOptions::default()),
        Err(MetricsError::NonFinitePoint {
            index: 5,
            truth: 4,
            predicted: 4
        })
    );
}

#[test]
fn bad_input_is_refused() {
    let options = EvaluateOptions::default();
    let points = flat(4);
    assert_eq!(
        evaluate(&points, &[0, 0, 0], &[0, 0, 0, 0], &options),
        Err(MetricsError::LengthMismatch {
            points: 4,
            truth: 3,
            predicted: 4
        })
    );
    let message = evaluate(&points, &[0; 4], &[0; 5], &options)
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("4 points") && message.contains("5 predicted"),
        "{message}"
    );
    assert_eq!(
        evaluate(&points, &[0, -2, 0, 0], &[0; 4], &options),
        Err(MetricsError::InvalidLabel {
            labels: Labels::Truth,
            index: 1,
            label: -2
        })
    );
    assert_eq!(
        evaluate(&points, &[0; 4], &[0, 0, 0, i32::MIN], &options),
        Err(MetricsError::InvalidLabel {
            labels: Labels::Predicted,
            index: 3,
            label: i32::MIN
        })
    );
    for overlap in [0.5, 0.3, 1.0 + 1e-9, f64::NAN, f64::INFINITY, -0.8] {
        let options = EvaluateOptions::new().with_overlap(overlap);
        assert!(
            matches!(
                evaluate(&points, &[0; 4], &[0; 4], &options),
                Err(MetricsError::InvalidOverlap { .. })
            ),
            "{overlap}"
        );
    }
    let exact = EvaluateOptions::new().with_overlap(1.0);
    assert_eq!(
        evaluate(&points, &[0; 4], &[0; 4], &exact).unwrap().correct,
        1
    );
}

#[test]
fn defaults() {
    let options = EvaluateOptions::default();
    assert_eq!(options.overlap, 0.8);
    assert_eq!(options.min_truth_points, 0);
    assert_eq!(EvaluateOptions::new(), options);
}
