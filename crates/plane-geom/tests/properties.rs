//! Properties of the frame, the plane and the eigen routines against independent oracles:
//! identities computed another way (Lagrange's identity, the triple product, trace and
//! determinant), matrices built from known eigenpairs, and the defining equation
//! `A v = λ v`.
#![allow(clippy::unwrap_used)]

use plane_geom::vec3::{add, cross, dot, norm, scale, sub, unit};
use plane_geom::{Plane, PlaneFrame, symmetric_eigen, symmetric_eigenvalues};
use proptest::prelude::*;

fn coord() -> impl Strategy<Value = f64> {
    -100.0f64..100.0
}

fn vector() -> impl Strategy<Value = [f64; 3]> {
    [coord(), coord(), coord()]
}

/// A direction not too close to zero (so its unit is well conditioned).
fn direction() -> impl Strategy<Value = [f64; 3]> {
    vector().prop_filter("non-zero", |v| norm(*v) > 1e-3)
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + a.abs().max(b.abs()))
}

/// The 3 × 3 determinant by cofactors along the first row.
fn det(m: [[f64; 3]; 3]) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

fn mat_vec(m: [[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    [dot(m[0], v), dot(m[1], v), dot(m[2], v)]
}

/// `Σ λᵢ uᵢ uᵢᵀ` for orthonormal `u`: a symmetric matrix with known eigenpairs.
fn from_eigenpairs(values: [f64; 3], u: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let mut m = [[0.0; 3]; 3];
    for k in 0..3 {
        for i in 0..3 {
            for j in 0..3 {
                m[i][j] += values[k] * u[k][i] * u[k][j];
            }
        }
    }
    m
}

proptest! {
    #[test]
    fn vector_identities(a in vector(), b in vector()) {
        // Lagrange's identity |a × b|² = |a|²|b|² − (a·b)², and a × b ⟂ a, b.
        let c = cross(a, b);
        let scale_ab = dot(a, a) * dot(b, b);
        prop_assert!((dot(c, c) - (scale_ab - dot(a, b) * dot(a, b))).abs() <= 1e-9 * (1.0 + scale_ab));
        prop_assert!(dot(c, a).abs() <= 1e-9 * (1.0 + norm(c) * norm(a)));
        prop_assert_eq!(sub(add(a, b), b).map(|x| (x * 1e6).round()), a.map(|x| (x * 1e6).round()));
        prop_assert_eq!(scale(a, 2.0), add(a, a));
        if let Some(u) = unit(a) {
            prop_assert!(close(norm(u), 1.0, 1e-15));
            prop_assert!(close(dot(u, a), norm(a), 1e-12));
        }
    }

    #[test]
    fn frame_is_orthonormal_right_handed_and_isometric(
        n in direction(), origin in vector(), p in vector(), r in vector(), s in vector(),
    ) {
        let f = PlaneFrame::new(n).unwrap().with_origin(origin);
        let u = unit(n).unwrap();
        prop_assert_eq!(f.normal, u);
        for (a, b, want) in [(f.e1, f.e1, 1.0), (f.e2, f.e2, 1.0), (f.e1, f.e2, 0.0), (f.e1, u, 0.0), (f.e2, u, 0.0)] {
            prop_assert!(close(dot(a, b), want, 1e-14));
        }
        // Right-handed: the triple product e1 · (e2 × n) is +1.
        prop_assert!(close(dot(f.e1, cross(f.e2, u)), 1.0, 1e-14));
        // lift ∘ project is the orthogonal projection onto the plane through origin.
        let on_plane = sub(p, scale(u, dot(sub(p, origin), u)));
        let back = f.lift(f.project(p));
        prop_assert!(norm(sub(back, on_plane)) <= 1e-10 * (1.0 + norm(p) + norm(origin)));
        // project ∘ lift is the identity.
        let q = [p[0], p[1]];
        let q2 = f.project(f.lift(q));
        prop_assert!(close(q2[0], q[0], 1e-12) && close(q2[1], q[1], 1e-12));
        // The projection is an isometry of the plane, and preserves orientation as seen
        // from the normal's side: 2D signed area equals the 3D one along n.
        let (a3, b3, c3) = (f.lift([p[0], p[1]]), f.lift([r[0], r[1]]), f.lift([s[0], s[1]]));
        let (a2, b2, c2) = (f.project(a3), f.project(b3), f.project(c3));
        let d2 = ((b2[0] - a2[0]).powi(2) + (b2[1] - a2[1]).powi(2)).sqrt();
        prop_assert!(close(d2, norm(sub(b3, a3)), 1e-10));
        let area2 = (b2[0] - a2[0]) * (c2[1] - a2[1]) - (b2[1] - a2[1]) * (c2[0] - a2[0]);
        let area3 = dot(cross(sub(b3, a3), sub(c3, a3)), u);
        prop_assert!((area2 - area3).abs() <= 1e-8 * (1.0 + area3.abs()));
        prop_assert!(f.signed_distance(add(origin, scale(u, 2.5))) - 2.5 <= 1e-12);
    }

    #[test]
    fn plane_distances_match_the_construction(n in direction(), point in vector(), t in -50.0f64..50.0, p in vector()) {
        let plane = Plane::from_normal_and_point(n, point).unwrap();
        let u = unit(n).unwrap();
        // A point t along the normal from a point on the plane is at signed distance t.
        prop_assert!((plane.signed_distance(add(point, scale(u, t))) - t).abs() <= 1e-10 * (1.0 + norm(point)));
        let proj = plane.project(p);
        prop_assert!(plane.signed_distance(proj).abs() <= 1e-10 * (1.0 + norm(p) + norm(point)));
        prop_assert!(close(plane.flipped().signed_distance(p), -plane.signed_distance(p), 1e-15));
        let f = plane.frame();
        prop_assert!(plane.signed_distance(f.origin).abs() <= 1e-10 * (1.0 + norm(point)));
        prop_assert!(plane.signed_distance(f.lift([t, -t])).abs() <= 1e-10 * (1.0 + norm(point) + t.abs()));
    }

    #[test]
    fn eigen_recovers_known_eigenpairs(
        values in [-10.0f64..10.0, -10.0f64..10.0, -10.0f64..10.0],
        a in direction(), b in direction(),
    ) {
        // An orthonormal basis from two random directions (Gram–Schmidt).
        let u0 = unit(a).unwrap();
        let Some(u1) = unit(sub(b, scale(u0, dot(b, u0)))) else { return Ok(()); };
        let u2 = cross(u0, u1);
        let m = from_eigenpairs(values, [u0, u1, u2]);
        let e = symmetric_eigen(m).unwrap();
        let mut want = values;
        want.sort_by(f64::total_cmp);
        for k in 0..3 {
            prop_assert!((e.values[k] - want[k]).abs() <= 1e-9, "{:?} vs {:?}", e.values, want);
            // The defining equation A v = λ v, and unit length.
            let v = e.vectors[k];
            prop_assert!(close(norm(v), 1.0, 1e-12));
            prop_assert!(norm(sub(mat_vec(m, v), scale(v, e.values[k]))) <= 1e-9);
        }
        // Trace and determinant, computed from the matrix directly.
        let trace = m[0][0] + m[1][1] + m[2][2];
        prop_assert!((e.values.iter().sum::<f64>() - trace).abs() <= 1e-9);
        prop_assert!((e.values.iter().product::<f64>() - det(m)).abs() <= 1e-7);
        // The closed form agrees with the solver.
        let closed = symmetric_eigenvalues([m[0][0], m[1][1], m[2][2], m[0][1], m[0][2], m[1][2]]);
        for k in 0..3 {
            prop_assert!((closed[k] - e.values[k]).abs() <= 1e-6, "{:?} vs {:?}", closed, e.values);
        }
    }
}
