//! The native part of the `seqsmooth` Python package (`seqsmooth._seqsmooth`): a thin binding
//! of the `seqsmooth` library with pyo3 and rust-numpy. Each module binds one part of the
//! library; `python/seqsmooth/` re-exports it with the exceptions (`errors.py`) and the type
//! stubs.

mod arrays;
mod automatic;
mod bank;
mod bayes;
mod callables;
mod continuous;
mod errors;
mod fit;
mod fixed_lag;
mod frame;
mod kalman;
mod kalman_bank;
mod linear;
mod merge;
mod model_fit;
mod models;
mod paml;
mod persist;
mod polynomial;
mod smooth;
mod stream;
mod tables;
mod track;
mod unscented;

use pyo3::prelude::*;

#[pymodule]
fn _seqsmooth(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<polynomial::State>()?;
    m.add_class::<polynomial::PyPolynomialFilter>()?;
    m.add_class::<polynomial::PyExpandingMemory>()?;
    m.add_class::<polynomial::PyFadingMemory>()?;
    m.add_class::<polynomial::PyFixedMemory>()?;
    m.add_class::<automatic::PyAutomaticFilter>()?;
    m.add_class::<bank::PyBank>()?;
    m.add_class::<bank::PyFadingBank>()?;
    m.add_class::<bank::PyExpandingBank>()?;
    m.add_class::<kalman::PyKalmanFilter>()?;
    m.add_class::<kalman::PyInnovation>()?;
    m.add_class::<kalman_bank::PyKalmanBank>()?;
    m.add_class::<linear::PyLinearKalmanFilter>()?;
    m.add_class::<linear::PyLinearFixedLagSmoother>()?;
    m.add_class::<bayes::PyBayesFilter>()?;
    m.add_class::<unscented::PyUnscentedKalmanFilter>()?;
    m.add_class::<callables::PyExtendedKalmanFilter>()?;
    m.add_class::<continuous::PyContinuousModel>()?;
    m.add_class::<continuous::PyContinuousKalmanFilter>()?;
    m.add_class::<track::PyRadarTracker>()?;
    m.add_class::<models::PyCoordinatedTurn>()?;
    m.add_class::<fit::PySlidingFit>()?;
    m.add_class::<merge::PyInformation>()?;
    m.add_class::<stream::PyFilterStream>()?;
    m.add_function(wrap_pyfunction!(smooth::smooth, m)?)?;
    m.add_function(wrap_pyfunction!(model_fit::fit_model, m)?)?;
    m.add_function(wrap_pyfunction!(frame::filter_series, m)?)?;
    m.add_function(wrap_pyfunction!(errors::error_kinds, m)?)?;
    m.add_function(wrap_pyfunction!(errors::parameter_kinds, m)?)?;
    m.add_function(wrap_pyfunction!(tables::gains, m)?)?;
    m.add_function(wrap_pyfunction!(tables::vrf, m)?)?;
    m.add_function(wrap_pyfunction!(paml::gauss_rule, m)?)?;
    m.add_function(wrap_pyfunction!(paml::polynomial_samples, m)?)?;
    m.add_function(wrap_pyfunction!(paml::luenberger_gains, m)?)?;
    m.add_function(wrap_pyfunction!(paml::fit_curve, m)?)?;
    m.add_function(wrap_pyfunction!(paml::cramer_rao_bound, m)?)?;
    m.add_class::<paml::PyOnlineSmoother>()?;
    m.add_class::<paml::PyCurveFit>()?;
    m.add_function(wrap_pyfunction!(arrays::seconds, m)?)?;
    m.add("MAX_DEGREE", seqsmooth::polynomial::MAX_DEGREE)?;
    m.add("TAU_SCAN_ROWS", seqsmooth::polynomial::tau::TAU_SCAN_ROWS)?;
    // The one version: the workspace's Cargo version, which maturin also gives the package.
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
