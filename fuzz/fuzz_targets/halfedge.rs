//! Half-edge meshes from arbitrary triangles under every non-manifold and degenerate
//! policy: a mesh that builds passes `sanity_check`.
#![no_main]

use halfedge_mesh::{DegeneratePolicy, HalfEdgeMesh, MeshOptions, NonManifoldPolicy};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let [policy, nv, rest @ ..] = data else {
        return;
    };
    let nv = usize::from(*nv % 32) + 1;
    // Vertices on a small integer grid (coincident and collinear points are common).
    let (coords, tris) = rest.split_at((nv * 3).min(rest.len()));
    let vertices: Vec<[f64; 3]> = coords
        .chunks_exact(3)
        .map(|c| {
            [
                f64::from(c[0] as i8 % 5),
                f64::from(c[1] as i8 % 5),
                f64::from(c[2] as i8 % 3),
            ]
        })
        .collect();
    let triangles: Vec<[u32; 3]> = tris
        .chunks_exact(3)
        .map(|t| {
            [
                u32::from(t[0] % 40),
                u32::from(t[1] % 40),
                u32::from(t[2] % 40),
            ]
        })
        .collect();
    let non_manifold = match policy % 3 {
        0 => NonManifoldPolicy::KeepFirst,
        1 => NonManifoldPolicy::MostSimilarNormals,
        _ => NonManifoldPolicy::AllBorder,
    };
    let degenerate = if policy & 4 == 0 {
        DegeneratePolicy::Error
    } else {
        DegeneratePolicy::Drop
    };
    let options = MeshOptions::new()
        .non_manifold(non_manifold)
        .degenerate(degenerate);
    if let Ok((mesh, _)) = HalfEdgeMesh::from_triangles_with_options(vertices, triangles, options) {
        if let Err(e) = mesh.sanity_check() {
            panic!("a built mesh fails its sanity check: {e}");
        }
    }
});
