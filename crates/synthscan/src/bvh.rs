//! A bounding-volume hierarchy over a scene's faces for nearest-hit ray queries.

use crate::face::Face;
use crate::vec3::{V3, axpy, dot};

/// Faces per leaf.
const LEAF_SIZE: usize = 4;

#[derive(Debug, Clone, Copy)]
struct Node {
    lo: V3,
    hi: V3,
    /// Leaf: first index into `order`; inner node: index of the right child (the left
    /// child follows the node).
    first: u32,
    /// Faces in a leaf; 0 for an inner node.
    count: u32,
}

/// Median-split BVH over face bounding boxes (padded so flat faces have thickness).
///
/// Faces whose box spans more than a quarter of the scene's (walls, floors) would make
/// every node they fall in large; they are kept out of the tree and tested first, which
/// also gives the traversal a near hit to prune against.
#[derive(Debug, Clone)]
pub(crate) struct Bvh {
    nodes: Vec<Node>,
    order: Vec<u32>,
    big: Vec<u32>,
}

impl Bvh {
    pub(crate) fn new(faces: &[Face]) -> Self {
        let boxes: Vec<(V3, V3)> = faces
            .iter()
            .map(|f| {
                let (lo, hi) = f.bounding_box();
                let pad = 1e-9 * (1.0 + (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max));
                (lo.map(|x| x - pad), hi.map(|x| x + pad))
            })
            .collect();
        let diag = |(lo, hi): (V3, V3)| (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for (a, b) in &boxes {
            for k in 0..3 {
                lo[k] = lo[k].min(a[k]);
                hi[k] = hi[k].max(b[k]);
            }
        }
        let scene_diag = diag((lo, hi));
        let (big, order): (Vec<u32>, Vec<u32>) =
            (0..faces.len() as u32).partition(|&i| diag(boxes[i as usize]) > 0.25 * scene_diag);
        let mut bvh = Self {
            nodes: Vec::with_capacity(2 * faces.len() / LEAF_SIZE + 1),
            order,
            big,
        };
        if !bvh.order.is_empty() {
            bvh.build(&boxes, 0, bvh.order.len());
        }
        bvh
    }

    fn build(&mut self, boxes: &[(V3, V3)], start: usize, end: usize) {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for &i in &self.order[start..end] {
            let (a, b) = boxes[i as usize];
            for k in 0..3 {
                lo[k] = lo[k].min(a[k]);
                hi[k] = hi[k].max(b[k]);
            }
        }
        let me = self.nodes.len();
        self.nodes.push(Node {
            lo,
            hi,
            first: start as u32,
            count: (end - start) as u32,
        });
        if end - start <= LEAF_SIZE {
            return;
        }
        let axis = (0..3)
            .max_by(|&a, &b| (hi[a] - lo[a]).total_cmp(&(hi[b] - lo[b])))
            .unwrap_or(0);
        let centre = |i: u32| {
            let (a, b) = boxes[i as usize];
            a[axis] + b[axis]
        };
        self.order[start..end].sort_by(|&a, &b| centre(a).total_cmp(&centre(b)).then(a.cmp(&b)));
        let mid = (start + end) / 2;
        self.nodes[me].count = 0;
        self.build(boxes, start, mid);
        self.nodes[me].first = self.nodes.len() as u32;
        self.build(boxes, mid, end);
    }

    /// Nearest hit `(range, face index)` along `origin + t dir`, `t > 1e-9`. Equal ranges go
    /// to the lower face index, so the answer does not depend on the tree's shape.
    pub(crate) fn cast(&self, faces: &[Face], origin: V3, dir: V3) -> Option<(f64, usize)> {
        let inv = dir.map(|d| 1.0 / d);
        let mut best: Option<(f64, usize)> = None;
        let consider = |fi: usize, best: &mut Option<(f64, usize)>| {
            if let Some(t) = hit(&faces[fi], origin, dir)
                && best.is_none_or(|(bt, bi)| t < bt || (t == bt && fi < bi))
            {
                *best = Some((t, fi));
            }
        };
        for &fi in &self.big {
            consider(fi as usize, &mut best);
        }
        let mut stack = [0u32; 64];
        let mut top = 0;
        if !self.nodes.is_empty() {
            stack[0] = 0;
            top = 1;
        }
        while top > 0 {
            top -= 1;
            let node = self.nodes[stack[top] as usize];
            let Some(entry) = slab(&node, origin, inv) else {
                continue;
            };
            if best.is_some_and(|(bt, _)| entry > bt) {
                continue;
            }
            if node.count > 0 {
                for &fi in &self.order[node.first as usize..(node.first + node.count) as usize] {
                    consider(fi as usize, &mut best);
                }
            } else if top + 2 <= stack.len() {
                let left = stack[top] + 1;
                let right = node.first;
                // Visit the nearer child first: push it last.
                let tl = slab(&self.nodes[left as usize], origin, inv);
                let tr = slab(&self.nodes[right as usize], origin, inv);
                let (near, far) = match (tl, tr) {
                    (Some(a), Some(b)) if b < a => (right, left),
                    _ => (left, right),
                };
                stack[top] = far;
                stack[top + 1] = near;
                top += 2;
            }
        }
        best
    }
}

/// Entry range of the ray into the node's box, or `None` if it misses (or the box is behind).
#[inline]
fn slab(node: &Node, o: V3, inv: V3) -> Option<f64> {
    let mut t0 = 0.0f64;
    let mut t1 = f64::INFINITY;
    for k in 0..3 {
        let a = (node.lo[k] - o[k]) * inv[k];
        let b = (node.hi[k] - o[k]) * inv[k];
        // NaN (0 · ∞, a ray in the box's boundary plane) leaves the interval unchanged.
        t0 = t0.max(a.min(b));
        t1 = t1.min(a.max(b));
    }
    (t0 <= t1).then_some(t0)
}

/// Range at which the ray hits the face, if it does (either side).
#[inline]
pub(crate) fn hit(f: &Face, origin: V3, dir: V3) -> Option<f64> {
    let n = f.normal();
    let denom = dot(n, dir);
    if denom.abs() < 1e-12 {
        return None;
    }
    let t = (f.offset() - dot(n, origin)) / denom;
    if t.is_nan() || t <= 1e-9 {
        return None;
    }
    let p = axpy(origin, t, dir);
    (f.bbox_contains(p, 1e-9 * (1.0 + t)) && f.contains_2d(f.frame().to_2d(p))).then_some(t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::rngs::Xoshiro256PlusPlus;
    use rand::{RngExt, SeedableRng};

    /// The tree gives exactly the linear scan's answer (lowest index among equal ranges).
    #[test]
    fn bvh_matches_linear_scan() -> Result<(), crate::SceneError> {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(5);
        for seed in 0..3 {
            let (scene, _) = crate::synpeb_like(seed)?;
            let faces = scene.faces();
            let bvh = Bvh::new(faces);
            for _ in 0..3000 {
                let o = [
                    0.1 + 5.8 * rng.random::<f64>(),
                    0.1 + 4.8 * rng.random::<f64>(),
                    0.1 + 2.8 * rng.random::<f64>(),
                ];
                let d = crate::vec3::normalize([
                    rng.random::<f64>() - 0.5,
                    rng.random::<f64>() - 0.5,
                    rng.random::<f64>() - 0.5,
                ])
                .unwrap_or([1.0, 0.0, 0.0]);
                let mut linear: Option<(f64, usize)> = None;
                for (i, f) in faces.iter().enumerate() {
                    if let Some(t) = hit(f, o, d)
                        && linear.is_none_or(|(bt, _)| t < bt)
                    {
                        linear = Some((t, i));
                    }
                }
                assert_eq!(bvh.cast(faces, o, d), linear);
            }
        }
        Ok(())
    }
}
