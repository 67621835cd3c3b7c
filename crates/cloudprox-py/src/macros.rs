//! Macros that write a Python class from one list of its fields. The names
//! they use (pyo3's prelude, `PyDict`, `PyTuple`, `PyIterator`) are resolved
//! where they are invoked.

/// A frozen Python class over a core statistics struct `$core` made of
/// `counters: $counters` and `time_seconds`. The one list of counters given
/// here makes the getters, `to_dict` (the counters, then `time_seconds`),
/// pickling (the counters in that order as exact 64-bit words, see
/// `StateWord`, then `time_seconds`: a list, as more counters than the 12
/// items of a tuple pyo3 converts) and
/// `__repr__` (the fields
/// named after `repr:`, then `time_seconds`); equality is the core's, which
/// compares the counters. The counters are destructured without `..`, so a
/// counter added in the core must be added to the list.
macro_rules! stats_class {
    (
        $(#[doc = $doc:literal])*
        $py_name:literal: $class:ident($core:ident { counters: $counters:ident }),
        state: $state:ident,
        repr: [$($repr:ident),+],
        counters: {
            $( $(#[doc = $field_doc:literal])* $field:ident: $ty:ty, )+
        }
    ) => {
        /// The pickled form of the statistics: the counters in order (as
        /// exact 64-bit words), then the wall time.
        type $state = (Vec<u64>, f64);

        $(#[doc = $doc])*
        #[pyclass(name = $py_name, frozen, module = "cloudprox._native")]
        pub struct $class {
            inner: $core,
        }

        impl $class {
            /// Wraps core statistics.
            pub(crate) fn wrap(inner: $core) -> Self {
                Self { inner }
            }

            /// The pickled form of `s`.
            pub(crate) fn state_of(s: &$core) -> $state {
                use $crate::result::StateWord;
                let $counters { $($field),+ } = &s.counters;
                (vec![$($field.to_word(),)+], s.time_seconds)
            }

            /// Statistics from their pickled form; an error if it does not
            /// hold one word per counter.
            pub(crate) fn from_state(py: Python<'_>, state: $state) -> PyResult<$core> {
                use $crate::result::StateWord;
                let (words, time_seconds) = state;
                let names = [$(stringify!($field),)+];
                if words.len() != names.len() {
                    return Err($crate::error::invalid_input(py, format!(
                        concat!("a pickled ", $py_name, " holds {} counters, expected {} ({})"),
                        words.len(),
                        names.len(),
                        names.join(", ")
                    )));
                }
                let mut words = words.into_iter();
                Ok($core {
                    counters: $counters {
                        // One word per counter: checked above.
                        $($field: <$ty>::from_word(words.next().unwrap_or_default()),)+
                    },
                    time_seconds,
                })
            }
        }

        #[pymethods]
        impl $class {
            $(
                $(#[doc = $field_doc])*
                #[getter]
                fn $field(&self) -> $ty {
                    self.inner.counters.$field
                }
            )+

            /// Wall time of the query, in seconds.
            #[getter]
            fn time_seconds(&self) -> f64 {
                self.inner.time_seconds
            }

            /// The statistics as a dict of ``int`` and ``float``, ready for JSON.
            fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
                let c = &self.inner.counters;
                let d = PyDict::new(py);
                $( d.set_item(stringify!($field), c.$field)?; )+
                d.set_item("time_seconds", self.inner.time_seconds)?;
                Ok(d)
            }

            fn __eq__(&self, other: &Self) -> bool {
                self.inner == other.inner
            }

            /// Pickle support: every counter and the wall time.
            fn __reduce__<'py>(
                slf: &Bound<'py, Self>,
            ) -> PyResult<(Bound<'py, PyAny>, ($state,))> {
                Ok((
                    slf.getattr("_from_state")?,
                    (Self::state_of(&slf.get().inner),),
                ))
            }

            /// Rebuilds pickled statistics (see `__reduce__`).
            #[staticmethod]
            fn _from_state(py: Python<'_>, state: $state) -> PyResult<Self> {
                Ok(Self::wrap(Self::from_state(py, state)?))
            }

            fn __repr__(&self) -> String {
                let c = &self.inner.counters;
                format!(
                    concat!($py_name, "(", $(stringify!($repr), "={}, ",)+ "time_seconds={})"),
                    $(c.$repr,)+
                    $crate::result::fmt_g(self.inner.time_seconds)
                )
            }
        }
    };
}

/// A frozen Python class of a few named values that also unpacks as their
/// tuple: the struct `$class` of `$field: $ty`, a getter per field, and
/// `__iter__`, `__getitem__` and `__len__` over `(field, ...)` in the order
/// given. `$ty` is a `Py<...>` or an `Option<Py<...>>` (`None` in Python).
/// The methods after the fields (`__repr__`, ...) join the class's
/// `#[pymethods]`.
macro_rules! tuple_class {
    (
        $(#[doc = $doc:literal])*
        $py_name:literal: $class:ident {
            $( $(#[doc = $field_doc:literal])* $field:ident: $ty:ty, )+
        }
        $($methods:tt)*
    ) => {
        $(#[doc = $doc])*
        #[pyclass(name = $py_name, frozen, module = "cloudprox._native")]
        pub struct $class {
            $( $field: $ty, )+
        }

        impl $class {
            /// The fields as a tuple, in order.
            fn as_tuple<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
                ($(&self.$field,)+).into_pyobject(py)
            }
        }

        #[pymethods]
        impl $class {
            $(
                $(#[doc = $field_doc])*
                #[getter]
                fn $field<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
                    pyo3::IntoPyObjectExt::into_bound_py_any(&self.$field, py)
                }
            )+

            /// The fields in order (for unpacking).
            fn __iter__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyIterator>> {
                self.as_tuple(py)?.try_iter()
            }

            /// The field at `index` of the tuple of fields.
            fn __getitem__<'py>(
                &self,
                py: Python<'py>,
                index: isize,
            ) -> PyResult<Bound<'py, PyAny>> {
                self.as_tuple(py)?.as_any().get_item(index)
            }

            #[allow(clippy::unused_self)]
            fn __len__(&self) -> usize {
                [$(stringify!($field)),+].len()
            }

            $($methods)*
        }
    };
}
