//! The bilateral normal filter on the implicit right-cut mesh, `f32` planes per triangle
//! type, a band of cell rows per task.

use opc_mesh::{OpcMesh, OrganizedPointCloud};
use rayon::prelude::*;

use super::{
    Band, Offsets, PlaneSet, Planes, Ring, exp2_nonpositive, fma, min_rows_per_task, row_in_blocks,
    span, term_at,
};
use crate::grid::{Gather, SLOT_CHUNK, TRIANGLES_PER_CELL, UNIT_BLOCK, in_slot_order, widen_units};
use crate::{BilateralOptions, SlotNormals, SmoothError};

/// x, y, z planes, indexed by cell `r · (cols − 1) + c`.
type Xyz<'a> = [&'a [f32]; 3];

/// Planes per triangle type in [`PassWork::types`]: normal x, y, z, centroid x, y, z
/// and the mask.
const TYPE_PLANES: usize = 7;

/// What the filter reads of the triangles of one type `k` (see [`crate::grid`]), indexed
/// by cell: their centroids and masks (1.0 where the triangle exists). Missing
/// triangles hold zeros and mask 0.0.
#[derive(Clone, Copy)]
struct TypeView<'a> {
    centroid: Xyz<'a>,
    mask: &'a [f32],
}

/// Reusable buffers of the bilateral filter: the cloud's point planes and the rest.
#[derive(Default)]
pub(crate) struct BilateralWork {
    planes: Planes,
    pub(crate) passes: PassWork,
}

/// The bilateral filter's buffers after the point planes, each plane at its own offset
/// modulo 4 KiB (the kernels stream through up to 13 of them at once).
#[derive(Default)]
pub(crate) struct PassWork {
    /// Per triangle type `k`, its [`TYPE_PLANES`] planes from plane `7k` on.
    types: PlaneSet<{ 2 * TYPE_PLANES }>,
    /// The filtered normals (type 0 x, y, z, then type 1) of the odd passes and the even
    /// ones; the first pass reads the normals in `types`.
    odd: PlaneSet<6, { 2 * TYPE_PLANES }>,
    even: PlaneSet<6, { 2 * TYPE_PLANES + 6 }>,
}

/// Six planes as the x, y, z planes of the two triangle types.
fn by_type([a, b, c, d, e, f]: [&[f32]; 6]) -> [Xyz<'_>; 2] {
    [[a, b, c], [d, e, f]]
}

/// The filtered normals of both triangle types and their masks, indexed by cell.
pub(crate) struct Filtered<'a> {
    normals: [Xyz<'a>; 2],
    masks: [&'a [f32]; 2],
    /// Cell columns.
    cols: usize,
    parallel: bool,
}

impl Filtered<'_> {
    /// The normal in `slot`, `None` where its triangle is missing.
    #[inline]
    fn get(&self, slot: usize) -> Option<[f32; 3]> {
        let (cell, k) = (slot / TRIANGLES_PER_CELL, slot % TRIANGLES_PER_CELL);
        let [x, y, z] = self.normals[k];
        (self.masks[k][cell] > 0.0).then(|| [x[cell], y[cell], z[cell]])
    }

    /// One normal per slot into `out` (resized), `[NaN; 3]` where the triangle is missing.
    pub(crate) fn write_slots(&self, out: &mut Vec<[f32; 3]>) {
        let cells = self.masks[0].len();
        out.resize(TRIANGLES_PER_CELL * cells, [0.0; 3]);
        out.par_chunks_mut(TRIANGLES_PER_CELL * self.cols)
            .enumerate()
            .with_min_len(min_rows_per_task(self.parallel))
            .for_each(|(r, out)| {
                let first = r * out.len();
                for (i, slot) in out.iter_mut().enumerate() {
                    *slot = self.get(first + i).unwrap_or([f32::NAN; 3]);
                }
            });
    }

    /// The unit `f64` normals of the triangles of a mesh built from the same cloud, given
    /// its slot → triangle map, when the map is in slot order as `opc_mesh` builds it
    /// (see [`crate::grid::in_slot_order`]); `None` otherwise.
    fn in_slot_order(
        &self,
        triangle_map: &[u32],
        num_triangles: usize,
        buffer: Vec<[f64; 3]>,
    ) -> Option<Vec<[f64; 3]>> {
        let slots = TRIANGLES_PER_CELL * self.masks[0].len();
        if triangle_map.len() != slots {
            return None;
        }
        let units = || [[[0.0; UNIT_BLOCK]; 3]; 2];
        let gather = |units: &mut _, chunk: usize, map: &[u32], gather: &mut Gather<'_>| {
            // Chunks hold whole cells (an even number of slots).
            let start = chunk * SLOT_CHUNK / TRIANGLES_PER_CELL;
            let cells = start..start + map.len() / TRIANGLES_PER_CELL;
            let normals = self.normals.map(|p| p.map(|q| &q[cells.clone()]));
            let masks = self.masks.map(|m| &m[cells.clone()]);
            gather_cells(normals, masks, map, units, gather);
        };
        in_slot_order(
            triangle_map,
            num_triangles,
            buffer,
            SLOT_CHUNK,
            units,
            gather,
        )
    }
}

/// Computes normals and centroids and filters the normals. Options are validated.
pub(crate) fn bilateral<'a>(
    work: &'a mut BilateralWork,
    cloud: &OrganizedPointCloud,
    options: &BilateralOptions,
    parallel: bool,
) -> Filtered<'a> {
    let (passes, points) = fill_points(work, cloud, parallel);
    bilateral_of_planes(
        passes,
        points,
        cloud.rows(),
        cloud.cols(),
        options,
        parallel,
    )
}

/// `work`'s point planes filled from `cloud` (see [`Planes`]), and its pass buffers.
fn fill_points<'w>(
    work: &'w mut BilateralWork,
    cloud: &OrganizedPointCloud,
    parallel: bool,
) -> (&'w mut PassWork, [&'w [f32]; 4]) {
    let BilateralWork { planes, passes } = work;
    planes.fill(cloud.points(), cloud.cols(), parallel);
    let points = [&planes.x, &planes.y, &planes.z, &planes.m].map(Vec::as_slice);
    (passes, points)
}

/// [`bilateral`] with the filtered normals set as `opc`'s triangle normals (`opc` built
/// from the same cloud; see [`bilateral_of_planes_into_mesh`]).
pub(crate) fn bilateral_into_mesh(
    work: &mut BilateralWork,
    cloud: &OrganizedPointCloud,
    options: &BilateralOptions,
    parallel: bool,
    opc: &mut OpcMesh,
) -> Result<(), SmoothError> {
    let (rows, cols) = (cloud.rows(), cloud.cols());
    let (passes, points) = fill_points(work, cloud, parallel);
    bilateral_of_planes_into_mesh(passes, points, rows, cols, options, parallel, opc)
}

/// [`bilateral`] of a `rows × cols` cloud given as its `f32` point planes x, y, z and
/// mask (see [`Planes`]).
fn bilateral_of_planes<'a>(
    work: &'a mut PassWork,
    points: [&[f32]; 4],
    rows: usize,
    cols: usize,
    options: &BilateralOptions,
    parallel: bool,
) -> Filtered<'a> {
    let mut passes = Passes::new(work, points, rows, cols, options, parallel);
    for pass in 0..passes.iterations {
        passes.run(pass);
    }
    passes.into_filtered()
}

/// [`bilateral_of_planes`] with the filtered normals set as the triangle normals of
/// `opc`, a mesh of the same cloud. When its map is in slot order, as `opc_mesh` builds
/// it (see [`crate::grid::in_slot_order`]), the last pass hands each row it writes
/// straight to the gather into mesh order, while the row is in cache, instead of writing
/// planes for a separate pass to read.
pub(crate) fn bilateral_of_planes_into_mesh(
    work: &mut PassWork,
    points: [&[f32]; 4],
    rows: usize,
    cols: usize,
    options: &BilateralOptions,
    parallel: bool,
    opc: &mut OpcMesh,
) -> Result<(), SmoothError> {
    let mut passes = Passes::new(work, points, rows, cols, options, parallel);
    if let Some(last) = passes.iterations.checked_sub(1) {
        for pass in 0..last {
            passes.run(pass);
        }
        let spare = crate::grid::spare_normals(opc);
        let (map, triangles) = (&opc.triangle_map, opc.mesh.num_triangles());
        if let Some(normals) = passes.last_in_slot_order(last, map.as_slice(), triangles, spare) {
            return crate::grid::set_mesh_normals(opc, normals);
        }
        // Not in slot order: the gather of the planes, whose checks read the same map and
        // masks, would refuse it too.
        passes.run(last);
        return through_slots(&passes.into_filtered(), rows, cols, opc);
    }
    let filtered = passes.into_filtered();
    let spare = crate::grid::spare_normals(opc);
    let map = opc.triangle_map.as_slice();
    match filtered.in_slot_order(map, opc.mesh.num_triangles(), spare) {
        Some(normals) => crate::grid::set_mesh_normals(opc, normals),
        None => through_slots(&filtered, rows, cols, opc),
    }
}

/// Sets `filtered` as the triangle normals of `opc` through per-slot normals and the
/// map's checks ([`SlotNormals::apply_to_opc_mesh`]), which name what is wrong with a
/// map that is not in slot order.
fn through_slots(
    filtered: &Filtered<'_>,
    rows: usize,
    cols: usize,
    opc: &mut OpcMesh,
) -> Result<(), SmoothError> {
    let mut slots = SlotNormals::default();
    slots.refill(rows, cols, |n| filtered.write_slots(n));
    slots.apply_to_opc_mesh(opc)
}

/// The passes of one run of the filter: the triangle types computed, and the planes
/// the passes write.
struct Passes<'a> {
    filter: Filter,
    /// Passes to run: none where the kernel does not fit in the grid.
    iterations: u32,
    unfiltered: [Xyz<'a>; 2],
    views: [TypeView<'a>; 2],
    odd: &'a mut PlaneSet<6, { 2 * TYPE_PLANES }>,
    even: &'a mut PlaneSet<6, { 2 * TYPE_PLANES + 6 }>,
    /// Cells per band (see [`BAND_ROWS`]).
    band: usize,
    parallel: bool,
}

impl<'a> Passes<'a> {
    /// Computes the triangle types of a `rows × cols` cloud given as its point planes
    /// (see [`bilateral_of_planes`]) into `work`, whose pass planes it sizes.
    fn new(
        work: &'a mut PassWork,
        points: [&[f32]; 4],
        rows: usize,
        cols: usize,
        options: &BilateralOptions,
        parallel: bool,
    ) -> Self {
        let PassWork { types, odd, even } = work;
        let cells = Cells {
            rows: rows - 1,
            cols: cols - 1,
            half: (options.kernel / 2) as usize,
        };
        let num_cells = cells.rows * cells.cols;
        types.resize(num_cells);
        compute_types(points, cols, parallel, types.planes_mut());
        let type_planes = types.planes();
        let type_view = |k: usize| {
            let p = &type_planes[TYPE_PLANES * k..TYPE_PLANES * (k + 1)];
            let normal = [p[0], p[1], p[2]];
            let view = TypeView {
                centroid: [p[3], p[4], p[5]],
                mask: p[6],
            };
            (normal, view)
        };
        let [(normal0, view0), (normal1, view1)] = [type_view(0), type_view(1)];
        let fits = cells.rows > 2 * cells.half && cells.cols > 2 * cells.half;
        let iterations = if fits { options.iterations } else { 0 };
        if iterations > 0 {
            odd.resize(num_cells);
            even.resize(num_cells);
        }
        let (inv_var_length, inv_var_angle) = options.inverse_variances();
        Self {
            filter: Filter::new(cells, inv_var_length, inv_var_angle),
            iterations,
            unfiltered: [normal0, normal1],
            views: [view0, view1],
            odd,
            even,
            band: if parallel { BAND_ROWS } else { cells.rows } * cells.cols,
            parallel,
        }
    }

    /// The normals `pass` filters: the unfiltered ones for the first, else those the pass
    /// before wrote ([`Self::into_filtered`] gives those of the last pass).
    fn input(&self, pass: u32) -> [Xyz<'_>; 2] {
        match pass {
            0 => self.unfiltered,
            _ if pass % 2 == 1 => by_type(self.odd.planes()),
            _ => by_type(self.even.planes()),
        }
    }

    /// Runs `pass` (counted from 0, in order) into its planes, a band of rows per task.
    fn run(&mut self, pass: u32) {
        let Self {
            filter,
            unfiltered,
            views,
            odd,
            even,
            band,
            parallel,
            ..
        } = self;
        let (band, parallel) = (*band, *parallel);
        let (previous, next) = match pass {
            0 => (*unfiltered, odd.planes_mut()),
            _ if pass % 2 == 1 => (by_type(odd.planes()), even.planes_mut()),
            _ => (by_type(even.planes()), odd.planes_mut()),
        };
        let cols = filter.cells.cols;
        let [n0x, n0y, n0z, n1x, n1y, n1z] = next;
        (
            n0x.par_chunks_mut(band),
            n0y.par_chunks_mut(band),
            n0z.par_chunks_mut(band),
            n1x.par_chunks_mut(band),
            n1y.par_chunks_mut(band),
            n1z.par_chunks_mut(band),
        )
            .into_par_iter()
            .enumerate()
            .with_min_len(min_rows_per_task(parallel))
            .for_each_init(
                || filter.ring(),
                |ring, (b, (a, b2, c, d, e, f))| {
                    let first = b * band / cols;
                    let part = ring.band(first, first + a.len() / cols, filter.offsets.above());
                    rows_of_band(
                        filter,
                        part,
                        &previous,
                        views,
                        &mut ring.values,
                        [[a, b2, c], [d, e, f]],
                    );
                },
            );
    }

    /// Runs the last pass, `pass`, handing each row, as it is written into a row of
    /// scratch, to the gather of [`Filtered::in_slot_order`]: that output without the
    /// planes. `None` (and nothing written) where that gives `None`.
    fn last_in_slot_order(
        &self,
        pass: u32,
        triangle_map: &[u32],
        num_triangles: usize,
        buffer: Vec<[f64; 3]>,
    ) -> Option<Vec<[f64; 3]>> {
        let cols = self.filter.cells.cols;
        if triangle_map.len() != TRIANGLES_PER_CELL * self.filter.cells.rows * cols {
            return None;
        }
        let previous = self.input(pass);
        let init = || {
            let row = || [(); 3].map(|()| vec![0.0f32; cols]);
            (
                self.filter.ring(),
                [row(), row()],
                [[[0.0; UNIT_BLOCK]; 3]; 2],
            )
        };
        let chunk = TRIANGLES_PER_CELL * self.band;
        in_slot_order(
            triangle_map,
            num_triangles,
            buffer,
            chunk,
            init,
            |(ring, row, units), b, map, gather| {
                let first = b * self.band / cols;
                for (i, map) in map.chunks(TRIANGLES_PER_CELL * cols).enumerate() {
                    let r = first + i;
                    let part = ring.band(r, r + 1, self.filter.offsets.above());
                    let out = row.each_mut().map(|p| p.each_mut().map(Vec::as_mut_slice));
                    rows_of_band(
                        &self.filter,
                        part,
                        &previous,
                        &self.views,
                        &mut ring.values,
                        out,
                    );
                    let cells = r * cols..(r + 1) * cols;
                    let normals = row.each_ref().map(|p| p.each_ref().map(Vec::as_slice));
                    let masks = self.views.map(|v| &v.mask[cells.clone()]);
                    gather_cells(normals, masks, map, units, gather);
                }
            },
        )
    }

    /// The filtered normals after all passes have run.
    fn into_filtered(self) -> Filtered<'a> {
        let Self {
            filter,
            iterations,
            unfiltered,
            views,
            odd,
            even,
            parallel,
            ..
        } = self;
        let normals = match iterations {
            0 => unfiltered,
            n if n % 2 == 1 => by_type(odd.planes()),
            _ => by_type(even.planes()),
        };
        Filtered {
            normals,
            masks: [views[0].mask, views[1].mask],
            cols: filter.cells.cols,
            parallel,
        }
    }
}

/// Hands [`Gather::slot`] both triangles of each of a run of cells, in slot order: their
/// unit `f64` normals, widened a block at a time into `units` ([`widen_units`]) from the
/// cells' normal planes `normals`, whether they are present (`masks`) and their map
/// entries (`map`, two per cell).
#[inline(always)]
fn gather_cells(
    normals: [Xyz<'_>; 2],
    masks: [&[f32]; 2],
    map: &[u32],
    units: &mut [[[f64; UNIT_BLOCK]; 3]; 2],
    gather: &mut Gather<'_>,
) {
    for (b, map) in map.chunks(TRIANGLES_PER_CELL * UNIT_BLOCK).enumerate() {
        let block = b * UNIT_BLOCK..b * UNIT_BLOCK + map.len() / TRIANGLES_PER_CELL;
        for (k, units) in units.iter_mut().enumerate() {
            widen_units(normals[k].map(|p| &p[block.clone()]), units);
        }
        let [m0, m1] = masks.map(|m| &m[block.clone()]);
        let [[x0, y0, z0], [x1, y1, z1]] = &*units;
        for (run, map) in map.chunks(TRIANGLES_PER_CELL * DENSE_RUN).enumerate() {
            let cells = run * DENSE_RUN..run * DENSE_RUN + map.len() / TRIANGLES_PER_CELL;
            let present = cells
                .clone()
                .fold(true, |all, c| all & (m0[c] > 0.0) & (m1[c] > 0.0));
            let cell = |i: usize| {
                let c = cells.start + i;
                [[x0[c], y0[c], z0[c]], [x1[c], y1[c], z1[c]]]
            };
            if gather.dense_cells(map, present, cell) {
                continue;
            }
            for (c, pair) in cells.zip(map.chunks_exact(TRIANGLES_PER_CELL)) {
                gather.slot([x0[c], y0[c], z0[c]], m0[c] > 0.0, pair[0]);
                gather.slot([x1[c], y1[c], z1[c]], m1[c] > 0.0, pair[1]);
            }
        }
    }
}

/// Cells per run that [`gather_cells`] writes at once where it can
/// ([`Gather::dense_cells`]).
const DENSE_RUN: usize = 16;

/// Normals, centroids and masks of the triangles of both types of every cell of a cloud
/// with `cols` columns whose points are the planes `points`, into `[nx, ny, nz, cx, cy,
/// cz, mask]` of type 0, then of type 1; both types of a cell row in one task, which reads
/// its two rows of points once.
fn compute_types(
    points: [&[f32]; 4],
    cols: usize,
    parallel: bool,
    planes: [&mut [f32]; 2 * TYPE_PLANES],
) {
    let cc = cols - 1;
    let [
        nx0,
        ny0,
        nz0,
        cx0,
        cy0,
        cz0,
        m0,
        nx1,
        ny1,
        nz1,
        cx1,
        cy1,
        cz1,
        m1,
    ] = planes.map(|p| p.par_chunks_mut(cc));
    let type0 = (nx0, ny0, nz0, cx0, cy0, cz0, m0);
    let type1 = (nx1, ny1, nz1, cx1, cy1, cz1, m1);
    (type0, type1)
        .into_par_iter()
        .enumerate()
        .with_min_len(min_rows_per_task(parallel))
        .for_each(|(r, rows)| {
            let top = r * cols;
            let bottom = top + cols;
            let corner = |start| points.map(|p| span(p, start, cc));
            let ((nx0, ny0, nz0, cx0, cy0, cz0, m0), (nx1, ny1, nz1, cx1, cy1, cz1, m1)) = rows;
            // p1 = (r, c), p2 = (r, c + 1), p3 = (r + 1, c + 1), p4 = (r + 1, c);
            // type 0 is [p3, p2, p1], type 1 is [p1, p4, p3].
            type_row(
                [bottom + 1, top + 1, top].map(corner),
                [nx0, ny0, nz0],
                [cx0, cy0, cz0],
                m0,
            );
            type_row(
                [top, bottom, bottom + 1].map(corner),
                [nx1, ny1, nz1],
                [cx1, cy1, cz1],
                m1,
            );
        });
}

/// One cell row of one triangle type: from the x, y, z, mask spans of its corners
/// `[a, b, c]`, the unit normals `(b − a) × (c − a)` (zero when missing or degenerate),
/// the centroids (zero when missing) and the mask. Vectorised; the arithmetic is the
/// same on every target (no fused multiply-add), so results do not depend on the CPU.
#[multiversion::multiversion(targets("x86_64+avx512f+avx512vl+avx512bw+avx512dq", "x86_64+avx2"))]
fn type_row(
    [a, b, q]: [[&[f32]; 4]; 3],
    [nx, ny, nz]: [&mut [f32]; 3],
    [cx, cy, cz]: [&mut [f32]; 3],
    m: &mut [f32],
) {
    let len = m.len();
    let [ax, ay, az, am] = a.map(|p| &p[..len]);
    let [bx, by, bz, bm] = b.map(|p| &p[..len]);
    let [qx, qy, qz, qm] = q.map(|p| &p[..len]);
    let (nx, ny, nz) = (&mut nx[..len], &mut ny[..len], &mut nz[..len]);
    let (cx, cy, cz) = (&mut cx[..len], &mut cy[..len], &mut cz[..len]);
    for i in 0..len {
        let valid = am[i] * bm[i] * qm[i] > 0.0;
        let (ux, uy, uz) = (bx[i] - ax[i], by[i] - ay[i], bz[i] - az[i]);
        let (vx, vy, vz) = (qx[i] - ax[i], qy[i] - ay[i], qz[i] - az[i]);
        let px = uy * vz - uz * vy;
        let py = uz * vx - ux * vz;
        let pz = ux * vy - uy * vx;
        let len = (px * px + py * py + pz * pz).sqrt();
        let unit = valid && len > 0.0;
        nx[i] = if unit { px / len } else { 0.0 };
        ny[i] = if unit { py / len } else { 0.0 };
        nz[i] = if unit { pz / len } else { 0.0 };
        cx[i] = if valid {
            (ax[i] + bx[i] + qx[i]) / 3.0
        } else {
            0.0
        };
        cy[i] = if valid {
            (ay[i] + by[i] + qy[i]) / 3.0
        } else {
            0.0
        };
        cz[i] = if valid {
            (az[i] + bz[i] + qz[i]) / 3.0
        } else {
            0.0
        };
        m[i] = if valid { 1.0 } else { 0.0 };
    }
}

/// The cell grid and the kernel half-width.
#[derive(Clone, Copy)]
struct Cells {
    rows: usize,
    cols: usize,
    half: usize,
}

struct Filter {
    cells: Cells,
    /// The inverse variances of length and of the normals' distance in powers of two:
    /// `log2 e / σ²`; the second doubled (see [`Filter::weight`]).
    length_log2: f32,
    two_angle_log2: f32,
    /// The kernel's cell offsets.
    offsets: Offsets,
}

impl Filter {
    fn new(cells: Cells, inv_var_length: f32, inv_var_angle: f32) -> Self {
        let log2_e = std::f32::consts::LOG2_E;
        Self {
            cells,
            length_log2: inv_var_length * log2_e,
            two_angle_log2: 2.0 * inv_var_angle * log2_e,
            offsets: Offsets::new(cells.half),
        }
    }

    /// Room for the pair weights of the ring's cell rows, at least `half + 1` (none without
    /// sharing).
    fn ring(&self) -> Ring {
        let per_row = self.offsets.forward.len() * TRIANGLES_PER_CELL * TRIANGLES_PER_CELL;
        self.offsets.ring(per_row * self.cells.cols)
    }

    /// The weight of a pair of triangles from their centroids' difference `e` and their
    /// normals `n`, `m`, in fused multiply-adds (see [`fma`]): `exp(−|e|²/σl² −
    /// |n − m|²/σa²)` as a power of two. For unit normals the squared difference
    /// `|n − m|²` is `2 − 2 n · m`: one dot product instead of three differences. A
    /// missing triangle's zero normal gets a wrong weight that way, but harmlessly: its
    /// own sum is never used (it keeps its normal) and its zero normal adds nothing to its
    /// neighbours' sums. The same bits whichever triangle comes first. `ROUNDS`: see
    /// [`exp2_nonpositive`].
    #[inline(always)]
    fn weight<const ROUNDS: bool>(
        &self,
        [ex, ey, ez]: [f32; 3],
        [nx, ny, nz]: [f32; 3],
        [mx, my, mz]: [f32; 3],
    ) -> f32 {
        let length = fma(ez, ez, fma(ey, ey, ex * ex));
        let dot = fma(nz, mz, fma(ny, my, nx * mx));
        exp2_nonpositive::<ROUNDS>(fma(
            dot,
            self.two_angle_log2,
            fma(length, -self.length_log2, -self.two_angle_log2),
        ))
    }

    /// Where, in the ring, the weights between the type-`k1` triangles of cell row `r`
    /// and the type-`k2` ones at forward offset `pair` from them start.
    #[inline(always)]
    fn ring_row(&self, r: usize, pair: usize, k1: usize, k2: usize) -> usize {
        let slot = self.offsets.ring_slot(r) * self.offsets.forward.len() + pair;
        ((slot * TRIANGLES_PER_CELL + k1) * TRIANGLES_PER_CELL + k2) * self.cells.cols
    }
}

/// Cell rows per band of the parallel backend; a task takes two bands at least. A task's
/// first band first computes the pair weights of the `half` rows above it (see
/// [`Ring`]); results do not depend on it. Bands of 8 rows rather than 16 took the filter
/// at 424 × 240 from 2.16–2.27 to 2.08–2.17 ms on 2 threads, at 640 × 480 (ICL) from
/// 1.84–1.92 to 1.72–1.78.
const BAND_ROWS: usize = 8;

/// Writes the cell rows of `band` from its first on (both triangle types) into `out`,
/// which holds those rows, after the pair weights of the rows from its start on.
///
/// The weight of a pair of triangles depends on their centroids' and normals'
/// distances only, so it is the same seen from either: it is computed once, row by row,
/// for the offsets that point forward (later in raster order), into a ring of the last
/// `half + 1` rows. A triangle then finds its forward weights in its own row and its
/// backward ones in the rows above. That halves the exponentials. The sums run over the
/// neighbours in raster order as the filter's definition does, so the results are the
/// bits of the direct computation ([`direct_row`], which kernels too large for the
/// ring use).
#[multiversion::multiversion(targets(
    "x86_64+avx512f+avx512vl+avx512bw+avx512dq+fma",
    "x86_64+avx2+fma"
))]
fn rows_of_band(
    filter: &Filter,
    band: Band,
    normals: &[Xyz<'_>; 2],
    types: &[TypeView<'_>; 2],
    ring: &mut [f32],
    mut out: [[&mut [f32]; 3]; 2],
) {
    let Cells { rows, cols, half } = filter.cells;
    let Band { start, first } = band;
    let last = first + out[0][0].len() / cols;
    let shared = filter.offsets.shares_pairs();
    // 32 vector registers of 16 lanes (AVX-512) or 16 of 8 (AVX2), fixed in each compiled
    // copy: see [`pair_weights`] and [`BLOCK`].
    const WIDE: bool = multiversion::target::target_cfg_f!(target_feature = "avx512f");
    const CELLS: usize = if WIDE { WIDE_BLOCK } else { BLOCK };
    // Rounding in one instruction (see [`exp2_nonpositive`]); the copies name AVX2 or
    // AVX-512, not the SSE4.1 they imply.
    const ROUNDS: bool = multiversion::target::target_cfg_f!(any(
        target_feature = "sse4.1",
        target_feature = "avx2",
        target_feature = "avx512f"
    )) || cfg!(target_arch = "aarch64");
    for r in start..last {
        // Rows within `half` of the bottom are nobody's backward neighbours.
        if shared && r + half < rows {
            pair_weights::<{ !WIDE }, ROUNDS>(filter, r, normals, types, ring);
        }
        if r >= first {
            let at = (r - first) * cols..(r - first + 1) * cols;
            let row_out = out
                .each_mut()
                .map(|planes| planes.each_mut().map(|plane| &mut plane[at.clone()]));
            if shared {
                // Terms of a triangle's sum: the 8, 24 or 48 neighbour cells of kernel
                // 3, 5 or 7, two triangles each.
                // (Called, not taken as a function pointer: only inlined into this
                // function does it get its target features.)
                match half {
                    1 => output_row::<16, CELLS>(filter, r, normals, types, ring, row_out),
                    2 => output_row::<48, CELLS>(filter, r, normals, types, ring, row_out),
                    _ => output_row::<96, CELLS>(filter, r, normals, types, ring, row_out),
                }
            } else {
                direct_row::<ROUNDS>(filter, r, normals, types, row_out);
            }
        }
    }
}

/// The weights between cell row `r`'s triangles and those at each forward offset, for
/// every pair of types, into the ring; pairs reaching past the grid are skipped.
///
/// Where registers allow (`SEPARATE` false: AVX-512) the four pairs of types of one
/// offset share one pass over the row, which reads each triangle's normal and centroid
/// once instead of twice. That pass walks 28 planes, more pointers than x86-64 has
/// general-purpose registers; with AVX2 (`SEPARATE` true) its loop reloaded them from
/// the stack, and a pass per pair of types (13 planes: [`type_pair_weights`]) took the
/// bilateral stage of a 424 × 240 frame from 6.15 to 5.38 ms on one thread (AMD EPYC,
/// AVX2, three alternated runs). The weights are the same bits either way. Both passes
/// run a row in whole vector blocks and end it with one more block that overlaps the one
/// before ([`block_runs`]), not with the last cells one at a time.
#[inline(always)]
fn pair_weights<const SEPARATE: bool, const ROUNDS: bool>(
    filter: &Filter,
    r: usize,
    normals: &[Xyz<'_>; 2],
    types: &[TypeView<'_>; 2],
    ring: &mut [f32],
) {
    let Cells { rows, cols, .. } = filter.cells;
    for (pair, &(dr, dc)) in filter.offsets.forward.iter().enumerate() {
        if r + dr >= rows {
            continue;
        }
        // Cells c with c + dc inside the row.
        let lo = dc.min(0).unsigned_abs();
        let hi = cols - dc.max(0) as usize;
        let len = hi - lo;
        let p = r * cols + lo;
        let q = ((r + dr) * cols + lo).wrapping_add_signed(dc);
        // Per type: centroid x, y, z and normal x, y, z from `at`.
        let side = |at: usize| {
            [0, 1].map(|k| {
                let [cx, cy, cz] = types[k].centroid.each_ref().map(|c| span(c, at, len));
                let [nx, ny, nz] = normals[k].each_ref().map(|n| span(n, at, len));
                [cx, cy, cz, nx, ny, nz]
            })
        };
        // The ring rows of the pairs (k1, k2) = (0, 0), (0, 1), (1, 0), (1, 1) follow
        // each other `cols` apart.
        let start = filter.ring_row(r, pair, 0, 0) + lo;
        let rows4 = &mut ring[start..start + 3 * cols + len];
        let (w00, rest) = rows4.split_at_mut(cols);
        let (w01, rest) = rest.split_at_mut(cols);
        let (w10, w11) = rest.split_at_mut(cols);
        let (w00, w01) = (&mut w00[..len], &mut w01[..len]);
        let (w10, w11) = (&mut w10[..len], &mut w11[..len]);
        let (own, other) = (side(p), side(q));
        if SEPARATE {
            type_pair_weights::<ROUNDS>(filter, own[0], other[0], w00);
            type_pair_weights::<ROUNDS>(filter, own[0], other[1], w01);
            type_pair_weights::<ROUNDS>(filter, own[1], other[0], w10);
            type_pair_weights::<ROUNDS>(filter, own[1], other[1], w11);
            continue;
        }
        for (from, n) in block_runs(len, WIDE_LANES) {
            let run = from..from + n;
            let w = [
                &mut w00[run.clone()],
                &mut w01[run.clone()],
                &mut w10[run.clone()],
                &mut w11[run],
            ];
            four_pair_run::<ROUNDS>(filter, own, other, from, w);
        }
    }
}

/// The weights of [`pair_weights`]' pass over all four pairs of types, for the cells
/// `start..start + w[0].len()`: `own` and `other` are the centroid x, y, z and normal x,
/// y, z planes of both types of the row's cells and of their neighbours at the pass's
/// offset, `w` the run's part of the ring rows of the pairs (0, 0), (0, 1), (1, 0),
/// (1, 1). In blocks of [`WIDE_LANES`] ([`block_runs`]): in the AVX-512 copy, a block of
/// 16 cells is 154 instructions and a cell left to the scalar loop about 230, so the up
/// to 15 cells that ended each row were about a quarter of the pass's instructions at
/// 424 × 240.
#[inline(always)]
fn four_pair_run<const ROUNDS: bool>(
    filter: &Filter,
    own: [[&[f32]; 6]; 2],
    other: [[&[f32]; 6]; 2],
    start: usize,
    [w00, w01, w10, w11]: [&mut [f32]; 4],
) {
    let at = start..start + w00.len();
    let [
        [pc0x, pc0y, pc0z, pn0x, pn0y, pn0z],
        [pc1x, pc1y, pc1z, pn1x, pn1y, pn1z],
    ] = own;
    let [
        [qc0x, qc0y, qc0z, qn0x, qn0y, qn0z],
        [qc1x, qc1y, qc1z, qn1x, qn1y, qn1z],
    ] = other;
    // Sliced one by one, as in [`type_pair_run`]: mapped over the arrays, the slicing ran
    // out of line, four calls a run.
    let (pc0x, pc0y, pc0z) = (&pc0x[at.clone()], &pc0y[at.clone()], &pc0z[at.clone()]);
    let (pn0x, pn0y, pn0z) = (&pn0x[at.clone()], &pn0y[at.clone()], &pn0z[at.clone()]);
    let (pc1x, pc1y, pc1z) = (&pc1x[at.clone()], &pc1y[at.clone()], &pc1z[at.clone()]);
    let (pn1x, pn1y, pn1z) = (&pn1x[at.clone()], &pn1y[at.clone()], &pn1z[at.clone()]);
    let (qc0x, qc0y, qc0z) = (&qc0x[at.clone()], &qc0y[at.clone()], &qc0z[at.clone()]);
    let (qn0x, qn0y, qn0z) = (&qn0x[at.clone()], &qn0y[at.clone()], &qn0z[at.clone()]);
    let (qc1x, qc1y, qc1z) = (&qc1x[at.clone()], &qc1y[at.clone()], &qc1z[at.clone()]);
    let (qn1x, qn1y, qn1z) = (&qn1x[at.clone()], &qn1y[at.clone()], &qn1z[at]);
    let (w01, w10, w11) = (
        &mut w01[..w00.len()],
        &mut w10[..w00.len()],
        &mut w11[..w00.len()],
    );
    for i in 0..w00.len() {
        let own = [
            [pc0x[i], pc0y[i], pc0z[i], pn0x[i], pn0y[i], pn0z[i]],
            [pc1x[i], pc1y[i], pc1z[i], pn1x[i], pn1y[i], pn1z[i]],
        ];
        let other = [
            [qc0x[i], qc0y[i], qc0z[i], qn0x[i], qn0y[i], qn0z[i]],
            [qc1x[i], qc1y[i], qc1z[i], qn1x[i], qn1y[i], qn1z[i]],
        ];
        let weight = |a: [f32; 6], b: [f32; 6]| {
            filter.weight::<ROUNDS>(
                [a[0] - b[0], a[1] - b[1], a[2] - b[2]],
                [a[3], a[4], a[5]],
                [b[3], b[4], b[5]],
            )
        };
        w00[i] = weight(own[0], other[0]);
        w01[i] = weight(own[0], other[1]);
        w10[i] = weight(own[1], other[0]);
        w11[i] = weight(own[1], other[1]);
    }
}

/// Into `w`, the weights between the triangles `a` and `b`, each given as its centroid
/// x, y, z and normal x, y, z planes from the first of `w.len()` cells on (see
/// [`pair_weights`]), in blocks of [`LANES`] ([`block_runs`]): ending the row with one
/// overlapping block instead of up to 7 cells one at a time took the bilateral stage of a
/// 424 × 240 frame from 5.20–5.43 to 4.98–5.17 ms on one thread (AMD EPYC, AVX2,
/// alternated runs).
#[inline(always)]
fn type_pair_weights<const ROUNDS: bool>(
    filter: &Filter,
    a: [&[f32]; 6],
    b: [&[f32]; 6],
    w: &mut [f32],
) {
    for (from, n) in block_runs(w.len(), LANES) {
        type_pair_run::<ROUNDS>(filter, a, b, from, &mut w[from..from + n]);
    }
}

/// `f32` lanes of AVX2: the blocks of [`type_pair_weights`].
const LANES: usize = 8;

/// `f32` lanes of AVX-512: the blocks of the pass of [`pair_weights`] over all four pairs
/// of types.
const WIDE_LANES: usize = 16;

/// The two runs `(first cell, cells)` that cover a row of `len` cells in blocks of
/// `lanes`: its whole blocks, then one block of its last `lanes` cells, which overlaps the
/// one before (empty where the whole blocks cover the row; a row shorter than a block is
/// that second run alone). A loop over the second run computes the weights of the overlap
/// again, to the same bits (each depends on its own cell only), instead of ending in up
/// to `lanes − 1` cells one at a time. The sums of [`output_row`] end their rows by the
/// same rule ([`row_in_blocks`], which calls a block of fixed width where these runs are
/// loops the compiler vectorises).
#[inline(always)]
fn block_runs(len: usize, lanes: usize) -> [(usize, usize); 2] {
    let whole = len - len % lanes;
    let last = if whole < len {
        len.saturating_sub(lanes)
    } else {
        len
    };
    [(0, whole), (last, len - last)]
}

/// [`type_pair_weights`] of the cells `start..start + w.len()`.
#[inline(always)]
fn type_pair_run<const ROUNDS: bool>(
    filter: &Filter,
    a: [&[f32]; 6],
    b: [&[f32]; 6],
    start: usize,
    w: &mut [f32],
) {
    let at = start..start + w.len();
    let [ax, ay, az, anx, any, anz] = a;
    let [bx, by, bz, bnx, bny, bnz] = b;
    // Sliced one by one: a closure mapped over the arrays can stay out of line, without
    // the kernel's target features.
    let (ax, ay, az) = (&ax[at.clone()], &ay[at.clone()], &az[at.clone()]);
    let (anx, any, anz) = (&anx[at.clone()], &any[at.clone()], &anz[at.clone()]);
    let (bx, by, bz) = (&bx[at.clone()], &by[at.clone()], &bz[at.clone()]);
    let (bnx, bny, bnz) = (&bnx[at.clone()], &bny[at.clone()], &bnz[at]);
    for i in 0..w.len() {
        w[i] = filter.weight::<ROUNDS>(
            [ax[i] - bx[i], ay[i] - by[i], az[i] - bz[i]],
            [anx[i], any[i], anz[i]],
            [bnx[i], bny[i], bnz[i]],
        );
    }
}

/// Cells whose sums one block of [`output_row`] keeps in registers across all terms: the
/// row is read once per term, the sums not at all. Six sums a cell: 16 cells take 12 of
/// AVX2's 16 vector registers (32 cells, 24 of them, spilled to the stack: the filter
/// took 1.3–1.5 % longer at 424 × 240, one thread, AMD EPYC; 8 cells, 40 % longer).
const BLOCK: usize = 16;

/// [`BLOCK`] with AVX-512: 32 cells take 12 of its 32 vector registers.
const WIDE_BLOCK: usize = 32;

/// Writes cell row `r` of the next pass (both triangle types) into `out`; the ring
/// holds the pair weights of rows `r − half ..= r`.
///
/// A missing triangle's normal is zero (as [`compute_types`] makes it and
/// [`unit_or_own`] keeps it), so its terms add exact zeros without a mask; the terms are
/// added in the order of [`direct_row`]. Both triangle types of a cell have the same
/// neighbours, so each neighbour's normal is read once for both sums. The sums of
/// `CELLS` cells ([`BLOCK`] or [`WIDE_BLOCK`]) at a time stay in registers while every
/// term is added to them and while they are normalised ([`normalized`]: normalising the
/// written row afterwards, as [`direct_row`] does, took the filter 4 % longer at
/// 424 × 240).
#[inline(always)]
fn output_row<const TERMS: usize, const CELLS: usize>(
    filter: &Filter,
    r: usize,
    normals: &[Xyz<'_>; 2],
    types: &[TypeView<'_>; 2],
    ring: &[f32],
    mut out: [[&mut [f32]; 3]; 2],
) {
    let Some(own) = copy_borders(filter.cells, r, normals, &mut out) else {
        return;
    };
    let Cells { cols, half, .. } = filter.cells;
    let len = cols - 2 * half;
    // Per term (neighbour cell, then its triangle type kn, in raster order): the weights
    // of the type-0 and type-1 triangles with the neighbour and the neighbour's normal
    // x, y, z.
    // Filled in a loop: `std::array::from_fn` ran out of line, a call per term.
    let mut terms: [[&[f32]; 5]; TERMS] = [[&[]; 5]; TERMS];
    for (t, term) in terms.iter_mut().enumerate() {
        let (nb, kn) = (
            &filter.offsets.neighbours[t / TRIANGLES_PER_CELL],
            t % TRIANGLES_PER_CELL,
        );
        let w = |ko: usize| {
            let start = if nb.forward {
                filter.ring_row(r, nb.pair, ko, kn) + half
            } else {
                let row = r.wrapping_add_signed(nb.dr);
                (filter.ring_row(row, nb.pair, kn, ko) + half).wrapping_add_signed(nb.dc)
            };
            span(ring, start, len)
        };
        let q = own.wrapping_add_signed(nb.dr * cols as isize + nb.dc);
        let [x, y, z] = normals[kn].each_ref().map(|n| span(n, q, len));
        *term = [w(0), w(1), x, y, z];
    }
    let mut sums = {
        let [[a0x, a0y, a0z], [a1x, a1y, a1z]] = out
            .each_mut()
            .map(|planes| planes.each_mut().map(|o| &mut o[half..half + len]));
        [a0x, a0y, a0z, a1x, a1y, a1z]
    };
    row_in_blocks(
        len,
        &mut sums,
        #[inline(always)]
        |at| {
            normalized(
                term_sums::<CELLS, TERMS>(&terms, at),
                own + at,
                normals,
                types,
            )
        },
        #[inline(always)]
        |i| normalized(term_sums::<1, TERMS>(&terms, i), own + i, normals, types),
    );
}

/// The sums of the `N` cells from `at` on of the terms, each term given as the weights of
/// the cells' type-0 and type-1 triangles with a neighbour and that neighbour's normal
/// x, y, z: the weighted normals of type 0 (x, y, z), then of type 1. They stay in
/// registers across the terms.
#[inline(always)]
fn term_sums<const N: usize, const TERMS: usize>(
    terms: &[[&[f32]; 5]; TERMS],
    at: usize,
) -> [[f32; N]; 6] {
    let mut acc = [[0.0f32; N]; 6];
    for term in terms {
        let [w0, w1, qx, qy, qz] = term_at::<N>(term, at);
        for i in 0..N {
            acc[0][i] = fma(w0[i], qx[i], acc[0][i]);
            acc[1][i] = fma(w0[i], qy[i], acc[1][i]);
            acc[2][i] = fma(w0[i], qz[i], acc[2][i]);
            acc[3][i] = fma(w1[i], qx[i], acc[3][i]);
            acc[4][i] = fma(w1[i], qy[i], acc[4][i]);
            acc[5][i] = fma(w1[i], qz[i], acc[5][i]);
        }
    }
    acc
}

/// [`output_row`] with each weight computed where it is used: the filter's definition,
/// for kernels too large to share weights.
#[inline(always)]
fn direct_row<const ROUNDS: bool>(
    filter: &Filter,
    r: usize,
    normals: &[Xyz<'_>; 2],
    types: &[TypeView<'_>; 2],
    mut out: [[&mut [f32]; 3]; 2],
) {
    let Some(own) = copy_borders(filter.cells, r, normals, &mut out) else {
        return;
    };
    let Cells { cols, half, .. } = filter.cells;
    let len = cols - 2 * half;
    for (ko, planes) in out.iter_mut().enumerate() {
        let [ax, ay, az] = planes.each_mut().map(|o| &mut o[half..half + len]);
        ax.fill(0.0);
        ay.fill(0.0);
        az.fill(0.0);
        let [nx, ny, nz] = normals[ko].each_ref().map(|n| &n[own..own + len]);
        let [cx, cy, cz] = types[ko].centroid.each_ref().map(|c| &c[own..own + len]);
        for nb in &filter.offsets.neighbours {
            let q = own.wrapping_add_signed(nb.dr * cols as isize + nb.dc);
            for kn in 0..TRIANGLES_PER_CELL {
                let [qnx, qny, qnz] = normals[kn].each_ref().map(|n| &n[q..q + len]);
                let [qcx, qcy, qcz] = types[kn].centroid.each_ref().map(|c| &c[q..q + len]);
                let qm = &types[kn].mask[q..q + len];
                for i in 0..len {
                    let w = qm[i]
                        * filter.weight::<ROUNDS>(
                            [cx[i] - qcx[i], cy[i] - qcy[i], cz[i] - qcz[i]],
                            [nx[i], ny[i], nz[i]],
                            [qnx[i], qny[i], qnz[i]],
                        );
                    ax[i] = fma(w, qnx[i], ax[i]);
                    ay[i] = fma(w, qny[i], ay[i]);
                    az[i] = fma(w, qnz[i], az[i]);
                }
            }
        }
        normalize([ax, ay, az], own, &normals[ko], types[ko].mask);
    }
}

/// Copies the normals of row `r`'s border cells (all of a border row) into `out`;
/// `Some(first interior cell)` unless the row is a border row.
#[inline(always)]
fn copy_borders(
    cells: Cells,
    r: usize,
    normals: &[Xyz<'_>; 2],
    out: &mut [[&mut [f32]; 3]; 2],
) -> Option<usize> {
    let Cells { rows, cols, half } = cells;
    let base = r * cols;
    let border_row = r < half || r + half >= rows;
    for (planes, normals) in out.iter_mut().zip(normals) {
        for (o, n) in planes.iter_mut().zip(normals) {
            let n = &n[base..base + cols];
            if border_row {
                o.copy_from_slice(n);
            } else {
                o[..half].copy_from_slice(&n[..half]);
                o[cols - half..].copy_from_slice(&n[cols - half..]);
            }
        }
    }
    (!border_row).then_some(base + half)
}

/// Turns the weighted sums `a` of the interior cells from `own` into unit normals (see
/// [`unit_or_own`]).
#[inline(always)]
fn normalize(a: [&mut [f32]; 3], own: usize, normals: &Xyz<'_>, mask: &[f32]) {
    let [ax, ay, az] = a;
    let len = ax.len();
    let [nx, ny, nz] = normals.each_ref().map(|n| &n[own..own + len]);
    let om = &mask[own..own + len];
    for i in 0..len {
        let present = om[i] > 0.0;
        [ax[i], ay[i], az[i]] = unit_or_own([ax[i], ay[i], az[i]], [nx[i], ny[i], nz[i]], present);
    }
}

/// [`normalize`] for the sums of one block of `N` cells from `at` on, both types (as
/// [`term_sums`] gives them), while they are still in registers.
#[inline(always)]
fn normalized<const N: usize>(
    mut sums: [[f32; N]; 6],
    at: usize,
    normals: &[Xyz<'_>; 2],
    types: &[TypeView<'_>; 2],
) -> [[f32; N]; 6] {
    let [s0x, s0y, s0z, s1x, s1y, s1z] = &mut sums;
    for (k, [sx, sy, sz]) in [[s0x, s0y, s0z], [s1x, s1y, s1z]].into_iter().enumerate() {
        let [nx, ny, nz] = normals[k];
        let (nx, ny, nz) = (span(nx, at, N), span(ny, at, N), span(nz, at, N));
        let mask = span(types[k].mask, at, N);
        for i in 0..N {
            let own = [nx[i], ny[i], nz[i]];
            [sx[i], sy[i], sz[i]] = unit_or_own([sx[i], sy[i], sz[i]], own, mask[i] > 0.0);
        }
    }
    sums
}

/// A triangle's weighted sum `a` as a unit normal; a missing triangle (not `present`),
/// or one whose sum vanishes, keeps its normal `own`. The sum is first scaled, exactly,
/// by the power of two that brings its largest component into [0.5, 1) (a subnormal
/// one to at least 2^-23), so that the squares of small sums (weights near
/// [`super::fast_exp::EXP_NEG_CUTOFF`]) stay normal `f32` numbers, as on the GPU; then
/// one square root and one division serve all three components.
#[inline(always)]
fn unit_or_own([ax, ay, az]: [f32; 3], own: [f32; 3], present: bool) -> [f32; 3] {
    let m = ax.abs().max(ay.abs()).max(az.abs());
    if present && m > 0.0 {
        // 2^(126 − E) for m's biased exponent E (sums stay far below 2^125).
        let scale = f32::from_bits(0x7e80_0000u32.wrapping_sub(m.to_bits() & 0x7f80_0000));
        let (bx, by, bz) = (ax * scale, ay * scale, az * scale);
        let inverse = 1.0 / (bx * bx + by * by + bz * bz).sqrt();
        [bx * inverse, by * inverse, bz * inverse]
    } else {
        own
    }
}

#[cfg(test)]
mod tests {
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::*;

    /// One triangle type's normal and centroid planes and its mask.
    type RandomType = ([Vec<f32>; 3], [Vec<f32>; 3], Vec<f32>);

    /// Random normals, centroids and masks on a grid of cells, per triangle type.
    fn random_planes(cells: Cells, seed: u64) -> [RandomType; 2] {
        let n = cells.rows * cells.cols;
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut plane = |scale: f32| -> Vec<f32> {
            (0..n)
                .map(|_| scale * (rng.random::<f32>() - 0.5))
                .collect()
        };
        [0, 1].map(|k| {
            let mask: Vec<f32> = (0..n).map(|i| f32::from((i + k) % 7 != 0)).collect();
            let centroid = [plane(0.4), plane(0.4), plane(0.4)];
            // Missing triangles have zero normals, as `compute_types` makes them.
            let normal = [(); 3].map(|()| {
                let mut p = plane(1.0);
                for (v, m) in p.iter_mut().zip(&mask) {
                    *v *= m;
                }
                p
            });
            (normal, centroid, mask)
        })
    }

    /// Cell rows, columns and kernel half-width of the grids the tests filter: every
    /// kernel that shares weights, grids narrower and wider than the kernel, and rows
    /// shorter than, a multiple of and between multiples of [`LANES`], [`WIDE_LANES`],
    /// [`BLOCK`] and [`WIDE_BLOCK`].
    const GRIDS: [(usize, usize, usize); 11] = [
        (6, 29, 1),
        (9, 7, 2),
        (12, 40, 2),
        (8, 3, 1),
        (11, 17, 3),
        (7, 75, 1),
        (8, 70, 3),
        (7, 34, 1),
        (6, 45, 2),
        (5, 18, 1),
        (6, 16, 1),
    ];

    /// Calls `test` with the random normals and triangle types ([`random_planes`], seeded
    /// from the grid's size and `seed`) and the filter of each of [`GRIDS`].
    fn on_grids(seed: u64, test: impl Fn(Cells, &[Xyz<'_>; 2], &[TypeView<'_>; 2], &Filter)) {
        for (rows, cols, half) in GRIDS {
            let cells = Cells { rows, cols, half };
            let data = random_planes(cells, (rows * cols) as u64 + seed);
            let normals = data
                .each_ref()
                .map(|(n, _, _)| n.each_ref().map(Vec::as_slice));
            let types = data.each_ref().map(|(_, c, m)| TypeView {
                centroid: c.each_ref().map(Vec::as_slice),
                mask: m,
            });
            test(cells, &normals, &types, &Filter::new(cells, 30.0, 4.0));
        }
    }

    /// Bands of every start and size, with the weights shared between rows and types,
    /// give the bits of the direct computation, row by row, on each of [`GRIDS`].
    #[test]
    fn bands_match_the_direct_computation() {
        on_grids(0, |cells, normals, types, filter| {
            let Cells { rows, cols, half } = cells;
            let empty = |n: usize| [0, 1].map(|_| [0, 1, 2].map(|_| vec![0.0f32; n]));
            let mut expected = empty(rows * cols);
            for r in 0..rows {
                let at = r * cols..(r + 1) * cols;
                let out = expected
                    .each_mut()
                    .map(|planes| planes.each_mut().map(|p| &mut p[at.clone()]));
                // The rounding of a machine without a rounding instruction: the kernels
                // must give the same bits with theirs.
                direct_row::<false>(filter, r, normals, types, out);
            }
            // Bands continuing one ring (in order, as a rayon task takes them), and bands
            // each on a ring of stale weights.
            for (band, shared) in [1, 2, 5, rows]
                .into_iter()
                .flat_map(|b| [(b, true), (b, false)])
            {
                let mut got = empty(rows * cols);
                let stale = || {
                    let mut ring = filter.ring();
                    ring.values.fill(f32::NAN);
                    ring
                };
                let mut ring = stale();
                for first in (0..rows).step_by(band) {
                    if !shared {
                        ring = stale();
                    }
                    let at = first * cols..(first + band).min(rows) * cols;
                    let out = got
                        .each_mut()
                        .map(|planes| planes.each_mut().map(|p| &mut p[at.clone()]));
                    let last = (first + band).min(rows);
                    let part = ring.band(first, last, filter.offsets.above());
                    rows_of_band(filter, part, normals, types, &mut ring.values, out);
                }
                let bits = |v: &[[Vec<f32>; 3]; 2]| -> Vec<u32> {
                    v.iter().flatten().flatten().map(|f| f.to_bits()).collect()
                };
                assert_eq!(
                    bits(&got),
                    bits(&expected),
                    "{rows}×{cols}, half {half}, band {band}, shared ring {shared}"
                );
            }
        });
    }

    /// The pass over all four pairs of triangle types at once (the AVX-512 layout) and
    /// the pass per pair (the AVX2 layout, whose rows end in an overlapping block) write
    /// the same bits into the ring, whichever layout this machine's kernels use.
    #[test]
    fn both_pair_weight_layouts_agree() {
        on_grids(1, |cells, normals, types, filter| {
            let Cells { rows, cols, half } = cells;
            let (mut shared, mut separate) = (filter.ring(), filter.ring());
            for r in 0..rows {
                pair_weights::<false, true>(filter, r, normals, types, &mut shared.values);
                pair_weights::<true, true>(filter, r, normals, types, &mut separate.values);
                let bits = |v: &[f32]| -> Vec<u32> { v.iter().map(|f| f.to_bits()).collect() };
                assert_eq!(
                    bits(&shared.values),
                    bits(&separate.values),
                    "{rows}×{cols}, half {half}, row {r}"
                );
            }
        });
    }

    #[test]
    fn block_runs_cover_each_row_once_in_whole_blocks() {
        for lanes in [LANES, WIDE_LANES] {
            for len in 0..5 * lanes {
                let [(a, n), (b, m)] = block_runs(len, lanes);
                assert_eq!((a, n % lanes), (0, 0), "{len}, {lanes}");
                assert_eq!(b + m, len, "{len}, {lanes}");
                // The second run is one block (the row itself when shorter), or empty, and
                // starts where the whole blocks end or inside their last.
                assert_eq!(
                    m,
                    if n == len { 0 } else { len.min(lanes) },
                    "{len}, {lanes}"
                );
                assert!(b <= n && n - b < lanes, "{len}, {lanes}");
            }
        }
    }
}
