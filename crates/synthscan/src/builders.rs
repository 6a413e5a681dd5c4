//! Ready-made scenes: a room with a table and an obstacle, stairs, ramps, and a room with
//! random polyhedra (SynPEB-like).

use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};

use crate::error::{SceneError, non_negative, positive};
use crate::scene::Scene;
use crate::solid::Solid;
use crate::vec3::{V3, add, cross, dot};
use plane_geom::Polygon3;

/// The floor's label in every builder scene that has a floor.
pub const FLOOR_LABEL: i32 = 0;

/// An axis-aligned box standing on the floor (metres).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FloorBox {
    /// Centre of the footprint `[x, y]`.
    pub center: [f64; 2],
    /// Size `[x, y, z]`.
    pub size: [f64; 3],
}

/// A table: a box top on four square box legs (metres).
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct TableConfig {
    /// Centre of the top's footprint `[x, y]` (default `[2.0, 2.5]`).
    pub center: [f64; 2],
    /// Size of the top `[x, y]` (default `[1.2, 0.8]`).
    pub top_size: [f64; 2],
    /// Height of the top surface above the floor (default 0.75).
    pub height: f64,
    /// Thickness of the top (default 0.05).
    pub top_thickness: f64,
    /// Side of the square legs (default 0.06).
    pub leg_width: f64,
    /// Distance from the top's edges to the legs' outer faces (default 0.05).
    pub leg_inset: f64,
}

impl Default for TableConfig {
    fn default() -> Self {
        Self {
            center: [2.0, 2.5],
            top_size: [1.2, 0.8],
            height: 0.75,
            top_thickness: 0.05,
            leg_width: 0.06,
            leg_inset: 0.05,
        }
    }
}

/// A rectangular room with an optional ceiling, table and obstacle box (metres).
///
/// The room spans `[0, size.x] × [0, size.y] × [0, size.z]`, z up.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct RoomConfig {
    /// Room size `[x, y, z]` (default `[6.0, 5.0, 3.0]`).
    pub size: [f64; 3],
    /// Whether the room has a ceiling (default `true`).
    pub ceiling: bool,
    /// The table (default: [`TableConfig::default`]).
    pub table: Option<TableConfig>,
    /// A box on the floor (default: 0.6 × 0.6 × 0.5 at `[4.5, 1.5]`).
    pub obstacle: Option<FloorBox>,
}

impl Default for RoomConfig {
    fn default() -> Self {
        Self {
            size: [6.0, 5.0, 3.0],
            ceiling: true,
            table: Some(TableConfig::default()),
            obstacle: Some(FloorBox {
                center: [4.5, 1.5],
                size: [0.6, 0.6, 0.5],
            }),
        }
    }
}

impl RoomConfig {
    /// Sets the room size.
    pub fn with_size(mut self, size: [f64; 3]) -> Self {
        self.size = size;
        self
    }
    /// Sets whether there is a ceiling.
    pub fn with_ceiling(mut self, ceiling: bool) -> Self {
        self.ceiling = ceiling;
        self
    }
    /// Sets the table (`None`: no table).
    pub fn with_table(mut self, table: Option<TableConfig>) -> Self {
        self.table = table;
        self
    }
    /// Sets the obstacle (`None`: no obstacle).
    pub fn with_obstacle(mut self, obstacle: Option<FloorBox>) -> Self {
        self.obstacle = obstacle;
        self
    }
}

/// A straight staircase rising along `+x` from `x = 0`, spanning `y ∈ [0, width]` (metres).
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct StairsConfig {
    /// Number of steps (default 4).
    pub steps: usize,
    /// Horizontal depth of each tread (default 0.3).
    pub tread_depth: f64,
    /// Height of each riser (default 0.18).
    pub riser_height: f64,
    /// Width of the stairs (default 1.0).
    pub width: f64,
    /// Floor around the stairs out to this distance; 0 for no floor (default 1.0).
    pub floor_margin: f64,
}

impl Default for StairsConfig {
    fn default() -> Self {
        Self {
            steps: 4,
            tread_depth: 0.3,
            riser_height: 0.18,
            width: 1.0,
            floor_margin: 1.0,
        }
    }
}

/// Ramps (wedges) side by side along `+y`, each rising along `+x` from `x = 0` to
/// `x = run` at its angle (metres, degrees).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct RampsConfig {
    /// Slope of each ramp in degrees, each in `(0, 80]` (default `[10, 20, 30, 45]`).
    pub angles_deg: Vec<f64>,
    /// Horizontal run of each ramp (default 1.5).
    pub run: f64,
    /// Width of each ramp along y (default 1.0).
    pub width: f64,
    /// Gap between ramps (default 0.5, must be `> 0` with a floor).
    pub gap: f64,
    /// Floor around the ramps out to this distance; 0 for no floor (default 1.0).
    pub floor_margin: f64,
}

impl Default for RampsConfig {
    fn default() -> Self {
        Self {
            angles_deg: vec![10.0, 20.0, 30.0, 45.0],
            run: 1.5,
            width: 1.0,
            gap: 0.5,
            floor_margin: 1.0,
        }
    }
}

/// A room populated with random polyhedra (boxes, wedges, prisms; some tilted), like the
/// SynPEB benchmark scenes. Metres and degrees; z up, room `[0, x] × [0, y] × [0, z]`.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct RandomPolyhedraConfig {
    /// Seed (default 0).
    pub seed: u64,
    /// Room size `[x, y, z]` (default `[6.0, 5.0, 3.0]`).
    pub room_size: [f64; 3],
    /// Whether the room has a ceiling (default `true`).
    pub ceiling: bool,
    /// Number of objects (default 22).
    pub objects: usize,
    /// Range of object dimensions `[min, max]` (default `[0.2, 0.75]`).
    pub size_range: [f64; 2],
    /// Fraction of objects tilted off the vertical, in `[0, 1]` (default 0.3).
    pub tilted_fraction: f64,
    /// Largest tilt in degrees, in `[0, 90]` (default 35).
    pub max_tilt_deg: f64,
    /// Smallest horizontal clearance between objects, and to the walls (default 0.1).
    pub gap: f64,
    /// Discs `([x, y], radius)` kept free of objects, e.g. around a sensor (default: the
    /// spot under the sensor of [`crate::synpeb_like`], `([0.5, 2.5], 1.0)`).
    pub keep_clear: Vec<([f64; 2], f64)>,
}

impl Default for RandomPolyhedraConfig {
    fn default() -> Self {
        Self {
            seed: 0,
            room_size: [6.0, 5.0, 3.0],
            ceiling: true,
            objects: 22,
            size_range: [0.2, 0.75],
            tilted_fraction: 0.3,
            max_tilt_deg: 35.0,
            gap: 0.1,
            keep_clear: vec![([0.5, 2.5], 1.0)],
        }
    }
}

impl RandomPolyhedraConfig {
    /// Sets the seed.
    pub fn with_seed(mut self, seed: u64) -> Self {
        self.seed = seed;
        self
    }
    /// Sets the number of objects.
    pub fn with_objects(mut self, objects: usize) -> Self {
        self.objects = objects;
        self
    }
}

/// A rectangle `p0, p0 + e1, p0 + e1 + e2, p0 + e2` (normal along `e1 × e2`).
fn rect(p0: V3, e1: V3, e2: V3) -> Vec<V3> {
    vec![p0, add(p0, e1), add(add(p0, e1), e2), add(p0, e2)]
}

/// Reverses `ring` if its normal does not point along `want`.
fn oriented(mut ring: Vec<V3>, want: V3) -> Vec<V3> {
    let mut n = [0.0; 3];
    for i in 0..ring.len() {
        n = add(n, cross(ring[i], ring[(i + 1) % ring.len()]));
    }
    if dot(n, want) < 0.0 {
        ring.reverse();
    }
    ring
}

/// Footprint rectangle `[x0, x1] × [y0, y1]`.
type Rect = [f64; 4];

fn overlaps(a: Rect, b: Rect) -> bool {
    a[0] <= b[1] && b[0] <= a[1] && a[2] <= b[3] && b[2] <= a[3]
}

fn inside(a: Rect, size: [f64; 3]) -> bool {
    a[0] > 0.0 && a[1] < size[0] && a[2] > 0.0 && a[3] < size[1]
}

fn floor_ring(r: Rect) -> Vec<V3> {
    rect(
        [r[0], r[2], 0.0],
        [r[1] - r[0], 0.0, 0.0],
        [0.0, r[3] - r[2], 0.0],
    )
}

/// Adds floor (label 0, with `holes`), four walls facing in, and an optional ceiling.
pub(crate) fn add_shell(
    scene: &mut Scene,
    size: [f64; 3],
    ceiling: bool,
    holes: Vec<Vec<V3>>,
) -> Result<(), SceneError> {
    let [w, d, h] = size;
    let floor = Polygon3 {
        shell: floor_ring([0.0, w, 0.0, d]),
        holes,
    };
    scene.add_polygon(FLOOR_LABEL, floor)?;
    let walls = [
        rect([0.0, 0.0, 0.0], [0.0, 0.0, h], [w, 0.0, 0.0]),
        rect([w, 0.0, 0.0], [0.0, 0.0, h], [0.0, d, 0.0]),
        rect([0.0, d, 0.0], [w, 0.0, 0.0], [0.0, 0.0, h]),
        rect([0.0, 0.0, 0.0], [0.0, d, 0.0], [0.0, 0.0, h]),
    ];
    for ring in walls {
        let label = scene.next_label();
        scene.add_polygon(label, Polygon3::from_shell(ring))?;
    }
    if ceiling {
        let label = scene.next_label();
        scene.add_polygon(
            label,
            Polygon3::from_shell(rect([0.0, 0.0, h], [0.0, d, 0.0], [w, 0.0, 0.0])),
        )?;
    }
    Ok(())
}

fn check_size3(name: &'static str, size: [f64; 3]) -> Result<(), SceneError> {
    for v in size {
        positive(name, v)?;
    }
    Ok(())
}

impl Scene {
    /// A closed room with an optional table and an obstacle box on the floor.
    ///
    /// Labels: floor 0 ([`FLOOR_LABEL`]), walls 1–4 (`y = 0`, `x = max`, `y = max`,
    /// `x = 0`), ceiling 5 if present, then the table top's six faces, the legs' four sides
    /// each, and the obstacle's top and sides, in that order. Walls and ceiling face into
    /// the room. The legs and the obstacle cut their footprints out of the floor, so a
    /// floor seen from above has a hole where the obstacle stands.
    ///
    /// # Errors
    /// Non-positive sizes, objects outside the room or touching its walls, legs too big
    /// for the top, an obstacle overlapping a leg or reaching into the table top.
    pub fn room(config: &RoomConfig) -> Result<Scene, SceneError> {
        check_size3("size", config.size)?;
        let [w, d, h] = config.size;
        let mut solids: Vec<(Solid, bool)> = Vec::new();
        let mut holes = Vec::new();
        let mut leg_rects = Vec::new();
        let mut top_rect = None;
        if let Some(t) = &config.table {
            let [lx, ly] = t.top_size;
            positive("table.top_size", lx)?;
            positive("table.top_size", ly)?;
            positive("table.top_thickness", t.top_thickness)?;
            positive("table.leg_width", t.leg_width)?;
            non_negative("table.leg_inset", t.leg_inset)?;
            let under = positive("table.height", t.height)? - t.top_thickness;
            if under <= 0.0 || t.height >= h {
                return Err(SceneError::Placement {
                    what: "table",
                    reason: "its height must exceed the top thickness and be below the ceiling",
                });
            }
            if 2.0 * (t.leg_inset + t.leg_width) >= lx.min(ly) {
                return Err(SceneError::Placement {
                    what: "table",
                    reason: "legs and inset take up the whole top",
                });
            }
            let r = [
                t.center[0] - lx / 2.0,
                t.center[0] + lx / 2.0,
                t.center[1] - ly / 2.0,
                t.center[1] + ly / 2.0,
            ];
            if !inside(r, config.size) {
                return Err(SceneError::Placement {
                    what: "table",
                    reason: "its top must lie strictly inside the room",
                });
            }
            top_rect = Some((r, under));
            let top = Solid::cuboid([lx, ly, t.top_thickness])?.translated([
                t.center[0],
                t.center[1],
                under,
            ]);
            solids.push((top, false));
            let off = [
                lx / 2.0 - t.leg_inset - t.leg_width / 2.0,
                ly / 2.0 - t.leg_inset - t.leg_width / 2.0,
            ];
            for (sx, sy) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                let (cx, cy) = (t.center[0] + sx * off[0], t.center[1] + sy * off[1]);
                let leg =
                    Solid::cuboid([t.leg_width, t.leg_width, under])?.translated([cx, cy, 0.0]);
                let hw = t.leg_width / 2.0;
                leg_rects.push([cx - hw, cx + hw, cy - hw, cy + hw]);
                holes.extend(leg.footprint());
                solids.push((leg, true));
            }
        }
        if let Some(o) = &config.obstacle {
            check_size3("obstacle.size", o.size)?;
            let r = [
                o.center[0] - o.size[0] / 2.0,
                o.center[0] + o.size[0] / 2.0,
                o.center[1] - o.size[1] / 2.0,
                o.center[1] + o.size[1] / 2.0,
            ];
            if !inside(r, config.size) || o.size[2] >= h {
                return Err(SceneError::Placement {
                    what: "obstacle",
                    reason: "it must lie strictly inside the room and below the ceiling",
                });
            }
            if leg_rects.iter().any(|&l| overlaps(l, r)) {
                return Err(SceneError::Placement {
                    what: "obstacle",
                    reason: "it overlaps or touches a table leg",
                });
            }
            if top_rect.is_some_and(|(t, under)| overlaps(t, r) && o.size[2] >= under) {
                return Err(SceneError::Placement {
                    what: "obstacle",
                    reason: "it reaches into the table top",
                });
            }
            let b = Solid::cuboid(o.size)?.translated([o.center[0], o.center[1], 0.0]);
            holes.extend(b.footprint());
            solids.push((b, true));
        }
        let mut scene = Scene::new();
        add_shell(&mut scene, [w, d, h], config.ceiling, holes)?;
        for (i, (solid, resting)) in solids.iter().enumerate() {
            let is_leg = config.table.is_some() && (1..=4).contains(&i);
            if is_leg {
                // A leg's top is hidden inside the table top: add its sides only.
                for ring in solid.face_rings() {
                    let vertical = {
                        let mut n = [0.0; 3];
                        for k in 0..ring.len() {
                            n = add(n, cross(ring[k], ring[(k + 1) % ring.len()]));
                        }
                        n[2].abs() < 1e-12 * dot(n, n).sqrt()
                    };
                    if vertical {
                        let label = scene.next_label();
                        scene.add_polygon(label, Polygon3::from_shell(ring))?;
                    }
                }
            } else {
                scene.add_solid(solid, *resting)?;
            }
        }
        Ok(scene)
    }

    /// A straight staircase (see [`StairsConfig`]) on an optional floor.
    ///
    /// Labels: floor 0 if `floor_margin > 0`, then riser 0, tread 0, riser 1, tread 1, …
    /// (risers face `−x`, treads up), then the back (`+x`) and the two sides (`−y`, `+y`;
    /// non-convex staircase profiles). The stairs' footprint is cut out of the floor.
    ///
    /// # Errors
    /// Zero steps or non-positive sizes.
    pub fn stairs(config: &StairsConfig) -> Result<Scene, SceneError> {
        if config.steps == 0 {
            return Err(SceneError::InvalidParameter {
                name: "steps",
                value: 0.0,
                reason: "must be >= 1",
            });
        }
        let d = positive("tread_depth", config.tread_depth)?;
        let h = positive("riser_height", config.riser_height)?;
        let w = positive("width", config.width)?;
        let m = non_negative("floor_margin", config.floor_margin)?;
        let n = config.steps;
        let (len, top) = (n as f64 * d, n as f64 * h);
        let mut scene = Scene::new();
        if m > 0.0 {
            let floor = Polygon3::from_shell(floor_ring([-m, len + m, -m, w + m]))
                .with_hole(floor_ring([0.0, len, 0.0, w]));
            scene.add_polygon(FLOOR_LABEL, floor)?;
        }
        let add = |scene: &mut Scene, ring: Vec<V3>| -> Result<(), SceneError> {
            let label = scene.next_label();
            scene
                .add_polygon(label, Polygon3::from_shell(ring))
                .map(|_| ())
        };
        for i in 0..n {
            let (x, z) = (i as f64 * d, i as f64 * h);
            add(&mut scene, rect([x, 0.0, z], [0.0, 0.0, h], [0.0, w, 0.0]))?;
            add(
                &mut scene,
                rect([x, 0.0, z + h], [d, 0.0, 0.0], [0.0, w, 0.0]),
            )?;
        }
        add(
            &mut scene,
            rect([len, 0.0, 0.0], [0.0, w, 0.0], [0.0, 0.0, top]),
        )?;
        let mut profile = vec![[0.0, 0.0]];
        for i in 0..n {
            let z = (i + 1) as f64 * h;
            profile.push([i as f64 * d, z]);
            profile.push([(i + 1) as f64 * d, z]);
        }
        profile.push([len, 0.0]);
        for (y, want) in [(0.0, [0.0, -1.0, 0.0]), (w, [0.0, 1.0, 0.0])] {
            let ring = profile.iter().map(|p| [p[0], y, p[1]]).collect();
            add(&mut scene, oriented(ring, want))?;
        }
        Ok(scene)
    }

    /// Ramps at the given angles (see [`RampsConfig`]) on an optional floor.
    ///
    /// Labels: floor 0 if `floor_margin > 0`, then per ramp four faces: back (`+x`), side
    /// `−y`, side `+y`, slope. The slope of ramp `i` has label `4 i + 3 + f` (`f` = 1 with a
    /// floor, else 0) and normal `(−sin a, 0, cos a)`. Footprints are cut out of the floor.
    ///
    /// # Errors
    /// No angles, an angle outside `(0, 80]`, non-positive sizes, or a zero gap with a floor.
    pub fn ramps(config: &RampsConfig) -> Result<Scene, SceneError> {
        if config.angles_deg.is_empty() {
            return Err(SceneError::InvalidParameter {
                name: "angles_deg",
                value: 0.0,
                reason: "give at least one angle",
            });
        }
        let run = positive("run", config.run)?;
        let w = positive("width", config.width)?;
        let m = non_negative("floor_margin", config.floor_margin)?;
        let gap = if m > 0.0 {
            positive("gap", config.gap)?
        } else {
            non_negative("gap", config.gap)?
        };
        let mut solids = Vec::new();
        for &a in &config.angles_deg {
            if !(a > 0.0 && a <= 80.0) {
                return Err(SceneError::InvalidParameter {
                    name: "angles_deg",
                    value: a,
                    reason: "each angle must be in (0, 80] degrees",
                });
            }
            let y = solids.len() as f64 * (w + gap) + w / 2.0;
            let s =
                Solid::wedge([run, w, run * a.to_radians().tan()])?.translated([run / 2.0, y, 0.0]);
            solids.push(s);
        }
        let mut scene = Scene::new();
        if m > 0.0 {
            let ymax = solids.len() as f64 * (w + gap) - gap;
            let floor = Polygon3 {
                shell: floor_ring([-m, run + m, -m, ymax + m]),
                holes: solids.iter().filter_map(Solid::footprint).collect(),
            };
            scene.add_polygon(FLOOR_LABEL, floor)?;
        }
        for s in &solids {
            scene.add_solid(s, true)?;
        }
        Ok(scene)
    }

    /// A room populated with random polyhedra, deterministic by `config.seed`
    /// (SynPEB-like; see [`RandomPolyhedraConfig`]).
    ///
    /// Each object is a box, a wedge or a prism (3–8 sides) with dimensions drawn from
    /// `size_range`, a random heading, and with probability `tilted_fraction` a tilt of up
    /// to `max_tilt_deg` about both horizontal axes. Every object rests on the floor (tilted
    /// ones on an edge or corner) at least `gap` from the walls, the other objects and the
    /// `keep_clear` discs, and below the ceiling. Untilted objects cut their footprints out
    /// of the floor and have no bottom face.
    ///
    /// Labels: floor 0, walls 1–4, ceiling 5 if present, then each object's faces.
    ///
    /// # Errors
    /// Invalid sizes or fractions, or no room for an object after 1000 tries
    /// ([`SceneError::PlacementFailed`]).
    pub fn random_polyhedra(config: &RandomPolyhedraConfig) -> Result<Scene, SceneError> {
        check_size3("room_size", config.room_size)?;
        let [smin, smax] = config.size_range;
        positive("size_range[0]", smin)?;
        if !(smax >= smin && smax.is_finite()) {
            return Err(SceneError::InvalidParameter {
                name: "size_range[1]",
                value: smax,
                reason: "must be finite and >= size_range[0]",
            });
        }
        if !(0.0..=1.0).contains(&config.tilted_fraction) {
            return Err(SceneError::InvalidParameter {
                name: "tilted_fraction",
                value: config.tilted_fraction,
                reason: "must be in [0, 1]",
            });
        }
        if !(0.0..=90.0).contains(&config.max_tilt_deg) {
            return Err(SceneError::InvalidParameter {
                name: "max_tilt_deg",
                value: config.max_tilt_deg,
                reason: "must be in [0, 90]",
            });
        }
        let gap = positive("gap", config.gap)?;
        for &(c, r) in &config.keep_clear {
            non_negative("keep_clear radius", r)?;
            crate::error::finite("keep_clear centre", c[0])?;
            crate::error::finite("keep_clear centre", c[1])?;
        }
        let [w, d, h] = config.room_size;
        const ATTEMPTS: usize = 1000;
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(config.seed);
        let mut placed: Vec<(Solid, bool, [f64; 3])> = Vec::new();
        for object in 0..config.objects {
            let mut done = false;
            for _ in 0..ATTEMPTS {
                let mut dim = || smin + (smax - smin) * rng.random::<f64>();
                let (a, b, c) = (dim(), dim(), dim());
                let kind = rng.random_range(0..3u32);
                let solid = match kind {
                    0 => Solid::cuboid([a, b, c])?,
                    1 => Solid::wedge([a, b, c])?,
                    _ => Solid::prism(rng.random_range(3..=8usize), a / 2.0, c)?,
                };
                let yaw = 360.0 * rng.random::<f64>();
                let tilted = rng.random::<f64>() < config.tilted_fraction;
                let (tx, ty) = (
                    config.max_tilt_deg * (2.0 * rng.random::<f64>() - 1.0),
                    config.max_tilt_deg * (2.0 * rng.random::<f64>() - 1.0),
                );
                let (ux, uy) = (rng.random::<f64>(), rng.random::<f64>());
                let mut solid = solid.rotated_z(yaw);
                if tilted {
                    solid = solid.rotated_x(tx).rotated_y(ty);
                }
                let (zmin, zmax) = solid.z_range();
                let (cx, cy, r) = solid.bounding_circle_xy();
                let px = r + gap + ux * (w - 2.0 * (r + gap));
                let py = r + gap + uy * (d - 2.0 * (r + gap));
                let fits = w > 2.0 * (r + gap)
                    && d > 2.0 * (r + gap)
                    && zmax - zmin < h - gap
                    && placed
                        .iter()
                        .all(|(_, _, o)| (px - o[0]).hypot(py - o[1]) > r + o[2] + gap)
                    && config
                        .keep_clear
                        .iter()
                        .all(|(c, kr)| (px - c[0]).hypot(py - c[1]) > r + kr + gap);
                if fits {
                    let solid = solid.translated([px - cx, py - cy, -zmin]);
                    let resting = solid.bottom_face().is_some();
                    placed.push((solid, resting, [px, py, r]));
                    done = true;
                    break;
                }
            }
            if !done {
                return Err(SceneError::PlacementFailed {
                    object,
                    requested: config.objects,
                    attempts: ATTEMPTS,
                });
            }
        }
        let holes = placed
            .iter()
            .filter(|(_, resting, _)| *resting)
            .filter_map(|(s, _, _)| s.footprint())
            .collect();
        let mut scene = Scene::new();
        add_shell(&mut scene, config.room_size, config.ceiling, holes)?;
        for (solid, resting, _) in &placed {
            scene.add_solid(solid, *resting)?;
        }
        Ok(scene)
    }
}
