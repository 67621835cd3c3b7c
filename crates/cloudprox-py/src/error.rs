//! The exception hierarchy and the mapping of core errors (and panics) onto it.
//!
//! ```text
//! Exception
//! └── CloudproxError
//!     ├── InvalidInputError  (also a ValueError)
//!     ├── FormatError        (also a ValueError): a corrupt or unsupported file
//!     └── SolverError        (also a RuntimeError)
//! ```
//!
//! `CloudproxError` is made with `create_exception!`. The three others need two bases
//! each, which `create_exception!` cannot express, so they are made once per
//! interpreter by calling `type(name, (CloudproxError, builtin), namespace)` and kept
//! in a [`PyOnceLock`].

use std::any::Any;
use std::panic::{catch_unwind, AssertUnwindSafe};

use pyo3::exceptions::{PyException, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyDict, PyTuple, PyType};

pyo3::create_exception!(
    cloudprox._native,
    CloudproxError,
    PyException,
    "Base class of every exception raised by cloudprox."
);

static INVALID_INPUT_ERROR: PyOnceLock<Py<PyType>> = PyOnceLock::new();
static SOLVER_ERROR: PyOnceLock<Py<PyType>> = PyOnceLock::new();
static FORMAT_ERROR: PyOnceLock<Py<PyType>> = PyOnceLock::new();

const FORMAT_ERROR_DOC: &str = "A file's content is not valid in its format.\n\n\
Raised for corrupt, truncated or unsupported files; the message names the file and the\n\
problem. Missing files raise ``FileNotFoundError`` instead. Subclass of both\n\
``CloudproxError`` and ``ValueError``.";

const INVALID_INPUT_DOC: &str =
    "An input is out of its domain or has the wrong shape or dtype.\n\n\
Raised for NaN or infinite coordinates, empty clouds, arrays of the wrong shape, negative\n\
sigmas, covariances that are not symmetric positive semi-definite, poses that are not rigid,\n\
thresholds out of order and unknown option names. Subclass of both ``CloudproxError`` and\n\
``ValueError``.";

const SOLVER_ERROR_DOC: &str = "A solver failed in a way that cannot be reported as data.\n\n\
Reserved: a solve that does not converge is not an error (it falls back to a plane and is\n\
reported in ``ContactPatch.status`` and ``CollisionResult.stats``). Subclass of both\n\
``CloudproxError`` and ``RuntimeError``.";

/// A subclass of `CloudproxError` and `builtin`, living in `cloudprox._native`.
fn make_subclass(
    py: Python<'_>,
    name: &str,
    doc: &str,
    builtin: Bound<'_, PyType>,
) -> PyResult<Py<PyType>> {
    let bases = PyTuple::new(py, [py.get_type::<CloudproxError>(), builtin])?;
    let namespace = PyDict::new(py);
    namespace.set_item("__module__", "cloudprox._native")?;
    namespace.set_item("__doc__", doc)?;
    let ty = py.get_type::<PyType>().call1((name, bases, namespace))?;
    Ok(ty.cast_into::<PyType>()?.unbind())
}

/// The `InvalidInputError` type.
pub fn invalid_input_type(py: Python<'_>) -> PyResult<Bound<'_, PyType>> {
    INVALID_INPUT_ERROR
        .get_or_try_init(py, || {
            make_subclass(
                py,
                "InvalidInputError",
                INVALID_INPUT_DOC,
                py.get_type::<PyValueError>(),
            )
        })
        .map(|t| t.bind(py).clone())
}

/// The `SolverError` type.
pub fn solver_error_type(py: Python<'_>) -> PyResult<Bound<'_, PyType>> {
    SOLVER_ERROR
        .get_or_try_init(py, || {
            make_subclass(
                py,
                "SolverError",
                SOLVER_ERROR_DOC,
                py.get_type::<PyRuntimeError>(),
            )
        })
        .map(|t| t.bind(py).clone())
}

/// The `FormatError` type.
pub fn format_error_type(py: Python<'_>) -> PyResult<Bound<'_, PyType>> {
    FORMAT_ERROR
        .get_or_try_init(py, || {
            make_subclass(
                py,
                "FormatError",
                FORMAT_ERROR_DOC,
                py.get_type::<PyValueError>(),
            )
        })
        .map(|t| t.bind(py).clone())
}

/// The builtin `OSError` subclass for an I/O error kind.
fn os_error(kind: std::io::ErrorKind, msg: String) -> PyErr {
    use pyo3::exceptions::{
        PyFileNotFoundError, PyIsADirectoryError, PyOSError, PyPermissionError,
    };
    match kind {
        std::io::ErrorKind::NotFound => PyFileNotFoundError::new_err(msg),
        std::io::ErrorKind::PermissionDenied => PyPermissionError::new_err(msg),
        std::io::ErrorKind::IsADirectory => PyIsADirectoryError::new_err(msg),
        _ => PyOSError::new_err(msg),
    }
}

/// An `InvalidInputError` with `msg`.
pub fn invalid_input(py: Python<'_>, msg: impl Into<String>) -> PyErr {
    match invalid_input_type(py) {
        Ok(ty) => PyErr::from_type(ty, msg.into()),
        Err(e) => e,
    }
}

/// The Python exception for a core error: `InvalidInput` and `Shape` become
/// `InvalidInputError` with the core's message, `Format` a `FormatError`, `Io`
/// the matching `OSError`. The core's `Error` is `#[non_exhaustive]`: a
/// variant added later is a `CloudproxError` with its message until it is
/// mapped here.
pub fn core_error(py: Python<'_>, err: cloudprox::Error) -> PyErr {
    match err {
        cloudprox::Error::InvalidInput(msg) => invalid_input(py, msg),
        e @ cloudprox::Error::Shape { .. } => invalid_input(py, e.to_string()),
        e @ cloudprox::Error::Format { .. } => match format_error_type(py) {
            Ok(ty) => PyErr::from_type(ty, e.to_string()),
            Err(e) => e,
        },
        cloudprox::Error::Io {
            path,
            kind,
            message,
        } => os_error(kind, format!("{path}: {message}")),
        e => CloudproxError::new_err(e.to_string()),
    }
}

/// Maps a core `Result` to a `PyResult`.
pub trait CoreResultExt<T> {
    /// The value, or the core error as a Python exception.
    fn or_py(self, py: Python<'_>) -> PyResult<T>;
}

impl<T> CoreResultExt<T> for cloudprox::Result<T> {
    fn or_py(self, py: Python<'_>) -> PyResult<T> {
        self.map_err(|e| core_error(py, e))
    }
}

/// A panic caught at the boundary, as text.
#[derive(Debug)]
pub struct Panicked(String);

impl Panicked {
    /// The panic as a `CloudproxError` that says it is a bug.
    pub fn into_py_err(self) -> PyErr {
        CloudproxError::new_err(format!(
            "internal error in the cloudprox core (this is a bug, please report it): {}",
            self.0
        ))
    }
}

fn panic_text(payload: &(dyn Any + Send)) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "unknown panic".to_string()
    }
}

/// Runs `f`, turning a panic into [`Panicked`] so that it never unwinds into Python.
pub fn guard<T>(f: impl FnOnce() -> T) -> Result<T, Panicked> {
    catch_unwind(AssertUnwindSafe(f)).map_err(|p| Panicked(panic_text(p.as_ref())))
}

/// Runs the core call `f` with the GIL released and maps both a panic and a core
/// error to Python exceptions.
pub fn run_detached<T, F>(py: Python<'_>, f: F) -> PyResult<T>
where
    F: FnOnce() -> cloudprox::Result<T> + Send,
    T: Send,
{
    match py.detach(move || guard(f)) {
        Ok(r) => r.or_py(py),
        Err(p) => Err(p.into_py_err()),
    }
}

/// Adds the three exception classes to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("CloudproxError", py.get_type::<CloudproxError>())?;
    m.add("InvalidInputError", invalid_input_type(py)?)?;
    m.add("SolverError", solver_error_type(py)?)?;
    m.add("FormatError", format_error_type(py)?)?;
    Ok(())
}
