//! The Fast Gaussian Accumulator: a histogram of unit normals over the cells of a refined
//! icosahedron, filled by Algorithm 3 or by the S2 cell table built from it.

use crate::icosahedron::{Icosahedron, normalized};
use crate::image::{ImageLayout, UnwrappedImage};
use crate::integrate::{
    AsNormal, Bins, Driver, IntegrateStats, Parallelism, SUM_SCALE, SampleCache, Sampler,
};
use crate::search::CellSearch;
use crate::table::CellTable;
use crate::{FastGaError, unit_tolerance_checked};

/// Default tolerance on `|‖n‖² − 1|` for a normal to count as unit length.
pub const DEFAULT_UNIT_TOLERANCE: f64 = 1e-4;

/// How an accumulator finds the cell of a normal. All give the closest cell (up to ties
/// within 1e-12 in the dot product); they differ in query speed and in what they cost to
/// build. The crate README compares them (query and build time per level).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Search {
    /// Algorithm 3 of the paper: S2 id, linear model with exact error bounds, branchless
    /// binary search, then ascent over the 1-ring. The cheapest to build.
    LearnedIndex,
    /// A table over the S2 cells two levels finer than the icosahedron (at most S2 level 8)
    /// listing every cell that can be closest inside each: a query is the S2 cell's face and
    /// `(i, j)` plus the dot products with a few candidates, with no search and no ascent.
    /// The fastest to query but the costliest to build: 6·4^(level + 2) entries, each
    /// costing about what [`TABLE_PAYS_AFTER`] queries through the table save (the crate
    /// README gives the measured costs). At level 7
    /// its table is coarse and slow to build: prefer [`LearnedIndex`](Self::LearnedIndex) there.
    CellTable,
    /// [`LearnedIndex`](Self::LearnedIndex) until the normals integrated, counting the call
    /// at hand, reach [`TABLE_PAYS_AFTER`] per table entry, then [`CellTable`](Self::CellTable)
    /// (built once, before that call): a one-off detection on a single frame never pays for
    /// a table it would not win back, and an accumulator reused over a stream gets the table
    /// once it has paid for it (the cost is at most about twice that of the better choice made
    /// in hindsight). The default.
    #[default]
    Adaptive,
}

/// Normals per table entry that [`Search::Adaptive`] integrates with the learned index
/// before it builds the cell table: building an entry costs about what eight queries save
/// by going through the table instead of the learned index (instruction counts in the
/// crate README).
pub const TABLE_PAYS_AFTER: u64 = 8;

/// Histogram of unit normals on a refined icosahedron (the paper's Gaussian accumulator).
///
/// Each cell keeps a count and the sum of the normals binned in it (so peaks can report the
/// mean of the actual normals, not only the cell centre).
///
/// ```
/// use fastga::{GaussianAccumulator, Parallelism};
///
/// let mut ga = GaussianAccumulator::new(4)?;
/// let normals = [[0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [f64::NAN, 0.0, 0.0]];
/// let stats = ga.integrate(&normals, 1.0, Parallelism::Sequential)?;
/// assert_eq!((stats.integrated, stats.skipped_invalid), (3, 1));
/// let up = ga.find_cell([0.0, 0.0, 1.0]) as usize;
/// assert_eq!(ga.counts()[up], 2);
/// # Ok::<(), fastga::FastGaError>(())
/// ```
#[derive(Debug, Clone)]
pub struct GaussianAccumulator {
    ico: Icosahedron,
    learned: CellSearch,
    /// Present with [`Search::CellTable`], and with [`Search::Adaptive`] once built.
    table: Option<CellTable>,
    /// The search asked for.
    search: Search,
    /// Normals integrated so far (for [`Search::Adaptive`]).
    integrated: u64,
    bins: Bins,
    /// The sampled indices, kept across calls.
    sample: SampleCache,
    layout: ImageLayout,
    unit_tolerance: f64,
}

impl GaussianAccumulator {
    /// An empty accumulator on the icosahedron refined `level` times (0 ..= 7; the paper uses
    /// 3–5), searched with the default [`Search::Adaptive`].
    ///
    /// # Errors
    /// [`FastGaError::LevelOutOfRange`] above [`MAX_LEVEL`](crate::MAX_LEVEL).
    pub fn new(level: u32) -> Result<Self, FastGaError> {
        Self::with_search(level, Search::default())
    }

    /// An empty accumulator on the icosahedron refined `level` times, searched with `search`.
    ///
    /// # Errors
    /// [`FastGaError::LevelOutOfRange`] above [`MAX_LEVEL`](crate::MAX_LEVEL).
    pub fn with_search(level: u32, search: Search) -> Result<Self, FastGaError> {
        let ico = Icosahedron::new(level)?;
        let learned = CellSearch::new(&ico);
        // The table's construction finds S2 cell centres' closest cells with Algorithm 3.
        let table = (search == Search::CellTable).then(|| CellTable::new(&ico, &learned));
        let bins = Bins::new(ico.cell_count());
        let layout = ImageLayout::new(level);
        Ok(Self {
            ico,
            learned,
            table,
            search,
            integrated: 0,
            bins,
            sample: SampleCache::default(),
            layout,
            unit_tolerance: DEFAULT_UNIT_TOLERANCE,
        })
    }

    /// Sets the tolerance on `|‖n‖² − 1|` above which a normal is skipped as not unit length
    /// (default [`DEFAULT_UNIT_TOLERANCE`]).
    ///
    /// # Errors
    /// [`FastGaError::InvalidUnitTolerance`] unless `0 ≤ tolerance < 1`.
    pub fn set_unit_tolerance(&mut self, tolerance: f64) -> Result<(), FastGaError> {
        self.unit_tolerance = unit_tolerance_checked(tolerance)?;
        Ok(())
    }

    /// The icosahedron whose triangles are the cells.
    pub fn icosahedron(&self) -> &Icosahedron {
        &self.ico
    }

    /// The worst-case errors `(min, max)` of `index − predicted index` of the id → index line
    /// over all cells, computed at construction; the binary search window spans them.
    pub fn model_error_bounds(&self) -> (i64, i64) {
        self.learned.error_bounds()
    }

    /// Bins `normals` (each of unit length within the tolerance; others are counted in
    /// [`IntegrateStats::skipped_invalid`] and ignored) into the cells with the closest normal.
    ///
    /// `sample_fraction` in (0, 1] keeps that fraction of the input, chosen by a hash of each
    /// normal's index: the same normals for every call and thread count. Counts add up over
    /// calls; see [`clear`](Self::clear).
    ///
    /// # Errors
    /// [`FastGaError::InvalidSampleFraction`] outside (0, 1].
    pub fn integrate<N: AsNormal>(
        &mut self,
        normals: &[N],
        sample_fraction: f64,
        parallelism: Parallelism,
    ) -> Result<IntegrateStats, FastGaError> {
        let driver = Driver {
            kept: self
                .sample
                .kept(Sampler::new(sample_fraction)?, normals.len(), parallelism),
            unit_tolerance: self.unit_tolerance,
            parallelism,
        };
        if self.search == Search::Adaptive && self.table.is_none() {
            let expected = (normals.len() as f64 * sample_fraction) as u64;
            let entries = CellTable::entry_count(self.ico.level()) as u64;
            if self.integrated.saturating_add(expected) >= TABLE_PAYS_AFTER * entries {
                self.table = Some(CellTable::new(&self.ico, &self.learned));
            }
        }
        let learned = &self.learned;
        let stats = match &self.table {
            Some(table) => driver.run(normals, &mut self.bins, |batch, cells| {
                table.find_batch(batch, cells)
            }),
            None => driver.run(normals, &mut self.bins, |batch, cells| {
                learned.find_batch(batch, cells)
            }),
        };
        self.integrated = self.integrated.saturating_add(stats.integrated);
        Ok(stats)
    }

    /// Index of the cell whose normal is closest to `p` (by angle). `p` need not be unit
    /// length but must be finite and non-zero; the result is unspecified otherwise.
    #[inline]
    pub fn find_cell(&self, p: [f64; 3]) -> u32 {
        match &self.table {
            Some(table) => table.find(p),
            None => self.learned.find(p),
        }
    }

    /// The search this accumulator was built with.
    pub fn search(&self) -> Search {
        self.search
    }

    /// Whether queries go through the cell table now ([`Search::CellTable`], or
    /// [`Search::Adaptive`] once it built the table).
    pub fn uses_table(&self) -> bool {
        self.table.is_some()
    }

    /// Empties every cell.
    pub fn clear(&mut self) {
        self.bins.clear();
    }

    /// The number of normals in each cell (cells in [`Icosahedron::triangles`] order).
    pub fn counts(&self) -> &[u64] {
        &self.bins.counts
    }

    /// Total number of normals binned.
    pub fn total(&self) -> u64 {
        self.bins.counts.iter().sum()
    }

    /// The sum of the normals binned in `cell` (to within 2⁻³⁰ per normal), or zeros.
    pub fn cell_normal_sum(&self, cell: u32) -> [f64; 3] {
        self.bins.sums[cell as usize].map(|s| s as f64 / SUM_SCALE)
    }

    /// The mean direction of the normals binned in `cell`, or `None` if it is empty.
    pub fn cell_mean_normal(&self, cell: u32) -> Option<[f64; 3]> {
        (self.bins.counts[cell as usize] > 0).then(|| normalized(self.cell_normal_sum(cell)))
    }

    /// The value of each icosahedron vertex: the mean count of its incident cells (as in the
    /// original FastGA), indexed like [`Icosahedron::vertices`].
    pub fn vertex_values(&self) -> Vec<f64> {
        (0..self.ico.vertices().len() as u32)
            .map(|v| {
                let cells = self.ico.vertex_cells(v);
                let sum: u64 = cells.iter().map(|&c| self.bins.counts[c as usize]).sum();
                sum as f64 / cells.len() as f64
            })
            .collect()
    }

    /// The unwrapped image of the vertex values (five charts with one-pixel padding),
    /// normalised to 0–255.
    pub fn unwrapped_image(&self) -> UnwrappedImage {
        UnwrappedImage::new(&self.layout, &self.vertex_values())
    }

    pub(crate) fn layout(&self) -> &ImageLayout {
        &self.layout
    }
}
