//! `mesh --plot`: the textured planes rasterized with a z-buffer, their visible triangle
//! edges drawn on top — from the camera for depth images (perspective, the frame's
//! intrinsics), otherwise an oblique orthographic view (35° above the horizon, 30° round
//! `up`).

use plane_geom::vec3::{cross, dot};
use polylidar::Intrinsics;
use polylidar::planar_mesh::{MergedMesh, Texture};
use tiny_skia::{Color, Paint, PathBuilder, Pixmap, Stroke, Transform};

/// A depth camera: intrinsics and image size (columns, rows).
pub type Camera = (Intrinsics, usize, usize);

/// Picture pixels per camera pixel.
const CAMERA_SCALE: f64 = 2.0;
/// Longest side of an oblique picture.
const OBLIQUE_SIZE: f64 = 1400.0;

/// Where a vertex lands: picture column, row, and depth (larger is farther).
type Projected = [f64; 3];

/// Projects every vertex; `None` for a vertex behind the camera.
fn project(
    mesh: &MergedMesh,
    camera: Option<Camera>,
    up: [f64; 3],
) -> (Vec<Option<Projected>>, u32, u32) {
    if let Some((k, cols, rows)) = camera {
        let s = CAMERA_SCALE;
        let points = mesh
            .vertices
            .iter()
            .map(|p| {
                (p[2] > 1e-9).then(|| {
                    [
                        s * (k.fx * p[0] / p[2] + k.ppx + 0.5),
                        s * (k.fy * p[1] / p[2] + k.ppy + 0.5),
                        p[2],
                    ]
                })
            })
            .collect();
        return (points, (s * cols as f64) as u32, (s * rows as f64) as u32);
    }
    let u = normalize(up);
    let helper = if u[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let h1 = normalize(cross(helper, u));
    let h2 = cross(u, h1);
    let (a, b) = (30f64.to_radians(), 35f64.to_radians());
    let h: [f64; 3] = std::array::from_fn(|i| a.cos() * h1[i] + a.sin() * h2[i]);
    let eye: [f64; 3] = std::array::from_fn(|i| b.cos() * h[i] + b.sin() * u[i]);
    let forward = eye.map(|v| -v);
    let right = normalize(cross(forward, u));
    let screen_up = cross(right, forward);
    let raw: Vec<[f64; 3]> = mesh
        .vertices
        .iter()
        .map(|p| [dot(*p, right), dot(*p, screen_up), dot(*p, forward)])
        .collect();
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in &raw {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let span = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(f64::MIN_POSITIVE);
    let scale = (OBLIQUE_SIZE - 40.0) / span;
    let (w, h) = (
        ((hi[0] - lo[0]) * scale + 40.0).clamp(1.0, OBLIQUE_SIZE) as u32,
        ((hi[1] - lo[1]) * scale + 40.0).clamp(1.0, OBLIQUE_SIZE) as u32,
    );
    let points = raw
        .iter()
        .map(|p| {
            Some([
                20.0 + (p[0] - lo[0]) * scale,
                20.0 + (hi[1] - p[1]) * scale,
                p[2],
            ])
        })
        .collect();
    (points, w, h)
}

/// The picture as PNG bytes.
///
/// # Errors
/// A picture that cannot be allocated or encoded.
pub fn render(
    mesh: &MergedMesh,
    textures: &[Option<&Texture>],
    camera: Option<Camera>,
    up: [f64; 3],
) -> Result<Vec<u8>, String> {
    let (points, w, h) = project(mesh, camera, up);
    let mut pixmap = Pixmap::new(w.max(1), h.max(1)).ok_or("picture too large")?;
    pixmap.fill(if camera.is_some() {
        Color::from_rgba8(40, 40, 46, 255)
    } else {
        Color::WHITE
    });
    let (w, h) = (pixmap.width() as usize, pixmap.height() as usize);
    let mut depth = vec![f64::INFINITY; w * h];
    let mut owner = vec![u32::MAX; w * h];
    let perspective = camera.is_some();
    let data = pixmap.data_mut();
    for (k, range) in mesh.planes.iter().enumerate() {
        let first = range.first_triangle as usize;
        for t in first..first + range.triangles as usize {
            let tri = mesh.triangles[t];
            let Some(p) = tri
                .map(|v| points[v as usize])
                .into_iter()
                .collect::<Option<Vec<_>>>()
            else {
                continue;
            };
            let shade = |b: [f64; 3]| -> [u8; 3] {
                let uv = (!mesh.uv.is_empty()).then(|| {
                    let uvs = tri.map(|v| mesh.uv[v as usize]);
                    [0, 1].map(|c| b[0] * uvs[0][c] + b[1] * uvs[1][c] + b[2] * uvs[2][c])
                });
                match (uv, &mesh.atlas, textures.get(k).copied().flatten()) {
                    (Some(uv), Some(atlas), _) => {
                        let col = ((uv[0] * f64::from(atlas.width)).floor().max(0.0) as usize)
                            .min(atlas.width as usize - 1);
                        let row = (((1.0 - uv[1]) * f64::from(atlas.height)).floor().max(0.0)
                            as usize)
                            .min(atlas.height as usize - 1);
                        let i = 3 * (row * atlas.width as usize + col);
                        [atlas.rgb[i], atlas.rgb[i + 1], atlas.rgb[i + 2]]
                    }
                    (Some(uv), None, Some(texture)) => texture.sample(uv),
                    _ => plane_colour(range.plane),
                }
            };
            fill_triangle(&p, perspective, w, h, |i, z, b| {
                if z < depth[i] {
                    depth[i] = z;
                    owner[i] = t as u32;
                    let c = shade(b);
                    data[4 * i..4 * i + 4].copy_from_slice(&[c[0], c[1], c[2], 255]);
                }
            });
        }
    }
    draw_edges(&mut pixmap, mesh, &points, &owner);
    let caption = format!(
        "{} planes, {} triangles",
        mesh.planes.len(),
        mesh.triangles.len()
    );
    let white = camera.is_some();
    pixel_font::draw_text(
        &mut pixmap,
        8.0,
        8.0,
        &caption,
        2,
        if white { Color::WHITE } else { Color::BLACK },
        false,
    );
    pixmap.encode_png().map_err(|e| e.to_string())
}

/// Calls `put(pixel, depth, barycentric)` for every pixel centre inside triangle `p`;
/// barycentric coordinates are perspective-correct when `perspective`.
fn fill_triangle(
    p: &[[f64; 3]],
    perspective: bool,
    w: usize,
    h: usize,
    mut put: impl FnMut(usize, f64, [f64; 3]),
) {
    let [a, b, c] = [p[0], p[1], p[2]];
    let area = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
    if area.abs() < 1e-12 {
        return;
    }
    let x0 = a[0].min(b[0]).min(c[0]).floor().max(0.0) as usize;
    let x1 = (a[0].max(b[0]).max(c[0]).ceil().max(0.0) as usize).min(w);
    let y0 = a[1].min(b[1]).min(c[1]).floor().max(0.0) as usize;
    let y1 = (a[1].max(b[1]).max(c[1]).ceil().max(0.0) as usize).min(h);
    for y in y0..y1 {
        for x in x0..x1 {
            let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
            let w0 = ((b[0] - px) * (c[1] - py) - (c[0] - px) * (b[1] - py)) / area;
            let w1 = ((c[0] - px) * (a[1] - py) - (a[0] - px) * (c[1] - py)) / area;
            let w2 = 1.0 - w0 - w1;
            if w0 < 0.0 || w1 < 0.0 || w2 < 0.0 {
                continue;
            }
            let (bary, z) = if perspective {
                let q = [w0 / a[2], w1 / b[2], w2 / c[2]];
                let s = q[0] + q[1] + q[2];
                ([q[0] / s, q[1] / s, q[2] / s], 1.0 / s)
            } else {
                ([w0, w1, w2], w0 * a[2] + w1 * b[2] + w2 * c[2])
            };
            put(y * w + x, z, bary);
        }
    }
}

/// Edges of the triangles that own at least one pixel, thin and dark.
fn draw_edges(pixmap: &mut Pixmap, mesh: &MergedMesh, points: &[Option<Projected>], owner: &[u32]) {
    let mut visible = vec![false; mesh.triangles.len()];
    for &t in owner {
        if let Some(v) = visible.get_mut(t as usize) {
            *v = true;
        }
    }
    let mut builder = PathBuilder::new();
    for (t, tri) in mesh.triangles.iter().enumerate() {
        if !visible[t] {
            continue;
        }
        let Some(p) = tri
            .map(|v| points[v as usize])
            .into_iter()
            .collect::<Option<Vec<_>>>()
        else {
            continue;
        };
        builder.move_to(p[0][0] as f32, p[0][1] as f32);
        builder.line_to(p[1][0] as f32, p[1][1] as f32);
        builder.line_to(p[2][0] as f32, p[2][1] as f32);
        builder.close();
    }
    if let Some(path) = builder.finish() {
        let mut paint = Paint::default();
        paint.set_color_rgba8(10, 10, 10, 150);
        paint.anti_alias = true;
        let stroke = Stroke {
            width: 0.8,
            ..Stroke::default()
        };
        pixmap.stroke_path(&path, &paint, &stroke, Transform::identity(), None);
    }
}

/// A distinct colour per plane, for untextured meshes.
fn plane_colour(plane: usize) -> [u8; 3] {
    const PALETTE: [[u8; 3]; 8] = [
        [230, 159, 0],
        [86, 180, 233],
        [0, 158, 115],
        [240, 228, 66],
        [0, 114, 178],
        [213, 94, 0],
        [204, 121, 167],
        [150, 150, 150],
    ];
    PALETTE[plane % PALETTE.len()]
}

fn normalize(a: [f64; 3]) -> [f64; 3] {
    let n = dot(a, a).sqrt().max(f64::MIN_POSITIVE);
    a.map(|v| v / n)
}
