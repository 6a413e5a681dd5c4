//! The sweep state: triangles, twins, the hull as a linked list with an angular hash, and
//! the insertion of one point (outside the hull, or inside it as a fallback).

use super::predicates::{InCircleFilter, orient};
use crate::mesh::NO_TWIN;

/// Marks an empty hash bucket.
const NONE: u32 = u32::MAX;
/// Offset of the next and of the previous half-edge within a triangle, by corner.
const NEXT: [u32; 3] = [1, 2, 0];
const PREV: [u32; 3] = [2, 0, 1];

/// The triangulation under construction. Vertices are insertion positions (`0..n`).
pub(super) struct Sweep<'a> {
    coords: &'a [[f64; 2]],
    ranks: &'a [u32],
    /// `tris[h]` is the origin of half-edge `h` (three per triangle).
    tris: Vec<u32>,
    /// Twin of each half-edge or [`NO_TWIN`].
    twins: Vec<u32>,
    /// Hull successor (counter-clockwise) of each hull vertex; `next[v] == v` once `v`
    /// has left the hull.
    next: Vec<u32>,
    prev: Vec<u32>,
    /// The half-edge `v → next[v]` of each hull vertex.
    hull_edge: Vec<u32>,
    /// Pseudo-angle buckets around `centre`, each holding a vertex that was on the hull.
    hash: Vec<u32>,
    centre: [f64; 2],
    filter: InCircleFilter,
    /// Some vertex on the hull.
    hull_start: u32,
    /// Edges waiting to be legalized.
    stack: Vec<u32>,
}

impl<'a> Sweep<'a> {
    /// Starts from the counter-clockwise seed triangle `0, 1, 2`.
    pub fn new(coords: &'a [[f64; 2]], ranks: &'a [u32], centre: [f64; 2]) -> Self {
        let n = coords.len();
        let max_triangles = 2 * n;
        let hash_size = ((n as f64).sqrt().ceil() as usize).max(1);
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in coords {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let extent = (hi[0] - lo[0]).max(hi[1] - lo[1]);
        let mut sweep = Self {
            coords,
            ranks,
            tris: Vec::with_capacity(3 * max_triangles),
            twins: Vec::with_capacity(3 * max_triangles),
            next: vec![0; n],
            prev: vec![0; n],
            hull_edge: vec![0; n],
            hash: vec![NONE; hash_size],
            centre,
            filter: InCircleFilter::new(extent),
            hull_start: 0,
            stack: Vec::with_capacity(64),
        };
        sweep.push_triangle([0, 1, 2]);
        for (v, w) in [(0, 1), (1, 2), (2, 0)] {
            sweep.next[v as usize] = w;
            sweep.prev[w as usize] = v;
            sweep.hull_edge[v as usize] = v;
            sweep.hash_vertex(v);
        }
        sweep
    }

    /// Triangles (three vertices each), twins and the hull (counter-clockwise), in
    /// insertion positions.
    pub fn finish(self) -> (Vec<u32>, Vec<u32>, Vec<u32>) {
        let mut hull = Vec::new();
        let mut v = self.hull_start;
        loop {
            hull.push(v);
            v = self.next[v as usize];
            if v == self.hull_start {
                break;
            }
        }
        (self.tris, self.twins, hull)
    }

    #[inline(always)]
    fn xy(&self, v: u32) -> [f64; 2] {
        self.coords[v as usize]
    }

    #[inline(always)]
    fn hash_key(&self, p: [f64; 2]) -> usize {
        let (dx, dy) = (p[0] - self.centre[0], p[1] - self.centre[1]);
        let q = dx / (dx.abs() + dy.abs());
        let angle = if dy > 0.0 { 3.0 - q } else { 1.0 + q } / 4.0;
        let n = self.hash.len();
        // Truncation is the floor for the non-negative angle (NaN, at the centre, gives 0).
        ((angle * n as f64) as usize).min(n - 1)
    }

    #[inline(always)]
    fn hash_vertex(&mut self, v: u32) {
        let key = self.hash_key(self.xy(v));
        self.hash[key] = v;
    }

    /// Appends triangle `v` without twins and returns its first half-edge.
    #[inline(always)]
    fn push_triangle(&mut self, v: [u32; 3]) -> u32 {
        let t = self.tris.len() as u32;
        self.tris.extend_from_slice(&v);
        self.twins.extend_from_slice(&[NO_TWIN; 3]);
        t
    }

    /// Makes `a` and `b` twins; `b` may be [`NO_TWIN`], then `a` is a hull edge.
    #[inline(always)]
    fn link(&mut self, a: u32, b: u32) {
        self.twins[a as usize] = b;
        if b != NO_TWIN {
            self.twins[b as usize] = a;
        } else {
            self.hull_edge[self.tris[a as usize] as usize] = a;
        }
    }

    /// Inserts point `p` (the next insertion position).
    pub fn insert(&mut self, p: u32) {
        let xy = self.xy(p);
        let key = self.hash_key(xy);
        let len = self.hash.len();
        let mut start = NONE;
        for j in 0..len {
            let v = self.hash[(key + j) % len];
            if v != NONE && self.next[v as usize] != v {
                start = v;
                break;
            }
        }
        if start == NONE {
            start = self.hull_start;
        }
        start = self.prev[start as usize];
        let mut e = start;
        loop {
            let q = self.next[e as usize];
            if orient(self.xy(e), self.xy(q), xy) < 0.0 {
                break;
            }
            e = q;
            if e == start {
                self.insert_inside(p, start);
                return;
            }
        }

        // The first visible edge e → n.
        let mut n = self.next[e as usize];
        let t = self.push_triangle([e, p, n]);
        let old = self.hull_edge[e as usize];
        self.link(t, NO_TWIN);
        self.link(t + 1, NO_TWIN);
        self.link(t + 2, old);
        self.legalize(t + 2);

        // Visible edges after it.
        loop {
            let q = self.next[n as usize];
            if orient(self.xy(n), self.xy(q), xy) >= 0.0 {
                break;
            }
            let t = self.push_triangle([n, p, q]);
            let (sp, nq) = (self.hull_edge[p as usize], self.hull_edge[n as usize]);
            self.link(t, sp);
            self.link(t + 1, NO_TWIN);
            self.link(t + 2, nq);
            self.legalize(t + 2);
            self.next[n as usize] = n;
            n = q;
        }
        // Visible edges before it (only possible when the search found e at once).
        if e == start {
            loop {
                let q = self.prev[e as usize];
                if orient(self.xy(q), self.xy(e), xy) >= 0.0 {
                    break;
                }
                let t = self.push_triangle([q, p, e]);
                let (qe, ep) = (self.hull_edge[q as usize], self.hull_edge[e as usize]);
                self.link(t + 1, ep);
                self.link(t + 2, qe);
                self.link(t, NO_TWIN);
                self.legalize(t + 2);
                self.next[e as usize] = e;
                e = q;
            }
        }
        self.prev[p as usize] = e;
        self.next[e as usize] = p;
        self.prev[n as usize] = p;
        self.next[p as usize] = n;
        self.hull_start = e;
        self.hash_vertex(p);
        self.hash_vertex(e);
    }

    /// Restores the Delaunay property around a new point: `a` is a half-edge opposite it.
    fn legalize(&mut self, a: u32) {
        let Self {
            coords,
            ranks,
            tris,
            twins,
            hull_edge,
            filter,
            stack,
            ..
        } = self;
        legalize(
            Mesh {
                coords,
                ranks,
                tris,
                twins,
                hull_edge,
            },
            *filter,
            stack,
            a,
        );
    }

    /// Inserts `p`, which lies inside the hull or on its boundary, starting the search
    /// from the triangle of hull vertex `near`.
    fn insert_inside(&mut self, p: u32, near: u32) {
        let xy = self.xy(p);
        let t = self.locate(xy, self.hull_edge[near as usize] / 3);
        let h0 = 3 * t;
        let v = [0, 1, 2].map(|i| self.tris[(h0 + i) as usize]);
        let o = [0, 1, 2].map(|i| orient(self.xy(v[i]), self.xy(v[(i + 1) % 3]), xy));
        match o.iter().filter(|x| **x == 0.0).count() {
            0 => self.split_triangle(p, t),
            1 => {
                let i = o.iter().position(|x| *x == 0.0).unwrap_or(0) as u32;
                self.split_edge(p, h0 + i);
            }
            // On a vertex: duplicates were removed before, so this cannot happen.
            _ => {}
        }
    }

    /// The triangle containing `xy` (inside or on its boundary), by a visibility walk from
    /// triangle `t`; a linear scan if the walk does not end (it always does on a Delaunay
    /// triangulation).
    fn locate(&self, xy: [f64; 2], mut t: u32) -> u32 {
        let num_triangles = (self.tris.len() / 3) as u32;
        'walk: for _ in 0..=num_triangles {
            for i in 0..3 {
                let h = 3 * t + i;
                let (a, b) = (
                    self.tris[h as usize],
                    self.tris[(3 * t + (i + 1) % 3) as usize],
                );
                if orient(self.xy(a), self.xy(b), xy) < 0.0 {
                    let twin = self.twins[h as usize];
                    if twin == NO_TWIN {
                        break 'walk;
                    }
                    t = twin / 3;
                    continue 'walk;
                }
            }
            return t;
        }
        (0..num_triangles)
            .find(|&t| {
                (0..3).all(|i| {
                    let a = self.tris[(3 * t + i) as usize];
                    let b = self.tris[(3 * t + (i + 1) % 3) as usize];
                    orient(self.xy(a), self.xy(b), xy) >= 0.0
                })
            })
            .unwrap_or(t)
    }

    /// Splits triangle `t` into three around the interior point `p`.
    fn split_triangle(&mut self, p: u32, t: u32) {
        let h = 3 * t;
        let [v0, v1, v2] = [0, 1, 2].map(|i| self.tris[(h + i) as usize]);
        let [o1, o2] = [1, 2].map(|i| self.twins[(h + i) as usize]);
        // [v0, v1, p] reuses t; [v1, v2, p] and [v2, v0, p] are new.
        self.tris[(h + 2) as usize] = p;
        let t1 = self.push_triangle([v1, v2, p]);
        let t2 = self.push_triangle([v2, v0, p]);
        self.link(t1, o1);
        self.link(t2, o2);
        self.link(h + 1, t1 + 2);
        self.link(h + 2, t2 + 1);
        self.link(t1 + 1, t2 + 2);
        for e in [h, t1, t2] {
            self.legalize(e);
        }
    }

    /// Splits the edge `h` (from `A` to `B` in triangle [A, B, C]) at `p`, and its twin's
    /// triangle [B, A, D] if any.
    fn split_edge(&mut self, p: u32, h: u32) {
        let h0 = h - h % 3;
        let (hb, hc) = (h0 + (h + 1) % 3, h0 + (h + 2) % 3);
        let [a, b, c] = [h, hb, hc].map(|e| self.tris[e as usize]);
        let (o_bc, o_ca) = (self.twins[hb as usize], self.twins[hc as usize]);
        let twin = self.twins[h as usize];

        // [p, B, C] replaces [A, B, C]; [A, p, C] is new.
        let t = self.push_triangle([a, p, c]);
        self.set_triangle(h0, [p, b, c]);
        self.link(h0 + 1, o_bc);
        self.link(h0 + 2, t + 1);
        self.link(t + 2, o_ca);
        if twin == NO_TWIN {
            // A hull edge: p joins the hull between A and B.
            self.link(h0, NO_TWIN);
            self.link(t, NO_TWIN);
            self.next[a as usize] = p;
            self.prev[p as usize] = a;
            self.next[p as usize] = b;
            self.prev[b as usize] = p;
            self.hash_vertex(p);
            self.legalize(h0 + 1);
            self.legalize(t + 2);
            return;
        }
        let u0 = twin - twin % 3;
        let (ua, ud) = (u0 + (twin + 1) % 3, u0 + (twin + 2) % 3);
        let d = self.tris[ud as usize];
        let (o_ad, o_db) = (self.twins[ua as usize], self.twins[ud as usize]);
        // [p, A, D] replaces [B, A, D]; [B, p, D] is new.
        let u = self.push_triangle([b, p, d]);
        self.set_triangle(u0, [p, a, d]);
        self.link(u0 + 1, o_ad);
        self.link(u0 + 2, u + 1);
        self.link(u + 2, o_db);
        self.link(h0, u);
        self.link(t, u0);
        for e in [h0 + 1, t + 2, u0 + 1, u + 2] {
            self.legalize(e);
        }
    }

    fn set_triangle(&mut self, h0: u32, v: [u32; 3]) {
        self.tris[h0 as usize..h0 as usize + 3].copy_from_slice(&v);
    }
}

/// The arrays the legalization works on, borrowed apart so that they cannot alias.
struct Mesh<'m> {
    coords: &'m [[f64; 2]],
    ranks: &'m [u32],
    tris: &'m mut [u32],
    twins: &'m mut [u32],
    hull_edge: &'m mut [u32],
}

/// Flips edges until the triangles around the new point are Delaunay; `a` is a half-edge
/// opposite the new point, `stack` holds the others still to check.
fn legalize(m: Mesh<'_>, filter: InCircleFilter, stack: &mut Vec<u32>, mut a: u32) {
    let Mesh {
        coords,
        ranks,
        tris,
        twins,
        hull_edge,
    } = m;
    loop {
        let b = twins[a as usize];
        if b != NO_TWIN {
            // Triangle [A, B, P] holds a = A → B; its twin's triangle [B, A, Q] holds b.
            let (ra, rb) = ((a % 3) as usize, (b % 3) as usize);
            let (a0, b0) = (a - ra as u32, b - rb as u32);
            let ar = a0 + PREV[ra];
            let bl = b0 + PREV[rb];
            let va = tris[a as usize];
            let vb = tris[(a0 + NEXT[ra]) as usize];
            let vp = tris[ar as usize];
            let vq = tris[bl as usize];
            let (pa, pb, pp, pq) = (
                coords[va as usize],
                coords[vb as usize],
                coords[vp as usize],
                coords[vq as usize],
            );
            if filter.in_circle(pa, pb, pp, pq, || {
                [va, vb, vp, vq].map(|v| ranks[v as usize])
            }) {
                // Flip A–B to P–Q: [Q, B, P] in a's triangle, [P, A, Q] in b's.
                tris[a as usize] = vq;
                tris[b as usize] = vp;
                let (hbl, har) = (twins[bl as usize], twins[ar as usize]);
                twins[a as usize] = hbl;
                if hbl != NO_TWIN {
                    twins[hbl as usize] = a;
                } else {
                    hull_edge[vq as usize] = a;
                }
                twins[b as usize] = har;
                if har != NO_TWIN {
                    twins[har as usize] = b;
                } else {
                    hull_edge[vp as usize] = b;
                }
                twins[ar as usize] = bl;
                twins[bl as usize] = ar;
                stack.push(b0 + NEXT[rb]);
                continue;
            }
        }
        match stack.pop() {
            Some(h) => a = h,
            None => return,
        }
    }
}
