//! A k-d tree Gaussian accumulator (kiddo): the general-purpose baseline the paper measures
//! FastGA against (there with nanoflann). Same cells, same input handling, same results up to
//! ties; only the search differs.

use kiddo::{ImmutableKdTree, SquaredEuclidean};

use crate::accumulator::DEFAULT_UNIT_TOLERANCE;
use crate::icosahedron::Icosahedron;
use crate::integrate::{AsNormal, Bins, Driver, IntegrateStats, Parallelism, SampleCache, Sampler};
use crate::{FastGaError, unit_tolerance_checked};

/// Histogram of unit normals on a refined icosahedron, searched with a k-d tree over the cell
/// normals.
///
/// ```
/// use fastga::{KdAccumulator, Parallelism};
///
/// let mut kd = KdAccumulator::new(3)?;
/// kd.integrate(&[[0.0f32, 1.0, 0.0]], 1.0, Parallelism::Sequential)?;
/// assert_eq!(kd.counts().iter().sum::<u64>(), 1);
/// # Ok::<(), fastga::FastGaError>(())
/// ```
pub struct KdAccumulator {
    ico: Icosahedron,
    tree: ImmutableKdTree<f64, 3>,
    bins: Bins,
    /// The sampled indices, kept across calls.
    sample: SampleCache,
    unit_tolerance: f64,
}

impl std::fmt::Debug for KdAccumulator {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("KdAccumulator")
            .field("level", &self.ico.level())
            .field("cells", &self.ico.cell_count())
            .finish_non_exhaustive()
    }
}

impl KdAccumulator {
    /// An empty accumulator on the icosahedron refined `level` times, cells in the same order
    /// as [`GaussianAccumulator`](crate::GaussianAccumulator)'s.
    ///
    /// # Errors
    /// [`FastGaError::LevelOutOfRange`] above [`MAX_LEVEL`](crate::MAX_LEVEL), or
    /// [`FastGaError::KdTree`] if kiddo rejects the cell normals.
    pub fn new(level: u32) -> Result<Self, FastGaError> {
        let ico = Icosahedron::new(level)?;
        let tree = ImmutableKdTree::new_from_slice(ico.normals())
            .map_err(|e| FastGaError::KdTree(e.to_string()))?;
        let bins = Bins::new(ico.cell_count());
        Ok(Self {
            ico,
            tree,
            bins,
            sample: SampleCache::default(),
            unit_tolerance: DEFAULT_UNIT_TOLERANCE,
        })
    }

    /// Sets the tolerance on `|‖n‖² − 1|` (see
    /// [`GaussianAccumulator::set_unit_tolerance`](crate::GaussianAccumulator::set_unit_tolerance)).
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

    /// Index of the cell whose normal is nearest to `p` (Euclidean, which for unit `p` is the
    /// angular order).
    #[inline]
    pub fn find_cell(&self, p: [f64; 3]) -> u32 {
        nearest(&self.tree, p)
    }

    /// Bins `normals` like [`GaussianAccumulator::integrate`](crate::GaussianAccumulator::integrate).
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
        let tree = &self.tree;
        Ok(driver.run(normals, &mut self.bins, |batch, cells| {
            for (p, c) in batch.iter().zip(cells) {
                *c = nearest(tree, *p);
            }
        }))
    }

    /// Empties every cell.
    pub fn clear(&mut self) {
        self.bins.clear();
    }

    /// The number of normals in each cell.
    pub fn counts(&self) -> &[u64] {
        &self.bins.counts
    }
}

#[inline(always)]
fn nearest(tree: &ImmutableKdTree<f64, 3>, p: [f64; 3]) -> u32 {
    tree.query(&p)
        .nearest_one::<SquaredEuclidean<f64>>()
        .execute()
        .item
}
