//! A synthetic city seen by an airborne laser scanner, generated tile by tile.
//!
//! The city is a square of blocks separated by streets on gently sloping ground. Most
//! blocks hold one building with a flat, gabled or hipped roof; some flat roofs have a
//! courtyard (a hole down to the ground); trees stand around the buildings (clutter the
//! 2.5D pipeline must leave out). Everything is decided by hashes of the seed and the
//! block, so any part of the city can be generated without the rest: [`City::tile`] gives
//! the returns that fall in one square, and a city of a billion points is written tile by
//! tile without ever being held.
//!
//! The scanner flies strips along `+y` with 20 % side overlap; an oscillating mirror sweeps
//! each scan line across the strip in a zig-zag; rays are vertical (near-nadir), so roofs
//! and ground are hit and walls are not; a ray through a tree canopy reaches the ground
//! with [`CityConfig::penetration`] probability. Heights carry Gaussian noise.
//!
//! Ground truth ([`CityTile::labels`]): `0` ground, `-1` trees, and for roof face `f` of
//! building `b` (blocks numbered row by row) the label `1 + 4 b + f` — a flat roof has
//! face 0, a gabled roof faces 0–1, a hipped roof faces 0–3. [`City::roof_planes`] lists
//! every roof face with its plane. [`CityTile::classification`] holds the ASPRS classes
//! (2 ground, 5 high vegetation, 6 building). Lengths are metres.
//!
//! ```
//! use synthscan::{City, CityConfig};
//! let city = City::new(CityConfig::default().with_points(200_000))?;
//! let tile = city.tile([0.0, 0.0], 60.0);
//! assert!(tile.points.len() > 20_000);
//! assert_eq!(tile.points.len(), tile.labels.len());
//! // Tiles partition the city: one tile of twice the side has the points of four.
//! let quarters: usize = [[0.0, 0.0], [30.0, 0.0], [0.0, 30.0], [30.0, 30.0]]
//!     .iter()
//!     .map(|&o| city.tile(o, 30.0).points.len())
//!     .sum();
//! assert_eq!(quarters, tile.points.len());
//! # Ok::<(), synthscan::CityError>(())
//! ```

/// Errors of [`City::new`].
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CityError {
    /// A parameter is out of range.
    #[error("invalid city parameter {name} = {value}: {reason}")]
    Parameter {
        /// The field of [`CityConfig`].
        name: &'static str,
        /// Its value.
        value: f64,
        /// What it must be.
        reason: &'static str,
    },
}

/// The size and look of a [`City`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct CityConfig {
    /// About how many returns the whole city has: the size parameter (the side of the
    /// city is `sqrt(points / density)`).
    pub points: u64,
    /// Returns per square metre (8: a current airborne survey), counting the strips'
    /// overlap.
    pub density: f64,
    /// The pitch of the block grid (a block and its share of the streets), metres.
    pub block: f64,
    /// The street width between blocks, metres.
    pub street: f64,
    /// The standard deviation of the height noise, metres.
    pub noise: f64,
    /// The pitch of gabled and hipped roofs, degrees: each roof takes a value in this
    /// range.
    pub roof_pitch_deg: [f64; 2],
    /// Trees per block, on average.
    pub trees_per_block: f64,
    /// The chance that a ray through a tree canopy reaches the ground.
    pub penetration: f64,
    /// The width of one flight strip (swath), metres.
    pub swath: f64,
    /// Everything random follows from this.
    pub seed: u64,
}

impl Default for CityConfig {
    fn default() -> Self {
        Self {
            points: 1_000_000,
            density: 8.0,
            block: 60.0,
            street: 12.0,
            noise: 0.03,
            roof_pitch_deg: [20.0, 35.0],
            trees_per_block: 4.0,
            penetration: 0.3,
            swath: 300.0,
            seed: 1,
        }
    }
}

impl CityConfig {
    /// Sets [`Self::points`].
    pub fn with_points(mut self, points: u64) -> Self {
        self.points = points;
        self
    }

    /// Sets [`Self::density`].
    pub fn with_density(mut self, density: f64) -> Self {
        self.density = density;
        self
    }

    /// Sets [`Self::seed`].
    pub fn with_seed(mut self, seed: u64) -> Self {
        self.seed = seed;
        self
    }
}

/// The roof of a building.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RoofKind {
    /// One horizontal face; `courtyard` is a hole down to the ground
    /// (`[x0, y0, x1, y1]`).
    Flat {
        /// The courtyard, if any.
        courtyard: Option<[f64; 4]>,
    },
    /// Two faces meeting at a ridge along the longer side.
    Gabled,
    /// Four faces rising from every eave to a ridge (or apex).
    Hipped,
}

/// A building: a rectangular footprint, its eave height and roof.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Building {
    /// Its number: blocks row by row (`row · blocks + col`).
    pub index: u64,
    /// The footprint `[x0, y0, x1, y1]`.
    pub footprint: [f64; 4],
    /// The height of the eaves (of the whole roof when flat) above the ground's datum.
    pub eave: f64,
    /// The roof pitch, degrees (0 when flat).
    pub pitch_deg: f64,
    /// The roof.
    pub roof: RoofKind,
}

/// A roof face of the ground truth: its label and plane `normal · p = offset`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RoofPlane {
    /// The label its returns carry (`1 + 4 · building + face`).
    pub label: i64,
    /// The building's number.
    pub building: u64,
    /// Unit normal, pointing up.
    pub normal: [f64; 3],
    /// Plane offset.
    pub offset: f64,
}

/// The returns of one square of the city.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CityTile {
    /// `[x, y, z]`, metres.
    pub points: Vec<[f64; 3]>,
    /// The ground-truth label of each return (see the module documentation).
    pub labels: Vec<i64>,
    /// The ASPRS class of each return: 2 ground, 5 high vegetation, 6 building.
    pub classification: Vec<u8>,
}

/// A synthetic city: see the module documentation.
#[derive(Debug, Clone)]
pub struct City {
    config: CityConfig,
    side: f64,
    blocks: u64,
    /// The spacing of returns within one strip, along and across track.
    spacing: f64,
}

/// Side overlap of neighbouring strips.
const SIDELAP: f64 = 0.2;
/// The ground's slope along x and y.
const GROUND_SLOPE: [f64; 2] = [0.01, 0.005];

impl City {
    /// A city for `config`.
    ///
    /// # Errors
    /// [`CityError::Parameter`] for a density, block, swath or noise that is not positive
    /// and finite (noise may be 0), a street not below the block, a pitch outside 0–60°,
    /// a penetration outside 0–1, or fewer than 100 points.
    pub fn new(config: CityConfig) -> Result<Self, CityError> {
        let bad = |name, value, reason| {
            Err(CityError::Parameter {
                name,
                value,
                reason,
            })
        };
        let positive = |v: f64| v.is_finite() && v > 0.0;
        if config.points < 100 {
            return bad("points", config.points as f64, "at least 100");
        }
        if !positive(config.density) {
            return bad("density", config.density, "positive");
        }
        if !positive(config.block) {
            return bad("block", config.block, "positive");
        }
        if !(config.street.is_finite() && config.street >= 0.0 && config.street < config.block) {
            return bad("street", config.street, "from 0 to below the block");
        }
        if !(config.noise.is_finite() && config.noise >= 0.0) {
            return bad("noise", config.noise, "0 or more");
        }
        for p in config.roof_pitch_deg {
            if !(0.0..=60.0).contains(&p) {
                return bad("roof_pitch_deg", p, "0 to 60");
            }
        }
        if !(config.trees_per_block.is_finite() && (0.0..=50.0).contains(&config.trees_per_block)) {
            return bad("trees_per_block", config.trees_per_block, "0 to 50");
        }
        if !(0.0..=1.0).contains(&config.penetration) {
            return bad("penetration", config.penetration, "0 to 1");
        }
        if !positive(config.swath) {
            return bad("swath", config.swath, "positive");
        }
        let side = (config.points as f64 / config.density).sqrt();
        let blocks = (side / config.block).ceil().max(1.0) as u64;
        let spacing = 1.0 / (config.density * (1.0 - SIDELAP)).sqrt();
        Ok(Self {
            config,
            side,
            blocks,
            spacing,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &CityConfig {
        &self.config
    }

    /// The side of the square city, metres: it spans `[0, side)²`.
    pub fn side(&self) -> f64 {
        self.side
    }

    /// Blocks along each side.
    pub fn blocks(&self) -> u64 {
        self.blocks
    }

    /// The ground height at `(x, y)`.
    pub fn ground(&self, x: f64, y: f64) -> f64 {
        GROUND_SLOPE[0] * x + GROUND_SLOPE[1] * y
    }

    /// The building of block `(col, row)`, if it has one (about one block in ten is a
    /// park; a building that would cross the city's edge is left out).
    pub fn building(&self, col: u64, row: u64) -> Option<Building> {
        let c = &self.config;
        let index = row * self.blocks + col;
        let h = |k: u64| unit(hash3(c.seed, index, k));
        if h(0) < 0.1 {
            return None;
        }
        let inner = c.block - c.street;
        let (bx, by) = (
            col as f64 * c.block + c.street / 2.0,
            row as f64 * c.block + c.street / 2.0,
        );
        // Leave room around the building for trees.
        let room = (inner - 8.0).max(inner * 0.5);
        let w = room * (0.45 + 0.55 * h(1));
        let d = room * (0.45 + 0.55 * h(2));
        let x0 = bx + (inner - w) * (0.2 + 0.6 * h(3));
        let y0 = by + (inner - d) * (0.2 + 0.6 * h(4));
        let footprint = [x0, y0, x0 + w, y0 + d];
        if footprint[2] > self.side || footprint[3] > self.side {
            return None;
        }
        let eave = 6.0 + 24.0 * h(5);
        let kind = h(6);
        let [p0, p1] = c.roof_pitch_deg;
        let pitch = p0 + (p1 - p0) * h(7);
        let (roof, pitch_deg) = if kind < 0.4 {
            let courtyard = (h(8) < 0.5 && w.min(d) >= 25.0).then(|| {
                let (cw, cd) = (w * (0.3 + 0.15 * h(9)), d * (0.3 + 0.15 * h(10)));
                let (cx, cy) = (x0 + (w - cw) / 2.0, y0 + (d - cd) / 2.0);
                [cx, cy, cx + cw, cy + cd]
            });
            (RoofKind::Flat { courtyard }, 0.0)
        } else if kind < 0.7 {
            (RoofKind::Gabled, pitch)
        } else {
            (RoofKind::Hipped, pitch)
        };
        Some(Building {
            index,
            footprint,
            eave,
            pitch_deg,
            roof,
        })
    }

    /// Every building of the city, block by block.
    pub fn buildings(&self) -> impl Iterator<Item = Building> + '_ {
        (0..self.blocks)
            .flat_map(move |row| (0..self.blocks).filter_map(move |col| self.building(col, row)))
    }

    /// The ground-truth roof faces of every building inside the city.
    pub fn roof_planes(&self) -> Vec<RoofPlane> {
        let mut planes = Vec::new();
        for b in self.buildings() {
            let faces: u64 = match b.roof {
                RoofKind::Flat { .. } => 1,
                RoofKind::Gabled => 2,
                RoofKind::Hipped => 4,
            };
            for f in 0..faces {
                let (normal, point) = b.face_plane(f, self);
                let offset = normal[0] * point[0] + normal[1] * point[1] + normal[2] * point[2];
                planes.push(RoofPlane {
                    label: 1 + 4 * b.index as i64 + f as i64,
                    building: b.index,
                    normal,
                    offset,
                });
            }
        }
        planes
    }

    /// The surface under a vertical ray at `(x, y)`: height, label, class. `key` draws the
    /// ray's randomness (trees).
    fn surface(&self, x: f64, y: f64, key: u64) -> (f64, i64, u8) {
        let c = &self.config;
        let ground = self.ground(x, y);
        let (col, row) = ((x / c.block).floor(), (y / c.block).floor());
        if col < 0.0 || row < 0.0 {
            return (ground, 0, 2);
        }
        let (col, row) = (col as u64, row as u64);
        let building = self.building(col, row);
        if let Some((b, (z, face))) = building.and_then(|b| b.roof_at(x, y).map(|r| (b, r))) {
            let base = self.ground(b.footprint[0], b.footprint[1]);
            return (base + z, 1 + 4 * b.index as i64 + face as i64, 6);
        }
        // Trees of this block: centres away from the building and the block's edge.
        let index = row * self.blocks + col;
        let count = (c.trees_per_block * 2.0 * unit(hash3(c.seed, index, 100))).round() as u64;
        for t in 0..count {
            let h = |k: u64| unit(hash3(c.seed ^ 0x7EE5, index * 64 + t, k));
            let r = 2.0 + 3.0 * h(0);
            let inner = c.block - c.street;
            let (tx, ty) = (
                col as f64 * c.block + c.street / 2.0 + r + (inner - 2.0 * r) * h(1),
                row as f64 * c.block + c.street / 2.0 + r + (inner - 2.0 * r) * h(2),
            );
            if building.is_some_and(|b| {
                tx > b.footprint[0] - r
                    && tx < b.footprint[2] + r
                    && ty > b.footprint[1] - r
                    && ty < b.footprint[3] + r
            }) {
                continue;
            }
            let d2 = (x - tx).powi(2) + (y - ty).powi(2);
            if d2 >= r * r {
                continue;
            }
            if unit(key ^ 0x51A7) < c.penetration {
                return (ground, 0, 2);
            }
            let top = self.ground(tx, ty) + 4.0 + 10.0 * h(3) + 0.8 * (r * r - d2).sqrt();
            return (top - 0.5 * r * unit(key ^ 0xC0FF), -1, 5);
        }
        (ground, 0, 2)
    }

    /// The returns whose xy falls in the square `[x0, x0 + size) × [y0, y0 + size)` (and in
    /// the city): the same returns however the city is cut into squares.
    pub fn tile(&self, origin: [f64; 2], size: f64) -> CityTile {
        let mut tile = CityTile::default();
        let (x0, y0) = (origin[0].max(0.0), origin[1].max(0.0));
        let (x1, y1) = (
            (origin[0] + size).min(self.side),
            (origin[1] + size).min(self.side),
        );
        if !(x0 < x1 && y0 < y1) {
            return tile;
        }
        let a = self.spacing;
        let step = self.config.swath * (1.0 - SIDELAP);
        let strips = (self.side / step).ceil() as i64 + 1;
        for s in 0..strips {
            let left = s as f64 * step - 0.5 * SIDELAP * self.config.swath;
            let right = left + self.config.swath;
            if right < x0 - a || left > x1 + a {
                continue;
            }
            let phase = a * unit(hash3(self.config.seed, s as u64, 0x5EED));
            let i0 = (((x0 - left) / a).floor() as i64 - 2).max(0);
            let i1 = (((x1 - left) / a).ceil() as i64 + 2).min((self.config.swath / a) as i64);
            let j0 = ((y0 - phase) / a).floor() as i64 - 3;
            let j1 = ((y1 - phase) / a).ceil() as i64 + 2;
            for j in j0..=j1 {
                for i in i0..=i1 {
                    let key = hash3(self.config.seed, s as u64, ((j as u64) << 24) ^ i as u64);
                    let across = i as f64 * a;
                    let sweep = across / self.config.swath;
                    let zig = if j % 2 == 0 { sweep } else { 1.0 - sweep };
                    let x = left + across + 0.15 * a * (unit(key) - 0.5);
                    let y = phase + (j as f64 + zig) * a + 0.15 * a * (unit(key ^ 1) - 0.5);
                    if !(x >= x0 && x < x1 && y >= y0 && y < y1) {
                        continue;
                    }
                    let (z, label, class) = self.surface(x, y, key);
                    let noise = self.config.noise * gaussian(key ^ 0xAB);
                    tile.points.push([x, y, z + noise]);
                    tile.labels.push(label);
                    tile.classification.push(class);
                }
            }
        }
        tile
    }
}

impl Building {
    /// The roof height above the building's base at `(x, y)` and the face hit; `None`
    /// outside the footprint or in the courtyard.
    fn roof_at(&self, x: f64, y: f64) -> Option<(f64, u64)> {
        let [x0, y0, x1, y1] = self.footprint;
        if !(x >= x0 && x < x1 && y >= y0 && y < y1) {
            return None;
        }
        let t = self.pitch_deg.to_radians().tan();
        match self.roof {
            RoofKind::Flat { courtyard } => {
                if courtyard.is_some_and(|c| x >= c[0] && x < c[2] && y >= c[1] && y < c[3]) {
                    return None;
                }
                Some((self.eave, 0))
            }
            RoofKind::Gabled => {
                // The ridge runs along the longer side; `v` is across it.
                let (lo, hi, v) = if x1 - x0 >= y1 - y0 {
                    (y0, y1, y)
                } else {
                    (x0, x1, x)
                };
                let mid = 0.5 * (lo + hi);
                let face = u64::from(v >= mid);
                Some((self.eave + (0.5 * (hi - lo) - (v - mid).abs()) * t, face))
            }
            RoofKind::Hipped => {
                let d = [x - x0, x1 - x, y - y0, y1 - y];
                let (face, m) = d
                    .iter()
                    .enumerate()
                    .fold(
                        (0, f64::INFINITY),
                        |acc, (k, &v)| if v < acc.1 { (k, v) } else { acc },
                    );
                Some((self.eave + m * t, face as u64))
            }
        }
    }

    /// The unit normal (up) and a point of roof face `face`.
    fn face_plane(&self, face: u64, city: &City) -> ([f64; 3], [f64; 3]) {
        let [x0, y0, x1, y1] = self.footprint;
        let base = city.ground(x0, y0) + self.eave;
        let t = self.pitch_deg.to_radians().tan();
        let n = |gx: f64, gy: f64| {
            let len = (gx * gx + gy * gy + 1.0).sqrt();
            [-gx / len, -gy / len, 1.0 / len]
        };
        // Every face passes through an eave point at height `base`.
        match (self.roof, face) {
            (RoofKind::Flat { .. }, _) => ([0.0, 0.0, 1.0], [x0, y0, base]),
            (RoofKind::Gabled, f) => {
                let along_x = x1 - x0 >= y1 - y0;
                match (along_x, f) {
                    (true, 0) => (n(0.0, t), [x0, y0, base]),
                    (true, _) => (n(0.0, -t), [x0, y1, base]),
                    (false, 0) => (n(t, 0.0), [x0, y0, base]),
                    (false, _) => (n(-t, 0.0), [x1, y0, base]),
                }
            }
            (RoofKind::Hipped, 0) => (n(t, 0.0), [x0, y0, base]),
            (RoofKind::Hipped, 1) => (n(-t, 0.0), [x1, y0, base]),
            (RoofKind::Hipped, 2) => (n(0.0, t), [x0, y0, base]),
            (RoofKind::Hipped, _) => (n(0.0, -t), [x0, y1, base]),
        }
    }
}

/// A 64-bit hash of three numbers (splitmix64 steps).
fn hash3(a: u64, b: u64, c: u64) -> u64 {
    mix(mix(mix(a) ^ b) ^ c)
}

fn mix(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// A number in `[0, 1)` from a hash.
fn unit(h: u64) -> f64 {
    (mix(h) >> 11) as f64 / (1u64 << 53) as f64
}

/// A standard normal number from a hash (Box–Muller).
fn gaussian(h: u64) -> f64 {
    let u1 = unit(h).max(1e-300);
    let u2 = unit(h ^ 0xDEAD_BEEF);
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn small() -> City {
        City::new(CityConfig {
            points: 300_000,
            ..CityConfig::default()
        })
        .unwrap()
    }

    #[test]
    fn size_parameter_sets_the_point_count() {
        for points in [100_000u64, 400_000] {
            let city = City::new(CityConfig {
                points,
                ..CityConfig::default()
            })
            .unwrap();
            let n = city.tile([0.0, 0.0], city.side()).points.len() as f64;
            let ratio = n / points as f64;
            // A city narrower than a strip has no strip overlap: 80 % of the density.
            assert!((0.75..1.25).contains(&ratio), "{points}: {n}");
        }
    }

    #[test]
    fn every_roof_return_lies_on_its_ground_truth_plane() {
        let city = small();
        let planes: std::collections::HashMap<i64, RoofPlane> = city
            .roof_planes()
            .into_iter()
            .map(|p| (p.label, p))
            .collect();
        let tile = city.tile([0.0, 0.0], city.side());
        let mut kinds = [0usize; 3];
        let mut roof_points = 0;
        for ((p, &label), &class) in tile
            .points
            .iter()
            .zip(&tile.labels)
            .zip(&tile.classification)
        {
            match label {
                0 => assert_eq!(class, 2),
                -1 => assert_eq!(class, 5),
                l => {
                    assert_eq!(class, 6);
                    roof_points += 1;
                    let plane = &planes[&l];
                    let d =
                        plane.normal[0] * p[0] + plane.normal[1] * p[1] + plane.normal[2] * p[2]
                            - plane.offset;
                    assert!(d.abs() < 0.2, "label {l}: {d}");
                }
            }
        }
        for b in city.buildings() {
            kinds[match b.roof {
                RoofKind::Flat { .. } => 0,
                RoofKind::Gabled => 1,
                RoofKind::Hipped => 2,
            }] += 1;
        }
        assert!(kinds.iter().all(|&k| k > 0), "{kinds:?}");
        assert!(roof_points > tile.points.len() / 10);
        assert!(tile.labels.contains(&-1), "trees");
        assert!(
            city.buildings()
                .any(|b| matches!(b.roof, RoofKind::Flat { courtyard: Some(_) }))
        );
    }

    #[test]
    fn tiles_partition_the_city_whatever_the_cut() {
        let city = small();
        let whole = city.tile([0.0, 0.0], city.side());
        let mut parts: Vec<[f64; 3]> = Vec::new();
        let size = 47.0;
        let n = (city.side() / size).ceil() as usize;
        for r in 0..n {
            for c in 0..n {
                parts.extend(city.tile([c as f64 * size, r as f64 * size], size).points);
            }
        }
        let key = |p: &[f64; 3]| (p[0].to_bits(), p[1].to_bits(), p[2].to_bits());
        let mut a: Vec<_> = whole.points.iter().map(key).collect();
        let mut b: Vec<_> = parts.iter().map(key).collect();
        a.sort_unstable();
        b.sort_unstable();
        assert_eq!(a, b);
    }

    #[test]
    fn refuses_bad_parameters() {
        let c = CityConfig::default();
        for bad in [
            CityConfig { points: 10, ..c },
            CityConfig { density: 0.0, ..c },
            CityConfig { street: 60.0, ..c },
            CityConfig {
                roof_pitch_deg: [0.0, 80.0],
                ..c
            },
            CityConfig {
                penetration: 2.0,
                ..c
            },
            CityConfig {
                swath: f64::NAN,
                ..c
            },
        ] {
            assert!(City::new(bad).is_err());
        }
    }
}
