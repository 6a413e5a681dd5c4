//! Builder scenes: label layout, plane equations, validation errors.

use synthscan::{
    FLOOR_LABEL, FloorBox, RampsConfig, RandomPolyhedraConfig, RoomConfig, Scene, SceneError,
    StairsConfig, TableConfig,
};

fn close(a: [f64; 3], b: [f64; 3]) -> bool {
    (0..3).all(|k| (a[k] - b[k]).abs() < 1e-12)
}

#[test]
fn room_layout() -> Result<(), SceneError> {
    let scene = Scene::room(&RoomConfig::default())?;
    let gt = scene.ground_truth();
    // floor, 4 walls, ceiling, table top (6), legs (4 × 4), obstacle (5).
    assert_eq!(gt.len(), 6 + 6 + 16 + 5);
    assert_eq!(gt[0].label, FLOOR_LABEL);
    assert!(close(gt[0].normal, [0.0, 0.0, 1.0]));
    // Four legs and the obstacle are cut out of the floor.
    assert_eq!(gt[0].polygons[0].holes.len(), 5);
    let floor_area = scene.label_areas()[0].1;
    let expected = 30.0 - 4.0 * 0.06 * 0.06 - 0.36;
    assert!((floor_area - expected).abs() < 1e-9);
    // Walls and ceiling face into the room (centre at (3, 2.5, 1.5)).
    for p in &gt[1..6] {
        let centre_side: f64 = p.normal[0] * 3.0 + p.normal[1] * 2.5 + p.normal[2] * 1.5 - p.offset;
        assert!(centre_side > 0.0);
    }
    let bare = Scene::room(
        &RoomConfig::default()
            .with_ceiling(false)
            .with_table(None)
            .with_obstacle(None),
    )?;
    assert_eq!(bare.faces().len(), 5);
    Ok(())
}

#[test]
fn room_rejects_bad_placements() {
    let outside = RoomConfig::default().with_obstacle(Some(FloorBox {
        center: [5.9, 1.0],
        size: [0.5, 0.5, 0.5],
    }));
    assert!(matches!(
        Scene::room(&outside),
        Err(SceneError::Placement {
            what: "obstacle",
            ..
        })
    ));
    let on_leg = RoomConfig::default().with_obstacle(Some(FloorBox {
        center: [1.5, 2.2],
        size: [0.3, 0.3, 0.3],
    }));
    assert!(Scene::room(&on_leg).is_err());
    let into_top = RoomConfig::default().with_obstacle(Some(FloorBox {
        center: [2.0, 2.5],
        size: [0.3, 0.3, 0.9],
    }));
    assert!(Scene::room(&into_top).is_err());
    let under_table = RoomConfig::default().with_obstacle(Some(FloorBox {
        center: [2.0, 2.5],
        size: [0.3, 0.3, 0.4],
    }));
    assert!(Scene::room(&under_table).is_ok());
    let mut fat_legged_table = TableConfig::default();
    fat_legged_table.leg_width = 0.5;
    let fat_legs = RoomConfig::default().with_table(Some(fat_legged_table));
    assert!(Scene::room(&fat_legs).is_err());
    assert!(Scene::room(&RoomConfig::default().with_size([6.0, f64::NAN, 3.0])).is_err());
}

#[test]
fn stairs_planes() -> Result<(), SceneError> {
    let c = StairsConfig::default();
    let gt = Scene::stairs(&c)?.ground_truth();
    assert_eq!(gt.len(), 1 + 2 * c.steps + 3);
    for i in 0..c.steps {
        let riser = &gt[1 + 2 * i];
        let tread = &gt[2 + 2 * i];
        assert!(close(riser.normal, [-1.0, 0.0, 0.0]));
        assert!((riser.offset + i as f64 * c.tread_depth).abs() < 1e-12);
        assert!(close(tread.normal, [0.0, 0.0, 1.0]));
        assert!((tread.offset - (i + 1) as f64 * c.riser_height).abs() < 1e-12);
    }
    // The sides are non-convex staircase profiles facing out.
    let sides = &gt[gt.len() - 2..];
    assert!(close(sides[0].normal, [0.0, -1.0, 0.0]));
    assert!(close(sides[1].normal, [0.0, 1.0, 0.0]));
    assert_eq!(sides[0].polygons[0].shell.len(), 2 * c.steps + 2);
    let mut no_margin = c;
    no_margin.floor_margin = 0.0;
    let no_floor = Scene::stairs(&no_margin)?;
    assert_eq!(no_floor.faces().len(), 2 * c.steps + 3);
    let mut no_steps = c;
    no_steps.steps = 0;
    assert!(Scene::stairs(&no_steps).is_err());
    Ok(())
}

#[test]
fn ramp_slopes() -> Result<(), SceneError> {
    let c = RampsConfig::default();
    let gt = Scene::ramps(&c)?.ground_truth();
    assert_eq!(gt.len(), 1 + 4 * c.angles_deg.len());
    for (i, a) in c.angles_deg.iter().enumerate() {
        let slope = &gt[4 * i + 4];
        let (s, co) = a.to_radians().sin_cos();
        assert!((slope.normal[0] + s).abs() < 1e-12, "ramp {i}");
        assert!((slope.normal[2] - co).abs() < 1e-12, "ramp {i}");
        assert!(
            slope.offset.abs() < 1e-12,
            "every slope starts at x = 0, z = 0"
        );
    }
    let mut bad = c.clone();
    bad.angles_deg = vec![10.0, 95.0];
    assert!(Scene::ramps(&bad).is_err());
    let mut no_gap = c;
    no_gap.gap = 0.0;
    assert!(Scene::ramps(&no_gap).is_err());
    Ok(())
}

#[test]
fn random_polyhedra_fit_in_the_room() -> Result<(), SceneError> {
    for seed in 0..20 {
        let config = RandomPolyhedraConfig::default().with_seed(seed);
        let scene = Scene::random_polyhedra(&config)?;
        let [w, d, h] = config.room_size;
        for f in &scene.faces()[6..] {
            let (lo, hi) = f.bounding_box();
            assert!(lo[0] > 0.0 && lo[1] > 0.0 && lo[2] >= -1e-12, "seed {seed}");
            assert!(hi[0] < w && hi[1] < d && hi[2] < h, "seed {seed}");
        }
        // Room shell, then 3 to 9 visible faces per object.
        let n = scene.ground_truth().len();
        assert!(
            n >= 6 + 3 * config.objects && n <= 6 + 10 * config.objects,
            "seed {seed}: {n}"
        );
        assert!(
            scene
                .faces()
                .iter()
                .any(|f| f.normal()[2].abs() < 0.99 && f.normal()[2].abs() > 0.01),
            "seed {seed}: no tilted face"
        );
    }
    Ok(())
}

#[test]
fn random_polyhedra_errors() {
    let crowded = RandomPolyhedraConfig::default().with_objects(200);
    assert!(matches!(
        Scene::random_polyhedra(&crowded),
        Err(SceneError::PlacementFailed { requested: 200, .. })
    ));
    let mut bad = RandomPolyhedraConfig::default();
    bad.tilted_fraction = 1.5;
    assert!(Scene::random_polyhedra(&bad).is_err());
    let mut bad = RandomPolyhedraConfig::default();
    bad.size_range = [1.0, 0.5];
    assert!(Scene::random_polyhedra(&bad).is_err());
}
