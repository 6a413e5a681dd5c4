//! NumPy arrays in and out: float64 C-contiguous input is borrowed in place, float32 is
//! converted once, anything else is refused with the dtype and shape it should have.

use numpy::{
    Element, PyArray1, PyArrayDescrMethods, PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn,
    PyUntypedArray, PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;

/// `N` coordinates per point, borrowed from a float64 array or converted from float32.
pub enum Points<'py, const N: usize> {
    /// A C-contiguous float64 array, read in place.
    Borrowed(PyReadonlyArrayDyn<'py, f64>),
    /// A float32 array, converted to float64.
    Converted(Vec<[f64; N]>),
}

impl<const N: usize> Points<'_, N> {
    /// The points, `[f64; N]` each.
    pub fn as_slice(&self) -> &[[f64; N]] {
        match self {
            // `readable` made sure the array is contiguous and aligned.
            Points::Borrowed(a) => a.as_slice().map_or(&[], |s| s.as_chunks::<N>().0),
            Points::Converted(v) => v,
        }
    }

    /// The address of the buffer the Rust side reads: the array's own data pointer when it
    /// was borrowed in place.
    pub fn address(&self) -> usize {
        self.as_slice().as_ptr() as usize
    }
}

/// What an array argument must be, for error messages: `"points"`, `"(N, 3)"`.
#[derive(Clone, Copy)]
pub struct Expect {
    /// The argument's name.
    pub name: &'static str,
    /// The shape it must have, in NumPy's notation.
    pub shape: &'static str,
}

impl Expect {
    const fn new(name: &'static str, shape: &'static str) -> Self {
        Self { name, shape }
    }
}

/// The array arguments of the package, by the name and shape their errors give.
pub const POINTS_2D: Expect = Expect::new("points", "(N, 2)");
/// See [`POINTS_2D`].
pub const POINTS_3D: Expect = Expect::new("points", "(N, 3)");
/// See [`POINTS_2D`].
pub const CLOUD: Expect = Expect::new("cloud", "(H, W, 3)");
/// See [`POINTS_2D`].
pub const VERTICES: Expect = Expect::new("vertices", "(N, 3)");
/// See [`POINTS_2D`].
pub const TRIANGLES: Expect = Expect::new("triangles", "(M, 3)");
/// See [`POINTS_2D`].
pub const NORMALS: Expect = Expect::new("normals", "(N, 3)");
/// See [`POINTS_2D`].
pub const DEPTH: Expect = Expect::new("depth", "(H, W)");

/// The ndarray behind `obj`, or a `TypeError` naming what was expected.
pub fn ndarray<'a, 'py>(
    obj: &'a Bound<'py, PyAny>,
    expect: Expect,
    dtypes: &str,
) -> PyResult<&'a Bound<'py, PyUntypedArray>> {
    obj.cast::<PyUntypedArray>().map_err(|_| {
        let type_name = obj
            .get_type()
            .name()
            .map_or_else(|_| "?".to_owned(), |n| n.to_string());
        PyTypeError::new_err(format!(
            "{} must be a numpy.ndarray of {dtypes} with shape {}, not {type_name} \
             (use numpy.ascontiguousarray(x, dtype=numpy.float64))",
            expect.name, expect.shape
        ))
    })
}

/// Checks the number of dimensions and the fixed trailing sizes (`tail`) of an array.
pub fn check_shape(
    array: &Bound<'_, PyUntypedArray>,
    expect: Expect,
    ndim: usize,
    tail: &[usize],
) -> PyResult<()> {
    let shape = array.shape();
    if shape.len() != ndim || !shape.ends_with(tail) {
        return Err(PyValueError::new_err(format!(
            "{} must have shape {}, got {}",
            expect.name,
            expect.shape,
            shape_text(shape)
        )));
    }
    Ok(())
}

/// `(3, 4)` as NumPy writes shapes.
pub fn shape_text(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(ToString::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

fn dtype_name(array: &Bound<'_, PyUntypedArray>) -> String {
    array
        .dtype()
        .str()
        .map_or_else(|_| "?".to_owned(), |s| s.to_string())
}

fn not_contiguous(expect: Expect) -> PyErr {
    PyValueError::new_err(format!(
        "{} must be C-contiguous (row-major, no strides) to be read in place; \
         pass numpy.ascontiguousarray({})",
        expect.name, expect.name
    ))
}

/// Float points of `N` coordinates in an array of `ndim` dimensions whose last axis has
/// `N` entries: `(M, N)` lists or `(H, W, N)` grids. float64 C-contiguous arrays are
/// borrowed; float32 arrays are converted.
pub fn points<'py, const N: usize>(
    obj: &Bound<'py, PyAny>,
    expect: Expect,
    ndim: usize,
) -> PyResult<Points<'py, N>> {
    let array = ndarray(obj, expect, "float64 or float32")?;
    check_shape(array, expect, ndim, &[N])?;
    if let Ok(a) = array.cast::<PyArrayDyn<f64>>() {
        return Ok(Points::Borrowed(readable(a, expect)?));
    }
    if let Ok(a) = array.cast::<PyArrayDyn<f32>>() {
        let readonly = a
            .try_readonly()
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        let array = readonly.as_array();
        let flat: Vec<f64> = array.iter().map(|&v| f64::from(v)).collect();
        let (chunks, _) = flat.as_chunks::<N>();
        return Ok(Points::Converted(chunks.to_vec()));
    }
    Err(PyTypeError::new_err(format!(
        "{} must have dtype float64 or float32, got {} (convert with {}.astype(numpy.float64))",
        expect.name,
        dtype_name(array),
        expect.name
    )))
}

/// A C-contiguous array of `T` with `ndim` dimensions and trailing sizes `tail`, borrowed.
pub fn exact<'py, T: Element>(
    obj: &Bound<'py, PyAny>,
    expect: Expect,
    dtype: &str,
    ndim: usize,
    tail: &[usize],
) -> PyResult<PyReadonlyArrayDyn<'py, T>> {
    let array = ndarray(obj, expect, dtype)?;
    check_shape(array, expect, ndim, tail)?;
    let Ok(a) = array.cast::<PyArrayDyn<T>>() else {
        return Err(PyTypeError::new_err(format!(
            "{} must have dtype {dtype}, got {}",
            expect.name,
            dtype_name(array)
        )));
    };
    readable(a, expect)
}

/// `a` borrowed read-only as one slice: refused when not C-contiguous; copied once by NumPy
/// when its data is not aligned for `T` (NumPy allows that, and Dask hands such arrays
/// to its workers), which could not be read in place.
fn readable<'py, T: Element>(
    a: &Bound<'py, PyArrayDyn<T>>,
    expect: Expect,
) -> PyResult<PyReadonlyArrayDyn<'py, T>> {
    if !a.is_c_contiguous() {
        return Err(not_contiguous(expect));
    }
    let borrow = |a: &Bound<'py, PyArrayDyn<T>>| {
        a.try_readonly()
            .map_err(|e| PyValueError::new_err(e.to_string()))
    };
    let readonly = borrow(a)?;
    if readonly.as_slice().is_ok() {
        return Ok(readonly);
    }
    let copy = a.call_method0("copy")?.cast_into::<PyArrayDyn<T>>()?;
    let readonly = borrow(&copy)?;
    match readonly.as_slice() {
        Ok(_) => Ok(readonly),
        Err(e) => Err(PyValueError::new_err(format!("{}: {e}", expect.name))),
    }
}

/// Triangle indices: an `(M, 3)` array of any integer dtype, checked to fit `u32`.
pub fn triangles(obj: &Bound<'_, PyAny>, expect: Expect) -> PyResult<Vec<[u32; 3]>> {
    let array = ndarray(obj, expect, "integers")?;
    check_shape(array, expect, 2, &[3])?;
    let kind = array.dtype().kind();
    if kind != b'i' && kind != b'u' {
        return Err(PyTypeError::new_err(format!(
            "{} must have an integer dtype (int32, int64, uint32, …), got {}",
            expect.name,
            dtype_name(array)
        )));
    }
    // One conversion to u32 whatever the integer type (the mesh owns its triangles).
    let as_i64 = obj.call_method1("astype", ("int64",))?;
    let a = as_i64
        .cast::<PyArrayDyn<i64>>()?
        .try_readonly()
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    let values = a.as_array();
    let mut out = Vec::with_capacity(values.len() / 3);
    let mut flat = values.iter();
    while let (Some(&a), Some(&b), Some(&c)) = (flat.next(), flat.next(), flat.next()) {
        let index = |v: i64| {
            u32::try_from(v).map_err(|_| {
                PyValueError::new_err(format!(
                    "{} holds {v}, not a vertex index (0 … 4294967295)",
                    expect.name
                ))
            })
        };
        out.push([index(a)?, index(b)?, index(c)?]);
    }
    Ok(out)
}

/// An `(M, N)` float64 array that owns `rows` (no copy: the vector becomes the array).
pub fn rows_to_array<'py, const N: usize>(
    py: Python<'py>,
    rows: Vec<[f64; N]>,
) -> PyResult<Bound<'py, PyAny>> {
    let m = rows.len();
    let flat: Vec<f64> = rows.into_flattened();
    Ok(PyArray1::from_vec(py, flat).reshape([m, N])?.into_any())
}

/// An `(M, N)` float32 array that owns `rows`.
pub fn rows_to_array_f32<'py, const N: usize>(
    py: Python<'py>,
    rows: Vec<[f32; N]>,
) -> PyResult<Bound<'py, PyAny>> {
    let m = rows.len();
    let flat: Vec<f32> = rows.into_flattened();
    Ok(PyArray1::from_vec(py, flat).reshape([m, N])?.into_any())
}

/// An `(M, 3)` uint32 array of triangles.
pub fn triangles_to_array<'py>(
    py: Python<'py>,
    rows: Vec<[u32; 3]>,
) -> PyResult<Bound<'py, PyAny>> {
    let m = rows.len();
    Ok(PyArray1::from_vec(py, rows.into_flattened())
        .reshape([m, 3])?
        .into_any())
}
