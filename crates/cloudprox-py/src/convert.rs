//! numpy <-> nalgebra conversion.
//!
//! Inputs are any numeric array-like: they go through `numpy.asarray`, are checked
//! for a numeric dtype, converted to C-contiguous float64 and then checked for
//! shape. Every rejection is an `InvalidInputError` that names the argument, the
//! expected shape and the actual one. Outputs are fresh numpy arrays.

use cloudprox::cloud::pose_from_matrix;
use cloudprox::math::{Matrix3, Matrix4, Point3, Pose, Vector3};
use numpy::prelude::*;
use numpy::{PyArray1, PyArray2, PyArray3, PyArrayDyn};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::error::{invalid_input, CoreResultExt};

/// `(5, 3)`, `(5,)` or `()`.
pub fn shape_str(shape: &[usize]) -> String {
    match shape {
        [] => "()".to_string(),
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

/// `obj` as a C-contiguous float64 array of any shape.
///
/// Integers, unsigned integers and floats are accepted; object arrays are accepted
/// if numpy can convert them to float. Strings, booleans, complex numbers and
/// ragged sequences are rejected.
pub fn to_f64_array<'py>(
    obj: &Bound<'py, PyAny>,
    what: &str,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let py = obj.py();
    let np = py.import("numpy")?;
    let arr = np.call_method1("asarray", (obj,)).map_err(|e| {
        invalid_input(
            py,
            format!("{what} must be a numeric array-like: {}", e.value(py)),
        )
    })?;
    let dtype = arr.getattr("dtype")?;
    let kind: String = dtype.getattr("kind")?.extract()?;
    if !matches!(kind.as_str(), "i" | "u" | "f" | "O") {
        return Err(invalid_input(
            py,
            format!(
                "{what} must be numeric, got an array of dtype {}",
                dtype.str()?
            ),
        ));
    }
    let kwargs = PyDict::new(py);
    kwargs.set_item("dtype", np.getattr("float64")?)?;
    kwargs.set_item("order", "C")?;
    let arr = np
        .call_method("asarray", (arr,), Some(&kwargs))
        .map_err(|e| invalid_input(py, format!("{what} must be numeric: {}", e.value(py))))?;
    arr.cast_into::<PyArrayDyn<f64>>().map_err(|_| {
        invalid_input(
            py,
            format!("{what} could not be converted to a float64 array"),
        )
    })
}

/// The shape of `arr` must match `expected` (`None` = any size); `pattern` is the
/// expected shape as shown in the message, e.g. `"(n, 3)"`.
pub fn check_shape(
    arr: &Bound<'_, PyArrayDyn<f64>>,
    expected: &[Option<usize>],
    what: &str,
    pattern: &str,
) -> PyResult<()> {
    let shape = arr.shape();
    let ok = shape.len() == expected.len()
        && shape
            .iter()
            .zip(expected)
            .all(|(&s, e)| e.is_none() || *e == Some(s));
    if ok {
        Ok(())
    } else {
        Err(invalid_input(
            arr.py(),
            format!(
                "{what} must have shape {pattern}, got shape {}",
                shape_str(shape)
            ),
        ))
    }
}

/// The data of a C-contiguous array, copied.
fn data(arr: &Bound<'_, PyArrayDyn<f64>>, what: &str) -> PyResult<Vec<f64>> {
    let ro = arr.readonly();
    ro.as_slice()
        .map(<[f64]>::to_vec)
        .map_err(|_| invalid_input(arr.py(), format!("{what} is not contiguous")))
}

/// The points of a point-cloud object of another library, if `obj` is one:
/// Open3D `PointCloud` (`.points`), trimesh `PointCloud` (`.vertices`), or
/// anything else with one of these attributes that is not itself an array.
fn foreign_points<'py>(obj: &Bound<'py, PyAny>) -> PyResult<Option<Bound<'py, PyAny>>> {
    let py = obj.py();
    let np = py.import("numpy")?;
    if obj.is_instance(&np.getattr("ndarray")?)? {
        return Ok(None);
    }
    for attr in ["points", "vertices"] {
        if obj.hasattr(attr)? {
            return Ok(Some(np.call_method1("asarray", (obj.getattr(attr)?,))?));
        }
    }
    Ok(None)
}

/// An `(n, 3)` array-like as points (any `n`, including 0). Point-cloud objects
/// of Open3D and trimesh are accepted too.
pub fn points_from(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<Point3>> {
    let arr = match foreign_points(obj)? {
        Some(inner) => to_f64_array(&inner, what)?,
        None => to_f64_array(obj, what)?,
    };
    check_shape(&arr, &[None, Some(3)], what, "(n, 3)")?;
    // One copy, straight from numpy's buffer into points.
    let ro = arr.readonly();
    let flat = ro
        .as_slice()
        .map_err(|_| invalid_input(arr.py(), format!("{what} is not contiguous")))?;
    Ok(flat
        .chunks_exact(3)
        .map(|c| Point3::new(c[0], c[1], c[2]))
        .collect())
}

/// An `(n, 3, 3)` array-like as 3x3 matrices.
pub fn matrices3_from(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<Matrix3>> {
    let arr = to_f64_array(obj, what)?;
    check_shape(&arr, &[None, Some(3), Some(3)], what, "(n, 3, 3)")?;
    Ok(data(&arr, what)?
        .chunks_exact(9)
        .map(Matrix3::from_row_slice)
        .collect())
}

/// A `(3,)` array-like as a vector.
pub fn vector3_from(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vector3> {
    let arr = to_f64_array(obj, what)?;
    check_shape(&arr, &[Some(3)], what, "(3,)")?;
    Ok(Vector3::from_row_slice(&data(&arr, what)?))
}

fn pose_from_slice(py: Python<'_>, m: &[f64], what: &str) -> PyResult<Pose> {
    pose_from_matrix(&Matrix4::from_row_slice(m))
        .map_err(|e| match e {
            cloudprox::Error::InvalidInput(msg) => {
                cloudprox::Error::InvalidInput(format!("{what}: {msg}"))
            }
            other => other,
        })
        .or_py(py)
}

/// A `(4, 4)` homogeneous transform as a rigid pose; `None` is the identity.
pub fn pose_from(py: Python<'_>, obj: Option<&Bound<'_, PyAny>>, what: &str) -> PyResult<Pose> {
    let Some(obj) = obj else {
        return Ok(Pose::identity());
    };
    let arr = to_f64_array(obj, what)?;
    check_shape(&arr, &[Some(4), Some(4)], what, "(4, 4)")?;
    pose_from_slice(py, &data(&arr, what)?, what)
}

/// An `(m, 4, 4)` stack of homogeneous transforms as rigid poses.
pub fn poses_from(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<Pose>> {
    let py = obj.py();
    let arr = to_f64_array(obj, what)?;
    check_shape(&arr, &[None, Some(4), Some(4)], what, "(m, 4, 4)")?;
    data(&arr, what)?
        .chunks_exact(16)
        .enumerate()
        .map(|(i, m)| pose_from_slice(py, m, &format!("{what}[{i}]")))
        .collect()
}

/// A float64 array of shape `(n,)`.
pub fn vec_to_py<'py>(py: Python<'py>, v: &[f64]) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_slice(py, v)
}

/// An int64 array of shape `(n,)` from point indices.
pub fn indices_to_py<'py>(py: Python<'py>, v: &[u32]) -> Bound<'py, PyArray1<i64>> {
    PyArray1::from_vec(py, v.iter().map(|&i| i64::from(i)).collect())
}

/// A float64 array of shape `(3,)`.
pub fn vector3_to_py<'py>(py: Python<'py>, v: &Vector3) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_slice(py, v.as_slice())
}

/// A float64 array of shape `(n, 3)` from vectors.
pub fn rows3_to_py(
    py: Python<'_>,
    rows: impl ExactSizeIterator<Item = Vector3>,
) -> PyResult<Bound<'_, PyArray2<f64>>> {
    let n = rows.len();
    let mut flat = Vec::with_capacity(3 * n);
    for r in rows {
        flat.extend_from_slice(r.as_slice());
    }
    PyArray1::from_vec(py, flat).reshape([n, 3])
}

/// A float64 array of shape `(n, 3)` from points.
pub fn points_to_py<'py>(
    py: Python<'py>,
    points: &[Point3],
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    rows3_to_py(py, points.iter().map(|p| p.coords))
}

/// A float64 array of shape `(n, 3, 3)` from 3x3 matrices (row-major).
pub fn matrices3_to_py<'py>(py: Python<'py>, m: &[Matrix3]) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let mut flat = Vec::with_capacity(9 * m.len());
    for c in m {
        for r in 0..3 {
            for k in 0..3 {
                flat.push(c[(r, k)]);
            }
        }
    }
    PyArray1::from_vec(py, flat).reshape([m.len(), 3, 3])
}

/// A `(4,)` array-like as four numbers.
pub fn array4_from(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<[f64; 4]> {
    let arr = to_f64_array(obj, what)?;
    check_shape(&arr, &[Some(4)], what, "(4,)")?;
    let d = data(&arr, what)?;
    Ok([d[0], d[1], d[2], d[3]])
}

/// The row-major entries of a pose's 4x4 homogeneous matrix.
fn pose_entries(pose: &Pose, out: &mut Vec<f64>) {
    let m = pose.to_homogeneous();
    for r in 0..4 {
        for c in 0..4 {
            out.push(m[(r, c)]);
        }
    }
}

/// A float64 array of shape `(4, 4)`: the pose's homogeneous matrix.
pub fn pose_to_py<'py>(py: Python<'py>, pose: &Pose) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let mut flat = Vec::with_capacity(16);
    pose_entries(pose, &mut flat);
    PyArray1::from_vec(py, flat).reshape([4, 4])
}

/// A float64 array of shape `(n, 4, 4)`: the poses' homogeneous matrices.
pub fn poses_to_py<'py>(py: Python<'py>, poses: &[Pose]) -> PyResult<Bound<'py, PyArray3<f64>>> {
    let mut flat = Vec::with_capacity(16 * poses.len());
    for p in poses {
        pose_entries(p, &mut flat);
    }
    PyArray1::from_vec(py, flat).reshape([poses.len(), 4, 4])
}
