//! numpy at the edge: inputs of any array-like (lists, tuples, arrays of any float or integer
//! dtype) checked for shape, outputs as new float64 / uint32 arrays.

use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use tissuesim::{Real, Vec3};

/// The `numpy` module, imported once.
fn numpy(py: Python<'_>) -> PyResult<&Bound<'_, PyModule>> {
    static NUMPY: PyOnceLock<Py<PyModule>> = PyOnceLock::new();
    NUMPY
        .get_or_try_init(py, || Ok(py.import("numpy")?.unbind()))
        .map(|m| m.bind(py))
}

/// `obj` as a C-contiguous numpy array of `dtype`, with `cols` columns (and `ndim` 2); the
/// error names `what` and the expected shape.
fn matrix<'py>(
    obj: &Bound<'py, PyAny>,
    dtype: &str,
    cols: usize,
    what: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let np = numpy(obj.py())?;
    let raw = np.call_method1("asarray", (obj,))?;
    let shape: Vec<usize> = raw.getattr("shape")?.extract()?;
    let size: usize = raw.getattr("size")?.extract()?;
    // An empty list has shape (0,): accept it as (0, cols).
    let ok = (shape.len() == 2 && shape[1] == cols) || (shape.len() == 1 && size == 0);
    if !ok {
        return Err(PyValueError::new_err(format!(
            "{what} must have shape (n, {cols}), got {shape:?}"
        )));
    }
    if dtype == "int64" {
        let kind: String = raw.getattr("dtype")?.getattr("kind")?.extract()?;
        if size > 0 && kind != "i" && kind != "u" {
            return Err(PyValueError::new_err(format!(
                "{what} must be integers (indices), got dtype {}",
                raw.getattr("dtype")?.str()?
            )));
        }
    }
    let array = np.call_method1("ascontiguousarray", (raw, dtype))?;
    np.call_method1("reshape", (array, (size / cols.max(1), cols)))
}

/// An (n, 3) array-like of coordinates (any real dtype) as vectors.
pub(crate) fn vec3s(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<Vec3>> {
    let a = matrix(obj, "float64", 3, what)?;
    let a = a.cast_into::<PyArray2<f64>>()?;
    let ro = a.readonly();
    let s = ro.as_slice()?;
    Ok(s.chunks_exact(3)
        .map(|c| Vec3::new(c[0], c[1], c[2]))
        .collect())
}

/// An (m, K) array-like of non-negative integer indices below 2³² as index arrays.
pub(crate) fn indices<const K: usize>(
    obj: &Bound<'_, PyAny>,
    what: &str,
) -> PyResult<Vec<[u32; K]>> {
    let a = matrix(obj, "int64", K, what)?;
    let a = a.cast_into::<PyArray2<i64>>()?;
    let ro = a.readonly();
    let s = ro.as_slice()?;
    if let Some(bad) = s.iter().find(|&&k| !(0..=u32::MAX as i64).contains(&k)) {
        return Err(PyValueError::new_err(format!(
            "{what}: index {bad} is out of range [0, 2^32)"
        )));
    }
    Ok(s.chunks_exact(K)
        .map(|c| std::array::from_fn(|i| c[i] as u32))
        .collect())
}

/// A 1-D array-like of non-negative integer indices below 2³².
pub(crate) fn index_list(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<u32>> {
    let np = numpy(obj.py())?;
    let flat = np.call_method1("ravel", (np.call_method1("asarray", (obj,))?,))?;
    Ok(
        indices::<1>(&flat.call_method1("reshape", ((-1, 1),))?, what)?
            .into_iter()
            .map(|[k]| k)
            .collect(),
    )
}

/// A point: any sequence of 3 reals.
pub(crate) fn vec3(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec3> {
    // Fast path: a float64 array of 3 (the haptic loop's poses), read without Python calls.
    if let Ok(a) = obj.cast::<PyArray1<f64>>() {
        if let Ok(ro) = a.try_readonly() {
            if let Ok([x, y, z]) = ro.as_slice() {
                return Ok(Vec3::new(*x, *y, *z));
            }
        }
    }
    let v: Vec<Real> = obj
        .extract()
        .map_err(|_| PyValueError::new_err(format!("{what} must be 3 numbers")))?;
    match v.as_slice() {
        [x, y, z] => Ok(Vec3::new(*x, *y, *z)),
        _ => Err(PyValueError::new_err(format!(
            "{what} must be 3 numbers, got {}",
            v.len()
        ))),
    }
}

/// Vectors as a new (n, 3) float64 array.
pub(crate) fn from_vec3s<'py>(
    py: Python<'py>,
    v: impl ExactSizeIterator<Item = Vec3>,
) -> Bound<'py, PyArray2<f64>> {
    let n = v.len();
    let mut data = Vec::with_capacity(3 * n);
    for p in v {
        data.extend_from_slice(&[p.x, p.y, p.z]);
    }
    Array2::from_shape_vec((n, 3), data)
        .expect("3 values per vector")
        .into_pyarray(py)
}

/// A vector as a new (3,) float64 array.
pub(crate) fn from_vec3<'py>(py: Python<'py>, v: Vec3) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_vec(py, vec![v.x, v.y, v.z])
}

/// Index arrays as a new (m, K) uint32 array.
pub(crate) fn from_indices<'py, const K: usize>(
    py: Python<'py>,
    v: impl ExactSizeIterator<Item = [u32; K]>,
) -> Bound<'py, PyArray2<u32>> {
    let n = v.len();
    let mut data = Vec::with_capacity(K * n);
    for t in v {
        data.extend_from_slice(&t);
    }
    Array2::from_shape_vec((n, K), data)
        .expect("K values per row")
        .into_pyarray(py)
}
