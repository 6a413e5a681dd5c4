//! Compressed adjacency lists (CSR) built from a triangle list.

use rayon::prelude::*;

/// For each key `0..n`, a sorted list of distinct values.
pub(crate) struct Csr {
    offsets: Vec<u32>,
    values: Vec<u32>,
}

impl Csr {
    /// Groups `(key, value)` pairs by key, sorting and removing duplicates.
    fn from_pairs(n: usize, mut pairs: Vec<u64>) -> Self {
        pairs.par_sort_unstable();
        pairs.dedup();
        let mut offsets = vec![0u32; n + 1];
        for &p in &pairs {
            offsets[(p >> 32) as usize + 1] += 1;
        }
        for i in 0..n {
            offsets[i + 1] += offsets[i];
        }
        let values = pairs.iter().map(|&p| p as u32).collect();
        Self { offsets, values }
    }

    /// Groups `(key, value)` pairs by key (sorted, without duplicates).
    pub fn from_lists(n: usize, pairs: Vec<(u32, u32)>) -> Self {
        let pairs = pairs
            .into_iter()
            .map(|(k, v)| (u64::from(k) << 32) | u64::from(v))
            .collect();
        Self::from_pairs(n, pairs)
    }

    /// The 1-ring vertex neighbours of every vertex of `triangles`.
    pub fn vertex_neighbours(num_vertices: usize, triangles: &[[u32; 3]]) -> Self {
        let pairs = triangles
            .par_iter()
            .flat_map_iter(|&[a, b, c]| {
                [(a, b), (b, a), (b, c), (c, b), (c, a), (a, c)]
                    .map(|(u, v)| (u64::from(u) << 32) | u64::from(v))
            })
            .collect();
        Self::from_pairs(num_vertices, pairs)
    }

    /// The triangles around every vertex.
    pub fn vertex_triangles(num_vertices: usize, triangles: &[[u32; 3]]) -> Self {
        let pairs = triangles
            .par_iter()
            .enumerate()
            .flat_map_iter(|(t, tri)| tri.map(|v| (u64::from(v) << 32) | t as u64))
            .collect();
        Self::from_pairs(num_vertices, pairs)
    }

    /// The values of `key`.
    #[inline]
    pub fn get(&self, key: usize) -> &[u32] {
        &self.values[self.offsets[key] as usize..self.offsets[key + 1] as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rings_of_two_triangles() {
        let triangles = [[0, 1, 2], [0, 2, 3]];
        let ring = Csr::vertex_neighbours(5, &triangles);
        assert_eq!(ring.get(0), &[1, 2, 3]);
        assert_eq!(ring.get(1), &[0, 2]);
        assert_eq!(ring.get(4), &[] as &[u32]);
        let around = Csr::vertex_triangles(5, &triangles);
        assert_eq!(around.get(2), &[0, 1]);
        assert_eq!(around.get(3), &[1]);
    }
}
