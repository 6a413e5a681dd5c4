//! Peak detection on the unwrapped image and single-linkage clustering of the peaks into
//! dominant normals.

use crate::accumulator::GaussianAccumulator;
use crate::icosahedron::{NORTH_POLE, SOUTH_POLE, dot, normalized};
use crate::image::UnwrappedImage;

/// A local maximum of the accumulator.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Peak {
    /// The icosahedron vertex at the maximum.
    pub vertex: u32,
    /// Its value on the image's 0–255 scale.
    pub value: f64,
    /// Mean direction of the normals binned in the vertex's incident cells: the peak's
    /// position refined below the cell size.
    pub normal: [f64; 3],
}

/// A dominant plane normal: a cluster of peaks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DominantNormal {
    /// Unit normal: the weighted mean of the cluster's peak normals.
    pub normal: [f64; 3],
    /// Total normalised weight of the cluster: the sum of its peaks' values / 255 (the highest
    /// single peak has weight 1).
    pub weight: f64,
}

impl GaussianAccumulator {
    /// The peaks of the unwrapped image: chart pixels whose value is at least
    /// `value_threshold` (0–255 scale), above zero, and not below any of the 8 pixels around
    /// them. Ties go to the lower vertex index, so a plateau of adjacent pixels (such as the
    /// three corners of a cell holding all the normals) gives one peak. The two poles, which
    /// the charts hold only in their borders, are tested the same way against their five
    /// neighbours. Strongest first (ties by vertex index).
    pub fn find_peaks(&self, value_threshold: f64) -> Vec<Peak> {
        let vertex_values = self.vertex_values();
        let image = UnwrappedImage::new(self.layout(), &vertex_values);
        self.peaks_of(&image, &vertex_values, value_threshold)
    }

    pub(crate) fn peaks_of(
        &self,
        image: &UnwrappedImage,
        vertex_values: &[f64],
        value_threshold: f64,
    ) -> Vec<Peak> {
        let (w, h) = (image.width() as usize, image.height() as usize);
        let values = image.values();
        let vertex = image.pixel_vertices();
        let mut peaks = Vec::new();
        let candidate = |v: f64| v > 0.0 && v >= value_threshold;
        // Whether (value, vertex) `a` outranks `b`: higher value, then lower vertex index.
        let outranks = |a: (f64, u32), b: (f64, u32)| a.0 > b.0 || (a.0 == b.0 && a.1 < b.1);
        for y in 1..h - 1 {
            for x in 1..w - 1 {
                let i = y * w + x;
                if !image.is_chart_pixel(x as u32, y as u32) || !candidate(values[i]) {
                    continue;
                }
                let centre = (values[i], vertex[i]);
                let beaten = [
                    i - w - 1,
                    i - w,
                    i - w + 1,
                    i - 1,
                    i + 1,
                    i + w - 1,
                    i + w,
                    i + w + 1,
                ]
                .iter()
                .any(|&j| vertex[j] != centre.1 && outranks((values[j], vertex[j]), centre));
                if !beaten {
                    peaks.push(self.peak(centre.1, centre.0));
                }
            }
        }
        let max = vertex_values.iter().copied().fold(0.0, f64::max);
        let scale = if max > 0.0 { 255.0 / max } else { 0.0 };
        for pole in [NORTH_POLE, SOUTH_POLE] {
            let centre = (vertex_values[pole as usize] * scale, pole);
            let beaten = self
                .icosahedron()
                .vertex_neighbors(pole)
                .iter()
                .any(|&u| outranks((vertex_values[u as usize] * scale, u), centre));
            if candidate(centre.0) && !beaten {
                peaks.push(self.peak(pole, centre.0));
            }
        }
        peaks.sort_by(|a, b| b.value.total_cmp(&a.value).then(a.vertex.cmp(&b.vertex)));
        peaks
    }

    fn peak(&self, vertex: u32, value: f64) -> Peak {
        let mut sum = [0.0; 3];
        for &c in self.icosahedron().vertex_cells(vertex) {
            let s = self.cell_normal_sum(c);
            for k in 0..3 {
                sum[k] += s[k];
            }
        }
        let normal = if dot(sum, sum) > 0.0 {
            normalized(sum)
        } else {
            self.icosahedron().vertices()[vertex as usize]
        };
        Peak {
            vertex,
            value,
            normal,
        }
    }
}

/// Single-linkage agglomerative clustering of `peaks` cut at Euclidean distance
/// `cluster_distance` between their normals; each cluster becomes a [`DominantNormal`] (the
/// weighted mean of its peak normals, weights value / 255) and clusters whose total weight is
/// below `min_cluster_weight` are dropped. Strongest first.
pub fn cluster_peaks(
    peaks: &[Peak],
    cluster_distance: f64,
    min_cluster_weight: f64,
) -> Vec<DominantNormal> {
    let mut parent: Vec<usize> = (0..peaks.len()).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let limit = cluster_distance * cluster_distance;
    for i in 0..peaks.len() {
        for j in i + 1..peaks.len() {
            let (a, b) = (peaks[i].normal, peaks[j].normal);
            let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
            if dot(d, d) <= limit {
                let (ri, rj) = (root(&mut parent, i), root(&mut parent, j));
                parent[ri.max(rj)] = ri.min(rj);
            }
        }
    }
    let mut sums = vec![([0.0; 3], 0.0); peaks.len()];
    for (i, p) in peaks.iter().enumerate() {
        let r = root(&mut parent, i);
        let weight = p.value / 255.0;
        for k in 0..3 {
            sums[r].0[k] += weight * p.normal[k];
        }
        sums[r].1 += weight;
    }
    let mut out: Vec<DominantNormal> = sums
        .into_iter()
        .filter(|(sum, weight)| {
            *weight > 0.0 && *weight >= min_cluster_weight && dot(*sum, *sum) > 0.0
        })
        .map(|(sum, weight)| DominantNormal {
            normal: normalized(sum),
            weight,
        })
        .collect();
    out.sort_by(|a, b| {
        b.weight.total_cmp(&a.weight).then_with(|| {
            a.normal
                .partial_cmp(&b.normal)
                .unwrap_or(std::cmp::Ordering::Equal)
        })
    });
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn peak(normal: [f64; 3], value: f64) -> Peak {
        Peak {
            vertex: 0,
            value,
            normal: normalized(normal),
        }
    }

    #[test]
    fn close_peaks_merge_into_their_weighted_mean() {
        let peaks = [
            peak([0.0, 0.0, 1.0], 255.0),
            peak([0.05, 0.0, 1.0], 127.5),
            peak([1.0, 0.0, 0.0], 51.0),
        ];
        let out = cluster_peaks(&peaks, 0.1, 0.15);
        assert_eq!(out.len(), 2);
        assert!((out[0].weight - 1.5).abs() < 1e-12);
        assert!(out[0].normal[0] > 0.0 && out[0].normal[0] < 0.05);
        assert!((out[1].weight - 0.2).abs() < 1e-12);
        // A weight cut above the small cluster drops it.
        assert_eq!(cluster_peaks(&peaks, 0.1, 0.25).len(), 1);
    }

    #[test]
    fn single_linkage_chains_through_intermediate_peaks() {
        let peaks: Vec<Peak> = (0..5)
            .map(|k| peak([0.08 * f64::from(k), 0.0, 1.0], 100.0))
            .collect();
        assert_eq!(cluster_peaks(&peaks, 0.1, 0.0).len(), 1);
        assert_eq!(cluster_peaks(&peaks, 0.01, 0.0).len(), 5);
    }
}
