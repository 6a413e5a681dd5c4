//! Unorganized 3D clouds with planes in every direction ([`Polylidar::extract_unorganized`]):
//! point normals (read or estimated), dominant directions, and per direction the points
//! that face it, triangulated as seen along it, grown into planes and extracted as
//! polygons with holes in 3D.
//!
//! The 2.5D path ([`Polylidar::extract_25d`]) triangulates a whole cloud along one `up`
//! vector and so finds only the planes that face it — the limit the Polylidar3D paper
//! names (§10). This path lifts it:
//!
//! 1. optional voxel downsampling ([`UnorganizedConfig::voxel`]); the points kept put
//!    in Morton order ([`cloud_normals::spatial_order`]), so that the neighbourhood
//!    passes below read memory mostly in order on a shuffled cloud (the returned mesh
//!    and labels are in the input order);
//! 2. normals: the caller's (a file's `normal_x/y/z`, `nx/ny/nz`), or PCA of the `k`
//!    nearest neighbours ([`cloud_normals`]), oriented towards
//!    [`UnorganizedConfig::viewpoint`] or into the half-space of [`Config::up`];
//! 3. dominant directions: FastGA on the normals taken both ways (so that a wall whose
//!    normals point either way is one direction), then again on the flat points that no
//!    direction explains yet (tilted faces too small to peak beside the floor), up to
//!    [`UnorganizedConfig::rounds`] rounds;
//! 4. each point to one direction: the nearest to its normal within `norm_thresh`, then
//!    the one most of its `k` neighbours took when its normal accepts it or most of them
//!    agree (a mode filter against noisy normals); per direction `d` its points, split
//!    into pieces connected through their nearest neighbours (a table top and the floor
//!    below it are two pieces), each piece triangulated in 2D on the plane orthogonal to
//!    `d` (2.5D Delaunay along `d`), the pieces in parallel; every point is triangulated
//!    once (FastGA sees an even sample of at most [`GA_SAMPLE`] points);
//! 5. the pieces as one mesh, segmented by the directions as the organized path does
//!    (`lmax`, `norm_thresh`, `z_thresh`, `min_triangles`, optional refinement), each
//!    segment's polygon extracted in its plane, optional post-processing;
//! 6. labels ([`Extraction::fitted`]): a point that several polygons use (an edge between a
//!    wall and the floor) goes to the one whose plane is nearest; a point that none uses
//!    goes to the nearest plane of its neighbours' polygons when it lies within
//!    `z_thresh / 2` of it, round after round from the points so labelled until none
//!    joins (at most 64 rounds), so that a patch of points whose noisy normals kept
//!    them out of the triangulation is filled from its rim; with voxels, every input
//!    point takes its voxel's polygon when it lies within that distance of its plane.

use cloud_normals::{
    Neighbours, Orientation, estimate_normals, neighbourhood_noise, orient, smooth_points,
    spatial_order, voxel_downsample,
};
use halfedge_mesh::{HalfEdgeMesh, MeshError, NO_TWIN};
use plane_geom::vec3::dot;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::config::setters;
use crate::{
    Config, Counts, Extraction, LaplacianIterations, Polylidar, PolylidarError, Timings,
    predict_smoothing_passes,
};

/// Directions at most.
pub const MAX_DIRECTIONS: usize = 64;

/// A point is "flat" for the later rounds of direction finding when at least this share
/// of its neighbours' normals lie within `norm_thresh` of its own.
pub const FLAT_SHARE: f64 = 0.8;

/// Normals FastGA integrates per round at most (an even sample of the points left).
pub const GA_SAMPLE: usize = 100_000;

/// A direction is refined to the mean of the normals within this cosine of it (or
/// `norm_thresh`, if tighter).
pub const REFINE_COS: f64 = 0.98;

/// A FastGA peak within this cosine of a direction already found (either sign), or within
/// `norm_thresh` if tighter, is that direction again (about 18°). Fixed rather than
/// `norm_thresh` itself: a loose assignment threshold for noisy normals (the `room`
/// preset's 0.85) must not merge distinct nearby directions, whose points would then be
/// triangulated along one of them.
pub const SAME_DIRECTION_COS: f64 = 0.95;

/// Parameters of the unorganized 3D path ([`Config::unorganized`]). Lengths in the unit of
/// the coordinates.
///
/// ```
/// use polylidar::{Config, UnorganizedConfig};
/// let config: Config = toml::from_str("[unorganized]\nk = 12\nvoxel = 0.02").unwrap();
/// let section = UnorganizedConfig::default().with_k(12).with_voxel(0.02);
/// assert_eq!(config.unorganized, Some(section));
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
#[non_exhaustive]
pub struct UnorganizedConfig {
    /// Nearest neighbours (the point included) for PCA normals, for the pieces each
    /// direction's points split into, and for labelling the points next to a plane.
    /// At least 3. Default 12.
    pub k: usize,
    /// Voxel downsampling: one point per cube of this side before anything else; `0`
    /// (the default) keeps every point. Length unit.
    pub voxel: f64,
    /// Where the sensor was (normals are turned towards it); absent: normals point into
    /// the half-space of [`Config::up`] (walls by a fixed side direction).
    pub viewpoint: Option<[f64; 3]>,
    /// Rounds of direction finding (the first on all normals, each further one on the
    /// flat points no direction found so far explains). At least 1. Default 3.
    pub rounds: usize,
    /// Passes of Laplacian smoothing of the points over their `k` nearest neighbours
    /// before normals are estimated and the points triangulated (noisy scans; edges round
    /// off by about a neighbourhood's radius): a count of at most
    /// [`mesh_smooth_gpu::MAX_ITERATIONS`] (1000), or [`LaplacianIterations::Auto`] (in
    /// TOML `smoothing = "auto"`), predicted per cloud from its
    /// [`cloud_normals::neighbourhood_noise`] by
    /// [`crate::predict_smoothing_passes`] (0 on clean clouds). The count run is reported
    /// in [`crate::Counts::laplacian_iterations`]. Default 0.
    pub smoothing: LaplacianIterations,
}

impl Default for UnorganizedConfig {
    fn default() -> Self {
        Self {
            k: 12,
            voxel: 0.0,
            viewpoint: None,
            rounds: 3,
            smoothing: LaplacianIterations::Fixed(0),
        }
    }
}

setters!(UnorganizedConfig {
    with_k => k: usize,
    with_voxel => voxel: f64,
    with_viewpoint => viewpoint: Option<[f64; 3]>,
    with_rounds => rounds: usize,
    with_smoothing => smoothing: LaplacianIterations,
});

impl UnorganizedConfig {
    /// Checks the ranges.
    ///
    /// # Errors
    /// [`PolylidarError::Config`] naming the bad field.
    pub fn validate(&self) -> Result<(), PolylidarError> {
        let bad = PolylidarError::config;
        if self.k < 3 {
            return bad("unorganized.k", self.k.to_string(), "must be at least 3");
        }
        if !(self.voxel.is_finite() && self.voxel >= 0.0) {
            return bad(
                "unorganized.voxel",
                self.voxel.to_string(),
                "must be a finite length ≥ 0",
            );
        }
        if self.rounds == 0 {
            return bad("unorganized.rounds", "0".to_owned(), "must be at least 1");
        }
        if let LaplacianIterations::Fixed(n) = self.smoothing
            && n > mesh_smooth_gpu::MAX_ITERATIONS
        {
            return bad(
                "unorganized.smoothing",
                self.smoothing.to_string(),
                "must be at most 1000 passes",
            );
        }
        if let Some(v) = self.viewpoint
            && !v.iter().all(|c| c.is_finite())
        {
            return bad(
                "unorganized.viewpoint",
                format!("{v:?}"),
                "must be a finite point",
            );
        }
        Ok(())
    }
}

impl Polylidar {
    /// Planes and polygons with holes of an unorganized 3D cloud, in every direction (see
    /// the [module docs](crate::unorganized)): `normals` (one per point, any length, a
    /// zero vector for none) when the file has them, else estimated; parameters from
    /// [`Config::unorganized`] (its defaults when absent). The extraction's mesh has one
    /// vertex per input point; [`Extraction::fitted`] labels every point.
    ///
    /// ```
    /// use polylidar::{Config, Polylidar};
    /// // Two walls of a corner, 3 × 3 m, sampled every 5 cm.
    /// let mut points = Vec::new();
    /// for i in 0..60 {
    ///     for j in 0..60 {
    ///         let (u, v) = (0.05 * i as f64 + 0.025, 0.05 * j as f64);
    ///         points.push([u, 0.0, v]); // the wall y = 0
    ///         points.push([0.0, u, v]); // the wall x = 0
    ///     }
    /// }
    /// let config = Config::new().with_lmax(0.2).with_z_thresh(0.05).with_norm_thresh(0.95);
    /// let extraction = Polylidar::new(config)?.extract_unorganized(&points, None)?;
    /// assert_eq!(extraction.polygons.len(), 2);
    /// # Ok::<(), polylidar::PolylidarError>(())
    /// ```
    ///
    /// # Errors
    /// [`PolylidarError::Config`] for `normals` of another length than `points` or bad
    /// [`UnorganizedConfig`] values; [`PolylidarError::Normals`] for an empty cloud or a
    /// non-finite point; and the errors of FastGA, segmentation and post-processing.
    pub fn extract_unorganized(
        &self,
        points: &[[f64; 3]],
        normals: Option<&[[f64; 3]]>,
    ) -> Result<Extraction, PolylidarError> {
        let section = self.config().unorganized.unwrap_or_default();
        section.validate()?;
        if let Some(n) = normals
            && n.len() != points.len()
        {
            return Err(PolylidarError::Config {
                field: "normals",
                value: format!("{} normals", n.len()),
                reason: "must be one per point",
            });
        }
        self.install(|| self.unorganized(points, normals, &section))
    }

    fn unorganized(
        &self,
        points: &[[f64; 3]],
        normals: Option<&[[f64; 3]]>,
        section: &UnorganizedConfig,
    ) -> Result<Extraction, PolylidarError> {
        let config = self.config();
        let mut timings = Timings::default();
        let voxels = match section.voxel > 0.0 {
            true => Some(timings.time("voxel", || voxel_downsample(points, section.voxel))?),
            false => None,
        };
        // The working points: all, or one per voxel, in Morton order (`work[w]` is the
        // input index of working point `w`): every neighbourhood pass below then reads
        // memory mostly in order, where a shuffled cloud would jump through it.
        let work: Vec<u32> = timings.time("order", || match &voxels {
            Some(v) => {
                let kept: Vec<[f64; 3]> = v
                    .representatives
                    .iter()
                    .map(|&i| points[i as usize])
                    .collect();
                spatial_order(&kept)
                    .into_iter()
                    .map(|r| v.representatives[r as usize])
                    .collect()
            }
            None => spatial_order(points),
        });
        let wpoints: Vec<[f64; 3]> = work.iter().map(|&i| points[i as usize]).collect();
        let Working {
            knn,
            passes,
            smoothed,
            normals: wnormals,
        } = timings.time("normals", || {
            working_normals(&wpoints, &work, normals, section, config.up)
        })?;
        let wpoints = smoothed.unwrap_or(wpoints);
        let directions = timings.time("fastga", || self.directions(&wnormals, &knn))?;
        let pieces = Pieces {
            points: &wpoints,
            normals: &wnormals,
            knn: &knn,
            directions: &directions,
            norm_thresh: config.norm_thresh,
            z_cut: if config.z_thresh > 0.0 {
                config.z_thresh
            } else {
                f64::INFINITY
            },
            min_points: if config.min_area > 0.0 {
                3
            } else {
                (config.min_triangles / 2).max(3)
            },
        };
        let (mesh, duplicate_points) = timings.time("mesh", || pieces.mesh())?;
        let counts = Counts {
            points: points.len(),
            duplicate_points,
            laplacian_iterations: passes,
            ..Counts::default()
        };
        let mut extraction = self.extract_planes(mesh, Some(directions), counts, timings)?;
        extraction.rim_distance = 0.0;
        let rim = if config.z_thresh > 0.0 {
            config.z_thresh / 2.0
        } else {
            config.lmax / 4.0
        };
        let mut label_timing = Timings::default();
        let fitted = label_timing.time("labels", || {
            let labels = fitted_labels(&extraction, &knn, rim);
            input_labels(&extraction, &labels, points, &work, voxels.as_ref(), rim)
        });
        extraction.fitted = fitted;
        extraction.mesh = in_input_order(std::mem::take(&mut extraction.mesh), points, &work);
        label_timing.prepend(std::mem::take(&mut extraction.diagnostics.timings));
        extraction.diagnostics.timings = label_timing;
        Ok(extraction)
    }

    /// Dominant directions of `normals`, round after round on what is left (see the
    /// module docs), each signed like most of the normals that agree with it; at most
    /// [`MAX_DIRECTIONS`].
    fn directions(
        &self,
        normals: &[[f64; 3]],
        knn: &Neighbours,
    ) -> Result<Vec<[f64; 3]>, PolylidarError> {
        let config = self.config();
        let cos = config.norm_thresh;
        let rounds = config.unorganized.unwrap_or_default().rounds;
        let flat: Vec<bool> = (0..normals.len())
            .into_par_iter()
            .map(|i| {
                let n = normals[i];
                let around = knn.of(i);
                let agree = around
                    .iter()
                    .filter(|&&j| dot(n, normals[j as usize]).abs() >= cos)
                    .count();
                dot(n, n) > 0.5 && agree as f64 >= FLAT_SHARE * around.len() as f64
            })
            .collect();
        let mut found: Vec<[f64; 3]> = Vec::new();
        let mut left: Vec<usize> = (0..normals.len())
            .filter(|&i| dot(normals[i], normals[i]) > 0.5)
            .collect();
        for round in 0..rounds {
            if round > 0 {
                left.retain(|&i| {
                    flat[i] && !found.iter().any(|d| dot(normals[i], *d).abs() >= cos)
                });
                if left.len() < config.min_triangles.max(3) {
                    break;
                }
            }
            // A histogram's peaks: an even sample of at most `GA_SAMPLE` points does.
            let step = left.len().div_ceil(GA_SAMPLE).max(1);
            let both: Vec<[f64; 3]> = left
                .iter()
                .step_by(step)
                .flat_map(|&i| {
                    let n = normals[i];
                    [n, n.map(|c| -c)]
                })
                .collect();
            let peaks = self.dominant_normals_of(&both)?;
            let before = found.len();
            for d in peaks {
                // Either sign of a direction found already (in this round: its antipode).
                if found
                    .iter()
                    .any(|f| dot(*f, d).abs() >= cos.max(SAME_DIRECTION_COS))
                {
                    continue;
                }
                if found.len() < MAX_DIRECTIONS {
                    found.push(d);
                }
            }
            if found.len() == before {
                break;
            }
        }
        // Sign: the way most of the agreeing (oriented) normals point; then the mean of
        // the normals near it (twice), finer than FastGA's cells: over a 6 m floor a
        // direction 1° off drifts by 10 cm, beyond `z_thresh`.
        let near = cos.max(REFINE_COS);
        Ok(found
            .into_iter()
            .map(|d| {
                let mut d = d;
                for _ in 0..2 {
                    // Summed in fixed chunks, in order: the same bits on every run and
                    // thread count (rayon's `reduce` groups by how work was stolen).
                    let add = |a: [f64; 3], b: [f64; 3]| [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
                    let sum = normals
                        .par_chunks(SUM_CHUNK)
                        .map(|chunk| {
                            chunk.iter().fold([0.0; 3], |sum, n| {
                                let c = dot(*n, d);
                                if c.abs() >= near {
                                    add(sum, n.map(|v| v * c.signum()))
                                } else {
                                    sum
                                }
                            })
                        })
                        .collect::<Vec<_>>()
                        .into_iter()
                        .fold([0.0; 3], add);
                    let len = dot(sum, sum).sqrt();
                    if len > 0.0 {
                        d = sum.map(|v| v / len);
                    }
                }
                let sign: f64 = normals
                    .par_iter()
                    .map(|n| {
                        let c = dot(*n, d);
                        if c.abs() >= cos { c.signum() } else { 0.0 }
                    })
                    .sum();
                if sign < 0.0 { d.map(|c| -c) } else { d }
            })
            .collect())
    }
}

/// The median distance of the points to their nearest neighbour: the spacing of a cloud
/// sampled in every direction (the 2.5D spacing of [`crate::scale`] projects walls away).
///
/// ```
/// let points: Vec<[f64; 3]> = (0..100).map(|i| [0.0, 0.5 * (i % 10) as f64, 0.5 * (i / 10) as f64]).collect();
/// assert_eq!(polylidar::unorganized::median_spacing(&points)?, 0.5);
/// # Ok::<(), polylidar::PolylidarError>(())
/// ```
///
/// # Errors
/// [`PolylidarError::Normals`] for an empty cloud or a non-finite point.
pub fn median_spacing(points: &[[f64; 3]]) -> Result<f64, PolylidarError> {
    let knn = Neighbours::new(points, 2)?;
    let mut d: Vec<f64> = (0..knn.len())
        .map(|i| {
            let [a, b] = [knn.of(i)[0], knn.of(i)[knn.k() - 1]].map(|v| points[v as usize]);
            dot(
                [a[0] - b[0], a[1] - b[1], a[2] - b[2]],
                [a[0] - b[0], a[1] - b[1], a[2] - b[2]],
            )
            .sqrt()
        })
        .collect();
    let mid = d.len() / 2;
    Ok(*d.select_nth_unstable_by(mid, f64::total_cmp).1)
}

/// The point normals a file stores, one per point in the order its reader returns the
/// points (feature `io`): PCD `normal_x`, `normal_y`, `normal_z` fields; `None` for a file
/// without them and for other formats.
///
/// # Errors
/// [`PolylidarError::Io`] for an unreadable PCD file.
#[cfg(feature = "io")]
pub fn read_normals(
    path: impl AsRef<std::path::Path>,
) -> Result<Option<Vec<[f64; 3]>>, PolylidarError> {
    let path = path.as_ref();
    if polylidar_io::format_of(path) != Some(polylidar_io::Format::Pcd) || !file_has_normals(path)?
    {
        return Ok(None);
    }
    let columns = polylidar_io::read_pcd_fields(path)?;
    let (Some(x), Some(y), Some(z)) = (
        columns.column("normal_x"),
        columns.column("normal_y"),
        columns.column("normal_z"),
    ) else {
        return Ok(None);
    };
    // The reader of the points skips points with a NaN coordinate; so do these.
    let (Some(px), Some(py), Some(pz)) = (
        columns.column("x"),
        columns.column("y"),
        columns.column("z"),
    ) else {
        return Ok(None);
    };
    let valid = |i: usize| px[i].is_finite() && py[i].is_finite() && pz[i].is_finite();
    Ok(Some(
        (0..x.len())
            .filter(|&i| valid(i))
            .map(|i| [x[i], y[i], z[i]])
            .collect(),
    ))
}

/// Whether a file stores point normals [`read_normals`] reads (only its header is
/// parsed; feature `io`).
///
/// # Errors
/// [`PolylidarError::Io`] for an unreadable PCD header.
#[cfg(feature = "io")]
pub fn file_has_normals(path: impl AsRef<std::path::Path>) -> Result<bool, PolylidarError> {
    let path = path.as_ref();
    if polylidar_io::format_of(path) != Some(polylidar_io::Format::Pcd) {
        return Ok(false);
    }
    let header = pcd_header(path)?;
    Ok(["normal_x", "normal_y", "normal_z"]
        .iter()
        .all(|n| header.field(n).is_some()))
}

/// The sensor position a PCD file's `VIEWPOINT` names (its translation), for turning
/// estimated normals towards it; `None` for other formats (feature `io`).
///
/// # Errors
/// [`PolylidarError::Io`] for an unreadable PCD header.
#[cfg(feature = "io")]
pub fn read_viewpoint(
    path: impl AsRef<std::path::Path>,
) -> Result<Option<[f64; 3]>, PolylidarError> {
    let path = path.as_ref();
    if polylidar_io::format_of(path) != Some(polylidar_io::Format::Pcd) {
        return Ok(None);
    }
    let v = pcd_header(path)?.viewpoint;
    Ok(Some([v[0], v[1], v[2]]))
}

/// The header of a PCD file, read from its first 64 KiB.
#[cfg(feature = "io")]
fn pcd_header(path: &std::path::Path) -> Result<polylidar_io::PcdHeader, PolylidarError> {
    use std::io::Read as _;
    let io = |e: std::io::Error| PolylidarError::Write {
        path: path.to_path_buf(),
        message: format!("cannot read: {e}"),
    };
    let mut head = Vec::new();
    std::fs::File::open(path)
        .map_err(io)?
        .take(64 * 1024)
        .read_to_end(&mut head)
        .map_err(io)?;
    Ok(polylidar_io::parse_pcd_header(&head).map_err(|e| e.at(path))?)
}

/// Neighbours and oriented unit normals of the working points (`work[w]` is the input
/// index of working point `w`).
fn working_normals(
    wpoints: &[[f64; 3]],
    work: &[u32],
    normals: Option<&[[f64; 3]]>,
    section: &UnorganizedConfig,
    up: [f64; 3],
) -> Result<Working, PolylidarError> {
    let knn = Neighbours::new(wpoints, section.k)?;
    let passes = match section.smoothing {
        LaplacianIterations::Fixed(n) => n,
        LaplacianIterations::Auto => {
            neighbourhood_noise(wpoints, &knn).map_or(0, predict_smoothing_passes)
        }
    };
    let smoothed = (passes > 0).then(|| smooth_points(wpoints, &knn, passes));
    let wpoints = smoothed.as_deref().unwrap_or(wpoints);
    let mut wnormals = match normals {
        Some(given) => work
            .par_iter()
            .map(|&i| {
                let n = given[i as usize];
                let len = dot(n, n).sqrt();
                if len.is_finite() && len > 0.0 {
                    n.map(|c| c / len)
                } else {
                    [0.0; 3]
                }
            })
            .collect(),
        None => estimate_normals(wpoints, &knn),
    };
    // Normals given with the points keep their sides.
    if normals.is_none() {
        let orientation = match section.viewpoint {
            Some(v) => Orientation::Towards(v),
            None => Orientation::Along(up),
        };
        orient(wpoints, &mut wnormals, orientation)?;
    }
    Ok(Working {
        knn,
        passes,
        smoothed,
        normals: wnormals,
    })
}

/// The working points' neighbours, smoothing passes run, smoothed positions and unit
/// normals.
struct Working {
    knn: Neighbours,
    /// Smoothing passes run ([`UnorganizedConfig::smoothing`], predicted for `Auto`).
    passes: u32,
    /// The smoothed points; `None` without smoothing.
    smoothed: Option<Vec<[f64; 3]>>,
    normals: Vec<[f64; 3]>,
}

/// What splitting the points by direction and into connected pieces needs.
struct Pieces<'a> {
    points: &'a [[f64; 3]],
    normals: &'a [[f64; 3]],
    knn: &'a Neighbours,
    directions: &'a [[f64; 3]],
    norm_thresh: f64,
    /// Neighbours further apart than this along the direction are not connected.
    z_cut: f64,
    /// Pieces with fewer points are not triangulated.
    min_points: usize,
}

/// One piece: a direction and working point indices.
type Piece = (usize, Vec<u32>);

/// A piece's triangulation and the duplicate points it left out; `None` for a piece
/// that has no triangle (collinear points).
type Triangulated = Option<(HalfEdgeMesh, usize)>;

impl Pieces<'_> {
    /// The pieces of every direction, triangulated along it and gathered into one mesh
    /// of the working points; and the duplicate points the triangulations left out.
    fn mesh(&self) -> Result<(HalfEdgeMesh, usize), PolylidarError> {
        let labels = self.labels();
        let mut pieces = self.split(&labels);
        // The order of the mesh: by (direction, first point); the triangulations run
        // largest first.
        pieces.sort_by_key(|(j, members)| (*j, members[0]));
        let mut order: Vec<usize> = (0..pieces.len()).collect();
        order.sort_by_key(|&p| std::cmp::Reverse(pieces[p].1.len()));
        let mut meshes: Vec<Triangulated> = vec![None; pieces.len()];
        let built: Vec<(usize, Result<Triangulated, MeshError>)> = order
            .par_iter()
            .map(|&p| {
                let (j, members) = &pieces[p];
                let local: Vec<[f64; 3]> =
                    members.iter().map(|&w| self.points[w as usize]).collect();
                let result =
                    match HalfEdgeMesh::delaunay_25d_with_report(&local, self.directions[*j]) {
                        Ok((mesh, report)) => Ok(Some((mesh, report.duplicate_points))),
                        Err(MeshError::Collinear { .. } | MeshError::TooFewPoints { .. }) => {
                            Ok(None)
                        }
                        Err(e) => Err(e),
                    };
                (p, result)
            })
            .collect();
        for (p, result) in built {
            meshes[p] = result?;
        }
        // Sized up front: grown piece by piece, the arrays were copied into fresh pages
        // again and again.
        let total: usize = meshes
            .iter()
            .flatten()
            .map(|(mesh, _)| mesh.triangles().len())
            .sum();
        let mut triangles = Vec::with_capacity(total);
        let mut halfedges = Vec::with_capacity(3 * total);
        let mut normals = Vec::with_capacity(total);
        let mut duplicates = 0;
        for ((_, members), mesh) in pieces.iter().zip(meshes) {
            let Some((mesh, dup)) = mesh else { continue };
            duplicates += dup;
            let offset = 3 * triangles.len() as u32;
            let (_, tris, twins, tnormals) = mesh.into_parts();
            normals.extend(tris.iter().zip(tnormals).map(|(t, geometric)| {
                self.vertex_mean_normal(t.map(|v| members[v as usize]), geometric)
            }));
            triangles.extend(tris.into_iter().map(|t| t.map(|v| members[v as usize])));
            halfedges.extend(
                twins
                    .into_iter()
                    .map(|h| if h == NO_TWIN { NO_TWIN } else { h + offset }),
            );
        }
        let mesh =
            HalfEdgeMesh::from_parts_trusted(self.points.to_vec(), triangles, halfedges, normals);
        Ok((mesh, duplicates))
    }

    /// The normal of a triangle of working points `corners`: the mean of their point
    /// normals, each turned to the side of the triangle's `geometric` normal (the point
    /// normals are smoother than three noisy points); `geometric` when they cancel out.
    fn vertex_mean_normal(&self, corners: [u32; 3], geometric: [f64; 3]) -> [f64; 3] {
        let mut sum = [0.0; 3];
        for c in corners {
            let n = self.normals[c as usize];
            let s = if dot(n, geometric) < 0.0 { -1.0 } else { 1.0 };
            for a in 0..3 {
                sum[a] += s * n[a];
            }
        }
        let len = dot(sum, sum).sqrt();
        if len > 1e-9 {
            sum.map(|c| c / len)
        } else {
            geometric
        }
    }

    /// Per point, the direction it goes to ([`NO_DIRECTION`] for none): the one its
    /// normal is nearest to, within `norm_thresh`; then the one most of its neighbours
    /// went to, when the point's normal accepts it or most of them agree (a mode filter:
    /// a noisy normal on a wall takes the wall's direction, an edge point the side most of
    /// its neighbours lie on).
    fn labels(&self) -> Vec<u32> {
        let nearest: Vec<u32> = self
            .normals
            .par_iter()
            .map(|n| self.nearest_direction(*n))
            .collect();
        (0..nearest.len())
            .into_par_iter()
            .map(|i| {
                let around = self.knn.of(i);
                let mut votes: [(u32, u32); MAX_VOTES] = [(NO_DIRECTION, 0); MAX_VOTES];
                let mut kinds = 0;
                for &n in around {
                    let l = nearest[n as usize];
                    if l == NO_DIRECTION {
                        continue;
                    }
                    match votes[..kinds].iter_mut().find(|v| v.0 == l) {
                        Some(v) => v.1 += 1,
                        None if kinds < MAX_VOTES => {
                            votes[kinds] = (l, 1);
                            kinds += 1;
                        }
                        None => {}
                    }
                }
                let n = self.normals[i];
                let fit = |l: u32| dot(n, self.directions[l as usize]).abs();
                let Some(&(top, count)) = votes[..kinds].iter().max_by(|a, b| {
                    a.1.cmp(&b.1)
                        .then(fit(a.0).total_cmp(&fit(b.0)))
                        .then(b.0.cmp(&a.0))
                }) else {
                    return NO_DIRECTION;
                };
                if 2 * count as usize > around.len() || fit(top) >= self.norm_thresh {
                    top
                } else {
                    nearest[i]
                }
            })
            .collect()
    }

    /// The direction nearest to unit normal `n` within `norm_thresh` (ties: the lower
    /// index), or [`NO_DIRECTION`].
    fn nearest_direction(&self, n: [f64; 3]) -> u32 {
        let mut best = (NO_DIRECTION, self.norm_thresh);
        for (j, d) in self.directions.iter().enumerate() {
            let c = dot(n, *d).abs();
            if c >= best.1 && (best.0 == NO_DIRECTION || c > best.1) {
                best = (j as u32, c);
            }
        }
        best.0
    }

    /// The pieces of every direction: the points `labels` gives it, connected through
    /// neighbours with the same label that lie within `z_cut` of each other along it;
    /// pieces with fewer than `min_points` dropped. Directions in parallel.
    fn split(&self, labels: &[u32]) -> Vec<Piece> {
        let mut members: Vec<Vec<u32>> = vec![Vec::new(); self.directions.len()];
        let mut local = vec![0u32; labels.len()];
        for (i, &l) in labels.iter().enumerate() {
            if l != NO_DIRECTION {
                local[i] = members[l as usize].len() as u32;
                members[l as usize].push(i as u32);
            }
        }
        members
            .par_iter()
            .enumerate()
            .flat_map_iter(|(j, members)| {
                let d = self.directions[j];
                let mut parent: Vec<u32> = (0..members.len() as u32).collect();
                for (a, &i) in members.iter().enumerate() {
                    let p = self.points[i as usize];
                    // The root of `a`, kept up to date through its unions.
                    let mut x = find(&mut parent, a as u32);
                    for &n in self.knn.of(i as usize) {
                        if labels[n as usize] != j as u32 || n == i {
                            continue;
                        }
                        let q = self.points[n as usize];
                        if dot(d, [p[0] - q[0], p[1] - q[1], p[2] - q[2]]).abs() > self.z_cut {
                            continue;
                        }
                        let y = find(&mut parent, local[n as usize]);
                        if x != y {
                            let (low, high) = if x < y { (x, y) } else { (y, x) };
                            parent[high as usize] = low;
                            x = low;
                        }
                    }
                }
                let mut keyed: Vec<(u32, u32)> = (0..members.len() as u32)
                    .map(|a| (find(&mut parent, a), members[a as usize]))
                    .collect();
                keyed.sort_unstable();
                keyed
                    .chunk_by(|a, b| a.0 == b.0)
                    .filter(|group| group.len() >= self.min_points)
                    .map(|group| (j, group.iter().map(|&(_, i)| i).collect()))
                    .collect::<Vec<Piece>>()
            })
            .collect()
    }
}

/// The root of `x` in a union-find forest, halving the path on the way.
fn find(parent: &mut [u32], mut x: u32) -> u32 {
    while parent[x as usize] != x {
        let up = parent[parent[x as usize] as usize];
        parent[x as usize] = up;
        x = up;
    }
    x
}

/// Normals per partial sum when a direction is refined.
const SUM_CHUNK: usize = 8192;

/// No direction (a point whose normal agrees with none).
const NO_DIRECTION: u32 = u32::MAX;

/// Rounds of labelling the points no polygon uses from their labelled neighbours at most
/// (each reaches about one point spacing further; on the Table 10u scenes it settles in
/// 10–20 rounds).
const RIM_ROUNDS: usize = 64;

/// Distinct labels counted among a point's neighbours at most.
const MAX_VOTES: usize = 8;

/// The polygon of every working point (the extraction's mesh vertices), by fit (see the
/// module docs, step 6).
fn fitted_labels(extraction: &Extraction, knn: &Neighbours, rim: f64) -> Vec<i32> {
    let points = extraction.mesh.vertices();
    let mut best = vec![(f64::INFINITY, -1i32); points.len()];
    let triangles = extraction.mesh.triangles();
    for (index, polygon) in extraction.polygons.iter().enumerate() {
        for &t in &polygon.triangles {
            for v in triangles[t as usize] {
                let d = plane_distance(extraction, index as i32, points[v as usize]);
                let slot = &mut best[v as usize];
                if d < slot.0 {
                    *slot = (d, index as i32);
                }
            }
        }
    }
    // Points in no polygon: the nearest plane among their neighbours' polygons, round
    // after round from the points labelled so far. Only the points still unlabelled are
    // visited, and after the first round only those with a neighbour labelled in the
    // round before: the others see the same labelled neighbours as when they last found
    // none near enough (clutter, 28,000 of Autzen's points, stays unlabelled through all
    // 21 rounds).
    let mut pending: Vec<usize> = (0..points.len()).filter(|&w| best[w].1 < 0).collect();
    let mut fresh = vec![true; points.len()];
    for _ in 0..RIM_ROUNDS {
        let rims: Vec<(usize, i32)> = pending
            .par_iter()
            .filter(|&&w| knn.of(w).iter().any(|&n| fresh[n as usize]))
            .filter_map(|&w| {
                knn.of(w)
                    .iter()
                    .map(|&n| best[n as usize].1)
                    .filter(|&l| l >= 0)
                    .map(|l| (plane_distance(extraction, l, points[w]), l))
                    .filter(|&(d, _)| d <= rim)
                    .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)))
                    .map(|(_, l)| (w, l))
            })
            .collect();
        if rims.is_empty() {
            break;
        }
        fresh.fill(false);
        for (w, l) in rims {
            best[w].1 = l;
            fresh[w] = true;
        }
        pending.retain(|&w| best[w].1 < 0);
    }
    best.into_iter().map(|(_, l)| l).collect()
}

/// The labels of the working points (`work[w]` is the input index of `w`) for every
/// input point; with voxels, a point not kept takes its voxel's polygon when it lies
/// within `rim` of its plane.
fn input_labels(
    extraction: &Extraction,
    labels: &[i32],
    points: &[[f64; 3]],
    work: &[u32],
    voxels: Option<&cloud_normals::Voxels>,
    rim: f64,
) -> Vec<i32> {
    let mut all = vec![-1; points.len()];
    for (&i, &l) in work.iter().zip(labels) {
        all[i as usize] = l;
    }
    if let Some(voxels) = voxels {
        let of_voxel: Vec<i32> = voxels
            .representatives
            .iter()
            .map(|&r| all[r as usize])
            .collect();
        for (i, label) in all.iter_mut().enumerate() {
            let l = of_voxel[voxels.voxel_of[i] as usize];
            if *label < 0 && l >= 0 && plane_distance(extraction, l, points[i]) <= rim {
                *label = l;
            }
        }
    }
    all
}

/// The distance of `p` from the plane of polygon `polygon`.
fn plane_distance(extraction: &Extraction, polygon: i32, p: [f64; 3]) -> f64 {
    let plane = &extraction.polygons[polygon as usize].plane;
    (dot(plane.normal, p) + plane.offset).abs()
}

/// The mesh of the working points with one vertex per input point instead: vertex
/// `work[w]` is working point `w` (smoothed, if it was), the other input points are
/// unused vertices at their input positions.
fn in_input_order(mesh: HalfEdgeMesh, points: &[[f64; 3]], work: &[u32]) -> HalfEdgeMesh {
    let (working, triangles, halfedges, normals) = mesh.into_parts();
    let mut vertices = points.to_vec();
    for (&i, p) in work.iter().zip(working) {
        vertices[i as usize] = p;
    }
    let triangles = triangles
        .into_iter()
        .map(|t| t.map(|v| work[v as usize]))
        .collect();
    HalfEdgeMesh::from_parts_trusted(vertices, triangles, halfedges, normals)
}

impl Config {
    /// Sets [`Config::unorganized`] (`None`: unorganized clouds take the 2.5D path unless
    /// asked for [`Polylidar::extract_unorganized`], which then uses the defaults).
    pub fn with_unorganized(mut self, unorganized: Option<UnorganizedConfig>) -> Self {
        self.unorganized = unorganized;
        self
    }
}
