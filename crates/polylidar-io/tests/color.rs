//! Colour readers: PCD `rgb`/`rgba` (binary float bits kept exactly, ascii, unsigned),
//! PLY vertex colours, and the RGB-D colour pictures of the shared fixtures (JPEG and PNG).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use polylidar_io::{
    color_path_for, parse_color_image, parse_pcd_colors, parse_ply_colors, read_color_image,
    read_pcd_colors,
};

fn pcd(fields: &str, ty: &str, data: &str, body: &[u8], points: usize) -> Vec<u8> {
    let mut out = format!(
        "# .PCD v0.7\nVERSION 0.7\nFIELDS {fields}\nSIZE 4 4 4 4\nTYPE F F F {ty}\nCOUNT 1 1 1 1\nWIDTH {points}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {points}\nDATA {data}\n"
    )
    .into_bytes();
    out.extend_from_slice(body);
    out
}

#[test]
fn pcd_rgb_float_bits_are_kept_exactly() {
    // Packed 0xAARRGGBB colours stored as float bits, one of them a signalling-NaN pattern
    // (alpha 255, red 150): a float conversion would change it.
    let colours: [u32; 3] = [0x00FF_8040, 0xFF96_0A0B, 0x0001_0203];
    let mut body = Vec::new();
    for (k, c) in colours.iter().enumerate() {
        for v in [k as f32, 0.0, 1.0] {
            body.extend_from_slice(&v.to_le_bytes());
        }
        body.extend_from_slice(&c.to_le_bytes());
    }
    let bytes = pcd("x y z rgb", "F", "binary", &body, 3);
    let got = parse_pcd_colors(&bytes).unwrap().unwrap();
    assert_eq!(got, vec![[255, 128, 64], [150, 10, 11], [1, 2, 3]]);
    // The same as an unsigned `rgba` field.
    let bytes = pcd("x y z rgba", "U", "binary", &body, 3);
    assert_eq!(parse_pcd_colors(&bytes).unwrap().unwrap()[1], [150, 10, 11]);
    // ascii floats go through their f32 bits.
    let text = format!("0 0 1 {:e}\n", f32::from_bits(0x00FF_8040));
    let bytes = pcd("x y z rgb", "F", "ascii", text.as_bytes(), 1);
    assert_eq!(
        parse_pcd_colors(&bytes).unwrap().unwrap(),
        vec![[255, 128, 64]]
    );
    // No colour field: None.
    let bytes = pcd("x y z intensity", "F", "binary", &body, 3);
    assert_eq!(parse_pcd_colors(&bytes).unwrap(), None);
}

#[test]
fn ply_vertex_colours_of_each_type() {
    let text = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n0 0 0 255 0 10\n1 0 0 1 2 3\n";
    assert_eq!(
        parse_ply_colors(text.as_bytes()).unwrap().unwrap(),
        vec![[255, 0, 10], [1, 2, 3]]
    );
    let floats = text
        .replace(
            "uchar red\nproperty uchar green\nproperty uchar blue",
            "float r\nproperty float g\nproperty float b",
        )
        .replace(
            "0 0 0 255 0 10\n1 0 0 1 2 3",
            "0 0 0 1.0 0.0 0.5\n1 0 0 0 0 0",
        );
    assert_eq!(
        parse_ply_colors(floats.as_bytes()).unwrap().unwrap()[0],
        [255, 0, 128]
    );
    let plain = "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n";
    assert_eq!(parse_ply_colors(plain.as_bytes()).unwrap(), None);
}

#[test]
fn colour_pictures_of_the_rgbd_frames() {
    let (Some(icl), Some(tum), Some(fragment)) = (
        test_fixtures::fixture("rgbd/icl_living_depth_00000.png"),
        test_fixtures::fixture("rgbd/tum_depth.png"),
        test_fixtures::fixture("rgbd/living_fragment.pcd"),
    ) else {
        test_fixtures::record_skip("polylidar-io colour: rgbd fixtures missing");
        return;
    };
    let jpg = color_path_for(&icl).unwrap();
    assert!(jpg.ends_with("icl_living_color_00000.jpg"));
    let png = color_path_for(&tum).unwrap();
    assert!(png.ends_with("tum_color.png"));
    for path in [jpg, png] {
        let image = read_color_image(&path).unwrap();
        assert_eq!(
            (image.width, image.height),
            (640, 480),
            "{}",
            path.display()
        );
        // A real picture: many distinct colours, not all dark.
        let mut distinct = image.rgb.clone();
        distinct.sort_unstable();
        distinct.dedup();
        assert!(
            distinct.len() > 5_000,
            "{}: {} colours",
            path.display(),
            distinct.len()
        );
        let mean: f64 = image
            .rgb
            .iter()
            .map(|c| f64::from(c[0]) + f64::from(c[1]) + f64::from(c[2]))
            .sum::<f64>()
            / (3.0 * image.rgb.len() as f64);
        assert!(
            (40.0..220.0).contains(&mean),
            "{}: mean {mean}",
            path.display()
        );
    }
    let colours = read_pcd_colors(&fragment).unwrap().unwrap();
    assert_eq!(colours.len(), 113_662);
    assert!(colours.iter().any(|c| c != &colours[0]));
    assert!(parse_color_image(b"GIF89a").is_err());
    assert!(color_path_for(fragment).is_err());
}
