//! Binding of `latent_core::projection`, and the one conversion of an `encoder` argument (a
//! GpMap or a Projection) into the core's `Encode` map.

use latent_core::{Encode, Projection, ProjectionConfig};
use numpy::{PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;

use crate::convert::{points, to_points, type_name};
use crate::errors::{InvalidInputError, guard, to_py};
use crate::gp::PyGpMap;

/// The core's defaults of the keyword arguments.
const DEFAULT: ProjectionConfig = ProjectionConfig::DEFAULT;

/// The iterative-projection encoder posture → latent of a GPLVM decoder (docs/encoders.md).
#[pyclass(name = "Projection", module = "latentrl._native", frozen)]
pub struct PyProjection {
    /// The core object, also handed to Rust loops without crossing into Python.
    pub inner: Projection,
}

#[pymethods]
impl PyProjection {
    #[new]
    #[pyo3(signature = (decoder, postures, *, max_iter = DEFAULT.max_iter, margin = DEFAULT.margin, tracking = DEFAULT.tracking))]
    fn new(
        py: Python<'_>,
        decoder: &Bound<'_, PyGpMap>,
        postures: PyReadonlyArray2<'_, f64>,
        max_iter: usize,
        margin: f64,
        tracking: bool,
    ) -> PyResult<Self> {
        guard(|| {
            let postures = points("postures", &postures)?;
            let config = ProjectionConfig {
                max_iter,
                margin,
                tracking,
            };
            let decoder = &decoder.get().inner;
            let inner = py
                .detach(|| Projection::new(decoder, postures, config))
                .map_err(to_py)?;
            Ok(Self { inner })
        })
    }

    fn encode<'py>(
        &self,
        py: Python<'py>,
        postures: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        guard(|| {
            let postures = points("postures", &postures)?;
            let latent = py.detach(|| self.inner.encode(&postures)).map_err(to_py)?;
            to_points(py, latent)
        })
    }

    fn encode_one<'py>(
        &self,
        py: Python<'py>,
        posture: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        guard(|| {
            let z = self.inner.encode_one(&posture.as_array().to_vec()).map_err(to_py)?;
            Ok(PyArray1::from_vec(py, z))
        })
    }

    #[getter]
    fn input_dim(&self) -> PyResult<usize> {
        guard(|| Ok(self.inner.posture_dim()))
    }

    #[getter]
    fn output_dim(&self) -> PyResult<usize> {
        guard(|| Ok(self.inner.latent_dim()))
    }
}

/// An `encoder` argument held by a Python object: a GpMap or a Projection.
pub(crate) enum EncoderObject {
    Map(Py<PyGpMap>),
    Projection(Py<PyProjection>),
}

impl EncoderObject {
    /// `value` as an encoder; an InvalidInputError naming `name` if it is neither kind.
    pub(crate) fn extract(name: &str, value: &Bound<'_, PyAny>) -> PyResult<Self> {
        if let Ok(map) = value.cast::<PyGpMap>() {
            Ok(Self::Map(map.clone().unbind()))
        } else if let Ok(projection) = value.cast::<PyProjection>() {
            Ok(Self::Projection(projection.clone().unbind()))
        } else {
            Err(InvalidInputError::new_err(format!(
                "{name}: expected a GpMap or a Projection, got {}",
                type_name(value)
            )))
        }
    }

    /// The core map.
    pub(crate) fn get(&self) -> &dyn Encode {
        match self {
            Self::Map(map) => &map.get().inner,
            Self::Projection(projection) => &projection.get().inner,
        }
    }
}
