//! Binding of `latent_core::LatentPolicy`: a trained latent policy with its GPLVM maps, and V(z)
//! of a learner's own features.

use latent_core::{LatentPolicy, LearnerConfig};
use numpy::{PyArray1, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;

use crate::convert::config_from;
use crate::errors::{guard, to_py};
use crate::gp::PyGpMap;
use crate::projection::EncoderObject;

/// V(z) (Eq. 7) at `points` of a learner's own features.
#[pyfunction]
pub fn learner_values<'py>(
    py: Python<'py>,
    learner: &Bound<'py, PyAny>,
    low: Vec<f64>,
    high: Vec<f64>,
    weights: Option<PyReadonlyArray1<'py, f64>>,
    points: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    guard(|| {
        let config: LearnerConfig = config_from("learner", learner)?;
        let weights = weights.map(|w| w.as_array().to_vec());
        let z = crate::convert::points("points", &points)?;
        let values = py
            .detach(|| LatentPolicy::learner_values(&config, &low, &high, weights.as_deref(), &z))
            .map_err(to_py)?;
        Ok(PyArray1::from_vec(py, values))
    })
}

/// A trained latent policy (`latent_core::LatentPolicy`) with its GPLVM maps.
#[pyclass(name = "LatentPolicy", module = "latentrl._native", frozen)]
pub struct PyLatentPolicy {
    policy: LatentPolicy,
    decoder: Py<PyGpMap>,
    encoder: EncoderObject,
}

#[pymethods]
impl PyLatentPolicy {
    #[new]
    fn new(
        learner: &Bound<'_, PyAny>,
        low: Vec<f64>,
        high: Vec<f64>,
        weights: PyReadonlyArray1<'_, f64>,
        decoder: Bound<'_, PyGpMap>,
        encoder: &Bound<'_, PyAny>,
    ) -> PyResult<Self> {
        guard(|| {
            let encoder = EncoderObject::extract("encoder", encoder)?;
            let config: LearnerConfig = config_from("learner", learner)?;
            let weights = weights.as_array().to_vec();
            let policy = LatentPolicy::new(&config, &low, &high, &weights, &decoder.get().inner, encoder.get())
                .map_err(to_py)?;
            #[rustfmt::skip]
            return Ok(Self { policy, decoder: decoder.unbind(), encoder });
        })
    }

    #[allow(clippy::type_complexity)]
    fn act<'py>(
        &self,
        py: Python<'py>,
        posture: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<(
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<f64>>,
    )> {
        guard(|| {
            let posture = posture.as_array().to_vec();
            let (decoder, encoder) = (&self.decoder.get().inner, self.encoder.get());
            let a = self.policy.act(decoder, encoder, &posture).map_err(to_py)?;
            let array = |v| PyArray1::from_vec(py, v);
            Ok((array(a.target), array(a.z), array(a.next)))
        })
    }

    fn values<'py>(&self, py: Python<'py>, points: PyReadonlyArray2<'py, f64>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        guard(|| {
            let z = crate::convert::points("points", &points)?;
            Ok(PyArray1::from_vec(py, self.policy.values(&z).map_err(to_py)?))
        })
    }
}
