//! Validation of label arrays and compaction of sparse plane ids to `0..count`.

use crate::error::{Labels, MetricsError};

/// Compact id of "no plane".
pub(crate) const NONE: u32 = u32::MAX;

/// The plane ids of one label array, renumbered densely.
pub(crate) struct Compacted {
    /// `ids[c]` is the original id of compact id `c`; increasing.
    pub(crate) ids: Vec<i32>,
    /// Original id → compact id.
    lookup: Lookup,
}

enum Lookup {
    /// Indexed by the original id (ids up to a few times the number of points).
    Table(Vec<u32>),
    /// Binary search in `ids` (large, sparse ids).
    Search,
}

impl Compacted {
    /// Compact id of `label`, [`NONE`] for −1. `label` must be −1 or an id present in the
    /// array this was built from.
    #[inline]
    pub(crate) fn get(&self, label: i32) -> u32 {
        if label < 0 {
            return NONE;
        }
        match &self.lookup {
            Lookup::Table(table) => table.get(label as usize).copied().unwrap_or(NONE),
            Lookup::Search => self.ids.binary_search(&label).map_or(NONE, |c| c as u32),
        }
    }
}

/// Checks that every label is −1 or non-negative and renumbers the ids present as
/// `0..count` in increasing order of the original id.
///
/// Ids up to a few times the number of points go through a direct lookup table
/// (O(n + max id)); larger, sparse ids are sorted and deduplicated (only the first label of
/// each run of equal labels is collected, so organized clouds with long runs sort little)
/// and found by binary search. Errors name the first invalid label.
pub(crate) fn compact(labels: &[i32], which: Labels) -> Result<Compacted, MetricsError> {
    // One pass: validate, and mark the ids present in a table that grows up to `limit`;
    // beyond it, fall back to sorting. Only the first label of each run is looked at.
    let limit = 4 * labels.len() + 4096;
    let mut table: Vec<u32> = Vec::new();
    let mut sparse = false;
    let mut previous = -1;
    for (index, &label) in labels.iter().enumerate() {
        if label == previous {
            continue;
        }
        previous = label;
        if label < 0 {
            if label < -1 {
                return Err(MetricsError::InvalidLabel {
                    labels: which,
                    index,
                    label,
                });
            }
            continue;
        }
        let slot = label as usize;
        if sparse {
            continue;
        }
        if slot >= table.len() {
            if slot >= limit {
                sparse = true;
                continue;
            }
            table.resize((slot + 1).max(2 * table.len()).min(limit), NONE);
        }
        table[slot] = 0;
    }
    if !sparse {
        let mut ids = Vec::new();
        for (slot, id) in table.iter_mut().zip(0i32..) {
            if *slot == 0 {
                *slot = ids.len() as u32;
                ids.push(id);
            }
        }
        return Ok(Compacted {
            ids,
            lookup: Lookup::Table(table),
        });
    }
    let mut ids = Vec::new();
    let mut previous = -1;
    for &label in labels {
        if label != previous && label >= 0 {
            ids.push(label);
        }
        previous = label;
    }
    ids.sort_unstable();
    ids.dedup();
    Ok(Compacted {
        ids,
        lookup: Lookup::Search,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn per_point(c: &Compacted, labels: &[i32]) -> Vec<u32> {
        labels.iter().map(|&l| c.get(l)).collect()
    }

    #[test]
    fn dense_and_sparse_paths_agree() {
        let labels = [5, -1, 3, 5, 5, 0, 3];
        let dense = compact(&labels, Labels::Truth).unwrap();
        assert!(matches!(dense.lookup, Lookup::Table(_)));
        assert_eq!(dense.ids, vec![0, 3, 5]);
        assert_eq!(per_point(&dense, &labels), vec![2, NONE, 1, 2, 2, 0, 1]);
        let sparse_labels = [i32::MAX, -1, 3, i32::MAX, i32::MAX, 0, 3];
        let sparse = compact(&sparse_labels, Labels::Truth).unwrap();
        assert!(matches!(sparse.lookup, Lookup::Search));
        assert_eq!(sparse.ids, vec![0, 3, i32::MAX]);
        assert_eq!(
            per_point(&sparse, &sparse_labels),
            per_point(&dense, &labels)
        );
        // Small ids first, then one beyond the table limit: falls back to sorting.
        let late = [0, 0, 3, -1, 5000, 3, 1 << 20];
        let c = compact(&late, Labels::Truth).unwrap();
        assert!(matches!(c.lookup, Lookup::Search));
        assert_eq!(c.ids, vec![0, 3, 5000, 1 << 20]);
        assert_eq!(per_point(&c, &late), vec![0, 0, 1, NONE, 2, 1, 3]);
    }

    #[test]
    fn all_none_and_empty() {
        let c = compact(&[-1, -1], Labels::Predicted).unwrap();
        assert!(c.ids.is_empty());
        assert_eq!(per_point(&c, &[-1, -1]), vec![NONE, NONE]);
        let c = compact(&[], Labels::Predicted).unwrap();
        assert!(c.ids.is_empty());
    }

    #[test]
    fn rejects_labels_below_minus_one() {
        assert_eq!(
            compact(&[0, -1, -2, -7], Labels::Predicted).err(),
            Some(MetricsError::InvalidLabel {
                labels: Labels::Predicted,
                index: 2,
                label: -2
            })
        );
    }
}
