//! Right-cut half-edge meshing of organized point clouds (Polylidar3D §4.2, Alg. 1–2).
//!
//! Two passes over the cell rows, both parallel with rayon:
//!
//! 1. classify every cell: which of its two triangles have three valid vertices and a
//!    well-defined normal (one byte per cell), and count them per row;
//! 2. after a prefix sum over the row counts (the first mesh triangle of every row), write
//!    each row's triangles, twins, normals and map entries into its own disjoint slice of
//!    the outputs. Twins come from the neighbouring cells' classes and running counts in
//!    the rows above and below: no lookups, no hashing. New output storage is pre-filled
//!    in parallel (see [`sized`]) so that page faults do not serialise the work; storage
//!    handed back from an earlier mesh is written over.
//!
//! Every output element depends only on the input, so the result is identical at any
//! thread count.

use halfedge_mesh::{NO_TWIN, cross_normal};
use rayon::prelude::*;

use crate::triangle_map::{NO_TRIANGLE, TriangleMap};
use crate::{OpcError, OpcMeshOptions, OrganizedPointCloudView, is_valid};

/// Storage for the mesh arrays: empty vectors for a new mesh, or the arrays of an earlier
/// mesh to write over.
#[derive(Default)]
pub(crate) struct Buffers {
    /// Where to copy the points, or `None` when the caller moves them into the mesh.
    pub(crate) vertices: Option<Vec<[f64; 3]>>,
    pub(crate) triangles: Vec<[u32; 3]>,
    pub(crate) halfedges: Vec<[u32; 3]>,
    pub(crate) normals: Vec<[f64; 3]>,
    pub(crate) map: Vec<[u32; 2]>,
}

/// The mesh arrays and the triangle map, before assembly.
pub(crate) struct Parts {
    /// The copied points, or empty when they are moved.
    pub(crate) vertices: Vec<[f64; 3]>,
    pub(crate) triangles: Vec<[u32; 3]>,
    pub(crate) halfedges: Vec<u32>,
    pub(crate) normals: Vec<[f64; 3]>,
    pub(crate) triangle_map: TriangleMap,
}

/// Class bit: the cell's first (upper-right) triangle exists.
const FIRST: u8 = 1;
/// Class bit: the cell's second (lower-left) triangle exists.
const SECOND: u8 = 2;

/// Triangles in a cell of this class (0, 1 or 2).
#[inline]
fn count(class: u8) -> u32 {
    u32::from(class & FIRST) + u32::from(class >> 1)
}

/// The unnormalised normal of triangle `[a, b, c]` and whether it can be normalised.
#[inline]
fn normal_of(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> ([f64; 3], f64) {
    let n = cross_normal(a, b, c);
    (n, n[0] * n[0] + n[1] * n[1] + n[2] * n[2])
}

/// Whether a squared normal length gives a finite unit normal.
#[inline]
fn normalisable(len2: f64) -> bool {
    (f64::MIN_POSITIVE..f64::INFINITY).contains(&len2)
}

/// Pass 1 for one cell row: classes of its cells, and their triangle count. Branch-free,
/// so that it vectorises where the CPU allows.
#[multiversion::multiversion(targets("x86_64+avx512f+avx512vl+avx512bw+avx512dq", "x86_64+avx2"))]
fn classify_row(top: &[[f64; 3]], bottom: &[[f64; 3]], classes: &mut [u8]) -> u32 {
    let n = classes.len();
    let (top, bottom) = (&top[..n + 1], &bottom[..n + 1]);
    let mut total = 0;
    for v in 0..n {
        let (p1, p2, p3, p4) = (top[v], top[v + 1], bottom[v + 1], bottom[v]);
        let diagonal = is_valid(&p1) & is_valid(&p3);
        let first = diagonal & is_valid(&p2) & normalisable(normal_of(p3, p2, p1).1);
        let second = diagonal & is_valid(&p4) & normalisable(normal_of(p1, p4, p3).1);
        classes[v] = (u8::from(first) * FIRST) | (u8::from(second) * SECOND);
        total += u32::from(first) + u32::from(second);
    }
    total
}

/// One cell row's share of the outputs, for pass 2.
struct RowOut<'a> {
    row: usize,
    /// Global index of the row's first triangle.
    first: u32,
    triangles: &'a mut [[u32; 3]],
    /// The twins of each triangle's three half-edges.
    halfedges: &'a mut [[u32; 3]],
    /// Empty unless normals are computed.
    normals: &'a mut [[f64; 3]],
    /// The row's map entries, two per cell.
    map: &'a mut [[u32; 2]],
}

/// Everything pass 2 reads.
struct Pass2<'a> {
    points: &'a [[f64; 3]],
    cols: usize,
    cell_rows: usize,
    classes: &'a [u8],
    /// First triangle of every cell row, and the total at the end.
    offsets: &'a [u32],
}

impl Pass2<'_> {
    fn classes_of(&self, row: usize) -> &[u8] {
        let cell_cols = self.cols - 1;
        &self.classes[row * cell_cols..][..cell_cols]
    }

    /// A neighbouring cell row's classes and first triangle, or none past the border.
    fn neighbour(&self, row: Option<usize>) -> (Option<&[u8]>, u32) {
        match row.filter(|&r| r < self.cell_rows) {
            Some(r) => (Some(self.classes_of(r)), self.offsets[r]),
            None => (None, 0),
        }
    }

    /// Writes the `map.len()` dense cells of cell row `u` from `at` on (see
    /// [`dense_run`]): what [`Self::write_row`] writes for them, without its branches.
    fn write_dense(
        &self,
        u: usize,
        at: Dense,
        triangles: &mut [[u32; 3]],
        halfedges: &mut [[u32; 3]],
        normals: &mut [[f64; 3]],
        map: &mut [[u32; 2]],
    ) {
        let (points, cols) = (self.points, self.cols);
        let p = (u * cols + at.cell) as u32;
        let cells = triangles
            .as_chunks_mut::<2>()
            .0
            .iter_mut()
            .zip(halfedges.as_chunks_mut::<2>().0)
            .zip(map.iter_mut());
        for (k, ((tris, twins), map)) in cells.enumerate() {
            let k = k as u32;
            let (p1, t) = (p + k, at.first + 2 * k);
            let (p2, p4) = (p1 + 1, p1 + cols as u32);
            let p3 = p4 + 1;
            *tris = [[p3, p2, p1], [p1, p4, p3]];
            // As in `write_row`, with the cells to the right, above and below dense; the
            // left twin of the run's first cell (the cell before it need not be dense) is
            // set after the loop.
            *twins = [
                [3 * (t + 3), 3 * (at.above + 2 * k + 1) + 1, 3 * (t + 1) + 2],
                [
                    3u32.wrapping_mul(t.wrapping_sub(2)),
                    3 * (at.below + 2 * k) + 1,
                    3 * t + 2,
                ],
            ];
            *map = [t, t + 1];
        }
        halfedges[1][0] = at.left;
        if !normals.is_empty() {
            let top = &points[u * cols + at.cell..];
            let bottom = &points[(u + 1) * cols + at.cell..];
            for (k, pair) in normals.as_chunks_mut::<2>().0.iter_mut().enumerate() {
                *pair = [
                    unit(normal_of(bottom[k + 1], top[k + 1], top[k])),
                    unit(normal_of(top[k], bottom[k], bottom[k + 1])),
                ];
            }
        }
    }

    /// Writes one cell row's triangles, twins, normals, map entries and vertices.
    fn write_row(&self, out: RowOut<'_>) {
        let RowOut {
            row: u,
            first,
            triangles,
            halfedges,
            normals,
            map,
        } = out;
        let cols = self.cols;
        let top = &self.points[u * cols..][..cols];
        let bottom = &self.points[(u + 1) * cols..][..cols];
        let classes = self.classes_of(u);
        let (above, mut next_above) = self.neighbour(u.checked_sub(1));
        let (below, mut next_below) = self.neighbour(Some(u + 1));
        let with_normals = !normals.is_empty();
        let row_start = (u * cols) as u32;
        let mut next = first;
        let mut left_first = NO_TWIN;
        let mut local = 0;
        let mut v = 0;
        while v < classes.len() {
            if let (Some(above), Some(below)) = (above, below) {
                let run = dense_run(classes, above, below, v);
                if run > 0 {
                    let at = Dense {
                        cell: v,
                        first: next,
                        above: next_above,
                        below: next_below,
                        left: left_first,
                    };
                    let end = local + 2 * run;
                    self.write_dense(
                        u,
                        at,
                        &mut triangles[local..end],
                        &mut halfedges[local..end],
                        normals.get_mut(local..end).unwrap_or_default(),
                        &mut map[v..v + run],
                    );
                    let step = 2 * run as u32;
                    left_first = 3 * (next + step - 2);
                    (next, next_above, next_below) =
                        (next + step, next_above + step, next_below + step);
                    (local, v) = (end, v + run);
                }
            }
            // A run stops before the row's last cell (a dense cell needs the one to its
            // right), so cell `v` is still in the row.
            let (class, map) = (classes[v], &mut map[v]);
            let class_above = above.map_or(0, |a| a[v]);
            let class_below = below.map_or(0, |b| b[v]);
            let class_right = classes.get(v + 1).copied().unwrap_or(0);
            let after = next + count(class);
            let p1 = row_start + v as u32;
            let p4 = p1 + cols as u32;
            let (p2, p3) = (p1 + 1, p4 + 1);
            let first_t = next;
            *map = [NO_TRIANGLE; 2];
            if class & FIRST != 0 {
                triangles[local] = [p3, p2, p1];
                let he = &mut halfedges[local];
                // Edge p3 → p2: the second triangle of the cell to the right.
                he[0] = if class_right & SECOND != 0 {
                    3 * (after + u32::from(class_right & FIRST))
                } else {
                    NO_TWIN
                };
                // Edge p2 → p1: the second triangle of the cell above.
                he[1] = if class_above & SECOND != 0 {
                    3 * (next_above + u32::from(class_above & FIRST)) + 1
                } else {
                    NO_TWIN
                };
                // Diagonal p1 → p3: this cell's second triangle.
                he[2] = if class & SECOND != 0 {
                    3 * (first_t + 1) + 2
                } else {
                    NO_TWIN
                };
                if with_normals {
                    normals[local] = unit(normal_of(bottom[v + 1], top[v + 1], top[v]));
                }
                map[0] = first_t;
                local += 1;
            }
            if class & SECOND != 0 {
                let second_t = first_t + u32::from(class & FIRST);
                triangles[local] = [p1, p4, p3];
                let he = &mut halfedges[local];
                // Edge p1 → p4: the first triangle of the cell to the left.
                he[0] = left_first;
                // Edge p4 → p3: the first triangle of the cell below.
                he[1] = if class_below & FIRST != 0 {
                    3 * next_below + 1
                } else {
                    NO_TWIN
                };
                // Diagonal p3 → p1: this cell's first triangle.
                he[2] = if class & FIRST != 0 {
                    3 * first_t + 2
                } else {
                    NO_TWIN
                };
                if with_normals {
                    normals[local] = unit(normal_of(top[v], bottom[v], bottom[v + 1]));
                }
                map[1] = second_t;
                local += 1;
            }
            left_first = if class & FIRST != 0 {
                3 * first_t
            } else {
                NO_TWIN
            };
            next = after;
            next_above += count(class_above);
            next_below += count(class_below);
            v += 1;
        }
        debug_assert_eq!(local, triangles.len());
    }
}

/// Where a run of dense cells starts: its first cell, its first triangle, the first
/// triangles of the cells above and below it, and the twin of its first cell's
/// left edge.
#[derive(Clone, Copy)]
struct Dense {
    cell: usize,
    first: u32,
    above: u32,
    below: u32,
    left: u32,
}

/// How many cells from `v` on are dense: the cell, the cells above and below it and the
/// cell to its right all hold both triangles. Inside such a run every triangle, twin and
/// map entry is an affine function of the cell (see [`Pass2::write_dense`]); a depth
/// frame is mostly such runs.
#[inline]
fn dense_run(classes: &[u8], above: &[u8], below: &[u8], v: usize) -> usize {
    const BOTH: u8 = FIRST | SECOND;
    (v..classes.len() - 1)
        .take_while(|&c| {
            (classes[c] == BOTH)
                & (classes[c + 1] == BOTH)
                & (above[c] == BOTH)
                & (below[c] == BOTH)
        })
        .count()
}

/// The unit normal of a normalisable cross product.
#[inline]
fn unit((n, len2): ([f64; 3], f64)) -> [f64; 3] {
    let inv = 1.0 / len2.sqrt();
    [n[0] * inv, n[1] * inv, n[2] * inv]
}

/// Checks that the half-edges of a `rows × cols` grid fit `u32` indices below [`NO_TWIN`].
fn check_mesh_size(rows: usize, cols: usize) -> Result<(), OpcError> {
    let halfedges = (rows - 1)
        .checked_mul(cols - 1)
        .and_then(|cells| cells.checked_mul(6));
    match halfedges {
        Some(h) if h <= NO_TWIN as usize => Ok(()),
        _ => Err(OpcError::TooLarge { rows, cols }),
    }
}

/// Meshes a cloud: pass 1, prefix sum, pass 2.
pub(crate) fn mesh_grid(
    view: OrganizedPointCloudView<'_>,
    buffers: Buffers,
    options: &OpcMeshOptions,
) -> Result<Parts, OpcError> {
    let (rows, cols) = (view.rows(), view.cols());
    check_mesh_size(rows, cols)?;
    let points = view.points();
    let (cell_rows, cell_cols) = (rows - 1, cols - 1);

    let mut classes = vec![0u8; cell_rows * cell_cols];
    let classify = |(u, classes): (usize, &mut [u8])| {
        classify_row(
            &points[u * cols..][..cols],
            &points[(u + 1) * cols..][..cols],
            classes,
        )
    };
    let counts: Vec<u32> = if options.parallel {
        classes
            .par_chunks_mut(cell_cols)
            .enumerate()
            .map(classify)
            .collect()
    } else {
        classes
            .chunks_mut(cell_cols)
            .enumerate()
            .map(classify)
            .collect()
    };
    let mut offsets = Vec::with_capacity(cell_rows + 1);
    let mut total = 0u32;
    offsets.push(total);
    for &n in &counts {
        total += n;
        offsets.push(total);
    }
    if total == 0 {
        return Err(OpcError::NoTriangles {
            valid_points: view.num_valid(),
            points: points.len(),
        });
    }

    let num_triangles = total as usize;
    let parallel = options.parallel;
    let n_normals = if options.compute_normals {
        num_triangles
    } else {
        0
    };
    let mut triangles = sized(buffers.triangles, num_triangles, parallel);
    let mut halfedges = sized(buffers.halfedges, num_triangles, parallel);
    let mut normals = sized(buffers.normals, n_normals, parallel);
    let mut map = sized(buffers.map, cell_rows * cell_cols, parallel);

    let mut jobs = Vec::with_capacity(cell_rows);
    let (mut t_rest, mut h_rest) = (triangles.as_mut_slice(), halfedges.as_mut_slice());
    let (mut n_rest, mut m_rest) = (normals.as_mut_slice(), map.as_mut_slice());
    for (u, &n) in counts.iter().enumerate() {
        let n = n as usize;
        let n_normals = if options.compute_normals { n } else { 0 };
        let triangles;
        let halfedges;
        let normals;
        let map;
        (triangles, t_rest) = std::mem::take(&mut t_rest).split_at_mut(n);
        (halfedges, h_rest) = std::mem::take(&mut h_rest).split_at_mut(n);
        (normals, n_rest) = std::mem::take(&mut n_rest).split_at_mut(n_normals);
        (map, m_rest) = std::mem::take(&mut m_rest).split_at_mut(cell_cols);
        jobs.push(RowOut {
            row: u,
            first: offsets[u],
            triangles,
            halfedges,
            normals,
            map,
        });
    }

    let pass2 = Pass2 {
        points,
        cols,
        cell_rows,
        classes: &classes,
        offsets: &offsets,
    };
    if options.parallel {
        jobs.into_par_iter().for_each(|job| pass2.write_row(job));
    } else {
        jobs.into_iter().for_each(|job| pass2.write_row(job));
    }

    Ok(Parts {
        vertices: buffers
            .vertices
            .map_or_else(Vec::new, |into| copy_points(into, points, parallel)),
        triangles,
        halfedges: flatten(halfedges),
        normals,
        triangle_map: TriangleMap::from_vec(cell_rows, cell_cols, flatten(map)),
    })
}

/// `items` cut or grown to `n` elements; the kept ones are left as they are (pass 2
/// overwrites every element). In parallel, rayon writes the new elements from several
/// threads, so that the first touch of every new page (the kernel's page fault and zeroing)
/// is spread over the threads too, where `vec!` would do it all on this one.
fn sized<T: Copy + Default + Send + Sync>(mut items: Vec<T>, n: usize, parallel: bool) -> Vec<T> {
    items.truncate(n);
    if parallel {
        let missing = n - items.len();
        items.par_extend(rayon::iter::repeat_n(T::default(), missing));
    } else {
        items.resize(n, T::default());
    }
    items
}

/// Elements per parallel copy job.
const COPY_CHUNK: usize = 1 << 14;

/// The points copied into `into` (an empty vector or an earlier mesh's vertices).
fn copy_points(mut into: Vec<[f64; 3]>, points: &[[f64; 3]], parallel: bool) -> Vec<[f64; 3]> {
    match (into.is_empty(), parallel) {
        (true, true) => points.par_iter().copied().collect(),
        (true, false) => points.to_vec(),
        (false, _) => {
            into.truncate(points.len());
            let kept = into.len();
            into.extend_from_slice(&points[kept..]);
            if parallel {
                into[..kept]
                    .par_chunks_mut(COPY_CHUNK)
                    .zip(points[..kept].par_chunks(COPY_CHUNK))
                    .for_each(|(to, from)| to.copy_from_slice(from));
            } else {
                into[..kept].copy_from_slice(&points[..kept]);
            }
            into
        }
    }
}

/// The inverse of [`flatten`]: flat `u32`s back as `[u32; N]` items, reusing the allocation
/// where its capacity allows, or an empty vector.
pub(crate) fn unflatten<const N: usize>(flat: Vec<u32>) -> Vec<[u32; N]>
where
    [u32; N]: bytemuck::AnyBitPattern,
{
    bytemuck::allocation::try_cast_vec(flat).unwrap_or_default()
}

/// `[u32; N]` items as a flat vector, reusing the allocation.
fn flatten<const N: usize>(items: Vec<[u32; N]>) -> Vec<u32>
where
    [u32; N]: bytemuck::NoUninit,
{
    bytemuck::allocation::try_cast_vec(items)
        .unwrap_or_else(|(_, items)| items.into_iter().flatten().collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mesh_size_limit() {
        // 6 (rows − 1)(cols − 1) half-edges must stay at or below u32::MAX.
        assert_eq!(check_mesh_size(2, 715_827_883), Ok(()));
        assert_eq!(
            check_mesh_size(2, 715_827_884),
            Err(OpcError::TooLarge {
                rows: 2,
                cols: 715_827_884
            })
        );
        assert_eq!(check_mesh_size(20_000, 30_000), Ok(()));
        assert!(check_mesh_size(40_000, 40_000).is_err());
        assert!(check_mesh_size(usize::MAX, usize::MAX).is_err());
    }

    #[test]
    fn buffer_helpers() {
        assert_eq!(flatten(vec![[1, 2, 3], [4, 5, 6]]), vec![1, 2, 3, 4, 5, 6]);
        let mut odd = Vec::with_capacity(3);
        odd.push([7u32, 8]);
        assert_eq!(flatten(odd), vec![7, 8]);
        assert_eq!(
            unflatten::<3>(vec![1, 2, 3, 4, 5, 6]),
            vec![[1, 2, 3], [4, 5, 6]]
        );
        assert_eq!(unflatten::<3>(vec![1, 2]), Vec::<[u32; 3]>::new());
        for parallel in [false, true] {
            assert_eq!(sized::<[u32; 2]>(Vec::new(), 5, parallel), vec![[0, 0]; 5]);
            assert_eq!(sized(vec![1u8, 2, 3], 2, parallel), vec![1, 2]);
            assert_eq!(sized(vec![1u8, 2], 4, parallel), vec![1, 2, 0, 0]);
            let points = [[1.0, 2.0, 3.0], [4.0, 5.0, 6.0], [7.0, 8.0, 9.0]];
            assert_eq!(copy_points(Vec::new(), &points, parallel), points);
            assert_eq!(copy_points(vec![[0.0; 3]], &points, parallel), points);
            assert_eq!(copy_points(vec![[0.0; 3]; 5], &points, parallel), points);
        }
    }

    #[test]
    fn classes_and_counts() {
        let p = |x: f64, y: f64| [x, y, 1.0];
        let nan = [f64::NAN; 3];
        let top = [p(0.0, 0.0), p(1.0, 0.0), nan, p(3.0, 0.0)];
        let bottom = [p(0.0, 1.0), p(1.0, 1.0), p(2.0, 1.0), p(3.0, 1.0)];
        let mut classes = [0u8; 3];
        assert_eq!(classify_row(&top, &bottom, &mut classes), 3);
        // Cell 1: top-right pixel invalid, so only the second triangle; cell 2: top-left
        // invalid, so neither.
        assert_eq!(classes, [FIRST | SECOND, SECOND, 0]);
    }
}
