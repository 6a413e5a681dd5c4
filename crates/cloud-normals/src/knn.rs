//! k nearest neighbours of every point of a cloud, with a k-d tree ([`kiddo`]).

use std::num::NonZeroUsize;

use kiddo::{ImmutableKdTree, SquaredEuclidean};
use rayon::prelude::*;

use crate::NormalsError;

/// Points per parallel work item.
const CHUNK: usize = 4096;

/// The `k` nearest neighbours of every point, stored flat: the neighbours of point `i` are
/// `indices[i * k .. (i + 1) * k]`, nearest first, the point itself included (first,
/// unless a duplicate of it comes first). With fewer than `k` points, `k` is the count.
#[derive(Debug, Clone, PartialEq)]
pub struct Neighbours {
    k: usize,
    indices: Vec<u32>,
}

impl Neighbours {
    /// The `k` nearest neighbours of each of `points` (the point itself counts as one).
    ///
    /// ```
    /// use cloud_normals::Neighbours;
    /// let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [5.0, 0.0, 0.0], [1.5, 0.0, 0.0]];
    /// let knn = Neighbours::new(&points, 2)?;
    /// assert_eq!(knn.of(0), [0, 1]);
    /// assert_eq!(knn.of(2), [2, 3]);
    /// # Ok::<(), cloud_normals::NormalsError>(())
    /// ```
    ///
    /// # Errors
    /// [`NormalsError::Empty`], [`NormalsError::NonFinite`], [`NormalsError::TooManyPoints`],
    /// and [`NormalsError::TooFewNeighbours`] for `k = 0`.
    pub fn new(points: &[[f64; 3]], k: usize) -> Result<Self, NormalsError> {
        check_points(points)?;
        let k = k.min(points.len());
        let Some(qty) = NonZeroUsize::new(k) else {
            return Err(NormalsError::TooFewNeighbours { k });
        };
        let tree: ImmutableKdTree<f64, 3> =
            ImmutableKdTree::new_from_slice(points).map_err(|_| NormalsError::TooManyPoints {
                points: points.len(),
            })?;
        let mut indices = vec![0u32; points.len() * k];
        indices
            .par_chunks_mut(CHUNK * k)
            .enumerate()
            .for_each(|(chunk, out)| {
                for (j, row) in out.chunks_exact_mut(k).enumerate() {
                    let p = &points[chunk * CHUNK + j];
                    let found = tree
                        .query(p)
                        .nearest_n::<SquaredEuclidean<f64>>(qty)
                        .execute();
                    for (slot, item) in row.iter_mut().zip(found) {
                        *slot = item.item;
                    }
                }
            });
        Ok(Self { k, indices })
    }

    /// Neighbours per point.
    pub fn k(&self) -> usize {
        self.k
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.indices.len().checked_div(self.k).unwrap_or(0)
    }

    /// Whether there is no point.
    pub fn is_empty(&self) -> bool {
        self.indices.is_empty()
    }

    /// The neighbours of point `i`, nearest first.
    ///
    /// # Panics
    /// If `i` is not a point index.
    #[inline]
    pub fn of(&self, i: usize) -> &[u32] {
        &self.indices[i * self.k..(i + 1) * self.k]
    }

    /// All neighbour lists, flat (`k` per point).
    pub fn as_flat(&self) -> &[u32] {
        &self.indices
    }
}

/// Checks that the cloud is non-empty, finite and addressable with `u32` indices.
pub(crate) fn check_points(points: &[[f64; 3]]) -> Result<(), NormalsError> {
    if points.is_empty() {
        return Err(NormalsError::Empty);
    }
    if points.len() >= u32::MAX as usize {
        return Err(NormalsError::TooManyPoints {
            points: points.len(),
        });
    }
    if let Some((index, point)) = points
        .iter()
        .enumerate()
        .find(|(_, p)| !p.iter().all(|c| c.is_finite()))
    {
        return Err(NormalsError::NonFinite {
            index,
            point: *point,
        });
    }
    Ok(())
}
