//! The `--plot` picture.
//!
//! * Organized input: the range image in grey (black where invalid), each plane's pixels
//!   tinted in its own colour, shells outlined in dark green and holes in orange, at
//!   pixel positions (so always the extracted polygons).
//! * Other input, seen along `up`: points in grey, polygon interiors in translucent
//!   green, shells in dark green and holes in orange (the post-processed polygons when
//!   `processed`).

use polylidar::{Extraction, OrganizedPointCloud, PlaneFrame};
use tiny_skia::{Color, FillRule, Paint, PathBuilder, Pixmap, Rect, Stroke, Transform};

use crate::input::Input;

/// Longest side of the picture in pixels.
const SIZE: f64 = 1200.0;
/// Blank border in pixels (projected view).
const MARGIN: f64 = 20.0;

/// Renders the picture as PNG bytes.
pub fn render(
    input: &Input,
    extraction: &Extraction,
    up: [f64; 3],
    processed: bool,
) -> Result<Vec<u8>, String> {
    match input {
        Input::Organized(cloud) => render_image(cloud, extraction),
        _ => render_projected(input, extraction, up, processed),
    }
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

fn render_image(cloud: &OrganizedPointCloud, extraction: &Extraction) -> Result<Vec<u8>, String> {
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
        *pixel = tiny_skia::ColorU8::from_rgba(red, green, blue, 255).premultiply();
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

    let to_px = |v: u32| {
        let (r, c) = ((v as usize / cols) as f64, (v as usize % cols) as f64);
        (((c + 0.5) * scale) as f32, ((r + 0.5) * scale) as f32)
    };
    let stroke = Stroke {
        width: 2.0,
        ..Stroke::default()
    };
    for polygon in &extraction.polygons {
        stroke_ring(
            &mut pixmap,
            polygon.shell.iter().map(|&v| to_px(v)),
            &paint(10, 80, 20, 255),
            &stroke,
        );
        for hole in &polygon.holes {
            stroke_ring(
                &mut pixmap,
                hole.iter().map(|&v| to_px(v)),
                &paint(240, 130, 20, 255),
                &stroke,
            );
        }
    }
    pixmap.encode_png().map_err(|e| e.to_string())
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

fn render_projected(
    input: &Input,
    extraction: &Extraction,
    up: [f64; 3],
    processed: bool,
) -> Result<Vec<u8>, String> {
    let frame = PlaneFrame::new(up);
    let points: Vec<[f64; 2]> = match input {
        Input::Points2d(p) => p.clone(),
        Input::Cloud(p) | Input::Mesh { vertices: p, .. } => {
            p.iter().map(|&q| frame.project(q)).collect()
        }
        Input::Organized(c) => c.points().iter().map(|&q| frame.project(q)).collect(),
    };
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in points
        .iter()
        .filter(|p| p[0].is_finite() && p[1].is_finite())
    {
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
    let width = ((hi[0] - lo[0]) * scale + 2.0 * MARGIN).ceil() as u32;
    let height = ((hi[1] - lo[1]) * scale + 2.0 * MARGIN).ceil() as u32;
    let mut pixmap = Pixmap::new(width.max(1), height.max(1)).ok_or("picture too large")?;
    pixmap.fill(Color::WHITE);
    // Image y grows downwards: flip so that +y is up.
    let to_px = |p: [f64; 2]| {
        (
            (MARGIN + (p[0] - lo[0]) * scale) as f32,
            (f64::from(height) - MARGIN - (p[1] - lo[1]) * scale) as f32,
        )
    };
    let dot = paint(120, 120, 120, 255);
    for &p in &points {
        let (x, y) = to_px(p);
        if let Some(rect) = Rect::from_xywh(x - 0.5, y - 0.5, 1.5, 1.5) {
            pixmap.fill_rect(rect, &dot, Transform::identity(), None);
        }
    }

    type Rings<'a> = (&'a [[f64; 3]], &'a [Vec<[f64; 3]>]);
    let rings: Vec<Rings<'_>> = if processed {
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
    };
    let project = |ring: &[[f64; 3]]| -> Vec<(f32, f32)> {
        ring.iter().map(|&p| to_px(frame.project(p))).collect()
    };
    let stroke = Stroke {
        width: 2.0,
        ..Stroke::default()
    };
    let (fill, shell_paint, hole_paint) = (
        paint(60, 180, 75, 70),
        paint(20, 110, 40, 255),
        paint(240, 130, 20, 255),
    );
    for (shell, holes) in rings {
        let mut all = PathBuilder::new();
        ring_path(project(shell).into_iter(), &mut all);
        for hole in holes {
            ring_path(project(hole).into_iter(), &mut all);
        }
        if let Some(path) = all.finish() {
            pixmap.fill_path(&path, &fill, FillRule::EvenOdd, Transform::identity(), None);
        }
        stroke_ring(
            &mut pixmap,
            project(shell).into_iter(),
            &shell_paint,
            &stroke,
        );
        for hole in holes {
            stroke_ring(&mut pixmap, project(hole).into_iter(), &hole_paint, &stroke);
        }
    }
    pixmap.encode_png().map_err(|e| e.to_string())
}
