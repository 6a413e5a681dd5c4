//! Scans as unorganized clouds: the image grid dropped and the points shuffled, and
//! several views of one scene merged, each point with its ground-truth plane label.

use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};

use crate::{
    GroundTruthPlane, Noise, Pose, RandomPolyhedraConfig, ScanResult, Scene, SceneError, Sensor,
    SphericalSensor,
};

/// Points without an order, with the plane label of each and the sensor positions they
/// were seen from.
#[derive(Debug, Clone, PartialEq)]
pub struct UnorganizedCloud {
    /// Points in the world frame (metres), all finite.
    pub points: Vec<[f64; 3]>,
    /// Ground-truth plane label per point (≥ 0).
    pub labels: Vec<i32>,
    /// Per point, the index of the view (into `viewpoints`) it came from.
    pub views: Vec<u32>,
    /// The sensor positions of the views.
    pub viewpoints: Vec<[f64; 3]>,
    /// The scene's ground-truth planes, sorted by label.
    pub planes: Vec<GroundTruthPlane>,
}

impl ScanResult {
    /// The scan as an unorganized cloud: the pixels that hit something, in an order
    /// shuffled by `seed` (Fisher–Yates), seen from `viewpoint` (the sensor position).
    ///
    /// ```
    /// use synthscan::{Noise, synpeb_like};
    /// let (scene, sensor) = synpeb_like(0)?;
    /// let scan = scene.scan(&sensor, &Noise::none())?;
    /// let cloud = scan.to_unorganized([0.5, 2.5, 1.0], 7);
    /// assert_eq!(cloud.points.len(), scan.num_valid());
    /// assert!(cloud.points.iter().flatten().all(|c| c.is_finite()));
    /// # Ok::<(), synthscan::SceneError>(())
    /// ```
    pub fn to_unorganized(&self, viewpoint: [f64; 3], seed: u64) -> UnorganizedCloud {
        let mut keep: Vec<usize> = (0..self.points.len())
            .filter(|&i| self.labels[i] >= 0)
            .collect();
        shuffle(&mut keep, seed);
        UnorganizedCloud {
            points: keep.iter().map(|&i| self.points[i]).collect(),
            labels: keep.iter().map(|&i| self.labels[i]).collect(),
            views: vec![0; keep.len()],
            viewpoints: vec![viewpoint],
            planes: self.planes.clone(),
        }
    }
}

impl Scene {
    /// Scans the scene with every sensor (view `v` with `noise` seeded `noise.seed + v`)
    /// and merges the hits into one unorganized cloud, shuffled by `seed`.
    ///
    /// # Errors
    /// As [`Scene::scan`].
    pub fn scan_views<S: Sensor>(
        &self,
        sensors: &[S],
        noise: &Noise,
        seed: u64,
    ) -> Result<UnorganizedCloud, SceneError> {
        let mut points = Vec::new();
        let mut labels = Vec::new();
        let mut views = Vec::new();
        let mut planes = Vec::new();
        for (v, sensor) in sensors.iter().enumerate() {
            let scan = self.scan(sensor, &noise.with_seed(noise.seed.wrapping_add(v as u64)))?;
            for (p, &l) in scan.points.iter().zip(&scan.labels) {
                if l >= 0 {
                    points.push(*p);
                    labels.push(l);
                    views.push(v as u32);
                }
            }
            planes = scan.planes;
        }
        let mut order: Vec<usize> = (0..points.len()).collect();
        shuffle(&mut order, seed);
        Ok(UnorganizedCloud {
            points: order.iter().map(|&i| points[i]).collect(),
            labels: order.iter().map(|&i| labels[i]).collect(),
            views: order.iter().map(|&i| views[i]).collect(),
            viewpoints: sensors.iter().map(|s| s.pose().translation()).collect(),
            planes,
        })
    }
}

/// Where [`synpeb_like_views`] puts its sensors, 1 m above the floor, and what each looks
/// at: the [`crate::synpeb_like`] sensor, then one on each other side of the room.
pub const VIEWS: [([f64; 3], [f64; 3]); 4] = [
    ([0.5, 2.5, 1.0], [6.0, 2.5, 1.0]),
    ([5.5, 2.5, 1.0], [0.0, 2.5, 1.0]),
    ([3.0, 0.5, 1.0], [3.0, 5.0, 1.0]),
    ([3.0, 4.5, 1.0], [3.0, 0.0, 1.0]),
];

/// A SynPEB-like room (as [`crate::synpeb_like`], with the floor under every sensor of
/// [`VIEWS`] kept clear) and `views` (1–4) of its 500 × 500 spherical sensors, for
/// [`Scene::scan_views`]: merged, about 250,000 points a view.
///
/// # Errors
/// [`SceneError::PlacementFailed`] if the seed's objects do not fit.
pub fn synpeb_like_views(
    seed: u64,
    views: usize,
) -> Result<(Scene, Vec<SphericalSensor>), SceneError> {
    let views = views.clamp(1, VIEWS.len());
    let mut config = RandomPolyhedraConfig::default().with_seed(seed);
    config.keep_clear = VIEWS[..views]
        .iter()
        .enumerate()
        .map(|(v, (eye, _))| ([eye[0], eye[1]], if v == 0 { 1.0 } else { 0.5 }))
        .collect();
    let scene = Scene::random_polyhedra(&config)?;
    let sensors = VIEWS[..views]
        .iter()
        .map(|&(eye, target)| {
            let pose = Pose::look_at(eye, target, [0.0, 0.0, 1.0])?;
            Ok(SphericalSensor::new(500, 500, 70.0, 60.0)?.with_pose(pose))
        })
        .collect::<Result<_, SceneError>>()?;
    Ok((scene, sensors))
}

/// Fisher–Yates shuffle, deterministic by `seed`.
fn shuffle(items: &mut [usize], seed: u64) {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    for i in (1..items.len()).rev() {
        let j = rng.random_range(0..=i);
        items.swap(i, j);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn merged_views_keep_each_scan_and_its_labels() {
        let (scene, sensors) = synpeb_like_views(1, 2).unwrap();
        let noise = Noise::new(0.0, 1.0, 3);
        let merged = scene.scan_views(&sensors, &noise, 5).unwrap();
        let mut total = 0;
        for (v, sensor) in sensors.iter().enumerate() {
            let scan = scene.scan(sensor, &noise.with_seed(3 + v as u64)).unwrap();
            let mut expected: Vec<([u64; 3], i32)> = scan
                .points
                .iter()
                .zip(&scan.labels)
                .filter(|(_, l)| **l >= 0)
                .map(|(p, l)| (p.map(f64::to_bits), *l))
                .collect();
            let mut got: Vec<([u64; 3], i32)> = (0..merged.points.len())
                .filter(|&i| merged.views[i] == v as u32)
                .map(|i| (merged.points[i].map(f64::to_bits), merged.labels[i]))
                .collect();
            expected.sort_unstable();
            got.sort_unstable();
            assert_eq!(got, expected, "view {v}");
            total += expected.len();
        }
        assert_eq!(merged.points.len(), total);
        assert_eq!(merged.viewpoints[1], VIEWS[1].0);
        // Shuffled: the views are interleaved.
        assert!(merged.views[..100].contains(&1));
    }

    #[test]
    fn to_unorganized_is_a_permutation_of_the_hits() {
        let (scene, sensor) = crate::synpeb_like(2).unwrap();
        let scan = scene.scan(&sensor, &Noise::none()).unwrap();
        let cloud = scan.to_unorganized([0.5, 2.5, 1.0], 1);
        let mut a: Vec<(i32, [u64; 3])> = cloud
            .labels
            .iter()
            .zip(&cloud.points)
            .map(|(l, p)| (*l, p.map(f64::to_bits)))
            .collect();
        let mut b: Vec<(i32, [u64; 3])> = scan
            .labels
            .iter()
            .zip(&scan.points)
            .filter(|(l, _)| **l >= 0)
            .map(|(l, p)| (*l, p.map(f64::to_bits)))
            .collect();
        assert_ne!(a, b, "shuffled");
        a.sort_unstable();
        b.sort_unstable();
        assert_eq!(a, b);
    }
}
