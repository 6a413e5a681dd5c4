//! Our S2 cell ids against the `s2` crate's.

mod common;

use common::{normalize, random_units};
use fastga::s2id;
use proptest::prelude::*;
use s2::cellid::CellID;
use s2::point::Point;
use s2::r3::vector::Vector;

fn reference(p: [f64; 3]) -> u64 {
    CellID::from(&Point(Vector {
        x: p[0],
        y: p[1],
        z: p[2],
    }))
    .0
}

#[test]
fn random_unit_vectors_get_the_s2_crate_ids() {
    for p in random_units(5, 100_000) {
        assert_eq!(s2id::cell_id(p), reference(p), "{p:?}");
    }
}

#[test]
fn axes_seams_and_corners_get_the_s2_crate_ids() {
    let values = [-1.0, -0.5, -1e-9, 0.0, 1e-9, 0.5, 1.0];
    for a in values {
        for b in values {
            for c in values {
                if a != 0.0 || b != 0.0 || c != 0.0 {
                    for p in [[a, b, c], normalize([a, b, c])] {
                        assert_eq!(s2id::cell_id(p), reference(p), "{p:?}");
                    }
                }
            }
        }
    }
}

#[test]
fn icosahedron_cells_are_in_s2_order() {
    let ico = fastga::Icosahedron::new(4).unwrap();
    for (&id, &n) in ico.cell_ids().iter().zip(ico.normals()) {
        assert_eq!(id, reference(n));
    }
}

proptest! {
    #[test]
    fn any_direction_gets_the_s2_crate_id(
        x in -1.0f64..1.0, y in -1.0f64..1.0, z in -1.0f64..1.0, scale in 0.01f64..100.0,
    ) {
        prop_assume!(x * x + y * y + z * z > 1e-12);
        let p = [x * scale, y * scale, z * scale];
        prop_assert_eq!(s2id::cell_id(p), reference(p));
        prop_assert_eq!(s2id::id_face(s2id::cell_id(p)), s2id::face(p));
    }
}
