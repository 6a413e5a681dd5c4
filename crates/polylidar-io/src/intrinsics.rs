//! Camera intrinsics files: Open3D's camera JSON, and any camera file by its extension
//! (Open3D JSON or RealSense `_metadata.csv`), with the size check against a depth image.
//!
//! With the `opc-mesh` feature, [`CameraIntrinsics`] converts into the pipeline's camera
//! model ([`opc_mesh::Intrinsics`], [`opc_mesh::DepthOptions`]), so that there is one
//! pinhole type in the pipeline and this crate's is only what a file says.

use std::path::Path;

use serde_json::Value;

use crate::depth::CameraIntrinsics;
use crate::error::{ErrorKind, Format, IoError, KindResult, read_file};
use crate::read_realsense_intrinsics;

/// Reads an Open3D camera JSON (`PinholeCameraIntrinsic`, as written by
/// `o3d.io.write_pinhole_camera_intrinsic`): `width`, `height` and a column-major 3 × 3
/// `intrinsic_matrix` `[fx, 0, 0, 0, fy, 0, cx, cy, 1]`. The file carries no depth scale
/// ([`CameraIntrinsics::depth_scale`] is `None`).
///
/// # Errors
/// Unreadable file, invalid JSON, a key missing, a size that is not a positive integer, a
/// matrix that is not 9 finite numbers of a pinhole camera (positive focal lengths, no
/// skew, last row `0 0 1`).
pub fn read_open3d_camera(path: impl AsRef<Path>) -> Result<CameraIntrinsics, IoError> {
    let path = path.as_ref();
    let bytes = read_file(path, Format::CameraJson)?;
    parse_open3d_camera(&String::from_utf8_lossy(&bytes)).map_err(|e| e.at(path))
}

/// Parses Open3D camera JSON text; see [`read_open3d_camera`].
///
/// ```
/// let json = r#"{"width": 640, "height": 480,
///     "intrinsic_matrix": [525.0, 0, 0, 0, 525.0, 0, 319.5, 239.5, 1]}"#;
/// let k = polylidar_io::parse_open3d_camera(json)?;
/// assert_eq!((k.width, k.height, k.fx, k.ppx, k.ppy), (640, 480, 525.0, 319.5, 239.5));
/// # Ok::<(), polylidar_io::IoError>(())
/// ```
///
/// # Errors
/// As [`read_open3d_camera`], with no file name.
pub fn parse_open3d_camera(text: &str) -> Result<CameraIntrinsics, IoError> {
    parse(text).map_err(|k| IoError::new(Format::CameraJson, k))
}

/// Reads camera intrinsics from a file by its extension: `.json` is an Open3D camera JSON
/// ([`read_open3d_camera`]), anything else a RealSense metadata CSV
/// ([`read_realsense_intrinsics`]).
///
/// # Errors
/// Those of the reader chosen.
pub fn read_camera_file(path: impl AsRef<Path>) -> Result<CameraIntrinsics, IoError> {
    let path = path.as_ref();
    let is_json = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"));
    if is_json {
        read_open3d_camera(path)
    } else {
        read_realsense_intrinsics(path)
    }
}

impl CameraIntrinsics {
    /// Checks that these intrinsics are for an image of `width × height` pixels.
    ///
    /// ```
    /// let k = polylidar_io::CameraIntrinsics { width: 640, height: 480, ..Default::default() };
    /// assert!(k.check_size(640, 480).is_ok());
    /// assert!(k.check_size(320, 240).is_err());
    /// ```
    ///
    /// # Errors
    /// [`ErrorKind::Shape`] naming both sizes.
    pub fn check_size(&self, width: usize, height: usize) -> Result<(), ErrorKind> {
        if (self.width, self.height) == (width, height) {
            Ok(())
        } else {
            Err(ErrorKind::Shape(format!(
                "the camera is {} × {}, the depth image {width} × {height}",
                self.width, self.height
            )))
        }
    }
}

#[cfg(feature = "opc-mesh")]
impl From<&CameraIntrinsics> for opc_mesh::Intrinsics {
    /// The pinhole model of the file (focal lengths and principal point).
    fn from(k: &CameraIntrinsics) -> Self {
        opc_mesh::Intrinsics::new(k.fx, k.fy, k.ppx, k.ppy)
    }
}

#[cfg(feature = "opc-mesh")]
impl From<&CameraIntrinsics> for opc_mesh::DepthOptions {
    /// Back-projection options for the file's camera: its depth scale when it states one,
    /// else [`opc_mesh::DepthOptions::new`]'s default (1 mm per unit).
    fn from(k: &CameraIntrinsics) -> Self {
        let options = opc_mesh::DepthOptions::new(k.into());
        match k.depth_scale {
            Some(scale) => options.with_depth_scale(scale),
            None => options,
        }
    }
}

fn parse(text: &str) -> KindResult<CameraIntrinsics> {
    let value: Value = serde_json::from_str(text).map_err(|e| ErrorKind::Line {
        line: e.line(),
        reason: format!("not JSON: {e}"),
    })?;
    let size = |key: &str| -> KindResult<usize> {
        let v = value
            .get(key)
            .ok_or_else(|| ErrorKind::MissingField(key.to_owned()))?;
        v.as_u64()
            .filter(|&n| n > 0 && n <= 1 << 20)
            .map(|n| n as usize)
            .ok_or_else(|| ErrorKind::BadHeader(format!("`{key}` is {v}, not an image size")))
    };
    let (width, height) = (size("width")?, size("height")?);
    let matrix = value
        .get("intrinsic_matrix")
        .ok_or_else(|| ErrorKind::MissingField("intrinsic_matrix".to_owned()))?;
    let numbers: Vec<f64> = matrix
        .as_array()
        .map(|a| a.iter().filter_map(Value::as_f64).collect())
        .unwrap_or_default();
    let [fx, m01, m02, skew, fy, m12, cx, cy, m22] = numbers[..] else {
        return Err(ErrorKind::BadHeader(format!(
            "`intrinsic_matrix` must be 9 numbers (a column-major 3 × 3 matrix), found {matrix}"
        )));
    };
    let bad = |what: &str| {
        Err(ErrorKind::BadHeader(format!(
            "`intrinsic_matrix` {matrix}: {what}"
        )))
    };
    if numbers.iter().any(|v| !v.is_finite()) {
        return bad("a number is not finite");
    }
    if fx <= 0.0 || fy <= 0.0 {
        return bad("the focal lengths (entries 0 and 4) must be > 0");
    }
    if skew != 0.0 {
        return bad("a skewed camera (entry 3) is not supported");
    }
    if (m01, m02, m12, m22) != (0.0, 0.0, 0.0, 1.0) {
        return bad("not a pinhole camera matrix (entries 1, 2, 5 must be 0 and entry 8 be 1)");
    }
    Ok(CameraIntrinsics {
        width,
        height,
        fx,
        fy,
        ppx: cx,
        ppy: cy,
        depth_scale: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const PRIMESENSE: &str = r#"{
        "width" : 640,
        "height" : 480,
        "intrinsic_matrix" : [ 525.0, 0, 0, 0, 525.0, 0, 319.5, 239.5, 1 ]
    }"#;

    #[test]
    fn reads_column_major_matrix() {
        let k = parse_open3d_camera(PRIMESENSE).unwrap();
        assert_eq!((k.width, k.height), (640, 480));
        assert_eq!((k.fx, k.fy, k.ppx, k.ppy), (525.0, 525.0, 319.5, 239.5));
        assert_eq!(k.depth_scale, None);
        // Different fx and fy land in the right places.
        let k = parse_open3d_camera(
            r#"{"width": 4, "height": 3, "intrinsic_matrix": [1, 0, 0, 0, 2, 0, 3, 4, 1]}"#,
        )
        .unwrap();
        assert_eq!((k.fx, k.fy, k.ppx, k.ppy), (1.0, 2.0, 3.0, 4.0));
    }

    #[test]
    fn errors_name_the_problem() {
        let cases = [
            ("{", "not JSON"),
            (r#"{"height": 3, "intrinsic_matrix": []}"#, "`width`"),
            (r#"{"width": 4, "height": 3}"#, "`intrinsic_matrix`"),
            (
                r#"{"width": -4, "height": 3, "intrinsic_matrix": []}"#,
                "not an image size",
            ),
            (
                r#"{"width": 4, "height": 3, "intrinsic_matrix": [1, 0, 0, 0, 2, 0, 3, 4]}"#,
                "9 numbers",
            ),
            (
                r#"{"width": 4, "height": 3, "intrinsic_matrix": [0, 0, 0, 0, 2, 0, 3, 4, 1]}"#,
                "focal lengths",
            ),
            (
                r#"{"width": 4, "height": 3, "intrinsic_matrix": [1, 0, 0, 0.5, 2, 0, 3, 4, 1]}"#,
                "skewed",
            ),
            (
                r#"{"width": 4, "height": 3, "intrinsic_matrix": [1, 0, 0, 0, 2, 0, 3, 4, 2]}"#,
                "pinhole",
            ),
        ];
        for (text, expected) in cases {
            let e = parse_open3d_camera(text).unwrap_err();
            assert!(e.to_string().contains(expected), "{text}: {e}");
        }
    }

    #[test]
    fn size_check() {
        let k = parse_open3d_camera(PRIMESENSE).unwrap();
        assert!(k.check_size(640, 480).is_ok());
        let e = k.check_size(480, 640).unwrap_err();
        assert!(e.to_string().contains("640 × 480"), "{e}");
    }
}
