//! S2 cell ids of unit vectors: cube face, quadratic (u, v) → (s, t) transform, (i, j) at
//! level 30 and the position along the face's Hilbert curve.
//!
//! The ids are those of the S2 Geometry library's leaf cells (checked against the `s2` crate in
//! the tests): the face sits in the top 3 bits, the 60-bit Hilbert position below it, and the
//! lowest bit is set. Sorting unit vectors by id orders them along one continuous space-filling
//! curve over the sphere, so vectors close in id are close on the sphere.

/// Number of levels of the S2 cell hierarchy; leaf cells are at this level.
pub const S2_MAX_LEVEL: u32 = 30;

const SWAP_MASK: u16 = 1;
const INVERT_MASK: u16 = 2;
const LOOKUP_BITS: u32 = 4;

/// Hilbert position (0–3) of the child at (i bit, j bit) = index `2 i + j`, per orientation.
const IJ_TO_POS: [[u16; 4]; 4] = [[0, 1, 3, 2], [0, 3, 1, 2], [2, 3, 1, 0], [2, 1, 3, 0]];
/// Orientation change when descending into the child at each Hilbert position.
const POS_TO_ORIENTATION: [u16; 4] = [SWAP_MASK, 0, 0, INVERT_MASK | SWAP_MASK];

/// `LOOKUP_POS[(i4 << 6) | (j4 << 2) | orientation]` = `(pos8 << 2) | new_orientation`: four
/// levels of the Hilbert curve at once.
static LOOKUP_POS: [u16; 1 << (2 * LOOKUP_BITS + 2)] = build_lookup();

const fn build_lookup() -> [u16; 1 << (2 * LOOKUP_BITS + 2)] {
    let mut table = [0u16; 1 << (2 * LOOKUP_BITS + 2)];
    let mut index = 0;
    while index < table.len() {
        let i = (index >> 6) & 15;
        let j = (index >> 2) & 15;
        let mut orientation = (index & 3) as u16;
        let mut pos = 0u16;
        let mut bit = LOOKUP_BITS;
        while bit > 0 {
            bit -= 1;
            let child = (((i >> bit) & 1) << 1) | ((j >> bit) & 1);
            let p = IJ_TO_POS[orientation as usize][child];
            pos = (pos << 2) | p;
            orientation ^= POS_TO_ORIENTATION[p as usize];
        }
        table[index] = (pos << 2) | orientation;
        index += 1;
    }
    table
}

/// Per face: (axis of u, sign of u, axis of v, sign of v, axis of the face normal).
const FACE_AXES: [(usize, f64, usize, f64, usize); 6] = [
    (1, 1.0, 2, 1.0, 0),
    (0, -1.0, 2, 1.0, 1),
    (0, -1.0, 1, -1.0, 2),
    (2, 1.0, 1, 1.0, 0),
    (2, 1.0, 0, -1.0, 1),
    (1, -1.0, 0, -1.0, 2),
];

/// The cube face (0 = +x, 1 = +y, 2 = +z, 3 = −x, 4 = −y, 5 = −z) of `p`: its largest
/// absolute component; ties go to x over y over z, as in the `s2` crate.
#[inline(always)]
pub fn face(p: [f64; 3]) -> u8 {
    let (ax, ay, az) = (p[0].abs(), p[1].abs(), p[2].abs());
    // Conditional moves: on random directions every comparison is a coin flip.
    let y = ay > ax;
    let axis = std::hint::select_unpredictable(y, 1u8, 0);
    let largest = std::hint::select_unpredictable(y, ay, ax);
    let axis = std::hint::select_unpredictable(az > largest, 2, axis);
    axis + 3 * u8::from(p[usize::from(axis)] < 0.0)
}

/// The cube face of `p` and its face coordinates `(u, v)` in [−1, 1].
#[inline(always)]
pub fn face_uv(p: [f64; 3]) -> (u8, f64, f64) {
    let f = face(p);
    let (ua, us, va, vs, wa) = FACE_AXES[usize::from(f)];
    let w = p[wa];
    // Divisions, not a reciprocal: the ids must match the `s2` crate's to the last bit.
    (f, us * p[ua] / w, vs * p[va] / w)
}

/// The unit vector at face coordinates `(s, t)` in [0, 1]² of cube face `face` (0–5): the
/// inverse of [`face_uv`] followed by [`uv_to_st`], normalised.
pub fn face_st_to_point(face: u8, s: f64, t: f64) -> [f64; 3] {
    let (ua, us, va, vs, wa) = FACE_AXES[usize::from(face)];
    let w = if face < 3 { 1.0 } else { -1.0 };
    let mut p = [0.0; 3];
    p[wa] = w;
    p[ua] = st_to_uv(s) * w * us;
    p[va] = st_to_uv(t) * w * vs;
    let len = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
    p.map(|x| x / len)
}

/// The quadratic projection from a face coordinate `u` in [−1, 1] to `s` in [0, 1].
#[inline(always)]
pub fn uv_to_st(u: f64) -> f64 {
    let half = 0.5 * (1.0 + 3.0 * u.abs()).sqrt();
    std::hint::select_unpredictable(u >= 0.0, half, 1.0 - half)
}

/// The inverse of [`uv_to_st`].
#[inline]
pub fn st_to_uv(s: f64) -> f64 {
    if s >= 0.5 {
        (4.0 * s * s - 1.0) / 3.0
    } else {
        (1.0 - 4.0 * (1.0 - s) * (1.0 - s)) / 3.0
    }
}

/// Leaf-cell coordinate (0 ..= 2^30 − 1) of `s` in [0, 1].
#[inline(always)]
fn st_to_ij(s: f64) -> u32 {
    const MAX_SIZE: f64 = (1u64 << S2_MAX_LEVEL) as f64;
    // s ≥ 0, so truncation is the floor; `as` saturates (NaN → 0), and the clamp keeps s = 1
    // inside the face.
    ((MAX_SIZE * s) as u32).min((1 << S2_MAX_LEVEL) - 1)
}

/// The S2 leaf-cell id of the direction `p` (any non-zero length; it is not normalised).
///
/// A zero or NaN vector gives an unspecified id; callers filter those first.
#[inline(always)]
pub fn cell_id(p: [f64; 3]) -> u64 {
    let (f, i, j) = face_ij(p);
    from_face_ij(f, i, j)
}

/// The id of the S2 cell at level `4 · steps − 2` (1 ≤ steps ≤ 8) that contains `p`, with the
/// bits below that level zero: a cheaper key that sorts like [`cell_id`] (the id of any
/// point is at least the prefix of its own cell and below the next cell's prefix). Each step
/// is one table lookup; the first covers the two top levels.
#[inline(always)]
pub fn cell_id_prefix(p: [f64; 3], steps: u32) -> u64 {
    let (f, i, j) = face_ij(p);
    hilbert(f, i, j, steps)
}

/// Cube face and leaf coordinates of `p`.
#[inline(always)]
fn face_ij(p: [f64; 3]) -> (u8, u32, u32) {
    let (f, u, v) = face_uv(p);
    (f, st_to_ij(uv_to_st(u)), st_to_ij(uv_to_st(v)))
}

/// The S2 leaf-cell id of face `face` (0–5) and leaf coordinates `i`, `j` (< 2^30).
#[inline(always)]
pub fn from_face_ij(face: u8, i: u32, j: u32) -> u64 {
    hilbert(face, i, j, 2 * LOOKUP_BITS) | 1
}

/// Face bits and the first `4 · steps − 2` levels of the Hilbert position, shifted into place.
#[inline(always)]
fn hilbert(face: u8, i: u32, j: u32, steps: u32) -> u64 {
    let mut position = 0u64;
    let mut bits = u16::from(face) & SWAP_MASK;
    let mask = (1u32 << LOOKUP_BITS) - 1;
    let mut k = 2 * LOOKUP_BITS;
    while k > 2 * LOOKUP_BITS - steps {
        k -= 1;
        let i4 = ((i >> (k * LOOKUP_BITS)) & mask) as u16;
        let j4 = ((j >> (k * LOOKUP_BITS)) & mask) as u16;
        bits = LOOKUP_POS[usize::from((i4 << 6) | (j4 << 2) | bits)];
        position |= u64::from(bits >> 2) << (2 * LOOKUP_BITS * k);
        bits &= SWAP_MASK | INVERT_MASK;
    }
    (u64::from(face) << 61) | (position << 1)
}

/// The cube face stored in the top 3 bits of an id.
#[inline]
pub fn id_face(id: u64) -> u8 {
    (id >> 61) as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axes_land_on_their_faces() {
        assert_eq!(face([1.0, 0.0, 0.0]), 0);
        assert_eq!(face([0.0, 1.0, 0.0]), 1);
        assert_eq!(face([0.0, 0.0, 1.0]), 2);
        assert_eq!(face([-1.0, 0.0, 0.0]), 3);
        assert_eq!(face([0.0, -1.0, 0.0]), 4);
        assert_eq!(face([0.0, 0.0, -1.0]), 5);
        for f in 0..6u8 {
            let mut p = [0.0; 3];
            p[usize::from(f % 3)] = if f < 3 { 1.0 } else { -1.0 };
            assert_eq!(id_face(cell_id(p)), f);
        }
    }

    #[test]
    fn face_centre_is_the_middle_of_the_hilbert_curve() {
        // i = j = 2^29 lies in the level-1 child with i bit 1 and j bit 1, which the curve of
        // face 0 (no swap) visits third: Hilbert position 2 in the top two position bits.
        let id = cell_id([1.0, 0.0, 0.0]);
        assert_eq!(id & 1, 1);
        assert_eq!(id_face(id), 0);
        assert_eq!((id >> 59) & 3, 2);
    }

    #[test]
    fn prefixes_bracket_the_full_id() {
        let p = [0.3, -0.7, 0.2];
        let id = cell_id(p);
        for steps in 1..=8 {
            let prefix = cell_id_prefix(p, steps);
            assert!(prefix <= id);
            assert!(id - prefix < 1 << (65 - 8 * steps));
        }
        assert_eq!(cell_id_prefix(p, 8) | 1, id);
    }

    #[test]
    fn face_st_to_point_inverts_face_uv() {
        for f in 0..6u8 {
            for (s, t) in [(0.5, 0.5), (0.1, 0.9), (0.97, 0.03), (0.3, 0.6)] {
                let p = face_st_to_point(f, s, t);
                assert!(((p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) - 1.0).abs() < 1e-15);
                let (face, u, v) = face_uv(p);
                assert_eq!(face, f);
                assert!((uv_to_st(u) - s).abs() < 1e-14, "face {f} s {s}");
                assert!((uv_to_st(v) - t).abs() < 1e-14, "face {f} t {t}");
            }
        }
    }

    #[test]
    fn quadratic_transform_maps_the_face_edges() {
        assert_eq!(uv_to_st(-1.0), 0.0);
        assert_eq!(uv_to_st(0.0), 0.5);
        assert_eq!(uv_to_st(1.0), 1.0);
        for u in [-1.0, -0.4, 0.0, 0.25, 1.0] {
            assert!((st_to_uv(uv_to_st(u)) - u).abs() < 1e-15);
        }
        assert_eq!(st_to_ij(1.0), (1 << 30) - 1);
        assert_eq!(st_to_ij(0.0), 0);
    }
}
