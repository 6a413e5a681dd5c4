//! The readers on the real files of `../shared/fixtures`, cross-checked by writing them in
//! other formats and reading them back.

// Test helpers fail loudly by design.
#![allow(clippy::unwrap_used, clippy::panic)]

use polylidar_io::{
    DepthImage, ErrorKind, InputKind, PcdEncoding, PcdScalar, PcdWriteOptions, PointCloud,
    encode_npy_f64, encode_pcd, metadata_path_for, parse_npy, parse_pcd, read_colorized_depth_png,
    read_depth_png, read_input, read_las, read_npy, read_pcd, read_pcd_fields,
    read_realsense_intrinsics, write_depth_png,
};
use test_fixtures::fixture;

fn same(a: f64, b: f64) -> bool {
    a == b || (a.is_nan() && b.is_nan())
}

fn same_cloud(a: &PointCloud, b: &PointCloud) -> bool {
    a.rows == b.rows
        && a.cols == b.cols
        && a.points
            .iter()
            .zip(&b.points)
            .all(|(p, q)| (0..3).all(|k| same(p[k], q[k])))
}

fn check_synpeb(name: &str) {
    let Some(path) = fixture(name) else { return };
    let cloud = read_pcd(&path).unwrap();
    assert_eq!((cloud.rows, cloud.cols), (500, 500));
    // A closed room seen from inside: (nearly) every pixel has a return; an invalid point
    // would be NaN in all three coordinates.
    let valid = cloud.valid_count();
    assert!(valid > 200_000, "{valid} valid points");
    assert!(
        cloud
            .points
            .iter()
            .all(|p| p.iter().all(|v| v.is_nan()) || p.iter().all(|v| v.is_finite()))
    );
    for p in cloud.points.iter().filter(|p| p[0].is_finite()) {
        assert!(p.iter().all(|v| v.abs() < 20.0), "{p:?}");
    }
    // The grid is really row-major WIDTH × HEIGHT: grid neighbours are close in space,
    // points 250 apart in memory are not.
    let dist = |a: [f64; 3], b: [f64; 3]| (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt();
    let mean = |step_r: usize, step_c: usize| {
        let mut sum = 0.0;
        let mut n = 0usize;
        for r in (0..500 - step_r).step_by(7) {
            for c in (0..500 - step_c).step_by(7) {
                let d = dist(
                    cloud.get(r, c).unwrap(),
                    cloud.get(r + step_r, c + step_c).unwrap(),
                );
                if d.is_finite() {
                    sum += d;
                    n += 1;
                }
            }
        }
        sum / n as f64
    };
    let (right, down, far) = (mean(0, 1), mean(1, 0), mean(0, 250));
    assert!(
        right < 0.05 && down < 0.05 && far > 0.3,
        "{right} {down} {far}"
    );
    // Every encoding we write reads back identically (f32 data is exact in f64 and in F 4);
    // on a 40-row band to keep the debug-build test quick.
    let band = PointCloud::organized(40, 500, cloud.points[..40 * 500].to_vec()).unwrap();
    for encoding in [
        PcdEncoding::Ascii,
        PcdEncoding::Binary,
        PcdEncoding::BinaryCompressed,
    ] {
        for scalar in [PcdScalar::F32, PcdScalar::F64] {
            let options = PcdWriteOptions::new(encoding).with_scalar(scalar);
            let back = parse_pcd(&encode_pcd(&band, &options).unwrap()).unwrap();
            assert!(same_cloud(&band, &back), "{encoding:?} {scalar:?}");
        }
    }
    // The extra field comes along in the column reader, consistent with the xyz reader.
    let fields = read_pcd_fields(&path).unwrap();
    assert_eq!(fields.names, vec!["x", "y", "z", "intensity"]);
    let z = fields.column("z").unwrap();
    assert!(z.iter().zip(&cloud.points).all(|(a, p)| same(*a, p[2])));
    assert_eq!(fields.column("intensity").unwrap().len(), 250_000);
}

#[test]
fn synpeb_pc_01() {
    check_synpeb("synpeb/pc_01.pcd");
}

#[test]
fn synpeb_pc_02() {
    check_synpeb("synpeb/pc_02.pcd");
}

#[test]
fn realsense_npy() {
    let Some(path) = fixture("realsense/rgbd_opc.npy") else {
        return;
    };
    let array = read_npy(&path).unwrap();
    assert_eq!(array.shape, vec![120, 212, 3]);
    let again = parse_npy(&encode_npy_f64(&array.shape, &array.data).unwrap()).unwrap();
    assert!(
        array
            .data
            .iter()
            .zip(&again.data)
            .all(|(a, b)| same(*a, *b))
    );
    let cloud = array.into_point_cloud().unwrap();
    assert_eq!((cloud.rows, cloud.cols), (120, 212));
    let valid = cloud.valid_count();
    assert!(valid > 10_000 && valid <= 120 * 212, "{valid} valid points");
    // An indoor RealSense frame: depths within a few metres.
    for p in cloud.points.iter().filter(|p| p[2].is_finite()) {
        assert!(p[2].abs() < 20.0, "{p:?}");
    }
    // The same cloud survives a PCD round trip.
    let bytes = encode_pcd(&cloud, &PcdWriteOptions::new(PcdEncoding::BinaryCompressed)).unwrap();
    assert!(same_cloud(&cloud, &parse_pcd(&bytes).unwrap()));
}

#[test]
fn unreal_lidar_npy() {
    let Some(path) = fixture("lidar/unreal_lidar.npy") else {
        return;
    };
    let InputKind::Cloud(cloud) = read_input(&path).unwrap() else {
        panic!("an H×W×3 NPY is an organized cloud");
    };
    assert_eq!((cloud.rows, cloud.cols), (64, 59));
    assert!(cloud.valid_count() > 0);
}

/// The RealSense PNGs in the fixtures are the Viewer's colorized pictures (8-bit RGB, Jet
/// colormap), not 16-bit depth: the depth reader must say so, the colorized reader must
/// decode them, and the intrinsics must match their size.
#[test]
fn realsense_depth_pictures_and_metadata() {
    for (name, w, h, fx) in [
        ("realsense/001_big_depth.png", 848, 480, 425.849243),
        ("realsense/001_small_depth.png", 424, 240, 212.924622),
    ] {
        let Some(path) = fixture(name) else { return };
        let err = read_depth_png(&path).unwrap_err();
        assert!(matches!(err.kind, ErrorKind::NotDepth(_)), "{err}");
        assert!(err.to_string().contains("colorized"), "{err}");
        assert!(read_input(&path).is_err());

        let picture = read_colorized_depth_png(&path).unwrap();
        assert_eq!((picture.width, picture.height), (w, h));
        let valid = picture.valid_count();
        assert!(
            valid > w * h * 3 / 4 && valid < w * h,
            "{valid} pixels with depth"
        );
        assert!(
            picture
                .data
                .iter()
                .all(|t| t.is_nan() || (0.0..=1.0).contains(t))
        );
        let depth = picture.to_depth_image(300, 4000);
        assert_eq!(depth.data.iter().filter(|&&d| d > 0).count(), valid);

        let meta = metadata_path_for(&path).unwrap();
        assert!(meta.to_string_lossy().ends_with("_depth_metadata.csv"));
        let k = read_realsense_intrinsics(&meta).unwrap();
        assert_eq!((k.width, k.height), (w, h));
        assert_eq!(k.fx, fx);
        assert_eq!(k.fy, fx);
        assert!(k.ppx > 0.4 * w as f64 && k.ppx < 0.6 * w as f64);
        assert!(k.ppy > 0.4 * h as f64 && k.ppy < 0.6 * h as f64);
    }
}

/// A 16-bit depth image beside its metadata reads as `InputKind::Depth` through dispatch.
#[test]
fn depth_png_dispatch() {
    let dir = std::env::temp_dir().join(format!("polylidar-io-depth-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let image = DepthImage {
        width: 4,
        height: 3,
        data: (0..12).map(|v| v * 100).collect(),
    };
    write_depth_png(dir.join("007_depth.png"), &image).unwrap();
    std::fs::write(
        dir.join("007_depth_metadata.csv"),
        "Resolution x,4\nResolution y,3\nFx,2.5\nFy,2.5\nPPx,2\nPPy,1.5\n",
    )
    .unwrap();
    let InputKind::Depth {
        image: back,
        intrinsics,
    } = read_input(dir.join("007_depth.png")).unwrap()
    else {
        panic!("a depth PNG reads as Depth");
    };
    assert_eq!(back, image);
    assert_eq!((intrinsics.fx, intrinsics.ppy), (2.5, 1.5));
    std::fs::write(
        dir.join("007_depth_metadata.csv"),
        "Resolution x,5\nResolution y,3\nFx,2.5\nFy,2.5\nPPx,2\nPPy,1.5\n",
    )
    .unwrap();
    assert!(read_input(dir.join("007_depth.png")).is_err());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn autzen_laz() {
    let Some(path) = fixture("lidar/autzen_trim.laz") else {
        return;
    };
    let las = read_las(&path).unwrap();
    assert_eq!(las.points.len(), 110_000);
    assert_eq!(las.classification.len(), 110_000);
    assert!(las.classification.iter().all(|&c| c == 1 || c == 2));
    assert!(las.classification.contains(&2));
    let span = |k: usize| {
        let (lo, hi) = las
            .points
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p[k]), hi.max(p[k]))
            });
        (lo, hi)
    };
    let (x0, x1) = span(0);
    let (y0, y1) = span(1);
    let (z0, z1) = span(2);
    assert!((x1 - x0 - 1180.0).abs() < 60.0, "x span {}", x1 - x0);
    assert!((y1 - y0 - 560.0).abs() < 40.0, "y span {}", y1 - y0);
    assert!(
        z0 > 400.0 && z0 < 412.0 && z1 > 515.0 && z1 < 527.0,
        "z {z0}..{z1}"
    );
}

#[test]
fn simple_las() {
    let Some(path) = fixture("lidar/simple.las") else {
        return;
    };
    let las = read_las(&path).unwrap();
    assert_eq!(las.points.len(), 1065);
    assert!(las.points.iter().all(|p| p.iter().all(|v| v.is_finite())));
    let InputKind::Cloud(cloud) = read_input(&path).unwrap() else {
        panic!("LAS reads as a cloud");
    };
    assert_eq!(cloud.points, las.points);
    assert!(!cloud.is_organized());
}
