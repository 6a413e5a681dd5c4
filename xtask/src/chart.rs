//! Line charts as PNG (tiny-skia): axes with ticks and grid, linear or log scales,
//! solid or dashed series with markers, a legend and labels in the built-in pixel font.

use std::path::Path;

use tiny_skia::{
    Color, FillRule, LineCap, Paint, PathBuilder, Pixmap, Rect, Stroke, StrokeDash, Transform,
};

use crate::error::{Result, msg};
use pixel_font::{HEIGHT, draw_text, text_width};

/// One line of the chart.
#[derive(Debug, Clone)]
pub struct Series {
    /// Legend text.
    pub label: String,
    /// (x, y) points, drawn in order.
    pub points: Vec<(f64, f64)>,
    /// RGB colour.
    pub color: [u8; 3],
    /// Dashed instead of solid.
    pub dashed: bool,
}

/// An axis: label, scale and ticks.
#[derive(Debug, Clone)]
pub struct Axis {
    /// Axis title.
    pub label: String,
    /// Logarithmic scale (values must be > 0).
    pub log: bool,
    /// Tick positions; the axis spans them and the data.
    pub ticks: Vec<f64>,
}

/// A line chart.
#[derive(Debug, Clone)]
pub struct Chart {
    /// Title above the plot.
    pub title: String,
    /// Horizontal axis.
    pub x: Axis,
    /// Vertical axis.
    pub y: Axis,
    /// The lines.
    pub series: Vec<Series>,
}

/// Colours that stay apart for the usual colour-vision deficiencies (Okabe–Ito).
pub const PALETTE: [[u8; 3]; 8] = [
    [0, 114, 178],
    [213, 94, 0],
    [0, 158, 115],
    [204, 121, 167],
    [230, 159, 0],
    [86, 180, 233],
    [0, 0, 0],
    [240, 228, 66],
];

const WIDTH: u32 = 960;
const HEIGHT_PX: u32 = 600;
const LEFT: f32 = 100.0;
const RIGHT: f32 = 300.0;
const TOP: f32 = 60.0;
const BOTTOM: f32 = 80.0;
const SCALE: u32 = 2;

impl Axis {
    fn value(&self, v: f64) -> f64 {
        if self.log { v.max(1e-300).ln() } else { v }
    }

    /// The axis range in scale units over the ticks and the data.
    fn range(&self, data: impl Iterator<Item = f64>) -> (f64, f64) {
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        for v in self.ticks.iter().copied().chain(data) {
            if v.is_finite() && (!self.log || v > 0.0) {
                let v = self.value(v);
                lo = lo.min(v);
                hi = hi.max(v);
            }
        }
        if !(lo.is_finite() && hi.is_finite()) {
            return (0.0, 1.0);
        }
        if hi - lo < 1e-12 {
            return (lo - 0.5, hi + 0.5);
        }
        (lo, hi)
    }
}

impl Chart {
    /// Draws the chart and writes it as PNG.
    ///
    /// # Errors
    /// Encoding or file-system errors.
    pub fn save(&self, path: &Path) -> Result<()> {
        let png = self
            .draw()?
            .encode_png()
            .map_err(|e| msg(format!("encoding {}: {e}", path.display())))?;
        crate::report::write_bytes(path, &png)
    }

    fn draw(&self) -> Result<Pixmap> {
        let mut pixmap =
            Pixmap::new(WIDTH, HEIGHT_PX).ok_or_else(|| msg("chart size is not drawable"))?;
        pixmap.fill(Color::WHITE);
        let (x0, x1) = self.x.range(
            self.series
                .iter()
                .flat_map(|s| s.points.iter().map(|p| p.0)),
        );
        let (y0, y1) = self.y.range(
            self.series
                .iter()
                .flat_map(|s| s.points.iter().map(|p| p.1)),
        );
        let plot_w = WIDTH as f32 - LEFT - RIGHT;
        let plot_h = HEIGHT_PX as f32 - TOP - BOTTOM;
        let px = |v: f64| LEFT + ((self.x.value(v) - x0) / (x1 - x0)) as f32 * plot_w;
        let py = |v: f64| TOP + plot_h - ((self.y.value(v) - y0) / (y1 - y0)) as f32 * plot_h;
        let black = Color::from_rgba8(0, 0, 0, 255);
        let grey = Color::from_rgba8(225, 225, 225, 255);
        let text_h = (HEIGHT * SCALE) as f32;

        // Grid and ticks.
        for &t in &self.x.ticks {
            let x = px(t);
            line(&mut pixmap, (x, TOP), (x, TOP + plot_h), grey, 1.0, false);
            let label = tick_label(t);
            let w = text_width(&label, SCALE) as f32;
            draw_text(
                &mut pixmap,
                x - w / 2.0,
                TOP + plot_h + 10.0,
                &label,
                SCALE,
                black,
                false,
            );
        }
        for &t in &self.y.ticks {
            let y = py(t);
            line(&mut pixmap, (LEFT, y), (LEFT + plot_w, y), grey, 1.0, false);
            let label = tick_label(t);
            let w = text_width(&label, SCALE) as f32;
            draw_text(
                &mut pixmap,
                LEFT - w - 10.0,
                y - text_h / 2.0,
                &label,
                SCALE,
                black,
                false,
            );
        }
        // Frame.
        line(
            &mut pixmap,
            (LEFT, TOP),
            (LEFT, TOP + plot_h),
            black,
            2.0,
            false,
        );
        line(
            &mut pixmap,
            (LEFT, TOP + plot_h),
            (LEFT + plot_w, TOP + plot_h),
            black,
            2.0,
            false,
        );

        // Series.
        for s in &self.series {
            let color = Color::from_rgba8(s.color[0], s.color[1], s.color[2], 255);
            let pts: Vec<(f32, f32)> = s
                .points
                .iter()
                .filter(|p| p.0.is_finite() && p.1.is_finite())
                .map(|&(x, y)| (px(x), py(y)))
                .collect();
            polyline(&mut pixmap, &pts, color, 3.0, s.dashed);
            for &(x, y) in &pts {
                marker(&mut pixmap, x, y, color);
            }
        }

        // Titles.
        let title_w = text_width(&self.title, SCALE) as f32;
        draw_text(
            &mut pixmap,
            LEFT + (plot_w - title_w) / 2.0,
            20.0,
            &self.title,
            SCALE,
            black,
            false,
        );
        let xl_w = text_width(&self.x.label, SCALE) as f32;
        draw_text(
            &mut pixmap,
            LEFT + (plot_w - xl_w) / 2.0,
            HEIGHT_PX as f32 - 35.0,
            &self.x.label,
            SCALE,
            black,
            false,
        );
        let yl_w = text_width(&self.y.label, SCALE) as f32;
        draw_text(
            &mut pixmap,
            20.0,
            TOP + (plot_h + yl_w) / 2.0,
            &self.y.label,
            SCALE,
            black,
            true,
        );

        // Legend.
        let lx = LEFT + plot_w + 25.0;
        for (i, s) in self.series.iter().enumerate() {
            let y = TOP + 10.0 + i as f32 * 28.0;
            let color = Color::from_rgba8(s.color[0], s.color[1], s.color[2], 255);
            line(
                &mut pixmap,
                (lx, y + text_h / 2.0),
                (lx + 40.0, y + text_h / 2.0),
                color,
                3.0,
                s.dashed,
            );
            marker(&mut pixmap, lx + 20.0, y + text_h / 2.0, color);
            draw_text(&mut pixmap, lx + 50.0, y, &s.label, SCALE, black, false);
        }
        Ok(pixmap)
    }
}

/// Tick text: integers without decimals, others with up to two.
fn tick_label(v: f64) -> String {
    if (v - v.round()).abs() < 1e-9 {
        if v.abs() >= 1000.0 && (v / 1000.0 - (v / 1000.0).round()).abs() < 1e-9 {
            format!("{}K", (v / 1000.0).round())
        } else {
            format!("{}", v.round())
        }
    } else {
        let s = format!("{v:.2}");
        s.trim_end_matches('0').trim_end_matches('.').to_owned()
    }
}

/// Ticks 1, 2, 5 × 10^k covering `lo..=hi` (both > 0).
pub fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let mut out = Vec::new();
    if !(lo > 0.0 && hi >= lo && hi.is_finite()) {
        return out;
    }
    let mut decade = 10f64.powf(lo.log10().floor());
    while decade <= hi * 1.0001 {
        for m in [1.0, 2.0, 5.0] {
            let t = decade * m;
            if t >= lo / 1.0001 && t <= hi * 1.0001 {
                out.push(t);
            }
        }
        decade *= 10.0;
    }
    out
}

/// `lo..=hi` (both > 0) widened to the nearest 1, 2, 5 × 10^k values.
pub fn log_bounds(lo: f64, hi: f64) -> (f64, f64) {
    let steps = |v: f64| {
        let decade = 10f64.powf(v.log10().floor());
        [1.0, 2.0, 5.0, 10.0].map(|m| m * decade)
    };
    let down = steps(lo)
        .into_iter()
        .rev()
        .find(|&t| t <= lo * 1.0001)
        .unwrap_or(lo);
    let up = steps(hi)
        .into_iter()
        .find(|&t| t >= hi / 1.0001)
        .unwrap_or(hi);
    (down, up)
}

/// About six round ticks covering `0..=hi`.
pub fn linear_ticks(hi: f64) -> Vec<f64> {
    if !(hi > 0.0 && hi.is_finite()) {
        return vec![0.0, 1.0];
    }
    let raw = hi / 5.0;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 2.5, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * mag);
    let n = (hi / step).ceil() as usize;
    (0..=n).map(|k| k as f64 * step).collect()
}

fn stroke(width: f32, dashed: bool) -> Stroke {
    Stroke {
        width,
        line_cap: LineCap::Round,
        dash: if dashed {
            StrokeDash::new(vec![10.0, 7.0], 0.0)
        } else {
            None
        },
        ..Stroke::default()
    }
}

fn paint(color: Color) -> Paint<'static> {
    let mut p = Paint::default();
    p.set_color(color);
    p.anti_alias = true;
    p
}

fn line(pixmap: &mut Pixmap, a: (f32, f32), b: (f32, f32), color: Color, width: f32, dashed: bool) {
    polyline(pixmap, &[a, b], color, width, dashed);
}

fn polyline(pixmap: &mut Pixmap, pts: &[(f32, f32)], color: Color, width: f32, dashed: bool) {
    let mut pb = PathBuilder::new();
    for (i, &(x, y)) in pts.iter().enumerate() {
        if i == 0 {
            pb.move_to(x, y);
        } else {
            pb.line_to(x, y);
        }
    }
    if let Some(path) = pb.finish() {
        pixmap.stroke_path(
            &path,
            &paint(color),
            &stroke(width, dashed),
            Transform::identity(),
            None,
        );
    }
}

fn marker(pixmap: &mut Pixmap, x: f32, y: f32, color: Color) {
    if let Some(path) = PathBuilder::from_circle(x, y, 4.5) {
        pixmap.fill_path(
            &path,
            &paint(color),
            FillRule::Winding,
            Transform::identity(),
            None,
        );
    } else if let Some(rect) = Rect::from_xywh(x - 3.0, y - 3.0, 6.0, 6.0) {
        pixmap.fill_rect(rect, &paint(color), Transform::identity(), None);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks() {
        assert_eq!(
            log_ticks(0.3, 60.0),
            vec![0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0]
        );
        assert_eq!(linear_ticks(4.0), vec![0.0, 1.0, 2.0, 3.0, 4.0]);
        assert_eq!(tick_label(2000.0), "2K");
        assert_eq!(log_bounds(0.7, 13.0), (0.5, 20.0));
        assert_eq!(log_bounds(1.0, 100.0), (1.0, 100.0));
        assert_eq!(tick_label(0.25), "0.25");
        assert_eq!(tick_label(3.0), "3");
    }

    #[test]
    fn draws_a_chart() {
        let chart = Chart {
            title: "T".into(),
            x: Axis {
                label: "x".into(),
                log: true,
                ticks: vec![1.0, 10.0],
            },
            y: Axis {
                label: "y".into(),
                log: false,
                ticks: linear_ticks(2.0),
            },
            series: vec![Series {
                label: "s".into(),
                points: vec![(1.0, 0.5), (10.0, 2.0)],
                color: PALETTE[0],
                dashed: true,
            }],
        };
        assert!(chart.draw().is_ok());
    }
}
