//! The refined icosahedron whose triangles are the cells of the Gaussian accumulator.
//!
//! Level 0 is the icosahedron with a vertex at each pole (±z); every level splits each triangle
//! into four at its edge midpoints, projected back onto the unit sphere. Level `L` has
//! `20·4^L` triangles and `10·4^L + 2` vertices.
//!
//! The vertices are laid out in the five charts of Cohen et al. that the unwrapped image uses:
//! vertex 0 is the north pole, vertex 1 the south pole, and chart `c` (0–4) owns the `2n²`
//! vertices `(s, t)` with `s` in `1..=n`, `t` in `0..2n`, `n = 2^L`. Chart `c` is the
//! parallelogram of four level-0 triangles north pole – upper ring vertex `c` – south pole –
//! lower ring vertex `c + 1`; `s` runs from the north pole towards upper vertex `c`, `t` from the
//! north pole towards upper vertex `c + 1`.
//!
//! Cells (triangles) are sorted by the [S2 cell id](crate::s2id) of their normal, so cells close
//! in the arrays are close on the sphere.

use rayon::prelude::*;

use crate::FastGaError;
use crate::s2id;

/// Cells per rayon task in the construction of an icosahedron and its search: levels up
/// to 3 (1,280 cells) run on one thread.
pub(crate) const CELLS_PER_TASK: usize = 2048;

/// The highest supported refinement level (1,310,720 cells).
pub const MAX_LEVEL: u32 = 7;

/// Sentinel in the neighbour matrix for "no neighbour" (cells next to the 12 level-0
/// vertices have 11 neighbours at level ≥ 1; level-0 cells have 9).
pub const NO_NEIGHBOR: u32 = u32::MAX;

/// Index of the north pole vertex (+z).
pub const NORTH_POLE: u32 = 0;
/// Index of the south pole vertex (−z).
pub const SOUTH_POLE: u32 = 1;

/// Number of charts of the unwrapped icosahedron.
pub(crate) const CHARTS: u32 = 5;

/// Chart coordinates at one level: `n = 2^level` lattice steps per level-0 edge.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Lattice {
    pub(crate) n: u32,
}

impl Lattice {
    pub(crate) fn new(level: u32) -> Self {
        Self { n: 1 << level }
    }

    pub(crate) fn vertex_count(self) -> usize {
        10 * (self.n as usize).pow(2) + 2
    }

    /// Index of an owned vertex: `s` in `1..=n`, `t` in `0..2n`.
    pub(crate) fn owned(self, chart: u32, s: u32, t: u32) -> u32 {
        debug_assert!((1..=self.n).contains(&s) && t < 2 * self.n);
        2 + chart * 2 * self.n * self.n + (s - 1) * 2 * self.n + t
    }

    /// Index of the vertex at chart coordinates `s` in `0..=n`, `t` in `0..=2n`, including the
    /// chart's shared border (owned by the next chart, or a pole).
    pub(crate) fn vertex(self, chart: u32, s: u32, t: u32) -> u32 {
        let n = self.n;
        let next = (chart + 1) % CHARTS;
        if s == 0 && t == 0 {
            NORTH_POLE
        } else if s == n && t == 2 * n {
            SOUTH_POLE
        } else if s == 0 {
            // The side north pole → upper vertex c+1 → lower vertex c+1 of chart c is the side
            // t = 0 followed by the first half of the side s = n of chart c+1.
            if t <= n {
                self.owned(next, t, 0)
            } else {
                self.owned(next, n, t - n)
            }
        } else if t == 2 * n {
            // The side lower vertex c+1 → south pole is the second half of side s = n of c+1.
            self.owned(next, n, n + s)
        } else {
            self.owned(chart, s, t)
        }
    }
}

/// A refined icosahedron: vertices, triangle cells sorted by S2 id, cell normals and the
/// 12-neighbour (1-ring) matrix.
#[derive(Debug, Clone)]
pub struct Icosahedron {
    level: u32,
    vertices: Vec<[f64; 3]>,
    triangles: Vec<[u32; 3]>,
    normals: Vec<[f64; 3]>,
    cell_ids: Vec<u64>,
    neighbors: Vec<[u32; 12]>,
    vertex_cell_offsets: Vec<u32>,
    vertex_cells: Vec<u32>,
}

impl Icosahedron {
    /// Builds the icosahedron refined `level` times (0 ..= [`MAX_LEVEL`]).
    ///
    /// # Errors
    /// [`FastGaError::LevelOutOfRange`] above [`MAX_LEVEL`].
    pub fn new(level: u32) -> Result<Self, FastGaError> {
        if level > MAX_LEVEL {
            return Err(FastGaError::LevelOutOfRange {
                level,
                max: MAX_LEVEL,
            });
        }
        let vertices = refined_vertices(level);
        let lattice = Lattice::new(level);
        let unsorted = lattice_triangles(lattice);

        // Per cell, in parallel where the level makes it worth it (a new detector at level
        // 5 took 16–18 ms serially); the same values in the same order on any pool.
        let unsorted_normals: Vec<[f64; 3]> = unsorted
            .par_iter()
            .with_min_len(CELLS_PER_TASK)
            .map(|t| triangle_normal(&vertices, *t))
            .collect();
        let mut order: Vec<(u64, u32)> = unsorted_normals
            .par_iter()
            .enumerate()
            .with_min_len(CELLS_PER_TASK)
            .map(|(i, n)| (s2id::cell_id(*n), i as u32))
            .collect();
        // The pairs are distinct (indices), so any sort gives the same order.
        order.par_sort_unstable();

        let triangles: Vec<[u32; 3]> = order.iter().map(|&(_, i)| unsorted[i as usize]).collect();
        let normals: Vec<[f64; 3]> = order
            .iter()
            .map(|&(_, i)| unsorted_normals[i as usize])
            .collect();
        let cell_ids: Vec<u64> = order.iter().map(|&(id, _)| id).collect();

        let (vertex_cell_offsets, vertex_cells) = incident_cells(vertices.len(), &triangles);
        let neighbors = one_ring(&triangles, &vertex_cell_offsets, &vertex_cells);
        Ok(Self {
            level,
            vertices,
            triangles,
            normals,
            cell_ids,
            neighbors,
            vertex_cell_offsets,
            vertex_cells,
        })
    }

    /// The refinement level.
    pub fn level(&self) -> u32 {
        self.level
    }

    /// Number of cells (triangles): `20·4^level`.
    pub fn cell_count(&self) -> usize {
        self.triangles.len()
    }

    /// Unit vertices: the two poles first, then the five charts (see the module docs).
    pub fn vertices(&self) -> &[[f64; 3]] {
        &self.vertices
    }

    /// Triangle cells as vertex indices, counter-clockwise seen from outside, sorted by S2 id.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// Unit normal of each cell (of its flat triangle).
    pub fn normals(&self) -> &[[f64; 3]] {
        &self.normals
    }

    /// S2 leaf-cell id of each cell normal, ascending.
    pub fn cell_ids(&self) -> &[u64] {
        &self.cell_ids
    }

    /// For each cell, the cells sharing at least one vertex with it (its 1-ring), ascending,
    /// padded with [`NO_NEIGHBOR`].
    pub fn neighbors(&self) -> &[[u32; 12]] {
        &self.neighbors
    }

    /// The cells that have vertex `v` as a corner (5 or 6).
    pub fn vertex_cells(&self, v: u32) -> &[u32] {
        let start = self.vertex_cell_offsets[v as usize] as usize;
        let end = self.vertex_cell_offsets[v as usize + 1] as usize;
        &self.vertex_cells[start..end]
    }

    /// The vertices joined to vertex `v` by an edge (5 or 6), ascending.
    pub fn vertex_neighbors(&self, v: u32) -> Vec<u32> {
        let mut out: Vec<u32> = self
            .vertex_cells(v)
            .iter()
            .flat_map(|&c| self.triangles[c as usize])
            .filter(|&w| w != v)
            .collect();
        out.sort_unstable();
        out.dedup();
        out
    }

    /// Index of the cell whose normal is closest to `p` by exhaustive search (the oracle the
    /// fast searches are tested against); ties go to the lowest index.
    pub fn nearest_cell_brute_force(&self, p: [f64; 3]) -> u32 {
        let mut best = 0;
        let mut best_dot = f64::NEG_INFINITY;
        for (i, n) in self.normals.iter().enumerate() {
            let d = dot(*n, p);
            if d > best_dot {
                best_dot = d;
                best = i as u32;
            }
        }
        best
    }
}

pub(crate) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub(crate) fn normalized(a: [f64; 3]) -> [f64; 3] {
    let len = dot(a, a).sqrt();
    [a[0] / len, a[1] / len, a[2] / len]
}

fn triangle_normal(vertices: &[[f64; 3]], t: [u32; 3]) -> [f64; 3] {
    let [a, b, c] = t.map(|v| vertices[v as usize]);
    normalized(cross(sub(b, a), sub(c, a)))
}

/// Level-0 vertices in lattice order: poles, then upper ring vertex c and lower ring vertex c
/// for each chart c (chart coordinates (1, 0) and (1, 1)).
fn base_vertices() -> Vec<[f64; 3]> {
    let z = 1.0 / 5f64.sqrt();
    let r = 2.0 / 5f64.sqrt();
    let mut out = vec![[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]];
    for c in 0..CHARTS {
        let upper = f64::from(c) * 72f64.to_radians();
        let lower = upper + 36f64.to_radians();
        out.push([r * upper.cos(), r * upper.sin(), z]);
        out.push([r * lower.cos(), r * lower.sin(), -z]);
    }
    out
}

/// Vertex positions at `level`, by repeated edge-midpoint subdivision projected to the sphere.
fn refined_vertices(level: u32) -> Vec<[f64; 3]> {
    let mut positions = base_vertices();
    for l in 1..=level {
        let coarse = Lattice::new(l - 1);
        let fine = Lattice::new(l);
        let n = fine.n;
        let mut next = vec![[0.0; 3]; fine.vertex_count()];
        next[NORTH_POLE as usize] = positions[NORTH_POLE as usize];
        next[SOUTH_POLE as usize] = positions[SOUTH_POLE as usize];
        let at = |c: u32, s: u32, t: u32| positions[coarse.vertex(c, s, t) as usize];
        for c in 0..CHARTS {
            for s in 1..=n {
                for t in 0..2 * n {
                    let p = match (s % 2, t % 2) {
                        (0, 0) => at(c, s / 2, t / 2),
                        (1, 0) => midpoint(at(c, (s - 1) / 2, t / 2), at(c, s.div_ceil(2), t / 2)),
                        (0, _) => midpoint(at(c, s / 2, (t - 1) / 2), at(c, s / 2, t.div_ceil(2))),
                        _ => midpoint(
                            at(c, (s - 1) / 2, t.div_ceil(2)),
                            at(c, s.div_ceil(2), (t - 1) / 2),
                        ),
                    };
                    next[fine.owned(c, s, t) as usize] = p;
                }
            }
        }
        positions = next;
    }
    positions
}

fn midpoint(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    normalized([a[0] + b[0], a[1] + b[1], a[2] + b[2]])
}

/// Two triangles per lattice square of each chart, split along the (s+1, t)–(s, t+1) diagonal.
fn lattice_triangles(lattice: Lattice) -> Vec<[u32; 3]> {
    let n = lattice.n;
    let mut out = Vec::with_capacity(20 * (n as usize).pow(2));
    for c in 0..CHARTS {
        for s in 0..n {
            for t in 0..2 * n {
                let v = |ds: u32, dt: u32| lattice.vertex(c, s + ds, t + dt);
                out.push([v(0, 0), v(1, 0), v(0, 1)]);
                out.push([v(1, 0), v(1, 1), v(0, 1)]);
            }
        }
    }
    out
}

/// Compressed vertex → incident cells lists.
fn incident_cells(vertex_count: usize, triangles: &[[u32; 3]]) -> (Vec<u32>, Vec<u32>) {
    let mut offsets = vec![0u32; vertex_count + 1];
    for t in triangles {
        for &v in t {
            offsets[v as usize + 1] += 1;
        }
    }
    for i in 0..vertex_count {
        offsets[i + 1] += offsets[i];
    }
    let mut fill = offsets.clone();
    let mut cells = vec![0u32; offsets[vertex_count] as usize];
    for (i, t) in triangles.iter().enumerate() {
        for &v in t {
            cells[fill[v as usize] as usize] = i as u32;
            fill[v as usize] += 1;
        }
    }
    (offsets, cells)
}

fn one_ring(triangles: &[[u32; 3]], offsets: &[u32], cells: &[u32]) -> Vec<[u32; 12]> {
    triangles
        .par_iter()
        .enumerate()
        .with_min_len(CELLS_PER_TASK)
        .map(|(i, t)| {
            // At most six cells meet at a vertex: 18 incident cells, the cell itself
            // three times among them.
            let mut ring = [NO_NEIGHBOR; 18];
            let mut len = 0;
            for &v in t {
                for &c in &cells[offsets[v as usize] as usize..offsets[v as usize + 1] as usize] {
                    if c != i as u32 && len < ring.len() {
                        ring[len] = c;
                        len += 1;
                    }
                }
            }
            let ring = &mut ring[..len];
            ring.sort_unstable();
            let mut row = [NO_NEIGHBOR; 12];
            let mut kept = 0;
            for (k, &c) in ring.iter().enumerate() {
                if (k == 0 || c != ring[k - 1]) && kept < row.len() {
                    row[kept] = c;
                    kept += 1;
                }
            }
            row
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_follow_table_1() {
        for level in 0..=5 {
            let ico = Icosahedron::new(level).unwrap();
            let n4 = 4usize.pow(level);
            assert_eq!(ico.cell_count(), 20 * n4);
            assert_eq!(ico.vertices().len(), 10 * n4 + 2);
        }
        assert!(matches!(
            Icosahedron::new(8),
            Err(FastGaError::LevelOutOfRange { level: 8, max: 7 })
        ));
    }

    #[test]
    fn mesh_is_a_closed_outward_sphere() {
        for level in 0..=4 {
            let ico = Icosahedron::new(level).unwrap();
            for v in ico.vertices() {
                assert!((dot(*v, *v) - 1.0).abs() < 1e-12);
            }
            let mut edges = std::collections::HashMap::new();
            for (t, n) in ico.triangles().iter().zip(ico.normals()) {
                let c = t.map(|v| ico.vertices()[v as usize]);
                let centroid = [
                    c[0][0] + c[1][0] + c[2][0],
                    c[0][1] + c[1][1] + c[2][1],
                    c[0][2] + c[1][2] + c[2][2],
                ];
                assert!(dot(*n, centroid) > 0.0, "inward triangle {t:?}");
                for k in 0..3 {
                    *edges.entry((t[k], t[(k + 1) % 3])).or_insert(0) += 1;
                }
            }
            // Every directed edge once and its twin once: a closed, consistently oriented mesh.
            for (&(a, b), &count) in &edges {
                assert_eq!(count, 1);
                assert_eq!(edges.get(&(b, a)), Some(&1));
            }
            // Euler characteristic of the sphere.
            let (v, e, f) = (ico.vertices().len(), edges.len() / 2, ico.cell_count());
            assert_eq!(v + f - e, 2);
        }
    }

    #[test]
    fn neighbor_matrix_has_sentinels_only_at_level_0_vertices() {
        for level in 0..=4 {
            let ico = Icosahedron::new(level).unwrap();
            let mut eleven = 0;
            for (i, row) in ico.neighbors().iter().enumerate() {
                let count = row.iter().filter(|&&c| c != NO_NEIGHBOR).count();
                assert!(row[..count].windows(2).all(|w| w[0] < w[1]));
                assert!(row[count..].iter().all(|&c| c == NO_NEIGHBOR));
                assert!(!row[..count].contains(&(i as u32)));
                match (level, count) {
                    (0, 9) | (_, 12) => {}
                    (_, 11) => eleven += 1,
                    _ => panic!("cell {i} at level {level} has {count} neighbours"),
                }
                for &c in &row[..count] {
                    assert!(ico.neighbors()[c as usize].contains(&(i as u32)));
                }
            }
            if level > 0 {
                assert_eq!(eleven, 60);
            }
        }
    }

    #[test]
    fn neighbor_matrix_lists_exactly_the_cells_sharing_a_vertex() {
        for level in 0..=2 {
            let ico = Icosahedron::new(level).unwrap();
            let tris = ico.triangles();
            for (i, row) in ico.neighbors().iter().enumerate() {
                let brute: Vec<u32> = (0..tris.len() as u32)
                    .filter(|&c| {
                        c != i as u32 && tris[c as usize].iter().any(|v| tris[i].contains(v))
                    })
                    .collect();
                let listed: Vec<u32> = row.iter().copied().filter(|&c| c != NO_NEIGHBOR).collect();
                assert_eq!(listed, brute, "level {level} cell {i}");
            }
        }
    }

    #[test]
    fn cells_are_sorted_by_s2_id() {
        let ico = Icosahedron::new(3).unwrap();
        assert!(ico.cell_ids().windows(2).all(|w| w[0] < w[1]));
        for (id, n) in ico.cell_ids().iter().zip(ico.normals()) {
            assert_eq!(*id, s2id::cell_id(*n));
        }
    }
}
