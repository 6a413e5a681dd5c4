//! NumPy `.npy` arrays: read any bool/integer/float dtype of either byte order into `f64`
//! (C or Fortran order, header versions 1–3); write `f64`, `f32` and `i32` arrays.

mod header;

use std::path::Path;

pub use header::Dtype;

use crate::cloud::PointCloud;
use crate::error::{ErrorKind, Format, IoError, KindResult, take, write_file};
use crate::limits::{Limits, times};

/// An n-dimensional array in C (row-major) order, converted to `f64`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct NpyArray {
    /// Dimensions, outermost first (empty for a 0-d array).
    pub shape: Vec<usize>,
    /// `shape.iter().product()` values in C order.
    pub data: Vec<f64>,
}

fn err(kind: ErrorKind) -> IoError {
    IoError::new(Format::Npy, kind)
}

fn shape_text(shape: &[usize]) -> String {
    format!(
        "({})",
        shape
            .iter()
            .map(usize::to_string)
            .collect::<Vec<_>>()
            .join(", ")
    )
}

impl NpyArray {
    /// Number of elements.
    pub fn len(&self) -> usize {
        self.data.len()
    }

    /// Whether the array holds no element.
    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }

    /// `(H, W, 3)` → organized cloud (`rows = H`, `cols = W`); `(N, 3)` → unorganized cloud.
    ///
    /// # Errors
    /// [`ErrorKind::Shape`] for any other shape.
    pub fn into_point_cloud(self) -> Result<PointCloud, IoError> {
        let (rows, cols) = match self.shape.as_slice() {
            &[h, w, 3] => (h, w),
            &[n, 3] => (1, n),
            other => {
                return Err(err(ErrorKind::Shape(format!(
                    "a point cloud needs shape (N, 3) or (H, W, 3), found {}",
                    shape_text(other)
                ))));
            }
        };
        let points = self
            .data
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect();
        Ok(PointCloud { rows, cols, points })
    }

    /// `(N, 2)` → 2D points.
    ///
    /// # Errors
    /// [`ErrorKind::Shape`] for any other shape.
    pub fn into_points_2d(self) -> Result<Vec<[f64; 2]>, IoError> {
        if !matches!(self.shape.as_slice(), &[_, 2]) {
            return Err(err(ErrorKind::Shape(format!(
                "2D points need shape (N, 2), found {}",
                shape_text(&self.shape)
            ))));
        }
        Ok(self.data.chunks_exact(2).map(|c| [c[0], c[1]]).collect())
    }
}

/// Reads an NPY file.
///
/// Accepts dtypes `b1`, `i1`–`i8`, `u1`–`u8`, `f4`, `f8` in either byte order (values
/// converted to `f64`; 64-bit integers beyond 2⁵³ round), C or Fortran order (Fortran data
/// is transposed to C order), header versions 1, 2 and 3.
///
/// # Errors
/// An [`IoError`] naming the file and the problem: bad magic, malformed header dictionary,
/// unsupported dtype (complex, half, structured, strings), truncated data, trailing bytes,
/// more values than [`Limits::for_path`] allows (8 bytes each, and the pipeline's share
/// per row of the last axis).
pub fn read_npy(path: impl AsRef<Path>) -> Result<NpyArray, IoError> {
    let path = path.as_ref();
    read_npy_with(path, &Limits::for_path(path))
}

/// As [`read_npy`], within `limits`.
///
/// # Errors
/// As [`read_npy`]; [`ErrorKind::OverBudget`] past `limits`.
pub fn read_npy_with(path: impl AsRef<Path>, limits: &Limits) -> Result<NpyArray, IoError> {
    let path = path.as_ref();
    parse_npy_with(&limits.read_file(path, Format::Npy)?, limits).map_err(|e| e.at(path))
}

/// Parses NPY bytes; see [`read_npy`].
///
/// # Errors
/// As [`read_npy`], with no file name.
pub fn parse_npy(bytes: &[u8]) -> Result<NpyArray, IoError> {
    parse_npy_with(bytes, &Limits::for_input_size(bytes.len() as u64))
}

/// As [`parse_npy`], within `limits`.
///
/// # Errors
/// As [`read_npy_with`], with no file name.
pub fn parse_npy_with(bytes: &[u8], limits: &Limits) -> Result<NpyArray, IoError> {
    parse(bytes, limits).map_err(err)
}

fn parse(bytes: &[u8], limits: &Limits) -> KindResult<NpyArray> {
    let h = header::parse_header(bytes)?;
    let count = h
        .shape
        .iter()
        .try_fold(1usize, |acc, &d| acc.checked_mul(d))
        .ok_or_else(|| ErrorKind::Shape(format!("shape {} overflows", shape_text(&h.shape))))?;
    let size = h.dtype.size();
    let needed = count
        .checked_mul(size)
        .ok_or_else(|| ErrorKind::Shape(format!("shape {} overflows", shape_text(&h.shape))))?;
    let raw = take(bytes, h.data_start, needed, "array data")?;
    let trailing = bytes.len() - h.data_start - needed;
    if trailing != 0 {
        return Err(ErrorKind::Shape(format!(
            "{trailing} bytes after the {count} elements of shape {}",
            shape_text(&h.shape)
        )));
    }
    // The f64 values (twice for Fortran order: the transposed copy), and the pipeline's
    // share per point: a row of the last axis ((N, 3), (H, W, 3), (N, 2)).
    let copies = if h.fortran_order && h.shape.len() > 1 {
        2
    } else {
        1
    };
    let points = match h.shape.as_slice() {
        [.., last] if h.shape.len() > 1 => count.checked_div(*last).unwrap_or(0),
        _ => count,
    };
    let estimate = (bytes.len() as u64)
        .saturating_add(times(count, 8 * copies))
        .saturating_add(limits.pipeline(points as u64));
    limits.check(estimate, || {
        format!(
            "an array of shape {}: {count} values of 8 bytes{}, {points} points of {} bytes in \
             the pipeline",
            shape_text(&h.shape),
            if copies == 2 {
                " (twice: Fortran order)"
            } else {
                ""
            },
            limits.pipeline_bytes_per_point
        )
    })?;
    let mut data = convert(raw, h.dtype, h.big_endian);
    if h.fortran_order && h.shape.len() > 1 {
        data = fortran_to_c(&data, &h.shape);
    }
    Ok(NpyArray {
        shape: h.shape,
        data,
    })
}

fn decode_all<const S: usize>(raw: &[u8], conv: impl Fn([u8; S]) -> f64) -> Vec<f64> {
    raw.chunks_exact(S)
        .map(|c| {
            let mut b = [0u8; S];
            b.copy_from_slice(c);
            conv(b)
        })
        .collect()
}

fn convert(raw: &[u8], dtype: Dtype, big: bool) -> Vec<f64> {
    macro_rules! num {
        ($t:ty) => {
            if big {
                decode_all(raw, |b| <$t>::from_be_bytes(b) as f64)
            } else {
                decode_all(raw, |b| <$t>::from_le_bytes(b) as f64)
            }
        };
    }
    match dtype {
        Dtype::Bool => decode_all(raw, |b: [u8; 1]| f64::from(u8::from(b[0] != 0))),
        Dtype::I8 => num!(i8),
        Dtype::I16 => num!(i16),
        Dtype::I32 => num!(i32),
        Dtype::I64 => num!(i64),
        Dtype::U8 => num!(u8),
        Dtype::U16 => num!(u16),
        Dtype::U32 => num!(u32),
        Dtype::U64 => num!(u64),
        Dtype::F32 => num!(f32),
        Dtype::F64 => num!(f64),
    }
}

/// Reorders column-major `data` of `shape` into row-major order.
fn fortran_to_c(data: &[f64], shape: &[usize]) -> Vec<f64> {
    // Fortran stride of axis j is the product of the dimensions before it.
    let mut fstride = vec![1usize; shape.len()];
    for j in 1..shape.len() {
        fstride[j] = fstride[j - 1] * shape[j - 1];
    }
    let mut index = vec![0usize; shape.len()];
    let mut out = Vec::with_capacity(data.len());
    let mut f_offset = 0usize;
    for _ in 0..data.len() {
        out.push(data[f_offset]);
        // Advance the C-order multi-index (last axis fastest), updating the F offset.
        for j in (0..shape.len()).rev() {
            index[j] += 1;
            f_offset += fstride[j];
            if index[j] < shape[j] {
                break;
            }
            f_offset -= fstride[j] * shape[j];
            index[j] = 0;
        }
    }
    out
}

fn encode(
    descr: &str,
    shape: &[usize],
    len: usize,
    body: impl FnOnce(&mut Vec<u8>),
) -> Result<Vec<u8>, IoError> {
    let count = shape.iter().try_fold(1usize, |acc, &d| acc.checked_mul(d));
    if count != Some(len) {
        return Err(err(ErrorKind::Shape(format!(
            "shape {} does not hold {len} values",
            shape_text(shape)
        ))));
    }
    let mut out = header::encode_header(descr, shape);
    body(&mut out);
    Ok(out)
}

/// Encodes `data` of `shape` as a little-endian `f64` NPY array.
///
/// # Errors
/// [`ErrorKind::Shape`] when `data.len()` is not the product of `shape`.
pub fn encode_npy_f64(shape: &[usize], data: &[f64]) -> Result<Vec<u8>, IoError> {
    encode("<f8", shape, data.len(), |out| {
        out.reserve(data.len() * 8);
        data.iter()
            .for_each(|v| out.extend_from_slice(&v.to_le_bytes()));
    })
}

/// Encodes `data` of `shape` as a little-endian `f32` NPY array (values rounded to `f32`).
///
/// # Errors
/// [`ErrorKind::Shape`] when `data.len()` is not the product of `shape`.
pub fn encode_npy_f32(shape: &[usize], data: &[f64]) -> Result<Vec<u8>, IoError> {
    encode("<f4", shape, data.len(), |out| {
        out.reserve(data.len() * 4);
        data.iter()
            .for_each(|&v| out.extend_from_slice(&(v as f32).to_le_bytes()));
    })
}

/// Encodes `data` of `shape` as a little-endian `i32` NPY array.
///
/// # Errors
/// [`ErrorKind::Shape`] when `data.len()` is not the product of `shape`.
pub fn encode_npy_i32(shape: &[usize], data: &[i32]) -> Result<Vec<u8>, IoError> {
    encode("<i4", shape, data.len(), |out| {
        out.reserve(data.len() * 4);
        data.iter()
            .for_each(|v| out.extend_from_slice(&v.to_le_bytes()));
    })
}

fn save(path: &Path, bytes: Result<Vec<u8>, IoError>) -> Result<(), IoError> {
    write_file(path, Format::Npy, &bytes.map_err(|e| e.at(path))?)
}

/// Writes `data` of `shape` (C order) as a `<f8` NPY file.
///
/// # Errors
/// Shape mismatch or a file system error.
pub fn write_npy_f64(path: impl AsRef<Path>, shape: &[usize], data: &[f64]) -> Result<(), IoError> {
    save(path.as_ref(), encode_npy_f64(shape, data))
}

/// Writes `data` of `shape` (C order) as a `<f4` NPY file.
///
/// # Errors
/// Shape mismatch or a file system error.
pub fn write_npy_f32(path: impl AsRef<Path>, shape: &[usize], data: &[f64]) -> Result<(), IoError> {
    save(path.as_ref(), encode_npy_f32(shape, data))
}

/// Writes `data` of `shape` (C order) as an `<i4` NPY file, e.g. an H×W label image.
///
/// # Errors
/// Shape mismatch or a file system error.
pub fn write_npy_i32(path: impl AsRef<Path>, shape: &[usize], data: &[i32]) -> Result<(), IoError> {
    save(path.as_ref(), encode_npy_i32(shape, data))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fortran_order_is_transposed() {
        // 2×3 matrix [[0, 1, 2], [3, 4, 5]] stored column-major: 0 3 1 4 2 5.
        let f = [0.0, 3.0, 1.0, 4.0, 2.0, 5.0];
        assert_eq!(
            fortran_to_c(&f, &[2, 3]),
            vec![0.0, 1.0, 2.0, 3.0, 4.0, 5.0]
        );
        // 2×2×2: C index (i, j, k) → value 4i + 2j + k, F offset i + 2j + 4k.
        let mut f3 = vec![0.0; 8];
        for i in 0..2 {
            for j in 0..2 {
                for k in 0..2 {
                    f3[i + 2 * j + 4 * k] = (4 * i + 2 * j + k) as f64;
                }
            }
        }
        assert_eq!(
            fortran_to_c(&f3, &[2, 2, 2]),
            (0..8).map(f64::from).collect::<Vec<_>>()
        );
    }

    #[test]
    fn big_endian_and_integers() {
        let mut b = header::encode_header(">i2", &[2]);
        b.extend_from_slice(&[0x01, 0x02, 0xff, 0xfe]);
        let a = parse_npy(&b).unwrap();
        assert_eq!(a.data, vec![258.0, -2.0]);
        let mut b = header::encode_header("<u2", &[1]);
        b.extend_from_slice(&[0xff, 0xff]);
        assert_eq!(parse_npy(&b).unwrap().data, vec![65535.0]);
    }

    #[test]
    fn round_trips() {
        let d = [1.5, f64::NAN, -3.25, 1e300, 0.0, 7.0];
        let a = parse_npy(&encode_npy_f64(&[2, 3], &d).unwrap()).unwrap();
        assert_eq!(a.shape, vec![2, 3]);
        assert!(
            a.data
                .iter()
                .zip(&d)
                .all(|(x, y)| x == y || (x.is_nan() && y.is_nan()))
        );
        let i = [-1, 0, 5, i32::MAX];
        let a = parse_npy(&encode_npy_i32(&[2, 2], &i).unwrap()).unwrap();
        assert_eq!(a.data, i.iter().map(|&v| f64::from(v)).collect::<Vec<_>>());
        let a = parse_npy(&encode_npy_f32(&[4], &[0.5, 1.0, 2.0, 3.0]).unwrap()).unwrap();
        assert_eq!(a.data, vec![0.5, 1.0, 2.0, 3.0]);
        assert!(encode_npy_f64(&[2, 2], &[1.0]).is_err());
    }

    #[test]
    fn shape_conversions() {
        let a = NpyArray {
            shape: vec![2, 2, 3],
            data: (0..12).map(f64::from).collect(),
        };
        let c = a.into_point_cloud().unwrap();
        assert_eq!((c.rows, c.cols), (2, 2));
        assert_eq!(c.points[3], [9.0, 10.0, 11.0]);
        let a = NpyArray {
            shape: vec![3, 2],
            data: (0..6).map(f64::from).collect(),
        };
        assert!(a.clone().into_point_cloud().is_err());
        assert_eq!(a.into_points_2d().unwrap()[2], [4.0, 5.0]);
    }

    #[test]
    fn corrupt_files_are_errors() {
        let good = encode_npy_f64(&[4], &[1.0, 2.0, 3.0, 4.0]).unwrap();
        assert!(parse_npy(&good[..good.len() - 1]).is_err());
        let mut long = good.clone();
        long.push(0);
        assert!(parse_npy(&long).is_err());
        assert!(parse_npy(b"\x93NUMPY\x04\x00").is_err());
        assert!(parse_npy(b"PK\x03\x04").is_err());
    }
}
