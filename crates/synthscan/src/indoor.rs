//! A furnished room seen by a handheld or robot-mounted RGB-D camera.

use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};

use crate::builders::add_shell;
use crate::depth::{DepthCameraKind, SimulatedDepthCamera};
use crate::error::{SceneError, non_negative, positive};
use crate::scene::Scene;
use crate::sensor::Pose;
use crate::solid::Solid;
use crate::vec3::{V3, add, cross, dot, norm, scale};
use plane_geom::Polygon3;

/// A room with furniture and a camera pose looking into it, for RGB-D benchmarks
/// ([`Scene::indoor`], [`rgbd_like`]). Metres and degrees; z up, room
/// `[0, x] × [0, y] × [0, z]`, the camera near the `x = 0` wall looking along `+x`.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
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
    /// The configuration of [`rgbd_like`] for `seed`: a room 4–5.5 × 3.2–4.5 × 2.5–2.8 m with
    /// 1–3 cabinets, 1–2 desks, 0–1 shelf, 1–3 boxes and one leaning board, all drawn from
    /// `seed`.
    pub fn random(seed: u64) -> Self {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed ^ 0x005E_ED0F_1D00_12AB);
        let room_size = [
            4.0 + 1.5 * rng.random::<f64>(),
            3.2 + 1.3 * rng.random::<f64>(),
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
            // Flush with the top's ends and front, so the desk's front is one plane.
            solid: Solid::cuboid([panel, ly, h - t])?.translated([
                s * (lx / 2.0 - panel / 2.0),
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

/// Corners of a footprint: half-size `half` turned by `yaw` degrees about its centre `c`.
fn rectangle(c: [f64; 2], half: [f64; 2], yaw: f64) -> [[f64; 2]; 4] {
    let (s, k) = yaw.to_radians().sin_cos();
    [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)].map(|(a, b)| {
        let (x, y) = (a * half[0], b * half[1]);
        [c[0] + k * x - s * y, c[1] + s * x + k * y]
    })
}

/// Whether two rectangles are at least `gap` apart along one of their edge directions
/// (separating axes).
fn separated(a: &[[f64; 2]; 4], b: &[[f64; 2]; 4], gap: f64) -> bool {
    let axes = [
        [a[1][0] - a[0][0], a[1][1] - a[0][1]],
        [a[3][0] - a[0][0], a[3][1] - a[0][1]],
        [b[1][0] - b[0][0], b[1][1] - b[0][1]],
        [b[3][0] - b[0][0], b[3][1] - b[0][1]],
    ];
    axes.into_iter().any(|e| {
        let len = e[0].hypot(e[1]);
        if len == 0.0 {
            return false;
        }
        let project = |r: &[[f64; 2]; 4]| {
            r.iter()
                .map(|p| (p[0] * e[0] + p[1] * e[1]) / len)
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                    (lo.min(v), hi.max(v))
                })
        };
        let ((alo, ahi), (blo, bhi)) = (project(a), project(b));
        alo >= bhi + gap || blo >= ahi + gap
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
    /// The furniture stands at least 1 m ahead of the camera (`x ≥ x_cam + 1`): cabinets, shelves and boards with their backs 2 cm from the far or a side
    /// wall, desks against a wall or free, boxes free with any heading; the pieces'
    /// footprints keep `gap` apart. Pieces standing on the floor cut their footprints out
    /// of it.
    ///
    /// Labels: floor 0, walls 1–4 (`y = 0`, `x = max`, `y = max`, `x = 0`), ceiling 5, then
    /// the pieces' planes: faces of one piece that lie on one plane share a label (a desk's
    /// front edge and its panels' fronts, a shelf's front), every other face has its own;
    /// faces hidden inside a piece are left out.
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
        let x_min = cam[0] + 1.0;
        let requested = pieces.len();
        let mut footprints: Vec<[[f64; 2]; 4]> = Vec::new();
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
                let corners = rectangle(c, piece.half, yaw);
                let clear = corners
                    .iter()
                    .all(|&[x, y]| x > 0.0 && x < w && y > 0.0 && y < d && x >= x_min - 1e-9)
                    && footprints.iter().all(|o| separated(&corners, o, gap));
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
            footprints.push(rectangle(c, piece.half, yaw));
            placed.push((yaw, c));
        }

        let mut holes = Vec::new();
        let mut rings: Vec<(usize, Vec<V3>)> = Vec::new();
        for (index, ((piece, _), &(yaw, c))) in pieces.iter().zip(&placed).enumerate() {
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
                        rings.push((index, ring));
                    }
                }
            }
        }
        let mut scene = Scene::new();
        add_shell(&mut scene, config.room_size, true, holes)?;
        // Faces of one piece on one plane share a label: (piece, normal, offset, label).
        let mut planes: Vec<(usize, V3, f64, i32)> = Vec::new();
        for (piece, ring) in rings {
            let n = ring_normal(&ring);
            let n = scale(n, 1.0 / norm(n));
            let offset = dot(n, ring[0]);
            let same = planes.iter().find(|&&(p, m, o, _)| {
                p == piece && dot(n, m) > 1.0 - 1e-12 && (o - offset).abs() < 1e-10
            });
            let label = match same {
                Some(&(_, _, _, label)) => label,
                None => {
                    let label = scene.next_label();
                    planes.push((piece, n, offset, label));
                    label
                }
            };
            scene.add_polygon(label, Polygon3::from_shell(ring))?;
        }
        Ok((scene, pose))
    }
}

/// An RGB-D benchmark frame: the furnished room of [`IndoorConfig::random`]`(seed)` and a
/// camera of `kind` at the room's camera pose ([`Scene::indoor`]). Where the seed's
/// furniture does not fit, pieces are left out (boxes first, then shelves, cabinets and
/// desks) until it does. The four kinds see the same room from the same pose, so full and
/// half resolution compare directly. Scan it with [`Scene::scan_depth`].
///
/// # Errors
/// None in practice; kept for the builders it calls.
pub fn rgbd_like(
    seed: u64,
    kind: DepthCameraKind,
) -> Result<(Scene, SimulatedDepthCamera), SceneError> {
    let mut config = IndoorConfig::random(seed);
    let (scene, pose) = loop {
        match Scene::indoor(&config) {
            Err(SceneError::PlacementFailed { .. }) => {
                if config.boxes > 0 {
                    config.boxes -= 1;
                } else if config.shelves > 0 {
                    config.shelves -= 1;
                } else if config.cabinets > 0 {
                    config.cabinets -= 1;
                } else if config.desks > 0 {
                    config.desks -= 1;
                } else {
                    config.boards = 0;
                }
            }
            other => break other?,
        }
    };
    Ok((scene, SimulatedDepthCamera::preset(kind)?.with_pose(pose)))
}
