//! Binding of `latent_core::gp` and `latent_core::gplvm`.

use latent_core::back_constraint::{encoder, nll_grad_back_constrained};
use latent_core::{GpMap, SeKernel, gplvm_objective};
use numpy::{PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;

use crate::convert::{fixed, points, to_points, to_vector};
use crate::errors::{guard, to_py};

/// Means (M, p) and variances (M,) as NumPy arrays.
type MeansVariances<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray1<f64>>);

/// (nll, ∂nll/∂latent (N, d), ∂nll/∂log θ (3,), jitter).
type NllGradient<'py> = (f64, Bound<'py, PyArray2<f64>>, Bound<'py, PyArray1<f64>>, f64);

/// (nll, ∂nll/∂weights (N, d), ∂nll/∂log θ (3,), ∂nll/∂log β, latent (N, d), jitter).
type BackConstrainedGradient<'py> = (
    f64,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<f64>>,
    f64,
    Bound<'py, PyArray2<f64>>,
    f64,
);

/// A fitted GP map (paper Eq. 4): predictive mean and variance from inputs to outputs.
#[pyclass(name = "GpMap", module = "latentrl._native", frozen)]
pub struct PyGpMap {
    /// The core object, also handed to Rust loops without crossing into Python.
    pub inner: GpMap,
}

#[pymethods]
impl PyGpMap {
    #[new]
    #[pyo3(signature = (inputs, outputs, theta, inducing = None))]
    fn new(
        py: Python<'_>,
        inputs: PyReadonlyArray2<'_, f64>,
        outputs: PyReadonlyArray2<'_, f64>,
        theta: PyReadonlyArray1<'_, f64>,
        inducing: Option<PyReadonlyArray2<'_, f64>>,
    ) -> PyResult<Self> {
        guard(|| {
            let inputs = points("inputs", &inputs)?;
            let outputs = points("outputs", &outputs)?;
            let kernel = SeKernel::new(fixed::<3>("theta", &theta)?).map_err(to_py)?;
            let inducing = inducing.map(|u| points("inducing", &u)).transpose()?;
            let inner = py
                .detach(|| GpMap::fit(inputs, outputs, kernel, inducing))
                .map_err(to_py)?;
            Ok(Self { inner })
        })
    }

    #[staticmethod]
    fn back_constraint(
        py: Python<'_>,
        inputs: PyReadonlyArray2<'_, f64>,
        weights: PyReadonlyArray2<'_, f64>,
        log_beta: f64,
    ) -> PyResult<Self> {
        guard(|| {
            let inputs = points("inputs", &inputs)?;
            let weights = points("weights", &weights)?;
            let inner = py.detach(|| encoder(inputs, weights, log_beta)).map_err(to_py)?;
            Ok(Self { inner })
        })
    }

    fn predict<'py>(&self, py: Python<'py>, queries: PyReadonlyArray2<'py, f64>) -> PyResult<MeansVariances<'py>> {
        guard(|| {
            let queries = points("queries", &queries)?;
            let (means, variances) = py.detach(|| self.inner.predict(&queries)).map_err(to_py)?;
            Ok((to_points(py, means)?, to_vector(py, variances)))
        })
    }

    fn predict_mean<'py>(
        &self,
        py: Python<'py>,
        queries: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        guard(|| {
            let queries = points("queries", &queries)?;
            let means = py.detach(|| self.inner.predict_mean(&queries)).map_err(to_py)?;
            to_points(py, means)
        })
    }

    fn predict_one<'py>(
        &self,
        py: Python<'py>,
        x: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<(Bound<'py, PyArray1<f64>>, f64)> {
        guard(|| {
            let x: Vec<f64> = x.as_array().iter().copied().collect();
            let (mean, variance) = self.inner.predict_one(&x).map_err(to_py)?;
            Ok((PyArray1::from_vec(py, mean), variance))
        })
    }

    #[getter]
    fn input_dim(&self) -> PyResult<usize> {
        guard(|| Ok(self.inner.input_dim()))
    }

    #[getter]
    fn output_dim(&self) -> PyResult<usize> {
        guard(|| Ok(self.inner.output_dim()))
    }

    #[getter]
    fn jitter(&self) -> PyResult<f64> {
        guard(|| Ok(self.inner.jitter()))
    }

    #[getter]
    fn theta(&self) -> PyResult<[f64; 3]> {
        guard(|| Ok(self.inner.kernel().theta()))
    }
}

/// GPLVM objective and gradient (the sparse DTC bound with `inducing`).
#[pyfunction]
#[pyo3(signature = (latent, data, log_theta, inducing = None))]
pub fn gplvm_nll_grad<'py>(
    py: Python<'py>,
    latent: PyReadonlyArray2<'py, f64>,
    data: PyReadonlyArray2<'py, f64>,
    log_theta: PyReadonlyArray1<'py, f64>,
    inducing: Option<PyReadonlyArray2<'py, f64>>,
) -> PyResult<NllGradient<'py>> {
    guard(|| {
        let latent = points("latent", &latent)?;
        let data = points("data", &data)?;
        let log_theta = fixed::<3>("log_theta", &log_theta)?;
        let inducing = inducing.map(|u| points("inducing", &u)).transpose()?;
        let r = py
            .detach(|| gplvm_objective(&latent, &data, log_theta, inducing.as_ref()))
            .map_err(to_py)?;
        Ok((
            r.nll,
            to_points(py, r.grad_latent)?,
            PyArray1::from_vec(py, r.grad_log_theta.to_vec()),
            r.jitter,
        ))
    })
}

/// Back-constrained GPLVM objective and gradient.
#[pyfunction]
pub fn gplvm_back_constrained_nll_grad<'py>(
    py: Python<'py>,
    weights: PyReadonlyArray2<'py, f64>,
    data: PyReadonlyArray2<'py, f64>,
    log_theta: PyReadonlyArray1<'py, f64>,
    log_beta: f64,
) -> PyResult<BackConstrainedGradient<'py>> {
    guard(|| {
        let weights = points("weights", &weights)?;
        let data = points("data", &data)?;
        let log_theta = fixed::<3>("log_theta", &log_theta)?;
        let r = py
            .detach(|| nll_grad_back_constrained(&weights, &data, log_theta, log_beta))
            .map_err(to_py)?;
        Ok((
            r.nll,
            to_points(py, r.grad_weights)?,
            PyArray1::from_vec(py, r.grad_log_theta.to_vec()),
            r.grad_log_beta,
            to_points(py, r.latent)?,
            r.jitter,
        ))
    })
}
