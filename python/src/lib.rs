//! `usm_study._native`: the Python bindings of the usm-study library (PyO3, abi3).
//!
//! The Python package `usm_study` (python/usm_study/) wraps this module: it turns the column
//! buffers returned here into polars DataFrames and gives every function its documented
//! signature. Every library error becomes a [`UsmStudyError`] (a `ValueError`) whose message
//! is the library's own, located `file:line:col: key: …` where the input has a place.
//!
//! Files:
//! - [`convert`]: Python values → TOML values, overrides, error conversion;
//! - [`run`]: `simulate`, `simulate_many` and the `Run` class;
//! - [`verbs`]: `design`, `scenario_info`, `sweep`, `optimise`, `tcm`, `ocp`;
//! - [`problem`]: the ask/tell `Problem` class.

use pyo3::prelude::*;

mod convert;
mod problem;
mod run;
mod verbs;

pyo3::create_exception!(
    _native,
    UsmStudyError,
    pyo3::exceptions::PyValueError,
    "An error of usm-study: bad input (its message is located `file:line:col: key: ...` when the \
     input has a place), an unreadable file or an output that could not be written."
);

/// The extension module.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("UsmStudyError", m.py().get_type::<UsmStudyError>())?;
    m.add_class::<run::Run>()?;
    m.add_class::<problem::Problem>()?;
    m.add_function(wrap_pyfunction!(run::simulate, m)?)?;
    m.add_function(wrap_pyfunction!(run::simulate_many, m)?)?;
    m.add_function(wrap_pyfunction!(verbs::design, m)?)?;
    m.add_function(wrap_pyfunction!(verbs::scenario_info, m)?)?;
    m.add_function(wrap_pyfunction!(verbs::sweep, m)?)?;
    m.add_function(wrap_pyfunction!(verbs::optimise, m)?)?;
    m.add_function(wrap_pyfunction!(verbs::tcm, m)?)?;
    m.add_function(wrap_pyfunction!(verbs::ocp, m)?)?;
    Ok(())
}
