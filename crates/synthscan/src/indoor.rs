//! A furnished room seen by a handheld or robot-mounted RGB-D camera.

use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};

use crate::builders::add_shell;
use crate::depth::{DepthCamera, DepthCameraKind};
use crate::error::{SceneError, non_negative, positive};
use crate::face::Polygon3d;
use crate::scene::Scene;
use crate::sensor::Pose;
use crate::solid::Solid;
use crate::vec3::{V3, add, cross};

/// A room with furniture and a camera pose looking into it, for RGB-D benchmarks
/// ([`Scene::indoor`], [`rgbd_like`]). Metres and degrees; z up, room
/// `[0, x] × [0, y] × [0, z]`, the camera near the `x = 0` wall looking along `+x`.
#[derive(Debug, Clone, PartialEq)]
pub struct IndoorConfig {
    /// Seed of the layout and the camera pose (default 0).
    pub seed: u64,
    /// Room size `[x, y, z]` (default `[5.0, 4.0, 2.6]`).
    pub room_size: [f64; 3],
    /// Cabinets against the walls: boxes 0.6–1.2 m wide, 0.35–0.6 m deep, 0.7–2 m tall
    /// (default 2).
    pub cabinets: usize,
    /// Desks, against a wall or free-standing: a top 1–1.6 × 0.6–0.8 m at 0.72–0.76 m on
    /// two side panels (default 1).
    pub desks: usize,
    /// Open shelves against a wall: two side panels, a top, a plinth and two or three
    /// boards, 0.6–1 m wide and 1–1.8 m tall (default 1).
    pub shelves: usize,
    /// Boxes on the floor, 0.3–0.7 m, any heading (default 2).
    pub boxes: usize,
    /// Boards 0.6–1 m wide and 1–1.6 m long leaning against a wall at 60–80° (default 1).
    pub boards: usize,
    /// Camera height range `[lo, hi]` (default `[0.8, 1.6]`).
    pub eye_height: [f64; 2],
    /// Range of the camera's downward pitch `[lo, hi]`, degrees (default `[10, 30]`).
    pub pitch_deg: [f64; 2],
    /// Smallest horizontal clearance between objects and to the walls they do not stand
    /// against (default 0.1).
    pub gap: f64,
}

impl Default for IndoorConfig {
    fn default() -> Self {
        Self {
            seed: 0,
            room_size: [5.0, 4.0, 2.6],
            cabinets: 2,
            desks: 1,
            shelves: 1,
            boxes: 2,
            boards: 1,
            eye_height: [0.8, 1.6],
            pitch_deg: [10.0, 30.0],
            gap: 0.1,
        }
    }
}

impl IndoorConfig {
    /// The configuration of [`rgbd_like`] for `seed`: a room 4.5–6 × 3.5–5 × 2.5–2.8 m with
    /// 1–3 cabinets, 1–2 desks, 0–1 shelf, 1–3 boxes and one leaning board, all drawn from
    /// `seed`.
    pub fn random(seed: u64) -> Self {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed ^ 0x5EED_0F_1D00_12AB);
        let room_size = [
            4.5 + 1.5 * rng.random::<f64>(),
            3.5 + 1.5 * rng.random::<f64>(),
            2.5 + 0.3 * rng.random::<f64>(),
        ];
        Self {
            seed,
            room_size,
            cabinets: rng.random_range(1..=3),
            desks: rng.random_range(1..=2),
            shelves: rng.random_range(0..=1),
            boxes: rng.random_range(1..=3),
            boards: 1,
            ..Self::default()
        }
    }

    /// Sets the seed.
    pub fn with_seed(mut self, seed: u64) -> Self {
        self.seed = seed;
        self
    }
}

/// One solid of a piece of furniture, in the piece's own frame (footprint centred on the
/// origin, front towards `+y`, floor at `z = 0`).
struct Part {
    solid: Solid,
    /// Stands on the floor: its footprint is cut out of the floor and its bottom left out.
    rests: bool,
    /// Which faces (by their normal in the piece's frame) are hidden by another part.
    hidden: fn(V3) -> bool,
}

/// A piece of furniture: its parts and the half-size `[x, y]` of its footprint.
struct Piece {
    parts: Vec<Part>,
    half: [f64; 2],
}

fn never(_: V3) -> bool {
    false
}
fn top(n: V3) -> bool {
    n[2] > 0.5
}
fn sides_x(n: V3) -> bool {
    n[0].abs() > 0.5
}
fn sides_x_and_bottom(n: V3) -> bool {
    sides_x(n) || n[2] < -0.5
}

/// Unnormalised normal of a ring (Newell).
fn ring_normal(ring: &[V3]) -> V3 {
    let mut n = [0.0; 3];
    for i in 0..ring.len() {
        n = add(n, cross(ring[i], ring[(i + 1) % ring.len()]));
    }
    n
}

fn cabinet(u: &mut impl FnMut(f64, f64) -> f64) -> Result<Piece, SceneError> {
    let (w, d, h) = (u(0.6, 1.2), u(0.35, 0.6), u(0.7, 2.0));
    Ok(Piece {
        parts: vec![Part {
            solid: Solid::cuboid([w, d, h])?,
            rests: true,
            hidden: never,
        }],
        half: [w / 2.0, d / 2.0],
    })
}

fn desk(u: &mut impl FnMut(f64, f64) -> f64) -> Result<Piece, SceneError> {
    let (lx, ly, h, t) = (u(1.0, 1.6), u(0.6, 0.8), u(0.72, 0.76), u(0.03, 0.05));
    let panel = 0.04;
    let mut parts = vec![Part {
        solid: Solid::cuboid([lx, ly, t])?.translated([0.0, 0.0, h - t]),
        rests: false,
        hidden: never,
    }];
    for s in [-1.0, 1.0] {
        parts.push(Part {
            solid: Solid::cuboid([panel, ly - 0.04, h - t])?.translated([
                s * (lx / 2.0 - panel / 2.0 - 0.02),
                0.0,
                0.0,
            ]),
            rests: true,
            hidden: top,
        });
    }
    Ok(Piece {
        parts,
        half: [lx / 2.0, ly / 2.0],
    })
}

fn shelf(u: &mut impl FnMut(f64, f64) -> f64, boards: usize) -> Result<Piece, SceneError> {
    let (w, d, h, t) = (u(0.6, 1.0), u(0.3, 0.4), u(1.0, 1.8), 0.03);
    let plinth = 0.08;
    let mut parts = vec![Part {
        solid: Solid::cuboid([w, d, t])?.translated([0.0, 0.0, h - t]),
        rests: false,
        hidden: never,
    }];
    for s in [-1.0, 1.0] {
        parts.push(Part {
            solid: Solid::cuboid([t, d, h - t])?.translated([s * (w - t) / 2.0, 0.0, 0.0]),
            rests: true,
            hidden: top,
        });
    }
    parts.push(Part {
        // Between the side panels, whose footprints are the floor's holes there.
        solid: Solid::cuboid([w - 2.0 * t, d, plinth])?,
        rests: false,
        hidden: sides_x_and_bottom,
    });
    let spacing = (h - t - plinth) / (boards + 1) as f64;
    for k in 1..=boards {
        parts.push(Part {
            solid: Solid::cuboid([w - 2.0 * t, d, t])?.translated([
                0.0,
                0.0,
                plinth + k as f64 * spacing - t / 2.0,
            ]),
            rests: false,
            hidden: sides_x,
        });
    }
    Ok(Piece {
        parts,
        half: [w / 2.0, d / 2.0],
    })
}

fn floor_box(u: &mut impl FnMut(f64, f64) -> f64) -> Result<Piece, SceneError> {
    let (a, b, c) = (u(0.3, 0.7), u(0.3, 0.7), u(0.3, 0.7));
    Ok(Piece {
        parts: vec![Part {
            solid: Solid::cuboid([a, b, c])?,
            rests: true,
            hidden: never,
        }],
        half: [a / 2.0, b / 2.0],
    })
}

/// A board leaning back (towards `−y`) against a wall, its lower edge on the floor.
fn board(u: &mut impl FnMut(f64, f64) -> f64) -> Result<Piece, SceneError> {
    let (w, len, angle) = (u(0.6, 1.0), u(1.0, 1.6), u(60.0, 80.0));
    let solid = Solid::cuboid([w, 0.02, len])?.rotated_x(90.0 - angle);
    let (zmin, _) = solid.z_range();
    let (ylo, yhi) = solid
        .vertices()
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p[1]), hi.max(p[1]))
        });
    let solid = solid.translated([0.0, -(ylo + yhi) / 2.0, -zmin]);
    Ok(Piece {
        parts: vec![Part {
            solid,
            rests: false,
            hidden: never,
        }],
        half: [w / 2.0, (yhi - ylo) / 2.0],
    })
}

/// Where a piece goes.
#[derive(Clone, Copy, PartialEq)]
enum Placement {
    /// Against a wall (its back towards the wall).
    Wall,
    /// Against a wall or free-standing, at random.
    Either,
    /// Free-standing, any heading.
    Free,
}

impl Scene {
    /// A furnished room (see [`IndoorConfig`]) and the pose of a camera looking into it,
    /// deterministic by `config.seed`.
    ///
    /// The camera stands 0.3–0.7 m from the `x = 0` wall, in the middle 30 % of the room's
    /// width, at a height drawn from `eye_height`, and looks at a point of the far wall
    /// (`x = size.x`) in its middle 40 %, pitched down by an angle drawn from `pitch_deg`.
    /// The furniture stands at least 1 m ahead of the camera (`x ≥ x_cam + 1`) and 0.9 m
    /// from it: cabinets, shelves and boards with their backs 2 cm from the far or a side
    /// wall, desks against a wall or free, boxes free with any heading; pieces keep `gap`
    /// between their bounding circles. Pieces standing on the floor cut their footprints out
    /// of it.
    ///
    /// Labels: floor 0, walls 1–4 (`y = 0`, `x = max`, `y = max`, `x = 0`), ceiling 5, then
    /// every face of every piece its own label (faces hidden inside a piece are left out).
    ///
    /// # Errors
    /// Invalid sizes or ranges, or a piece that finds no room after 500 tries
    /// ([`SceneError::PlacementFailed`]).
    pub fn indoor(config: &IndoorConfig) -> Result<(Scene, Pose), SceneError> {
        for v in config.room_size {
            positive("room_size", v)?;
        }
        let gap = non_negative("gap", config.gap)?;
        let [w, d, h] = config.room_size;
        for (name, [lo, hi]) in [
            ("eye_height", config.eye_height),
            ("pitch_deg", config.pitch_deg),
        ] {
            if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
                return Err(SceneError::InvalidParameter {
                    name,
                    value: hi,
                    reason: "must be a finite range [lo, hi] with lo <= hi",
                });
            }
        }
        if !(config.eye_height[0] > 0.0 && config.eye_height[1] < h) {
            return Err(SceneError::InvalidParameter {
                name: "eye_height",
                value: config.eye_height[1],
                reason: "must lie strictly between the floor and the ceiling",
            });
        }
        if !(config.pitch_deg[0] > -80.0 && config.pitch_deg[1] < 80.0) {
            return Err(SceneError::InvalidParameter {
                name: "pitch_deg",
                value: config.pitch_deg[1],
                reason: "must lie within (-80, 80) degrees",
            });
        }
        if w < 2.5 || d < 2.0 {
            return Err(SceneError::Placement {
                what: "camera",
                reason: "the room must be at least 2.5 m long (x) and 2 m wide (y)",
            });
        }
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(config.seed);
        let mut u = |lo: f64, hi: f64| lo + (hi - lo) * rng.random::<f64>();

        let cam = [
            u(0.3, 0.7),
            d * u(0.35, 0.65),
            u(config.eye_height[0], config.eye_height[1]),
        ];
        let look_y = d * u(0.3, 0.7);
        let pitch = u(config.pitch_deg[0], config.pitch_deg[1]).to_radians();
        let run = (w - cam[0]).hypot(look_y - cam[1]);
        let pose = Pose::look_at(
            cam,
            [w, look_y, cam[2] - run * pitch.tan()],
            [0.0, 0.0, 1.0],
        )?;

        let mut pieces: Vec<(Piece, Placement)> = Vec::new();
        for _ in 0..config.cabinets {
            pieces.push((cabinet(&mut u)?, Placement::Wall));
        }
        for _ in 0..config.shelves {
            let boards = if u(0.0, 1.0) < 0.5 { 2 } else { 3 };
            pieces.push((shelf(&mut u, boards)?, Placement::Wall));
        }
        for _ in 0..config.desks {
            pieces.push((desk(&mut u)?, Placement::Either));
        }
        for _ in 0..config.boards {
            pieces.push((board(&mut u)?, Placement::Wall));
        }
        for _ in 0..config.boxes {
            pieces.push((floor_box(&mut u)?, Placement::Free));
        }

        const ATTEMPTS: usize = 500;
        const WALL_GAP: f64 = 0.02;
        const CAMERA_CLEAR: f64 = 0.9;
        let x_min = cam[0] + 1.0;
        let requested = pieces.len();
        let mut discs: Vec<[f64; 3]> = Vec::new();
        let mut placed: Vec<(f64, [f64; 2])> = Vec::new();
        for (object, (piece, placement)) in pieces.iter().enumerate() {
            let [hx, hy] = piece.half;
            let r = hx.hypot(hy);
            let mut found = None;
            for _ in 0..ATTEMPTS {
                let on_wall = match placement {
                    Placement::Wall => true,
                    Placement::Free => false,
                    Placement::Either => u(0.0, 1.0) < 0.5,
                };
                let (yaw, c) = if on_wall {
                    let wall = u(0.0, 3.0);
                    let s = u(0.0, 1.0);
                    if wall < 1.0 {
                        // The far wall x = w, front towards −x.
                        (
                            90.0,
                            [w - WALL_GAP - hy, hx + gap + s * (d - 2.0 * (hx + gap))],
                        )
                    } else {
                        let x = x_min + hx + s * (w - gap - x_min - 2.0 * hx);
                        if wall < 2.0 {
                            (0.0, [x, WALL_GAP + hy])
                        } else {
                            (180.0, [x, d - WALL_GAP - hy])
                        }
                    }
                } else {
                    let s = (u(0.0, 1.0), u(0.0, 1.0));
                    (
                        u(0.0, 360.0),
                        [
                            x_min + r + s.0 * (w - gap - x_min - 2.0 * r),
                            r + gap + s.1 * (d - 2.0 * (r + gap)),
                        ],
                    )
                };
                let (sy, cy) = f64::to_radians(yaw).sin_cos();
                let corners_inside = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
                    .iter()
                    .all(|&(a, b)| {
                        let (px, py) = (a * hx, b * hy);
                        let (x, y) = (c[0] + cy * px - sy * py, c[1] + sy * px + cy * py);
                        x > 0.0 && x < w && y > 0.0 && y < d && x >= x_min - 1e-9
                    });
                let clear = corners_inside
                    && (c[0] - cam[0]).hypot(c[1] - cam[1]) > r + CAMERA_CLEAR
                    && discs
                        .iter()
                        .all(|o| (c[0] - o[0]).hypot(c[1] - o[1]) > r + o[2] + gap);
                if clear {
                    found = Some((yaw, c));
                    break;
                }
            }
            let Some((yaw, c)) = found else {
                return Err(SceneError::PlacementFailed {
                    object,
                    requested,
                    attempts: ATTEMPTS,
                });
            };
            discs.push([c[0], c[1], r]);
            placed.push((yaw, c));
        }

        let mut holes = Vec::new();
        let mut rings: Vec<Vec<V3>> = Vec::new();
        for ((piece, _), &(yaw, c)) in pieces.iter().zip(&placed) {
            for part in &piece.parts {
                let hidden: Vec<bool> = part
                    .solid
                    .face_rings()
                    .map(|ring| (part.hidden)(ring_normal(&ring)))
                    .collect();
                let solid = part
                    .solid
                    .clone()
                    .rotated_z(yaw)
                    .translated([c[0], c[1], 0.0]);
                let bottom = if part.rests {
                    solid.bottom_face()
                } else {
                    None
                };
                if part.rests {
                    holes.extend(solid.footprint());
                }
                for (i, ring) in solid.face_rings().enumerate() {
                    if !hidden[i] && Some(i) != bottom {
                        rings.push(ring);
                    }
                }
            }
        }
        let mut scene = Scene::new();
        add_shell(&mut scene, config.room_size, true, holes)?;
        for ring in rings {
            let label = scene.next_label();
            scene.add_polygon(label, Polygon3d::new(ring))?;
        }
        Ok((scene, pose))
    }
}

/// An RGB-D benchmark frame: the furnished room of [`IndoorConfig::random`]`(seed)` and a
/// camera of `kind` at the room's camera pose ([`Scene::indoor`]). The four kinds see the
/// same room from the same pose, so full and half resolution compare directly. Scan it with
/// [`Scene::scan_depth`].
///
/// # Errors
/// [`SceneError::PlacementFailed`] if the seed's furniture does not fit (not seen for seeds
/// 0–199).
pub fn rgbd_like(seed: u64, kind: DepthCameraKind) -> Result<(Scene, DepthCamera), SceneError> {
    let (scene, pose) = Scene::indoor(&IndoorConfig::random(seed))?;
    Ok((scene, DepthCamera::preset(kind)?.with_pose(pose)))
}
