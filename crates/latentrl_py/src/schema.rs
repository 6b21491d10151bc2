//! The schemas of what a user writes (a task file's keys, Experiment 1's), the `[run]` table
//! checked, and the names of the end-reason codes.

use ::sim::task::{SchemaTable, TaskConfig};
use latent_core::{EndReason, Params, RunConfig};
use pyo3::prelude::*;

use crate::convert::{config_or_default, config_to};
use crate::errors::{guard, to_py};

/// Schema tables as one list of dicts `{key, doc, rule, kind, default}`, one per key.
fn schema_list(py: Python<'_>, tables: Vec<SchemaTable>) -> PyResult<Bound<'_, PyAny>> {
    config_to(
        py,
        &tables.into_iter().flat_map(|table| table.entries).collect::<Vec<_>>(),
    )
}

/// Every key of a task file, as `schema_list`.
#[pyfunction]
pub fn task_schema(py: Python<'_>) -> PyResult<Bound<'_, PyAny>> {
    guard(|| schema_list(py, TaskConfig::schema_tables()))
}

/// The keys of Experiment 1's configuration, as `schema_list`.
#[pyfunction]
pub fn bimanual_schema(py: Python<'_>) -> PyResult<Bound<'_, PyAny>> {
    guard(|| schema_list(py, ::sim::bimanual::schema_tables()))
}

/// The run settings `run` (a dict of `[run]` keys; defaults for the rest) checked: every key's
/// effective value, or InvalidInputError naming `run.<key>` and its rule.
#[pyfunction]
#[pyo3(signature = (run = None))]
pub fn run_config<'py>(py: Python<'py>, run: Option<&Bound<'py, PyAny>>) -> PyResult<Bound<'py, PyAny>> {
    guard(|| {
        let config: RunConfig = config_or_default("run", run)?;
        config.check_fields("run").map_err(|e| to_py(e.into()))?;
        config_to(py, &config)
    })
}

/// The end reasons by code: their names in results files (0 timeout … 6 success).
#[pyfunction]
pub fn end_reasons() -> Vec<&'static str> {
    EndReason::ALL.iter().map(|e| e.name()).collect()
}
