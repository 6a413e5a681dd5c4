//! Depth-image back-projection against hand-computed points, stride against
//! downsampling, orientation of the resulting mesh, and parameter errors.

#![allow(clippy::expect_used, clippy::unwrap_used)]

use opc_mesh::{DepthOptions, Intrinsics, OpcError, OpcMeshOptions, OrganizedPointCloud};

fn close(a: [f64; 3], b: [f64; 3]) -> bool {
    (0..3).all(|k| (a[k] - b[k]).abs() <= 1e-12 * (1.0 + b[k].abs()))
}

#[test]
fn back_projection_matches_hand_computed_points() {
    // 3 rows × 4 columns; fx = 500, fy = 400, principal point (1.5, 1.0), 1 mm units.
    let depth: [u16; 12] = [
        1000, 2000, 0, 1500, //
        500, 65535, 1000, 1000, //
        0, 0, 3000, 250,
    ];
    let camera = Intrinsics::new(500.0, 400.0, 1.5, 1.0);
    let cloud =
        OrganizedPointCloud::from_depth_image(&depth, 3, 4, &DepthOptions::new(camera)).unwrap();
    assert_eq!((cloud.rows(), cloud.cols()), (3, 4));
    // x = (u − 1.5) z / 500, y = (v − 1) z / 400, z = d / 1000.
    let expected: [(usize, usize, [f64; 3]); 9] = [
        (0, 0, [-1.5 * 1.0 / 500.0, -1.0 / 400.0, 1.0]),
        (0, 1, [-0.5 * 2.0 / 500.0, -2.0 / 400.0, 2.0]),
        (0, 3, [1.5 * 1.5 / 500.0, -1.5 / 400.0, 1.5]),
        (1, 0, [-1.5 * 0.5 / 500.0, 0.0, 0.5]),
        (1, 1, [-0.5 * 65.535 / 500.0, 0.0, 65.535]),
        (1, 2, [0.5 / 500.0, 0.0, 1.0]),
        (1, 3, [1.5 / 500.0, 0.0, 1.0]),
        (2, 2, [0.5 * 3.0 / 500.0, 3.0 / 400.0, 3.0]),
        (2, 3, [1.5 * 0.25 / 500.0, 0.25 / 400.0, 0.25]),
    ];
    for (r, c, p) in expected {
        assert!(
            close(cloud.point(r, c), p),
            "({r}, {c}): {:?} vs {p:?}",
            cloud.point(r, c)
        );
    }
    for (r, c) in [(0, 2), (2, 0), (2, 1)] {
        assert!(
            cloud.point(r, c).iter().all(|x| x.is_nan()),
            "({r}, {c}) is invalid"
        );
    }
    assert_eq!(cloud.num_valid(), 9);
}

#[test]
fn depth_scale_and_max_depth() {
    let depth = [10u16, 20, 30, 40];
    let options = DepthOptions::new(Intrinsics::new(1.0, 1.0, 0.0, 0.0))
        .with_depth_scale(0.1)
        .with_max_depth(3.0);
    let cloud = OrganizedPointCloud::from_depth_image(&depth, 2, 2, &options).unwrap();
    assert!(close(cloud.point(0, 0), [0.0, 0.0, 1.0]));
    assert!(close(cloud.point(0, 1), [2.0, 0.0, 2.0]));
    assert!(
        close(cloud.point(1, 0), [0.0, 3.0, 3.0]),
        "3.0 is not beyond max_depth"
    );
    assert!(cloud.point(1, 1)[2].is_nan(), "4.0 is beyond max_depth");
}

/// A synthetic 16-bit depth image.
fn depth_image(rows: usize, cols: usize) -> Vec<u16> {
    (0..rows * cols)
        .map(|i| {
            let (r, c) = (i / cols, i % cols);
            if (r * 7 + c * 3) % 11 == 0 {
                0
            } else {
                (1000 + 5 * r + 3 * c) as u16
            }
        })
        .collect()
}

#[test]
fn stride_equals_downsampling_the_full_cloud() {
    let (rows, cols) = (23, 31);
    let depth = depth_image(rows, cols);
    let options = DepthOptions::new(Intrinsics::new(40.0, 42.0, 15.2, 11.7));
    let full = OrganizedPointCloud::from_depth_image(&depth, rows, cols, &options).unwrap();
    for stride in 1..=6 {
        let strided =
            OrganizedPointCloud::from_depth_image(&depth, rows, cols, &options.with_stride(stride))
                .unwrap();
        let downsampled = full.downsample(stride).unwrap();
        assert_eq!(
            (strided.rows(), strided.cols()),
            (rows.div_ceil(stride), cols.div_ceil(stride))
        );
        assert_eq!(
            (strided.rows(), strided.cols()),
            (downsampled.rows(), downsampled.cols())
        );
        for (a, b) in strided.points().iter().zip(downsampled.points()) {
            assert!(
                (0..3).all(|k| a[k].to_bits() == b[k].to_bits()),
                "stride {stride}"
            );
        }
    }
}

#[test]
fn normals_face_the_camera() {
    // A tilted plane z = 2 + 0.3 x − 0.2 y seen by a pinhole camera; the depth along each
    // ray solves z = 2 + 0.3 (u − ppx) z / fx − 0.2 (v − ppy) z / fy.
    let (rows, cols) = (40, 60);
    let k = Intrinsics::new(50.0, 55.0, 29.5, 19.5);
    let depth: Vec<u16> = (0..rows * cols)
        .map(|i| {
            let (v, u) = ((i / cols) as f64, (i % cols) as f64);
            let z = 2.0 / (1.0 - 0.3 * (u - k.ppx) / k.fx + 0.2 * (v - k.ppy) / k.fy);
            (z * 1000.0).round() as u16
        })
        .collect();
    let cloud =
        OrganizedPointCloud::from_depth_image(&depth, rows, cols, &DepthOptions::new(k)).unwrap();
    let opc = cloud.mesh(&OpcMeshOptions::default()).unwrap();
    opc.mesh.sanity_check().unwrap();
    assert_eq!(opc.mesh.num_triangles(), 2 * (rows - 1) * (cols - 1));
    let plane_normal = {
        let n = [0.3, -0.2, -1.0];
        let len = (0.09f64 + 0.04 + 1.0).sqrt();
        n.map(|x| x / len)
    };
    let vertices = opc.mesh.vertices();
    for (tri, n) in opc
        .mesh
        .triangles()
        .iter()
        .zip(opc.mesh.triangle_normals().unwrap())
    {
        let p = vertices[tri[0] as usize];
        let toward_camera = -(n[0] * p[0] + n[1] * p[1] + n[2] * p[2]);
        assert!(
            toward_camera > 0.0,
            "normal {n:?} at {p:?} faces away from the camera"
        );
        let cos = n.iter().zip(&plane_normal).map(|(a, b)| a * b).sum::<f64>();
        assert!(
            cos > 0.99,
            "normal {n:?} is not the plane's {plane_normal:?}"
        );
    }
}

#[test]
fn parameter_errors() {
    let depth = [1000u16; 6];
    let good = DepthOptions::new(Intrinsics::new(1.0, 1.0, 0.0, 0.0));
    let bad_parameter =
        |options: DepthOptions| match OrganizedPointCloud::from_depth_image(&depth, 2, 3, &options)
        {
            Err(OpcError::InvalidParameter { name, .. }) => name,
            other => panic!("expected an invalid parameter, got {other:?}"),
        };
    let with_k = |fx, fy, ppx, ppy| DepthOptions::new(Intrinsics::new(fx, fy, ppx, ppy));
    assert_eq!(bad_parameter(with_k(0.0, 1.0, 0.0, 0.0)), "intrinsics.fx");
    assert_eq!(bad_parameter(with_k(1.0, -2.0, 0.0, 0.0)), "intrinsics.fy");
    assert_eq!(
        bad_parameter(with_k(f64::NAN, 1.0, 0.0, 0.0)),
        "intrinsics.fx"
    );
    assert_eq!(
        bad_parameter(with_k(1.0, 1.0, f64::INFINITY, 0.0)),
        "intrinsics.ppx"
    );
    assert_eq!(
        bad_parameter(with_k(1.0, 1.0, 0.0, f64::NAN)),
        "intrinsics.ppy"
    );
    assert_eq!(bad_parameter(good.with_depth_scale(0.0)), "depth_scale");
    assert_eq!(bad_parameter(good.with_max_depth(f64::NAN)), "max_depth");
    assert_eq!(bad_parameter(good.with_stride(0)), "stride");
    let err = OrganizedPointCloud::from_depth_image(&depth, 2, 3, &good.with_depth_scale(-1.0))
        .unwrap_err();
    assert_eq!(
        err.to_string(),
        "depth_scale = -1 is invalid: it must be finite and > 0"
    );

    assert_eq!(
        OrganizedPointCloud::from_depth_image(&depth, 3, 3, &good),
        Err(OpcError::DepthLengthMismatch {
            rows: 3,
            cols: 3,
            found: 6
        })
    );
    assert_eq!(
        OrganizedPointCloud::from_depth_image(&depth, 1, 6, &good),
        Err(OpcError::TooSmall { rows: 1, cols: 6 })
    );
    assert_eq!(
        OrganizedPointCloud::from_depth_image(&depth, 2, 3, &good.with_stride(2)),
        Err(OpcError::TooSmall { rows: 1, cols: 2 })
    );
    assert!(OrganizedPointCloud::from_depth_image(&depth, 2, 3, &good).is_ok());
}
