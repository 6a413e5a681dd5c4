//! Hostile inputs of issue 22: decompression and header bombs are refused by the memory
//! budget before anything is allocated, streams are read only up to it, and every reader
//! error names what is wrong.

// Test helpers fail loudly by design.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::io::Cursor;

use polylidar_io::{
    ErrorKind, InputKind, Limits, PcdEncoding, PcdWriteOptions, PointCloud, encode_pcd, lzf,
    parse_csv_points, parse_depth_png, parse_depth_png_with, parse_las, parse_npy_with, parse_pcd,
    parse_pcd_fields, parse_ply, read_input_with, read_pcd_with, write_pcd_with_options,
};

fn over_budget(kind: &ErrorKind) -> bool {
    matches!(kind, ErrorKind::OverBudget { .. })
}

fn scratch(name: &str) -> (test_fixtures::ScratchDir, std::path::PathBuf) {
    let dir = test_fixtures::scratch_dir("polylidar-io-hardening", name);
    let path = dir.join(name);
    (dir, path)
}

/// A 16-bit greyscale PNG of `width × height` pixels of constant depth: tens of
/// kilobytes for tens of millions of pixels.
fn constant_png(width: u32, height: u32) -> Vec<u8> {
    let mut out = Vec::new();
    let mut encoder = png::Encoder::new(&mut out, width, height);
    encoder.set_color(png::ColorType::Grayscale);
    encoder.set_depth(png::BitDepth::Sixteen);
    encoder.set_compression(png::Compression::Fast);
    let mut writer = encoder.write_header().unwrap();
    let mut stream = writer.stream_writer().unwrap();
    let row: Vec<u8> = std::iter::repeat_n(1000u16.to_be_bytes(), width as usize)
        .flatten()
        .collect();
    for _ in 0..height {
        std::io::Write::write_all(&mut stream, &row).unwrap();
    }
    stream.finish().unwrap();
    writer.finish().unwrap();
    out
}

#[test]
fn png_bomb_is_refused_from_its_header() {
    let bytes = constant_png(6000, 6000);
    assert!(bytes.len() < 1 << 20, "{} bytes", bytes.len());
    let e = parse_depth_png(&bytes).unwrap_err();
    assert!(over_budget(&e.kind), "{e}");
    let text = e.to_string();
    assert!(text.contains("6000 × 6000 pixels"), "{text}");
    assert!(text.contains("memory budget"), "{text}");
    assert!(text.contains("--max-memory"), "{text}");
}

#[test]
fn the_default_budget_scales_with_the_input_size() {
    // 800 × 800 pixels from 4 kB: 430 MiB estimated, past the 384 MiB a small file gets,
    // so refused by default; the full cap, or a large file of the same claim, admits it.
    let bytes = constant_png(800, 800);
    assert!(bytes.len() < 16 << 10, "{} bytes", bytes.len());
    let e = parse_depth_png(&bytes).unwrap_err();
    assert!(over_budget(&e.kind), "{e}");
    assert!(e.to_string().contains("800 × 800 pixels"), "{e}");
    assert!(parse_depth_png_with(&bytes, &Limits::default()).is_ok());
    assert!(parse_depth_png_with(&bytes, &Limits::for_input_size(2 << 20)).is_ok());
    // The same through a file read by path.
    let (_dir, path) = scratch("scaled_800.png");
    std::fs::write(&path, &bytes).unwrap();
    let e = polylidar_io::read_depth_png(&path).unwrap_err();
    assert!(over_budget(&e.kind), "{e}");
    assert!(e.to_string().contains("scaled_800.png"), "{e}");
    // A small picture passes by default.
    assert!(parse_depth_png(&constant_png(640, 480)).is_ok());
}

#[test]
fn pcd_count_bomb_is_refused_before_its_columns_are_built() {
    let header = b"FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 100000000 1 1\nWIDTH 1\nHEIGHT 1\nDATA ascii\n";
    assert_eq!(header.len(), 83);
    let e = parse_pcd_fields(header).unwrap_err();
    assert!(over_budget(&e.kind), "{e}");
    assert!(e.to_string().contains("100000002 columns"), "{e}");
    // The same in binary, with a record claimed to be 400 MB long.
    let binary = String::from_utf8_lossy(header).replace("ascii", "binary");
    assert!(over_budget(
        &parse_pcd_fields(binary.as_bytes()).unwrap_err().kind
    ));
}

/// A PCD whose LZF block is back-references only: `points` points of zeros from about
/// `points × 12 / 88` bytes.
fn lzf_bomb(points: usize) -> Vec<u8> {
    let size = points * 12;
    let mut stream = vec![0u8, 0];
    let mut left = size - 1;
    while left >= 264 {
        // Length 7 + 255 + 2 = 264, distance 1.
        stream.extend_from_slice(&[7 << 5, 255, 0]);
        left -= 264;
    }
    while left > 0 {
        stream.extend_from_slice(&[0, 0]);
        left -= 1;
    }
    let mut bytes = format!(
        "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH {points}\nHEIGHT 1\n\
         POINTS {points}\nDATA binary_compressed\n"
    )
    .into_bytes();
    bytes.extend_from_slice(&(stream.len() as u32).to_le_bytes());
    bytes.extend_from_slice(&(size as u32).to_le_bytes());
    bytes.extend_from_slice(&stream);
    bytes
}

#[test]
fn lzf_bomb_is_refused_before_decompressing() {
    let bomb = lzf_bomb(7_500_000);
    assert!(bomb.len() < 1_100_000, "{} bytes", bomb.len());
    let e = parse_pcd(&bomb).unwrap_err();
    assert!(over_budget(&e.kind), "{e}");
    assert!(e.to_string().contains("7500000 points"), "{e}");
    // A small one within the budget decodes: the stream itself is valid.
    let small = lzf_bomb(1000);
    let cloud = parse_pcd(&small).unwrap();
    assert_eq!(cloud.points.len(), 1000);
    assert!(cloud.points.iter().all(|p| *p == [0.0; 3]));
    assert!(lzf::check_expansion(10, 10_000).is_err());
}

#[test]
fn the_budget_is_settable_and_counts_the_pipeline() {
    let cloud = PointCloud::unorganized(vec![[1.0, 2.0, 3.0]; 10_000]);
    let bytes = encode_pcd(&cloud, &PcdWriteOptions::new(PcdEncoding::Binary)).unwrap();
    // 10,000 points × (24 + 400) bytes ≈ 4.2 MB: refused under 1 MB, read without the
    // pipeline's share, read under the default.
    let small = Limits::default().with_max_memory(1 << 20);
    let e = polylidar_io::parse_pcd_with(&bytes, &small).unwrap_err();
    assert!(over_budget(&e.kind), "{e}");
    assert!(polylidar_io::parse_pcd_with(&bytes, &small.reading_only()).is_ok());
    assert!(parse_pcd(&bytes).is_ok());
    let npy = polylidar_io::encode_npy_f64(&[4, 3], &[0.0; 12]).unwrap();
    let e = parse_npy_with(&npy, &Limits::default().with_max_memory(100)).unwrap_err();
    assert!(over_budget(&e.kind), "{e}");
}

#[test]
fn files_past_the_budget_are_not_read() {
    let (_dir, path) = scratch("big.csv");
    std::fs::write(&path, "1,2,3\n".repeat(10_000)).unwrap();
    let tiny = Limits::default().with_max_memory(1000);
    let e = read_pcd_with(&path, &tiny).unwrap_err();
    assert!(over_budget(&e.kind), "{e}");
    assert_eq!(e.path.as_deref(), Some(path.as_path()));
    assert!(e.to_string().contains("big.csv"), "{e}");
}

#[cfg(unix)]
#[test]
fn endless_streams_stop_at_the_budget() {
    // /dev/zero never ends: the read stops one byte past the budget.
    let zero = std::path::Path::new("/dev/zero");
    if !zero.exists() {
        return;
    }
    let limits = Limits::default().with_max_memory(1 << 20);
    let e = polylidar_io::read_csv_points_with(zero, &limits).unwrap_err();
    assert!(over_budget(&e.kind), "{e}");
    assert!(e.to_string().contains("/dev/zero"), "{e}");
}

#[test]
fn nan_points_of_unorganized_pcd_are_skipped_and_counted() {
    let (_dir, path) = scratch("nan.pcd");
    let mut points = vec![[0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0]];
    points.insert(1, [f64::NAN; 3]);
    points.push([f64::NAN, 0.0, 0.0]);
    let cloud = PointCloud::unorganized(points);
    write_pcd_with_options(&path, &cloud, &PcdWriteOptions::new(PcdEncoding::Ascii)).unwrap();
    let (kind, notes) = read_input_with(&path, &Limits::default()).unwrap();
    assert_eq!(notes.invalid_skipped, 2);
    let InputKind::Cloud(read) = kind else {
        panic!("a cloud")
    };
    assert_eq!((read.rows, read.cols, read.points.len()), (1, 3, 3));
    assert_eq!(read.points[1], [1.0, 0.0, 1.0]);
    // An organized cloud keeps its invalid pixels.
    let grid =
        PointCloud::organized(2, 2, vec![[0.0; 3], [f64::NAN; 3], [1.0; 3], [2.0; 3]]).unwrap();
    write_pcd_with_options(&path, &grid, &PcdWriteOptions::new(PcdEncoding::Binary)).unwrap();
    let (kind, notes) = read_input_with(&path, &Limits::default()).unwrap();
    assert_eq!(notes.invalid_skipped, 0);
    assert!(matches!(kind, InputKind::Cloud(c) if c.points.len() == 4));
}

#[test]
fn a_mistyped_first_csv_row_is_not_dropped_as_a_header() {
    let e = parse_csv_points(b"1.5,2,3x\n4,5,6\n").unwrap_err();
    assert!(matches!(e.kind, ErrorKind::Line { line: 1, .. }), "{e}");
    assert!(e.to_string().contains("\"3x\""), "{e}");
    assert_eq!(parse_csv_points(b"x,y,z\n4,5,6\n").unwrap().len(), 1);
}

#[test]
fn ply_messages_say_what_is_wrong() {
    let ascii = b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n\
0 0 0\n1 0 0\n0 1 zero\n3 0 1 2\n";
    let e = parse_ply(ascii).unwrap_err();
    let text = e.to_string();
    assert!(!text.contains("compressed"), "{text}");
    assert!(matches!(e.kind, ErrorKind::Line { line: 12, .. }), "{text}");
    assert!(text.contains("\"zero\""), "{text}");
    let fractional = String::from_utf8_lossy(ascii)
        .replace("zero", "0")
        .replace("3 0 1 2", "3 0 1.5 2");
    let e = parse_ply(fractional.as_bytes()).unwrap_err();
    assert!(
        e.to_string()
            .contains("vertex index 1.5 is not a whole number"),
        "{e}"
    );
}

/// A small LAS file (`compressed`: LAZ) of 50 points written by the `las` crate.
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
            ..Default::default()
        };
        p.gps_time = Some(f64::from(i));
        p.color = Some(las::Color::new(0, 0, 0));
        writer.write_point(p).unwrap();
    }
    writer.close().unwrap();
    writer.into_inner().unwrap().into_inner()
}

#[test]
fn las_errors_name_the_header_field_or_the_records() {
    let las = small_las(false);
    assert_eq!(parse_las(&las).unwrap().points.len(), 50);
    let e = parse_las(&las[..las.len() - 10]).unwrap_err();
    let text = e.to_string();
    assert!(text.contains("number of point records"), "{text}");
    assert!(text.contains("49 complete records"), "{text}");
    let e = parse_las(&las[..100]).unwrap_err();
    assert!(e.to_string().contains("public header block"), "{e}");
    let mut bad = las.clone();
    bad[96..100].copy_from_slice(&1_000_000u32.to_le_bytes());
    let e = parse_las(&bad).unwrap_err();
    assert!(e.to_string().contains("offset to point data"), "{e}");
    let e = parse_las(b"not a las file at all").unwrap_err();
    assert!(e.to_string().contains("LASF"), "{e}");
    // A LAZ file cut short: the error names the records it could not decode.
    let laz = small_las(true);
    assert_eq!(parse_las(&laz).unwrap().points.len(), 50);
    for cut in [laz.len() - 20, laz.len() / 2 + 200] {
        let e = parse_las(&laz[..cut]).unwrap_err();
        assert!(
            !e.to_string().contains("failed to fill whole buffer"),
            "{e}"
        );
    }
}

/// Found by `scripts/fuzz.sh` (target `las`): a LAS 1.4 file whose header size says 227
/// bytes still has its extended VLRs read by `las`, and one claiming 2⁴⁸ bytes made it
/// abort on allocation. The claim is now checked whatever the header size.
#[test]
fn an_extended_vlr_of_a_short_14_header_is_checked() {
    let mut b = vec![0u8; 420];
    b[..4].copy_from_slice(b"LASF");
    (b[24], b[25]) = (1, 4);
    b[94..96].copy_from_slice(&227u16.to_le_bytes());
    b[96..100].copy_from_slice(&352u32.to_le_bytes());
    b[105..107].copy_from_slice(&20u16.to_le_bytes());
    for k in 0..3 {
        b[131 + 8 * k..139 + 8 * k].copy_from_slice(&0.01f64.to_le_bytes());
    }
    b[235..243].copy_from_slice(&352u64.to_le_bytes());
    b[243..247].copy_from_slice(&1u32.to_le_bytes());
    b[372..380].copy_from_slice(&(1u64 << 48).to_le_bytes());
    let e = parse_las(&b).unwrap_err();
    assert!(
        e.to_string().contains("extended variable-length record 0"),
        "{e}"
    );
}
