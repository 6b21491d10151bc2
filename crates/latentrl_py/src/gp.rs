//! Binding of `latent_core::gp` and `latent_core::gplvm`.

use latent_core::back_constraint::{encoder, nll_grad_back_constrained};
use latent_core::{GpMap, SeKernel, SparseNllGrad, nll_grad, sparse_nll_grad};
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
    /// Fits the map to `inputs` (N, q) and `outputs` (N, p) with `theta` = (θ1, θ2, θ3); with
    /// `inducing` (m, q), the sparse (DTC) map through those inducing inputs.
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
                .detach(|| match inducing {
                    Some(u) => GpMap::sparse(u, &inputs, &outputs, kernel),
                    None => GpMap::new(inputs, outputs, kernel),
                })
                .map_err(to_py)?;
            Ok(Self { inner })
        })
    }

    /// The back-constrained GPLVM's encoder: mean `weights · k_b(inputs, x)` with `weights`
    /// (N, p) and the back-constraint kernel of squared length-scale `exp(log_beta)`.
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

    /// Means (M, p) and variances (M,) at `queries` (M, q).
    fn predict<'py>(&self, py: Python<'py>, queries: PyReadonlyArray2<'py, f64>) -> PyResult<MeansVariances<'py>> {
        guard(|| {
            let queries = points("queries", &queries)?;
            let (means, variances) = py.detach(|| self.inner.predict(&queries)).map_err(to_py)?;
            Ok((to_points(py, means)?, to_vector(py, variances)))
        })
    }

    /// Means only (M, p) at `queries` (M, q): no variance, several times faster.
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

    /// Mean (p,) and variance at one point `x` (q,).
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

    /// Input dimension q.
    #[getter]
    fn input_dim(&self) -> PyResult<usize> {
        guard(|| Ok(self.inner.input_dim()))
    }

    /// Output dimension p.
    #[getter]
    fn output_dim(&self) -> PyResult<usize> {
        guard(|| Ok(self.inner.output_dim()))
    }

    /// Jitter added to the kernel matrix's diagonal to factorise it (0.0 if none).
    #[getter]
    fn jitter(&self) -> PyResult<f64> {
        guard(|| Ok(self.inner.jitter()))
    }

    /// (θ1, θ2, θ3).
    #[getter]
    fn theta(&self) -> PyResult<[f64; 3]> {
        guard(|| Ok(self.inner.kernel().theta()))
    }
}

/// GPLVM objective at `latent` (N, d) for centred `data` (N, D): returns (nll, dnll/dlatent
/// (N, d), dnll/dlog_theta (3,), jitter); with `inducing` (m, d) the sparse (DTC) bound, its
/// gradient (N + m, d) that of the latent points then of the inducing inputs.
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
            .detach(|| match inducing {
                None => nll_grad(&latent, &data, log_theta),
                Some(u) => sparse_nll_grad(&latent, &u, &data, log_theta).map(SparseNllGrad::stacked),
            })
            .map_err(to_py)?;
        Ok((
            r.nll,
            to_points(py, r.grad_latent)?,
            PyArray1::from_vec(py, r.grad_log_theta.to_vec()),
            r.jitter,
        ))
    })
}

/// Back-constrained GPLVM objective at `weights` (N, d) for centred `data` (N, D), GPLVM kernel
/// `exp(log_theta)` and back-constraint squared length-scale `exp(log_beta)`: returns (nll,
/// dnll/dweights (N, d), dnll/dlog_theta (3,), dnll/dlog_beta, latent points (N, d), jitter).
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
