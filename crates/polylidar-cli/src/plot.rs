//! The `--plot` picture: input points in grey, polygon interiors in translucent green,
//! shells in dark green and holes in orange, seen from the up direction.

use polylidar::{Extraction, PlaneFrame};
use tiny_skia::{Color, FillRule, Paint, PathBuilder, Pixmap, Rect, Stroke, Transform};

use crate::run::Input;

/// Longest side of the picture in pixels.
const SIZE: f64 = 1200.0;
/// Blank border in pixels.
const MARGIN: f64 = 20.0;

/// Renders the picture as PNG bytes.
pub fn render(input: &Input, extraction: &Extraction, up: [f64; 3]) -> Result<Vec<u8>, String> {
    let frame = PlaneFrame::new(up);
    let points: Vec<[f64; 2]> = match input {
        Input::Points2d(p) => p.clone(),
        Input::Cloud(p) => p.iter().map(|&q| frame.project(q)).collect(),
    };
    let finite = points
        .iter()
        .filter(|p| p[0].is_finite() && p[1].is_finite());
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in finite {
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

    let mut dot = Paint::default();
    dot.set_color_rgba8(120, 120, 120, 255);
    for &p in &points {
        let (x, y) = to_px(p);
        if let Some(rect) = Rect::from_xywh(x - 0.5, y - 0.5, 1.5, 1.5) {
            pixmap.fill_rect(rect, &dot, Transform::identity(), None);
        }
    }

    let ring_path = |builder: &mut PathBuilder, ring: &[[f64; 3]]| {
        for (i, &p) in ring.iter().enumerate() {
            let (x, y) = to_px(frame.project(p));
            if i == 0 {
                builder.move_to(x, y);
            } else {
                builder.line_to(x, y);
            }
        }
        builder.close();
    };
    let mut fill = Paint::default();
    fill.set_color_rgba8(60, 180, 75, 70);
    fill.anti_alias = true;
    let mut shell_paint = Paint::default();
    shell_paint.set_color_rgba8(20, 110, 40, 255);
    shell_paint.anti_alias = true;
    let mut hole_paint = Paint::default();
    hole_paint.set_color_rgba8(240, 130, 20, 255);
    hole_paint.anti_alias = true;
    let stroke = Stroke {
        width: 2.0,
        ..Stroke::default()
    };
    for polygon in &extraction.polygons {
        let mut all = PathBuilder::new();
        ring_path(&mut all, &polygon.shell_points);
        for hole in &polygon.hole_points {
            ring_path(&mut all, hole);
        }
        if let Some(path) = all.finish() {
            pixmap.fill_path(&path, &fill, FillRule::EvenOdd, Transform::identity(), None);
        }
        let mut shell = PathBuilder::new();
        ring_path(&mut shell, &polygon.shell_points);
        if let Some(path) = shell.finish() {
            pixmap.stroke_path(&path, &shell_paint, &stroke, Transform::identity(), None);
        }
        for hole in &polygon.hole_points {
            let mut builder = PathBuilder::new();
            ring_path(&mut builder, hole);
            if let Some(path) = builder.finish() {
                pixmap.stroke_path(&path, &hole_paint, &stroke, Transform::identity(), None);
            }
        }
    }
    pixmap.encode_png().map_err(|e| e.to_string())
}
