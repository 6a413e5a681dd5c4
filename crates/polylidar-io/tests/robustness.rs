//! In-tree fuzzing: every parser gets random bytes and truncated or corrupted valid files,
//! and must answer with a value or an error, never a panic (a panic fails the test).

// Test helpers fail loudly by design.
#![allow(clippy::unwrap_used, clippy::panic)]

use std::io::Cursor;
use std::sync::OnceLock;

use polylidar_io::{
    DepthImage, Limits, MeshData, PcdEncoding, PcdScalar, PcdWriteOptions, PointCloud,
    encode_depth_png, encode_npy_f32, encode_npy_f64, encode_npy_i32, encode_pcd, encode_ply, lzf,
    parse_color_image, parse_colorized_depth_png, parse_csv_points, parse_csv_points_with,
    parse_depth_png, parse_depth_png_with, parse_kitti_bin, parse_kitti_bin_with, parse_las,
    parse_las_with, parse_npy, parse_npy_with, parse_obj, parse_obj_with, parse_pcd,
    parse_pcd_fields, parse_pcd_fields_with, parse_pcd_with, parse_ply, parse_ply_with,
    parse_realsense_intrinsics,
};
use proptest::prelude::*;

/// Runs every parser on `bytes`; results are ignored, panics are failures.
fn parse_everything(bytes: &[u8]) {
    let _ = parse_pcd(bytes);
    let _ = parse_pcd_fields(bytes);
    let _ = parse_npy(bytes);
    let _ = parse_ply(bytes);
    let _ = parse_obj(bytes);
    let _ = parse_csv_points(bytes);
    let _ = parse_depth_png(bytes);
    let _ = parse_colorized_depth_png(bytes);
    let _ = parse_realsense_intrinsics(&String::from_utf8_lossy(bytes));
    let _ = lzf::decompress(bytes, bytes.len() * 3);
    let _ = parse_kitti_bin(bytes);
    let _ = parse_color_image(bytes);
    // The same readers under a budget small enough that many inputs meet it.
    let tight = Limits::default().with_max_memory(64 << 10);
    let _ = parse_pcd_with(bytes, &tight);
    let _ = parse_pcd_fields_with(bytes, &tight);
    let _ = parse_npy_with(bytes, &tight);
    let _ = parse_ply_with(bytes, &tight);
    let _ = parse_obj_with(bytes, &tight);
    let _ = parse_csv_points_with(bytes, &tight);
    let _ = parse_depth_png_with(bytes, &tight);
    let _ = parse_kitti_bin_with(bytes, &tight);
}

fn small_cloud() -> PointCloud {
    let mut points: Vec<[f64; 3]> = (0..24)
        .map(|i| [i as f64 * 0.5, (i % 5) as f64, 1.0 + (i % 3) as f64])
        .collect();
    points[7] = [f64::NAN; 3];
    PointCloud::organized(4, 6, points).unwrap()
}

fn small_mesh() -> MeshData {
    MeshData {
        vertices: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.5],
            [0.0, 1.0, 0.5],
        ],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
    }
}

/// A small LAS file (`compressed`: LAZ) written by the `las` crate, with known points.
fn small_las(compressed: bool) -> Vec<u8> {
    let mut builder = las::Builder::from((1, 2));
    builder.point_format = las::point::Format::new(3).unwrap();
    builder.point_format.is_compressed = compressed;
    let header = builder.into_header().unwrap();
    let mut writer = las::Writer::new(Cursor::new(Vec::new()), header).unwrap();
    for i in 0..50 {
        let mut p = las::Point {
            x: f64::from(i),
            y: f64::from(2 * i),
            z: 100.0 + f64::from(i % 7),
            classification: las::point::Classification::new(1 + (i % 2) as u8).unwrap(),
            ..Default::default()
        };
        p.gps_time = Some(0.0);
        p.color = Some(las::Color::new(0, 0, 0));
        writer.write_point(p).unwrap();
    }
    writer.close().unwrap();
    writer.into_inner().unwrap().into_inner()
}

/// Valid files of every format, the seeds of the corruption tests.
fn seeds() -> &'static Vec<Vec<u8>> {
    static SEEDS: OnceLock<Vec<Vec<u8>>> = OnceLock::new();
    SEEDS.get_or_init(|| {
        let cloud = small_cloud();
        let mut seeds = Vec::new();
        for encoding in [
            PcdEncoding::Ascii,
            PcdEncoding::Binary,
            PcdEncoding::BinaryCompressed,
        ] {
            for scalar in [PcdScalar::F32, PcdScalar::F64] {
                let options = PcdWriteOptions::new(encoding).with_scalar(scalar);
                seeds.push(encode_pcd(&cloud, &options).unwrap());
            }
        }
        let flat: Vec<f64> = cloud.points.iter().flatten().copied().collect();
        seeds.push(encode_npy_f64(&[4, 6, 3], &flat).unwrap());
        seeds.push(encode_npy_f32(&[24, 3], &flat).unwrap());
        seeds.push(encode_npy_i32(&[4, 6], &(0..24).collect::<Vec<_>>()).unwrap());
        seeds.push(encode_ply(&small_mesh()).unwrap());
        seeds.push(
            b"ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n\
0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n"
                .to_vec(),
        );
        seeds.push(b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1/1 2/2 3/3 4/4\nf -1 -2 -3\n".to_vec());
        seeds.push(b"x,y\n1,2\n3,4\n5.5,6e-3\n".to_vec());
        seeds.push(
            encode_depth_png(&DepthImage {
                width: 5,
                height: 4,
                data: (0..20).map(|v| v * 321).collect(),
            })
            .unwrap(),
        );
        seeds.push(b"Resolution x,4\nResolution y,3\nFx,2.5\nFy,2.5\nPPx,2\nPPy,1.5\n".to_vec());
        seeds.push(small_las(false));
        seeds.push(small_las(true));
        seeds
    })
}

#[test]
fn seeds_are_valid() {
    let s = seeds();
    for seed in &s[..6] {
        let c = parse_pcd(seed).unwrap();
        assert_eq!((c.rows, c.cols, c.valid_count()), (4, 6, 23));
    }
    assert_eq!(
        parse_npy(&s[6]).unwrap().into_point_cloud().unwrap().rows,
        4
    );
    assert_eq!(parse_ply(&s[9]).unwrap(), small_mesh());
    assert_eq!(parse_ply(&s[10]).unwrap().triangles.len(), 2);
    assert_eq!(parse_obj(&s[11]).unwrap().triangles.len(), 3);
    assert_eq!(parse_csv_points(&s[12]).unwrap().len(), 3);
    assert_eq!(parse_depth_png(&s[13]).unwrap().data[19], 19 * 321);
    for seed in &s[15..17] {
        let las = parse_las(seed).unwrap();
        assert_eq!(las.points.len(), 50);
        assert_eq!(las.points[9], [9.0, 18.0, 102.0]);
        assert_eq!(las.classification[9], 2);
    }
}

/// Parsers that get each seed after corruption: the seed's own parser plus all the others.
fn parse_with_las(bytes: &[u8]) {
    parse_everything(bytes);
    let _ = parse_las(bytes);
    let _ = parse_las_with(bytes, &Limits::default().with_max_memory(64 << 10));
}

#[derive(Debug, Clone)]
enum Damage {
    Truncate(usize),
    Overwrite(Vec<(usize, u8)>),
    Digits(Vec<(usize, u8)>),
    Delete(usize, usize),
}

fn damage() -> impl Strategy<Value = Damage> {
    prop_oneof![
        any::<usize>().prop_map(Damage::Truncate),
        proptest::collection::vec((any::<usize>(), any::<u8>()), 1..8).prop_map(Damage::Overwrite),
        proptest::collection::vec((any::<usize>(), b'0'..=b'9'), 1..4).prop_map(Damage::Digits),
        (any::<usize>(), 1usize..64).prop_map(|(a, n)| Damage::Delete(a, n)),
    ]
}

fn apply(seed: &[u8], damage: &Damage) -> Vec<u8> {
    let mut bytes = seed.to_vec();
    if bytes.is_empty() {
        return bytes;
    }
    let n = bytes.len();
    match damage {
        Damage::Truncate(at) => bytes.truncate(at % n),
        Damage::Overwrite(edits) | Damage::Digits(edits) => {
            for &(at, b) in edits {
                bytes[at % n] = b;
            }
        }
        Damage::Delete(at, len) => {
            let start = at % n;
            bytes.drain(start..(start + len).min(n));
        }
    }
    bytes
}

/// Cases per property: 512, or `POLYLIDAR_FUZZ_CASES` for longer runs.
fn cases() -> u32 {
    std::env::var("POLYLIDAR_FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(512)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(cases()))]

    #[test]
    fn random_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..600)) {
        parse_with_las(&bytes);
    }

    #[test]
    fn random_text_never_panics(text in "[ -~\n]{0,400}") {
        parse_everything(text.as_bytes());
    }

    #[test]
    fn headers_with_random_bodies_never_panic(
        which in 0usize..4,
        numbers in proptest::collection::vec(0u64..20, 4),
        body in proptest::collection::vec(any::<u8>(), 0..300),
    ) {
        let mut bytes = match which {
            0 => format!("VERSION 0.7\nFIELDS x y z rgb\nSIZE 4 8 2 4\nTYPE F F I U\nCOUNT 1 1 1 {}\nWIDTH {}\nHEIGHT {}\nDATA binary_compressed\n", numbers[0] + 1, numbers[1], numbers[2]).into_bytes(),
            1 => format!("VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH {}\nHEIGHT {}\nDATA ascii\n", numbers[1], numbers[2]).into_bytes(),
            2 => format!("ply\nformat binary_big_endian 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n", numbers[0], numbers[1]).into_bytes(),
            _ => {
                let order = if numbers[3] % 2 == 0 { "False" } else { "True" };
                let dict = format!("{{'descr': '<f4', 'fortran_order': {order}, 'shape': ({}, {}, 3), }}\n", numbers[1], numbers[2]);
                let mut b = b"\x93NUMPY\x01\x00".to_vec();
                b.extend_from_slice(&(dict.len() as u16).to_le_bytes());
                b.extend_from_slice(dict.as_bytes());
                b
            }
        };
        bytes.extend_from_slice(&body);
        parse_everything(&bytes);
    }

    #[test]
    fn corrupted_valid_files_never_panic(which in 0usize..17, damage in damage()) {
        let seed = &seeds()[which];
        parse_with_las(&apply(seed, &damage));
    }
}
