//! Texture generation (Alg. 1–2) against a brute-force nearest-neighbour oracle, uv
//! coordinates, the atlas, and the errors.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::Case;
use geo::Contains;
use planar_mesh::{
    Method, Packing, PlanarMeshError, PlaneMesh, Resolution, Segment, SimplifyOptions,
    TextureOptions, merge, simplify,
};
use proptest::prelude::*;

/// Random non-black colours, one per point.
fn colours(n: usize, seed: u64) -> Vec<[u8; 3]> {
    let mut x = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    (0..n)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            [
                1 + (x % 255) as u8,
                1 + ((x >> 8) % 255) as u8,
                1 + ((x >> 16) % 255) as u8,
            ]
        })
        .collect()
}

fn textured(
    case: &Case,
    step: f64,
    options: TextureOptions,
    seed: u64,
) -> (PlaneMesh, Vec<[f64; 3]>, Vec<[u8; 3]>) {
    // Jittered points so that nearest neighbours are unique.
    let points: Vec<[f64; 3]> = case
        .points(step)
        .iter()
        .enumerate()
        .map(|(k, p)| {
            let j = ((k as f64 * 0.618_033_988_7).fract() - 0.5) * step * 0.3;
            let q = case.flatten(*p);
            case.lift([q[0] + j, q[1] - 0.7 * j])
        })
        .collect();
    let colors = colours(points.len(), seed);
    let (shell, holes) = (case.shell3(), case.holes3());
    let mesh = simplify(
        &Segment::new(&points, &shell, &holes).with_colors(&colors),
        &SimplifyOptions::new()
            .with_method(Method::Point)
            .with_texture(options),
    )
    .unwrap();
    (mesh, points, colors)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn every_texel_has_the_colour_of_its_nearest_point(
        radii in prop::collection::vec(3.0f64..5.0, 5..20),
        holes in prop::collection::vec((3usize..7, 0.3f64..0.6), 0..4),
        tilt in [-1.0f64..1.0, -1.0f64..1.0],
        seed in any::<u64>(),
        bleed in any::<bool>(),
    ) {
        let case = Case::new(&radii, &holes, tilt, [1.0, 2.0, 3.0]);
        let options = TextureOptions::new()
            .with_resolution(Resolution::PerUnit(4.0))
            .with_bleed(bleed);
        let (mesh, points, colors) = textured(&case, 0.5, options, seed);
        let texture = mesh.texture.as_ref().unwrap();
        let truth = case.geo();
        let flat: Vec<[f64; 2]> = points.iter().map(|p| mesh.frame.project(*p)).collect();
        let mut inside = 0;
        for row in 0..texture.height {
            for col in 0..texture.width {
                let c = texture.texel_center(col, row);
                let original = case.flatten(mesh.frame.lift(c));
                let is_inside = truth.contains(&geo::Point::new(original[0], original[1]));
                let texel = texture.texel(col, row);
                if is_inside || texel != [0, 0, 0] {
                    // Brute force: the nearest point's colour.
                    let nearest = flat
                        .iter()
                        .enumerate()
                        .min_by(|a, b| {
                            let d = |p: &[f64; 2]| (p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2);
                            d(a.1).total_cmp(&d(b.1))
                        })
                        .unwrap()
                        .0;
                    prop_assert_eq!(texel, colors[nearest], "texel ({}, {})", col, row);
                }
                if is_inside {
                    inside += 1;
                } else if !bleed {
                    prop_assert_eq!(texel, [0, 0, 0], "outside texel ({}, {}) coloured", col, row);
                }
            }
        }
        prop_assert_eq!(inside, texture.inside);
        // uv: every vertex's uv is its position in the texture (Alg. 2).
        for (q, uv) in mesh.vertices_2d.iter().zip(&mesh.uv) {
            let u = (q[0] - texture.origin[0]) * texture.texels_per_unit / f64::from(texture.width);
            let v = (q[1] - texture.origin[1]) * texture.texels_per_unit / f64::from(texture.height);
            prop_assert!((uv[0] - u).abs() < 1e-12 && (uv[1] - v).abs() < 1e-12);
            prop_assert!((-1e-9..=1.0 + 1e-9).contains(&uv[0]) && (-1e-9..=1.0 + 1e-9).contains(&uv[1]));
        }
    }
}

#[test]
fn atlas_uv_samples_the_same_colours_as_the_plane_textures() {
    let a = Case::new(&[4.0; 12], &[(4, 0.5)], [0.3, -0.2], [0.0, 0.0, 0.0]);
    let b = Case::new(
        &[3.0, 4.0, 5.0, 4.0, 3.5, 4.5],
        &[],
        [-0.5, 0.1],
        [10.0, 0.0, 0.0],
    );
    let options = TextureOptions::new().with_resolution(Resolution::PerUnit(8.0));
    let (ma, ..) = textured(&a, 0.3, options, 1);
    let (mb, ..) = textured(&b, 0.3, options, 2);
    let merged = merge(&[(0, &ma), (1, &mb)], Packing::Atlas);
    let atlas = merged.atlas.as_ref().unwrap();
    assert_eq!(merged.uv.len(), merged.vertices.len());
    for (plane, mesh) in [(0usize, &ma), (1, &mb)] {
        let range = merged.planes[plane];
        let texture = mesh.texture.as_ref().unwrap();
        for (k, uv) in mesh.uv.iter().enumerate() {
            // Sample both at a point slightly inside the texel grid.
            let inner = [uv[0].clamp(0.01, 0.99), uv[1].clamp(0.01, 0.99)];
            let atlas_uv = merged.uv[range.first_vertex as usize + k];
            let o = range.atlas_offset.unwrap();
            let col = o[0] as usize + (inner[0] * f64::from(texture.width)).floor() as usize;
            let row =
                o[1] as usize + ((1.0 - inner[1]) * f64::from(texture.height)).floor() as usize;
            let i = 3 * (row * atlas.width as usize + col);
            assert_eq!(
                [atlas.rgb[i], atlas.rgb[i + 1], atlas.rgb[i + 2]],
                texture.sample(inner)
            );
            // The atlas uv is the plane uv scaled and shifted into the texture's place.
            let expect_u =
                (f64::from(o[0]) + uv[0] * f64::from(texture.width)) / f64::from(atlas.width);
            assert!((atlas_uv[0] - expect_u).abs() < 1e-12);
        }
    }
}

#[test]
fn bad_input_gets_a_clear_error() {
    let case = Case::new(&[4.0; 8], &[], [0.0, 0.0], [0.0; 3]);
    let points = case.points(0.5);
    let shell = case.shell3();
    let segment = Segment::new(&points, &shell, &[]);
    let texture = SimplifyOptions::new().with_texture(TextureOptions::new());
    assert_eq!(simplify(&segment, &texture), Err(PlanarMeshError::NoColors));
    let few = vec![[0u8; 3]; 3];
    assert!(matches!(
        simplify(&segment.with_colors(&few), &texture),
        Err(PlanarMeshError::ColorCount { colors: 3, .. })
    ));
    let deep = SimplifyOptions::new().with_depth(planar_mesh::Depth::Fixed(17));
    assert!(matches!(
        simplify(&segment, &deep),
        Err(PlanarMeshError::BadOption { name: "depth", .. })
    ));
    let r = SimplifyOptions::new()
        .with_texture(TextureOptions::new().with_resolution(Resolution::PerUnit(-1.0)));
    assert!(matches!(
        simplify(&segment.with_colors(&colours(points.len(), 3)), &r),
        Err(PlanarMeshError::BadOption {
            name: "resolution",
            ..
        })
    ));
    let flat_shell = [shell[0], shell[1], shell[0]];
    assert!(matches!(
        simplify(
            &Segment::new(&points, &flat_shell, &[]),
            &SimplifyOptions::new()
        ),
        Err(PlanarMeshError::EmptyShell { .. })
    ));
    let mut nan = shell.clone();
    nan[2][1] = f64::NAN;
    assert!(matches!(
        simplify(&Segment::new(&points, &nan, &[]), &SimplifyOptions::new()),
        Err(PlanarMeshError::NonFinite {
            what: "shell vertex",
            index: 2,
            ..
        })
    ));
}

#[test]
fn resolution_from_density_follows_the_point_spacing() {
    let case = Case::new(&[4.0; 16], &[], [0.0, 0.0], [0.0; 3]);
    let options = TextureOptions::new().with_resolution(Resolution::FromDensity);
    let (mesh, ..) = textured(&case, 0.25, options, 5);
    // One texel per 0.25 spacing: 4 per unit, within the polygon's sampling error.
    let r = mesh.texture.as_ref().unwrap().texels_per_unit;
    assert!((r - 4.0).abs() < 0.3, "{r}");
}
