//! Named parameter sets: [`Preset`], the papers' settings and ours, each a whole
//! [`Config`].

use std::fmt;
use std::str::FromStr;

use fastga::FastGaConfig;
use polypost::PostprocessConfig;

use crate::{
    BeamOutlierConfig, BilateralConfig, Config, DecimateConfig, DominantNormalsConfig,
    FieldOfViewConfig, FillConfig, LaplacianConfig, LaplacianIterations, ScanConfig,
};

/// A named parameter set: the papers' (their tables) and ours (beyond them). Lengths are
/// in metres. [`Preset::config`] gives the whole [`Config`]; the names ([`Preset::name`],
/// [`FromStr`], [`fmt::Display`]) are the ones the CLI's `--preset` and the Python
/// package's `preset=` accept.
///
/// ```
/// use polylidar::{Config, Preset};
/// let kitti: Preset = "kitti".parse()?;
/// assert_eq!(kitti, Preset::Kitti);
/// assert_eq!(kitti.to_string(), "kitti");
/// assert_eq!(kitti.config().min_triangles, 3500);
/// assert!(Preset::all().iter().all(|p| p.name().parse::<Preset>() == Ok(*p)));
/// assert!("kitty".parse::<Preset>().unwrap_err().to_string().contains("kitti-range"));
/// # Ok::<(), polylidar::UnknownPreset>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Preset {
    /// `rgbd` (Table 7): Laplacian λ 1, k 3, 2 it; bilateral σl 0.1, σa 0.15, k 3, 2 it;
    /// FastGA [`FastGaConfig::rgbd`] (level 3, v_min 50, d_peak 0.28, 12 %);
    /// min_triangles 500, norm 0.96, lmax 0.05, z 0.1, hole vertices 10; post
    /// [`PostprocessConfig::rgbd`] (α 0.02, β_neg 0.02, β_pos 0.005, γ 0.1, δ 0.1). The
    /// paper chose these for the D435i's depth sampled at 424 × 240, which the RealSense
    /// SDK's decimation by 2 made 212 × 120 before Polylidar3D saw it (§8.2, Table 6).
    /// Larger frames are decimated to about 424 columns first ([`Config::decimate`],
    /// [`DecimateConfig`] `"auto"`: 640 × 480 and 848 × 480 by 2), not to the paper's
    /// 212: that is 2–3 times faster again but finds markedly fewer planes on the
    /// synthetic RGB-D suite (Table 10b); [`DecimateConfig::with_target_columns`] picks it.
    Rgbd,
    /// `synpeb` (the authors' benchmark values, used for the timing comparisons with the
    /// original): Laplacian k 5, λ 1, 8 it; bilateral k 3, σ 0.1 / 0.1, 2 it; FastGA
    /// [`FastGaConfig::synpeb_benchmark`] (level 5, v_min 3, d_peak 0.1, weight 0.01, 12 %
    /// of at least 10,000 normals; the paper's Table 9 has v_min 2,
    /// [`FastGaConfig::synpeb`]); lmax 0.1, min_triangles 1000, z 0.07, norm 0.95, hole
    /// vertices 50; no post-processing.
    Synpeb,
    /// `synpeb-auto`: the detector that adapts to the data, for range scanners and depth
    /// cameras alike (measured on both synthetic suites and the real SynPEB frames in
    /// `cargo xtask bench`, Tables 10 and 10b): `synpeb` with Laplacian iterations `auto`
    /// (Table 9: "iterations = varies (predicted)"; predicted per cloud from its noise and
    /// the noise's correlation, see [`crate::auto_laplacian_iterations`]), refinement on
    /// ([`Config::refine`]: absorption, planes without a dominant normal, merging, one
    /// plane id for disjoint pieces), `min_triangles` 250 and `min_area` 0.015 m² (a
    /// region with fewer triangles is kept when it is that large: far planes, and lower
    /// resolutions).
    SynpebAuto,
    /// `rgbd-auto`: the adaptive detector for depth cameras: `synpeb-auto` with the
    /// Laplacian passes growing with range ([`LaplacianConfig::range_exponent`] 1), as the
    /// depth error of stereo and structured-light cameras, relative to the point spacing,
    /// does, and isolated missing returns filled ([`Config::fill_missing`]: 4 of 8
    /// neighbours within 3 % in range). It runs at full resolution; decimating as `rgbd`
    /// does ([`Config::decimate`]) makes a 640 × 480 or 848 × 480 frame 3–5 times faster
    /// for about 3 points of f on the synthetic RGB-D suite (Table 10b).
    RgbdAuto,
    /// `rooftop` (Table 3): Laplacian λ 1, 2 it; bilateral σ 0.1 / 0.1, 2 it; normal =
    /// `up`; min_triangles 200, norm 0.94, lmax 0.9, hole vertices 8, z 0.2; post
    /// [`PostprocessConfig::rooftop`] (α 0.1, β_neg 0.1, β_pos 0, γ 16, δ 0.5).
    Rooftop,
    /// `kitti` (Table 4, §9.2.2): min_triangles 3500, norm 0.97, lmax 1.25, hole vertices
    /// 6; post [`PostprocessConfig::kitti`] (α 0.2, β_neg 0.3, β_pos 0.02, γ 30, δ 0.5);
    /// and the frame prepared as the paper does ([`ScanConfig`]): beams from the firing
    /// order, every second point, the front camera's view (azimuth ±40.7°, elevation
    /// −15.6° to 13.5°: KITTI's 1242 × 375 pixel images at a focal length of about 721
    /// pixels), beam outliers dropped (2 neighbours a side within 0.06 of one line, point
    /// 0.2 off it, gaps up to 1).
    Kitti,
    /// `kitti-range` (ours, beyond the paper): the whole KITTI frame as a 64-row range
    /// image on the organized 3D path, for walls, kerbs and façades as well as the ground:
    /// every second point, no crop, no outlier removal (a dropped point would leave a hole
    /// in the image); Laplacian λ 1, k 3, 2 it (wall normals scatter too much without
    /// it); bilateral σl 0.1, σa 0.1, k 3, 1 it; FastGA level 4, v_min 2, d_peak 0.15,
    /// weight 0.01 (walls are light beside the road); min_triangles 100, norm 0.95,
    /// lmax 1.5, z 0.15, hole vertices 6; no post-processing.
    KittiRange,
    /// `mesh-basement` (Tables 14–15): FastGA [`FastGaConfig::mesh`] (level 4, v_min 15,
    /// d_peak 0.1, 12 %); min_triangles 80, norm 0.95, lmax 0.1, z 0.08, hole vertices 6;
    /// post [`PostprocessConfig::mesh_basement`] (α 0.01, β_neg 0.025, β_pos 0, γ 0.07,
    /// δ 0.05).
    MeshBasement,
    /// `mesh-mainfloor` (Tables 14–15): as `mesh-basement` with min_triangles 1000 and
    /// post [`PostprocessConfig::mesh_mainfloor`] (α 0.02, β_neg 0.05, β_pos 0.02,
    /// γ 0.25, δ 0.1).
    MeshMainfloor,
    /// `room` (ours): unorganized indoor clouds — scans with the grid dropped, merged
    /// views, SLAM maps — on the unorganized 3D path ([`Config::unorganized`], its
    /// defaults but `smoothing = "auto"`: passes predicted from the cloud's noise):
    /// FastGA level 4, v_min 5, d_peak 0.15, weight 0.01; lmax 0.1,
    /// min_triangles 250, min_area 0.015, z 0.07, norm 0.85 (32°: the normals of noisy
    /// merged views scatter past 18° even after smoothing, and the tighter 0.95 broke
    /// their planes into fragments), hole vertices 10, refinement on (a wall seen between
    /// objects is one plane).
    Room,
    /// `aerial` (ours): airborne LiDAR on the unorganized 3D path, for pitched roofs and
    /// façades as well as flat roofs and the ground: FastGA as `room`; lmax 3,
    /// min_triangles 60, z 0.3, norm 0.94, hole vertices 8, refinement on (without it a
    /// city's roof faces, each at its own pitch and azimuth, come out split between the
    /// dominant directions nearest to them), normals from 16 neighbours (an airborne
    /// scanner samples densely along its scan lines and sparsely across them, and where
    /// two flight strips overlap 12 neighbours can lie on two nearly coincident lines,
    /// their normals tilted: the ground broke into hundreds of slivers there).
    Aerial,
}

/// Every preset, in the order the CLI lists them.
const ALL: [Preset; 11] = [
    Preset::Rgbd,
    Preset::Synpeb,
    Preset::SynpebAuto,
    Preset::RgbdAuto,
    Preset::Rooftop,
    Preset::Kitti,
    Preset::KittiRange,
    Preset::MeshBasement,
    Preset::MeshMainfloor,
    Preset::Room,
    Preset::Aerial,
];

impl Preset {
    /// Every preset.
    pub fn all() -> &'static [Preset] {
        &ALL
    }

    /// The preset's name (`rgbd`, `synpeb-auto`, …), as [`FromStr`] reads it.
    pub fn name(self) -> &'static str {
        match self {
            Preset::Rgbd => "rgbd",
            Preset::Synpeb => "synpeb",
            Preset::SynpebAuto => "synpeb-auto",
            Preset::RgbdAuto => "rgbd-auto",
            Preset::Rooftop => "rooftop",
            Preset::Kitti => "kitti",
            Preset::KittiRange => "kitti-range",
            Preset::MeshBasement => "mesh-basement",
            Preset::MeshMainfloor => "mesh-mainfloor",
            Preset::Room => "room",
            Preset::Aerial => "aerial",
        }
    }

    /// The preset's parameters (see each variant), lengths in metres.
    pub fn config(self) -> Config {
        let base = Config::default();
        // Our presets beyond the papers: FastGA level 4, d_peak 0.15, 12 %, light
        // directions kept (weight 0.01; walls beside a road, façades beside a roof).
        let ours = |value_threshold| {
            DominantNormalsConfig::from(
                FastGaConfig::default()
                    .with_level(4)
                    .with_sample_fraction(0.12)
                    .with_value_threshold(value_threshold)
                    .with_cluster_distance(0.15)
                    .with_min_cluster_weight(0.01),
            )
        };
        match self {
            Preset::Rgbd => Config {
                laplacian: Some(LaplacianConfig::default()),
                bilateral: Some(BilateralConfig {
                    sigma_angle: 0.15,
                    ..BilateralConfig::default()
                }),
                fastga: FastGaConfig::rgbd().into(),
                min_triangles: 500,
                norm_thresh: 0.96,
                lmax: 0.05,
                z_thresh: 0.1,
                min_hole_vertices: 10,
                postprocess: Some(PostprocessConfig::rgbd()),
                decimate: Some(DecimateConfig::default()),
                ..base
            },
            Preset::Synpeb | Preset::SynpebAuto | Preset::RgbdAuto => {
                let adaptive = self != Preset::Synpeb;
                Config {
                    laplacian: Some(LaplacianConfig {
                        kernel: 5,
                        iterations: if adaptive {
                            LaplacianIterations::Auto
                        } else {
                            LaplacianIterations::Fixed(8)
                        },
                        range_exponent: if self == Preset::RgbdAuto { 1.0 } else { 0.0 },
                        ..LaplacianConfig::default()
                    }),
                    bilateral: Some(BilateralConfig::default()),
                    fastga: FastGaConfig::synpeb_benchmark().into(),
                    lmax: 0.1,
                    min_triangles: if adaptive { 250 } else { 1000 },
                    min_area: if adaptive { 0.015 } else { 0.0 },
                    z_thresh: 0.07,
                    norm_thresh: 0.95,
                    min_hole_vertices: 50,
                    refine: adaptive,
                    fill_missing: (self == Preset::RgbdAuto).then(FillConfig::default),
                    ..base
                }
            }
            Preset::Rooftop => Config {
                laplacian: Some(LaplacianConfig::default()),
                bilateral: Some(BilateralConfig::default()),
                min_triangles: 200,
                norm_thresh: 0.94,
                lmax: 0.9,
                min_hole_vertices: 8,
                z_thresh: 0.2,
                postprocess: Some(PostprocessConfig::rooftop()),
                ..base
            },
            Preset::Kitti => Config {
                min_triangles: 3500,
                norm_thresh: 0.97,
                lmax: 1.25,
                min_hole_vertices: 6,
                postprocess: Some(PostprocessConfig::kitti()),
                scan: Some(ScanConfig {
                    keep_every: 2,
                    field_of_view: Some(FieldOfViewConfig {
                        azimuth_deg: [-40.7, 40.7],
                        elevation_deg: [-15.6, 13.5],
                    }),
                    beam_outliers: Some(BeamOutlierConfig::default()),
                    ..ScanConfig::default()
                }),
                ..base
            },
            Preset::KittiRange => Config {
                // Walls are seen at a few centimetres per pixel with centimetres of range
                // noise: without vertex smoothing their normals scatter too widely for a
                // FastGA peak, and only the ground comes out.
                laplacian: Some(LaplacianConfig {
                    kernel: 3,
                    lambda: 1.0,
                    iterations: LaplacianIterations::Fixed(2),
                    ..LaplacianConfig::default()
                }),
                bilateral: Some(BilateralConfig {
                    iterations: 1,
                    ..BilateralConfig::default()
                }),
                fastga: ours(2.0),
                min_triangles: 100,
                norm_thresh: 0.95,
                lmax: 1.5,
                z_thresh: 0.15,
                min_hole_vertices: 6,
                scan: Some(ScanConfig {
                    keep_every: 2,
                    range_image_columns: Some(0),
                    ..ScanConfig::default()
                }),
                ..base
            },
            Preset::MeshBasement | Preset::MeshMainfloor => {
                let basement = self == Preset::MeshBasement;
                Config {
                    fastga: FastGaConfig::mesh().into(),
                    min_triangles: if basement { 80 } else { 1000 },
                    norm_thresh: 0.95,
                    lmax: 0.1,
                    z_thresh: 0.08,
                    min_hole_vertices: 6,
                    postprocess: Some(if basement {
                        PostprocessConfig::mesh_basement()
                    } else {
                        PostprocessConfig::mesh_mainfloor()
                    }),
                    ..base
                }
            }
            Preset::Room => Config {
                fastga: ours(5.0),
                lmax: 0.1,
                min_triangles: 250,
                z_thresh: 0.07,
                norm_thresh: 0.85,
                min_hole_vertices: 10,
                min_area: 0.015,
                refine: true,
                unorganized: Some(
                    crate::UnorganizedConfig::default()
                        .with_smoothing(crate::LaplacianIterations::Auto),
                ),
                ..base
            },
            Preset::Aerial => Config {
                fastga: ours(5.0),
                lmax: 3.0,
                min_triangles: 60,
                z_thresh: 0.3,
                norm_thresh: 0.94,
                min_hole_vertices: 8,
                refine: true,
                unorganized: Some(crate::UnorganizedConfig::default().with_k(16)),
                ..base
            },
        }
    }
}

impl From<Preset> for Config {
    fn from(preset: Preset) -> Self {
        preset.config()
    }
}

impl fmt::Display for Preset {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A name that is no [`Preset`]'s; its message lists the known names.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown preset {name:?}; known presets: {}", known_names())]
pub struct UnknownPreset {
    name: String,
}

impl UnknownPreset {
    /// The name given.
    pub fn name(&self) -> &str {
        &self.name
    }
}

/// The presets' names, comma separated.
fn known_names() -> String {
    ALL.map(Preset::name).join(", ")
}

impl FromStr for Preset {
    type Err = UnknownPreset;

    fn from_str(name: &str) -> Result<Self, Self::Err> {
        ALL.into_iter()
            .find(|p| p.name() == name)
            .ok_or_else(|| UnknownPreset {
                name: name.to_owned(),
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_preset_is_valid_and_named_once() {
        for (i, preset) in Preset::all().iter().enumerate() {
            assert_eq!(preset.config().validate().ok(), Some(()), "{preset}");
            assert_eq!(preset.name().parse::<Preset>(), Ok(*preset));
            assert!(Preset::all()[..i].iter().all(|p| p.name() != preset.name()));
        }
    }

    #[test]
    fn presets_take_the_stage_presets() {
        let post = |p: Preset| p.config().postprocess;
        assert_eq!(post(Preset::Rgbd), Some(PostprocessConfig::rgbd()));
        assert_eq!(post(Preset::Rooftop), Some(PostprocessConfig::rooftop()));
        assert_eq!(post(Preset::Kitti), Some(PostprocessConfig::kitti()));
        assert_eq!(
            post(Preset::MeshBasement),
            Some(PostprocessConfig::mesh_basement())
        );
        assert_eq!(
            post(Preset::MeshMainfloor),
            Some(PostprocessConfig::mesh_mainfloor())
        );
        let fastga = |p: Preset| p.config().fastga.config_for(usize::MAX);
        assert_eq!(fastga(Preset::Rgbd), FastGaConfig::rgbd());
        assert_eq!(fastga(Preset::MeshBasement), FastGaConfig::mesh());
        for p in [Preset::Synpeb, Preset::SynpebAuto, Preset::RgbdAuto] {
            assert_eq!(fastga(p), FastGaConfig::synpeb_benchmark(), "{p}");
        }
    }
}
