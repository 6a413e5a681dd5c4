//! A polygon with holes in plane coordinates, with the two queries the decimation and the
//! texture ask of it many times: which edges meet a square, and where a horizontal line
//! crosses the rings (even-odd rule).

/// A polygon with holes in the plane: `rings[0]` is the shell, the others holes; open
/// rings (the last vertex is not repeated) without consecutive duplicates.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Polygon2 {
    pub rings: Vec<Vec<[f64; 2]>>,
    /// Every ring edge, ring after ring.
    pub edges: Vec<[[f64; 2]; 2]>,
    /// Bounding box `[min, max]` of the shell.
    pub bbox: [[f64; 2]; 2],
    rows: RowIndex,
}

impl Polygon2 {
    /// The polygon of `shell` and `holes`, with consecutive duplicate vertices (and a
    /// repeated first vertex) removed and holes of fewer than 3 vertices dropped. `None`
    /// when the shell keeps fewer than 3 vertices.
    pub fn new(shell: Vec<[f64; 2]>, holes: Vec<Vec<[f64; 2]>>) -> Option<Self> {
        let shell = clean(shell);
        if shell.len() < 3 {
            return None;
        }
        let mut rings = vec![shell];
        rings.extend(holes.into_iter().map(clean).filter(|h| h.len() >= 3));
        let edges: Vec<[[f64; 2]; 2]> = rings
            .iter()
            .flat_map(|r| (0..r.len()).map(move |i| [r[i], r[(i + 1) % r.len()]]))
            .collect();
        let mut bbox = [[f64::INFINITY; 2], [f64::NEG_INFINITY; 2]];
        for p in &rings[0] {
            for k in 0..2 {
                bbox[0][k] = bbox[0][k].min(p[k]);
                bbox[1][k] = bbox[1][k].max(p[k]);
            }
        }
        let rows = RowIndex::new(&edges, bbox);
        Some(Self {
            rings,
            edges,
            bbox,
            rows,
        })
    }

    /// Shell area minus hole areas (each ring's absolute area).
    pub fn area(&self) -> f64 {
        let mut rings = self.rings.iter().map(|r| ring_area(r).abs());
        let shell = rings.next().unwrap_or(0.0);
        shell - rings.sum::<f64>()
    }

    /// Number of vertices over all rings.
    pub fn num_vertices(&self) -> usize {
        self.rings.iter().map(Vec::len).sum()
    }

    /// Whether `p` is inside (even-odd rule over all rings; points on an edge may go
    /// either way). The oracle of the tests; the crate asks [`LineCrossings`].
    #[cfg(test)]
    pub fn contains(&self, p: [f64; 2]) -> bool {
        let mut inside = false;
        for &e in self.rows.edges_near(p[1]) {
            let [a, b] = self.edges[e as usize];
            if (a[1] > p[1]) != (b[1] > p[1]) {
                let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
                if x > p[0] {
                    inside = !inside;
                }
            }
        }
        inside
    }

    /// The x coordinates where the horizontal line at `y` crosses the rings, sorted:
    /// inside spans are `[xs[0], xs[1]]`, `[xs[2], xs[3]]`, …
    pub fn crossings(&self, y: f64, xs: &mut Vec<f64>) {
        xs.clear();
        for &e in self.rows.edges_near(y) {
            let [a, b] = self.edges[e as usize];
            if (a[1] > y) != (b[1] > y) {
                xs.push(a[0] + (y - a[1]) / (b[1] - a[1]) * (b[0] - a[0]));
            }
        }
        xs.sort_unstable_by(f64::total_cmp);
    }
}

/// Where the polygon's rings cross the horizontal lines `y(0), y(1), …, y(lines − 1)`,
/// computed once per line: point-in-polygon answers along those lines cost a binary search.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct LineCrossings {
    /// The crossings of line `l` are `xs[starts[l]..starts[l + 1]]`, sorted.
    starts: Vec<u32>,
    xs: Vec<f64>,
}

impl LineCrossings {
    pub fn new(polygon: &Polygon2, lines: u32, y: impl Fn(u32) -> f64) -> Self {
        let mut starts = Vec::with_capacity(lines as usize + 1);
        let mut xs = Vec::new();
        let mut line = Vec::new();
        starts.push(0);
        for l in 0..lines {
            polygon.crossings(y(l), &mut line);
            xs.extend_from_slice(&line);
            starts.push(xs.len() as u32);
        }
        Self { starts, xs }
    }

    /// Whether the point at `x` on line `l` is inside (even-odd rule): the crossings right
    /// of `x` toggle "inside", as in `Polygon2::contains`, the tests' oracle, bit for bit.
    #[inline]
    pub fn contains(&self, l: u32, x: f64) -> bool {
        let xs = &self.xs[self.starts[l as usize] as usize..self.starts[l as usize + 1] as usize];
        let right = xs.len() - xs.partition_point(|&c| c <= x);
        right % 2 == 1
    }
}

/// The signed area of a ring (positive counter-clockwise).
pub(crate) fn ring_area(ring: &[[f64; 2]]) -> f64 {
    let n = ring.len();
    let mut sum = 0.0;
    for i in 0..n {
        let (a, b) = (ring[i], ring[(i + 1) % n]);
        sum += a[0] * b[1] - b[0] * a[1];
    }
    0.5 * sum
}

fn clean(mut ring: Vec<[f64; 2]>) -> Vec<[f64; 2]> {
    ring.dedup();
    while ring.len() > 1 && ring.first() == ring.last() {
        ring.pop();
    }
    ring
}

/// Whether segment `[a, b]` meets the closed box `[lo, hi]`.
#[inline]
pub(crate) fn segment_meets_box(a: [f64; 2], b: [f64; 2], lo: [f64; 2], hi: [f64; 2]) -> bool {
    // Both ends beyond one side of the box: no contact (comparisons rather than `max` and
    // `min`, whose NaN handling costs several instructions; coordinates are finite).
    for k in 0..2 {
        if (a[k] < lo[k] && b[k] < lo[k]) || (a[k] > hi[k] && b[k] > hi[k]) {
            return false;
        }
    }
    // The box's corners on one side of the segment's line: no contact.
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let side = |x: f64, y: f64| dx * (y - a[1]) - dy * (x - a[0]);
    let s = [
        side(lo[0], lo[1]),
        side(hi[0], lo[1]),
        side(hi[0], hi[1]),
        side(lo[0], hi[1]),
    ];
    !(s.iter().all(|&v| v > 0.0) || s.iter().all(|&v| v < 0.0))
}

/// Edges bucketed by horizontal bands of the bounding box, so that a horizontal line meets
/// only the few edges of its band.
#[derive(Debug, Clone, PartialEq)]
struct RowIndex {
    y0: f64,
    inv_height: f64,
    /// `ids[starts[r]..starts[r + 1]]` are the edges reaching band `r`.
    starts: Vec<u32>,
    ids: Vec<u32>,
}

impl RowIndex {
    fn new(edges: &[[[f64; 2]; 2]], bbox: [[f64; 2]; 2]) -> Self {
        let bands = edges.len().clamp(1, 4096);
        let span = (bbox[1][1] - bbox[0][1]).max(f64::MIN_POSITIVE);
        let inv_height = bands as f64 / span;
        let band =
            // `as` truncates towards zero and saturates: below the box (and NaN) is band 0.
            |y: f64| (((y - bbox[0][1]) * inv_height) as usize).min(bands - 1);
        let mut counts = vec![0u32; bands + 1];
        for [a, b] in edges {
            for r in band(a[1].min(b[1]))..=band(a[1].max(b[1])) {
                counts[r + 1] += 1;
            }
        }
        for r in 0..bands {
            counts[r + 1] += counts[r];
        }
        let mut fill = counts.clone();
        let mut ids = vec![0u32; counts[bands] as usize];
        for (e, [a, b]) in edges.iter().enumerate() {
            for r in band(a[1].min(b[1]))..=band(a[1].max(b[1])) {
                ids[fill[r] as usize] = e as u32;
                fill[r] += 1;
            }
        }
        Self {
            y0: bbox[0][1],
            inv_height,
            starts: counts,
            ids,
        }
    }

    #[inline]
    fn edges_near(&self, y: f64) -> &[u32] {
        let bands = self.starts.len() - 1;
        let r = (y - self.y0) * self.inv_height;
        if r.is_nan() || r < 0.0 || r >= bands as f64 + 1.0 {
            return &[];
        }
        let r = (r as usize).min(bands - 1);
        &self.ids[self.starts[r] as usize..self.starts[r + 1] as usize]
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn square_with_hole() -> Polygon2 {
        Polygon2::new(
            vec![[0.0, 0.0], [4.0, 0.0], [4.0, 4.0], [0.0, 4.0], [0.0, 0.0]],
            vec![vec![[1.0, 1.0], [1.0, 2.0], [2.0, 2.0], [2.0, 1.0]]],
        )
        .unwrap()
    }

    #[test]
    fn area_and_containment() {
        let p = square_with_hole();
        assert_eq!(p.rings[0].len(), 4);
        assert_eq!(p.area(), 15.0);
        assert!(p.contains([3.0, 3.0]));
        assert!(!p.contains([1.5, 1.5]));
        assert!(!p.contains([5.0, 1.5]));
        assert!(!p.contains([1.5, -1.0]));
        let mut xs = Vec::new();
        p.crossings(1.5, &mut xs);
        assert_eq!(xs, vec![0.0, 1.0, 2.0, 4.0]);
    }

    #[test]
    fn line_crossings_answer_as_contains() {
        let p = square_with_hole();
        let y = |l: u32| -0.25 + 0.5 * f64::from(l);
        let lines = LineCrossings::new(&p, 11, y);
        for l in 0..11 {
            for k in 0..25 {
                let x = -0.6 + 0.25 * f64::from(k);
                assert_eq!(lines.contains(l, x), p.contains([x, y(l)]), "{x}, {}", y(l));
            }
        }
    }

    #[test]
    fn segment_box_contact() {
        let (lo, hi) = ([0.0, 0.0], [1.0, 1.0]);
        assert!(segment_meets_box([-1.0, 0.5], [2.0, 0.5], lo, hi));
        assert!(segment_meets_box([1.0, 1.0], [2.0, 2.0], lo, hi)); // touches a corner
        assert!(!segment_meets_box([1.5, 0.0], [3.0, 1.0], lo, hi));
        assert!(!segment_meets_box([0.0, 2.1], [2.1, 0.0], lo, hi)); // passes the corner
        assert!(segment_meets_box([0.2, 0.2], [0.3, 0.3], lo, hi)); // inside
    }

    #[test]
    fn degenerate_shell_is_none() {
        assert!(Polygon2::new(vec![[0.0, 0.0], [1.0, 0.0], [0.0, 0.0]], vec![]).is_none());
    }
}
