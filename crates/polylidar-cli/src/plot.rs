//! The `--plot` picture, with a legend in its top-left corner.
//!
//! * Organized input: the range image in grey (light near, dark far, black where invalid),
//!   each plane's pixels tinted in its own colour, shells outlined in dark green and holes
//!   in orange, at pixel positions (so always the extracted polygons).
//! * 2D points: the points in grey, polygon interiors in translucent green, shells in dark
//!   green, holes in orange.
//! * Unorganized 3D clouds (2.5D), seen along `up`: a hillshade of the points' heights on a
//!   grid of a few point spacings (no scan-line stripes), each polygon filled in its own
//!   colour, holes outlined in orange (the post-processed polygons when `processed`).
//! * Meshes: an oblique view (from 35° above the horizon, 30° round `up`), triangles shaded
//!   by the angle to the viewer, each plane's triangles in its own colour, others grey;
//!   triangles facing away are not drawn, so a room is seen through its near walls.
//! * Unorganized clouds on the 3D path: the same view of the planes, from the side of `up`
//!   most of them face.

use polylidar::{Extraction, OrganizedPointCloud, PlaneFrame};
use tiny_skia::{Color, ColorU8, FillRule, Paint, PathBuilder, Pixmap, Rect, Stroke, Transform};

use crate::input::Input;
use pixel_font as font;

/// Longest side of the picture in pixels.
const SIZE: f64 = 1200.0;
/// Blank border in pixels (projected views).
const MARGIN: f64 = 20.0;
/// Shell outline colour (2D and organized input).
const SHELL: [u8; 3] = [20, 110, 40];
/// Hole outline colour.
const HOLE: [u8; 3] = [240, 130, 20];

/// One line of the legend: a swatch and its meaning.
enum Swatch {
    /// A filled square of this colour.
    Fill([u8; 3]),
    /// A short line of this colour.
    Line([u8; 3]),
    /// Several plane colours side by side.
    Planes,
}

/// Renders the picture as PNG bytes.
pub fn render(
    input: &Input,
    extraction: &Extraction,
    up: [f64; 3],
    processed: bool,
) -> Result<Vec<u8>, String> {
    let polygons = if processed {
        "post-processed polygon"
    } else {
        "polygon"
    };
    let (mut pixmap, legend) = match input {
        Input::Organized(cloud) => (
            render_image(cloud, extraction)?,
            vec![
                (
                    Swatch::Fill([200, 200, 200]),
                    "range: light near, dark far".to_owned(),
                ),
                (Swatch::Fill([0, 0, 0]), "no return".to_owned()),
                (Swatch::Planes, "one colour per plane".to_owned()),
                (Swatch::Line(SHELL), "polygon shell".to_owned()),
                (Swatch::Line(HOLE), "hole".to_owned()),
            ],
        ),
        Input::Points2d(points) => (
            render_points_2d(points, extraction)?,
            vec![
                (Swatch::Fill([120, 120, 120]), "input point".to_owned()),
                (Swatch::Fill([60, 180, 75]), "polygon".to_owned()),
                (Swatch::Line(HOLE), "hole".to_owned()),
            ],
        ),
        Input::Cloud(_) if !extraction.fitted.is_empty() => (
            render_oblique(extraction, facing_side(extraction, up))?,
            vec![(Swatch::Planes, "one colour per plane (3D path)".to_owned())],
        ),
        Input::Cloud(points) => (
            render_aerial(points, extraction, up, processed)?,
            vec![
                (
                    Swatch::Fill([150, 150, 150]),
                    "hillshade of the heights".to_owned(),
                ),
                (Swatch::Planes, format!("one colour per {polygons}")),
                (Swatch::Line(HOLE), "hole".to_owned()),
            ],
        ),
        Input::Mesh { .. } => (
            render_oblique(extraction, up)?,
            vec![
                (
                    Swatch::Fill([170, 170, 170]),
                    "triangle in no plane".to_owned(),
                ),
                (Swatch::Planes, "one colour per plane".to_owned()),
            ],
        ),
    };
    draw_legend(&mut pixmap, &legend);
    pixmap.encode_png().map_err(|e| e.to_string())
}

fn paint(r: u8, g: u8, b: u8, a: u8) -> Paint<'static> {
    let mut paint = Paint::default();
    paint.set_color_rgba8(r, g, b, a);
    paint.anti_alias = true;
    paint
}

/// A well-spread colour for plane `i` (golden-angle hues).
fn plane_colour(i: usize) -> [u8; 3] {
    let h = (i as f64 * 137.508) % 360.0 / 60.0;
    let x = 1.0 - (h % 2.0 - 1.0).abs();
    let (r, g, b) = match h as u32 {
        0 => (1.0, x, 0.0),
        1 => (x, 1.0, 0.0),
        2 => (0.0, 1.0, x),
        3 => (0.0, x, 1.0),
        4 => (x, 0.0, 1.0),
        _ => (1.0, 0.0, x),
    };
    [r, g, b].map(|c: f64| (40.0 + 215.0 * c) as u8)
}

/// The legend: a white box in the top-left corner, one swatch and text per line.
fn draw_legend(pixmap: &mut Pixmap, lines: &[(Swatch, String)]) {
    const SCALE: u32 = 2;
    let row = (font::HEIGHT * SCALE + 8) as f32;
    let swatch = 28.0;
    let text_width = lines
        .iter()
        .map(|(_, t)| font::text_width(t, SCALE))
        .max()
        .unwrap_or(0) as f32;
    let (x0, y0) = (8.0, 8.0);
    let box_width = 12.0 + swatch + 8.0 + text_width + 12.0;
    let box_height = 10.0 + row * lines.len() as f32 + 2.0;
    if let Some(rect) = Rect::from_xywh(x0, y0, box_width, box_height) {
        pixmap.fill_rect(
            rect,
            &paint(255, 255, 255, 225),
            Transform::identity(),
            None,
        );
    }
    for (i, (kind, text)) in lines.iter().enumerate() {
        let y = y0 + 10.0 + row * i as f32;
        let x = x0 + 12.0;
        let h = (font::HEIGHT * SCALE) as f32;
        match kind {
            Swatch::Fill([r, g, b]) => {
                if let Some(rect) = Rect::from_xywh(x, y, swatch, h) {
                    let p = paint(*r, *g, *b, 255);
                    pixmap.fill_rect(rect, &p, Transform::identity(), None);
                    let border = paint(90, 90, 90, 255);
                    stroke_ring(
                        pixmap,
                        [(x, y), (x + swatch, y), (x + swatch, y + h), (x, y + h)].into_iter(),
                        &border,
                        &Stroke::default(),
                    );
                }
            }
            Swatch::Line([r, g, b]) => {
                let stroke = Stroke {
                    width: 3.0,
                    ..Stroke::default()
                };
                let mut builder = PathBuilder::new();
                builder.move_to(x, y + h / 2.0);
                builder.line_to(x + swatch, y + h / 2.0);
                if let Some(path) = builder.finish() {
                    let p = paint(*r, *g, *b, 255);
                    pixmap.stroke_path(&path, &p, &stroke, Transform::identity(), None);
                }
            }
            Swatch::Planes => {
                for k in 0..4 {
                    let [r, g, b] = plane_colour(k);
                    let w = swatch / 4.0;
                    if let Some(rect) = Rect::from_xywh(x + w * k as f32, y, w, h) {
                        pixmap.fill_rect(rect, &paint(r, g, b, 255), Transform::identity(), None);
                    }
                }
            }
        }
        font::draw_text(
            pixmap,
            x + swatch + 8.0,
            y,
            text,
            SCALE,
            Color::from_rgba8(30, 30, 30, 255),
            false,
        );
    }
}

fn render_image(cloud: &OrganizedPointCloud, extraction: &Extraction) -> Result<Pixmap, String> {
    let (rows, cols) = (cloud.rows(), cloud.cols());
    let scale = (SIZE / rows.max(cols) as f64).floor().max(1.0);
    let (width, height) = ((cols as f64 * scale) as u32, (rows as f64 * scale) as u32);
    // Range image at native resolution, tinted by plane.
    let ranges: Vec<f64> = cloud
        .points()
        .iter()
        .map(|p| (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt())
        .collect();
    let (lo, hi) = ranges
        .iter()
        .filter(|r| r.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &r| {
            (lo.min(r), hi.max(r))
        });
    if lo > hi {
        return Err("no valid pixel to draw".to_owned());
    }
    let labels = extraction.point_labels();
    let mut image = Pixmap::new(cols as u32, rows as u32).ok_or("picture too large")?;
    for (i, pixel) in image.pixels_mut().iter_mut().enumerate() {
        let r = ranges[i];
        let [red, green, blue] = if !r.is_finite() {
            [0, 0, 0]
        } else {
            let grey = 230.0 - 170.0 * (r - lo) / (hi - lo).max(f64::MIN_POSITIVE);
            match usize::try_from(labels[i]) {
                Ok(plane) => plane_colour(plane).map(|c| (0.45 * grey + 0.55 * f64::from(c)) as u8),
                Err(_) => [grey as u8; 3],
            }
        };
        *pixel = ColorU8::from_rgba(red, green, blue, 255).premultiply();
    }
    let mut pixmap = Pixmap::new(width, height).ok_or("picture too large")?;
    let zoom = Transform::from_scale(scale as f32, scale as f32);
    let pattern = Paint {
        shader: tiny_skia::Pattern::new(
            image.as_ref(),
            tiny_skia::SpreadMode::Pad,
            tiny_skia::FilterQuality::Nearest,
            1.0,
            zoom,
        ),
        ..Paint::default()
    };
    let full = Rect::from_xywh(0.0, 0.0, width as f32, height as f32).ok_or("empty picture")?;
    pixmap.fill_rect(full, &pattern, Transform::identity(), None);

    // A decimated cloud's vertex stands for a block of pixels: drawn at its centre.
    let (grid_cols, block) = match &extraction.decimation {
        Some(d) => (d.grid().1, d.factor as f64),
        None => (cols, 1.0),
    };
    let to_px = |v: u32| {
        let (r, c) = (
            (v as usize / grid_cols) as f64,
            (v as usize % grid_cols) as f64,
        );
        (
            ((c + 0.5) * block * scale) as f32,
            ((r + 0.5) * block * scale) as f32,
        )
    };
    let stroke = Stroke {
        width: 2.0,
        ..Stroke::default()
    };
    let [sr, sg, sb] = SHELL;
    let [hr, hg, hb] = HOLE;
    for polygon in &extraction.polygons {
        stroke_ring(
            &mut pixmap,
            polygon.shell.iter().map(|&v| to_px(v)),
            &paint(sr, sg, sb, 255),
            &stroke,
        );
        for hole in &polygon.holes {
            stroke_ring(
                &mut pixmap,
                hole.iter().map(|&v| to_px(v)),
                &paint(hr, hg, hb, 255),
                &stroke,
            );
        }
    }
    Ok(pixmap)
}

fn ring_path(points: impl Iterator<Item = (f32, f32)>, builder: &mut PathBuilder) {
    for (i, (x, y)) in points.enumerate() {
        if i == 0 {
            builder.move_to(x, y);
        } else {
            builder.line_to(x, y);
        }
    }
    builder.close();
}

fn stroke_ring(
    pixmap: &mut Pixmap,
    points: impl Iterator<Item = (f32, f32)>,
    paint: &Paint<'_>,
    stroke: &Stroke,
) {
    let mut builder = PathBuilder::new();
    ring_path(points, &mut builder);
    if let Some(path) = builder.finish() {
        pixmap.stroke_path(&path, paint, stroke, Transform::identity(), None);
    }
}

/// Where a top view puts the points `points` (plane coordinates): a white picture of the
/// right size and the map from plane coordinates to pixels.
struct TopView {
    lo: [f64; 2],
    scale: f64,
    width: u32,
    height: u32,
}

impl TopView {
    fn new(points: impl Iterator<Item = [f64; 2]>) -> Result<Self, String> {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in points.filter(|p| p[0].is_finite() && p[1].is_finite()) {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        if !(lo[0] <= hi[0] && lo[1] <= hi[1]) {
            return Err("no finite point to draw".to_owned());
        }
        let span = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(f64::MIN_POSITIVE);
        let scale = (SIZE - 2.0 * MARGIN) / span;
        Ok(Self {
            lo,
            scale,
            width: ((hi[0] - lo[0]) * scale + 2.0 * MARGIN).ceil().max(1.0) as u32,
            height: ((hi[1] - lo[1]) * scale + 2.0 * MARGIN).ceil().max(1.0) as u32,
        })
    }

    fn pixmap(&self) -> Result<Pixmap, String> {
        let mut pixmap = Pixmap::new(self.width, self.height).ok_or("picture too large")?;
        pixmap.fill(Color::WHITE);
        Ok(pixmap)
    }

    /// Pixel position of plane point `p`; image y grows downwards, so +y is flipped up.
    fn px(&self, p: [f64; 2]) -> (f32, f32) {
        (
            (MARGIN + (p[0] - self.lo[0]) * self.scale) as f32,
            (f64::from(self.height) - MARGIN - (p[1] - self.lo[1]) * self.scale) as f32,
        )
    }
}

/// Fills and outlines polygon rings (`fill` per polygon index), holes in orange.
fn draw_polygons<'a>(
    pixmap: &mut Pixmap,
    rings: impl Iterator<Item = (&'a [[f64; 3]], &'a [Vec<[f64; 3]>])>,
    to_px: impl Fn([f64; 3]) -> (f32, f32),
    fill: impl Fn(usize) -> ([u8; 3], [u8; 3]),
    alpha: u8,
) {
    let stroke = Stroke {
        width: 2.0,
        ..Stroke::default()
    };
    let [hr, hg, hb] = HOLE;
    let hole_paint = paint(hr, hg, hb, 255);
    for (i, (shell, holes)) in rings.enumerate() {
        let project =
            |ring: &[[f64; 3]]| -> Vec<(f32, f32)> { ring.iter().map(|&p| to_px(p)).collect() };
        let ([fr, fg, fb], [sr, sg, sb]) = fill(i);
        let mut all = PathBuilder::new();
        ring_path(project(shell).into_iter(), &mut all);
        for hole in holes {
            ring_path(project(hole).into_iter(), &mut all);
        }
        if let Some(path) = all.finish() {
            pixmap.fill_path(
                &path,
                &paint(fr, fg, fb, alpha),
                FillRule::EvenOdd,
                Transform::identity(),
                None,
            );
        }
        stroke_ring(
            pixmap,
            project(shell).into_iter(),
            &paint(sr, sg, sb, 255),
            &stroke,
        );
        for hole in holes {
            stroke_ring(pixmap, project(hole).into_iter(), &hole_paint, &stroke);
        }
    }
}

type Rings<'a> = (&'a [[f64; 3]], &'a [Vec<[f64; 3]>]);

fn rings(extraction: &Extraction, processed: bool) -> Vec<Rings<'_>> {
    if processed {
        extraction
            .postprocessed
            .iter()
            .map(|p| (p.shell.as_slice(), p.holes.as_slice()))
            .collect()
    } else {
        extraction
            .polygons
            .iter()
            .map(|p| (p.shell_points.as_slice(), p.hole_points.as_slice()))
            .collect()
    }
}

fn render_points_2d(points: &[[f64; 2]], extraction: &Extraction) -> Result<Pixmap, String> {
    let view = TopView::new(points.iter().copied())?;
    let mut pixmap = view.pixmap()?;
    let dot = paint(120, 120, 120, 255);
    for &p in points {
        let (x, y) = view.px(p);
        if let Some(rect) = Rect::from_xywh(x - 0.5, y - 0.5, 1.5, 1.5) {
            pixmap.fill_rect(rect, &dot, Transform::identity(), None);
        }
    }
    draw_polygons(
        &mut pixmap,
        rings(extraction, false).into_iter(),
        |p| view.px([p[0], p[1]]),
        |_| ([60, 180, 75], SHELL),
        70,
    );
    Ok(pixmap)
}

/// The top view of a 2.5D cloud: hillshade of the highest point per grid cell, then the
/// polygons, each in its own colour.
fn render_aerial(
    points: &[[f64; 3]],
    extraction: &Extraction,
    up: [f64; 3],
    processed: bool,
) -> Result<Pixmap, String> {
    let frame = PlaneFrame::new(up).ok_or_else(|| format!("up {up:?} is zero or not finite"))?;
    let len = (up[0] * up[0] + up[1] * up[1] + up[2] * up[2]).sqrt();
    let height = |p: [f64; 3]| (p[0] * up[0] + p[1] * up[1] + p[2] * up[2]) / len;
    let planar: Vec<[f64; 2]> = points.iter().map(|&p| frame.project(p)).collect();
    let view = TopView::new(planar.iter().copied())?;
    let mut pixmap = view.pixmap()?;
    // Cells of twice the mean spacing (bounding box area / points), at least 2 pixels.
    let area = f64::from(view.width) * f64::from(view.height) / (view.scale * view.scale);
    let cell_px = (2.0 * (area / points.len().max(1) as f64).sqrt() * view.scale).max(2.0);
    let (gw, gh) = (
        (f64::from(view.width) / cell_px).ceil() as usize,
        (f64::from(view.height) / cell_px).ceil() as usize,
    );
    let mut grid = vec![f64::NAN; gw * gh];
    for (&p, &q) in points.iter().zip(&planar) {
        let (x, y) = view.px(q);
        let (gx, gy) = (
            (f64::from(x) / cell_px) as usize,
            (f64::from(y) / cell_px) as usize,
        );
        if gx < gw && gy < gh {
            let cell = &mut grid[gy * gw + gx];
            let h = height(p);
            if cell.is_nan() || h > *cell {
                *cell = h;
            }
        }
    }
    let shade = hillshade(&grid, gw, gh, cell_px / view.scale);
    let mut image = Pixmap::new(gw as u32, gh as u32).ok_or("picture too large")?;
    for (pixel, s) in image.pixels_mut().iter_mut().zip(&shade) {
        let c = match s {
            Some(s) => (70.0 + 170.0 * s) as u8,
            None => 255,
        };
        *pixel = ColorU8::from_rgba(c, c, c, 255).premultiply();
    }
    let pattern = Paint {
        shader: tiny_skia::Pattern::new(
            image.as_ref(),
            tiny_skia::SpreadMode::Pad,
            tiny_skia::FilterQuality::Bilinear,
            1.0,
            Transform::from_scale(cell_px as f32, cell_px as f32),
        ),
        ..Paint::default()
    };
    let full =
        Rect::from_xywh(0.0, 0.0, view.width as f32, view.height as f32).ok_or("empty picture")?;
    pixmap.fill_rect(full, &pattern, Transform::identity(), None);
    draw_polygons(
        &mut pixmap,
        rings(extraction, processed).into_iter(),
        |p| view.px(frame.project(p)),
        |i| {
            let c = plane_colour(i);
            (c, c.map(|v| (f64::from(v) * 0.55) as u8))
        },
        140,
    );
    Ok(pixmap)
}

/// Hillshade in [0, 1] of a height grid (sun from the north-west, 45° up); empty cells
/// take the mean of their non-empty neighbours, or stay `None`.
fn hillshade(grid: &[f64], w: usize, h: usize, cell: f64) -> Vec<Option<f64>> {
    let filled: Vec<f64> = (0..w * h)
        .map(|i| {
            if !grid[i].is_nan() {
                return grid[i];
            }
            let (x, y) = (i % w, i / w);
            let (mut sum, mut n) = (0.0, 0);
            for (dx, dy) in [
                (-1, -1),
                (0, -1),
                (1, -1),
                (-1, 0),
                (1, 0),
                (-1, 1),
                (0, 1),
                (1, 1),
            ] {
                let (nx, ny) = (x as i64 + dx, y as i64 + dy);
                if (0..w as i64).contains(&nx) && (0..h as i64).contains(&ny) {
                    let v = grid[ny as usize * w + nx as usize];
                    if !v.is_nan() {
                        sum += v;
                        n += 1;
                    }
                }
            }
            if n >= 3 { sum / f64::from(n) } else { f64::NAN }
        })
        .collect();
    let at = |x: usize, y: usize| filled[y * w + x];
    let (azimuth, altitude) = (315f64.to_radians(), 45f64.to_radians());
    (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            let centre = at(x, y);
            if centre.is_nan() {
                return None;
            }
            let side = |a: Option<f64>, b: Option<f64>| match (a, b) {
                (Some(a), Some(b)) => (b - a) / (2.0 * cell),
                (Some(a), None) => (centre - a) / cell,
                (None, Some(b)) => (b - centre) / cell,
                (None, None) => 0.0,
            };
            let get = |x: Option<usize>, y: Option<usize>| {
                let (x, y) = (x?, y?);
                (x < w && y < h).then(|| at(x, y)).filter(|v| !v.is_nan())
            };
            // Image rows grow southwards: dz/dy (north) is minus the row gradient.
            let dzdx = side(get(x.checked_sub(1), Some(y)), get(Some(x + 1), Some(y)));
            let dzdy = -side(get(Some(x), y.checked_sub(1)), get(Some(x), Some(y + 1)));
            let slope = dzdx.hypot(dzdy).atan();
            let aspect = dzdy.atan2(-dzdx);
            let s = altitude.sin() * slope.cos()
                + altitude.cos() * slope.sin() * (azimuth - aspect).cos();
            Some(s.clamp(0.0, 1.0))
        })
        .collect()
}

/// `up`, or its opposite when most of the planes' triangles face that way. The 3D path
/// winds each plane's triangles along its direction, signed like the cloud's normals; when
/// those point against `up` (a floor whose normals point down: `up` is the other way round
/// for this cloud) the planes would be seen from behind and not drawn.
fn facing_side(extraction: &Extraction, up: [f64; 3]) -> [f64; 3] {
    let Some(normals) = extraction.mesh.triangle_normals() else {
        return up;
    };
    let facing: f64 = extraction
        .polygons
        .iter()
        .flat_map(|p| &p.triangles)
        .filter_map(|&t| normals.get(t as usize))
        .map(|n| n[0] * up[0] + n[1] * up[1] + n[2] * up[2])
        .sum();
    if facing < 0.0 { up.map(|c| -c) } else { up }
}

/// An oblique view of the mesh: orthographic, z-buffered, shaded by the angle between
/// each triangle and the viewing direction.
fn render_oblique(extraction: &Extraction, up: [f64; 3]) -> Result<Pixmap, String> {
    let mesh = &extraction.mesh;
    let vertices = mesh.vertices();
    let unit = |v: [f64; 3]| {
        let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        v.map(|c| c / l)
    };
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let up = unit(up);
    let frame = PlaneFrame::new(up).ok_or_else(|| format!("up {up:?} is zero or not finite"))?;
    let (e1, e2) = (frame.e1, frame.e2);
    let (az, el) = (30f64.to_radians(), 35f64.to_radians());
    // From the scene towards the viewer.
    let eye = unit(
        [0, 1, 2].map(|k| el.cos() * (az.cos() * e1[k] + az.sin() * e2[k]) + el.sin() * up[k]),
    );
    let right = unit(cross(up, eye));
    let screen_up = cross(eye, right);
    let screen: Vec<[f64; 3]> = vertices
        .iter()
        .map(|&p| [dot(p, right), dot(p, screen_up), dot(p, eye)])
        .collect();
    let view = TopView::new(screen.iter().map(|s| [s[0], s[1]]))?;
    let mut pixmap = view.pixmap()?;
    let (w, h) = (view.width as usize, view.height as usize);
    let mut depth = vec![f64::NEG_INFINITY; w * h];
    let mut label = vec![-1i64; mesh.num_triangles()];
    for (i, polygon) in extraction.polygons.iter().enumerate() {
        for &t in &polygon.triangles {
            label[t as usize] = i as i64;
        }
    }
    let pixels = pixmap.pixels_mut();
    for (t, tri) in mesh.triangles().iter().enumerate() {
        let [a, b, c] = tri.map(|v| vertices[v as usize]);
        let n = cross(
            [0, 1, 2].map(|k| b[k] - a[k]),
            [0, 1, 2].map(|k| c[k] - a[k]),
        );
        let facing = dot(n, eye);
        if facing.is_nan() || facing <= 0.0 {
            continue;
        }
        let light = 0.35 + 0.65 * facing / dot(n, n).sqrt();
        let base = match usize::try_from(label[t]) {
            Ok(i) => plane_colour(i).map(f64::from),
            // The unorganized 3D path's triangles outside planes bridge gaps: not drawn.
            Err(_) if !extraction.fitted.is_empty() => continue,
            Err(_) => [185.0; 3],
        };
        let [r, g, bl] = base.map(|v| (v * light).min(255.0) as u8);
        let colour = ColorU8::from_rgba(r, g, bl, 255).premultiply();
        let p = tri.map(|v| {
            let s = screen[v as usize];
            let (x, y) = view.px([s[0], s[1]]);
            [f64::from(x), f64::from(y), s[2]]
        });
        let area =
            (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1]);
        if area.abs() < 1e-12 {
            continue;
        }
        let min_x = p
            .iter()
            .map(|q| q[0])
            .fold(f64::INFINITY, f64::min)
            .floor()
            .max(0.0) as usize;
        let max_x = (p
            .iter()
            .map(|q| q[0])
            .fold(f64::NEG_INFINITY, f64::max)
            .ceil() as usize)
            .min(w - 1);
        let min_y = p
            .iter()
            .map(|q| q[1])
            .fold(f64::INFINITY, f64::min)
            .floor()
            .max(0.0) as usize;
        let max_y = (p
            .iter()
            .map(|q| q[1])
            .fold(f64::NEG_INFINITY, f64::max)
            .ceil() as usize)
            .min(h - 1);
        for y in min_y..=max_y {
            for x in min_x..=max_x {
                let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
                let edge = |i: usize, j: usize| {
                    ((p[j][0] - p[i][0]) * (py - p[i][1]) - (p[j][1] - p[i][1]) * (px - p[i][0]))
                        / area
                };
                let (w0, w1, w2) = (edge(1, 2), edge(2, 0), edge(0, 1));
                if w0 < 0.0 || w1 < 0.0 || w2 < 0.0 {
                    continue;
                }
                let z = w0 * p[0][2] + w1 * p[1][2] + w2 * p[2][2];
                let k = y * w + x;
                if z > depth[k] {
                    depth[k] = z;
                    pixels[k] = colour;
                }
            }
        }
    }
    Ok(pixmap)
}
