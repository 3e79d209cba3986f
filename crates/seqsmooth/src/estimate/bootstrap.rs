//! The nominal trajectory that starts Gauss–Newton differential correction (Morrison §8.5):
//! polynomial fits to each measured sequence give its value and rates at the epoch, and the
//! observation map, inverted with those rates, gives the full state.

use super::PolynomialFit;
use crate::error::Error;
use crate::model::observation::Observation;
use crate::model::radar::{wrap, Radar};
use nalgebra::DVector;

/// The nominal state at `epoch` from the measurements (Morrison §8.5): a least-squares
/// polynomial of `degree ≥ 1` fitted to each of range, azimuth (unwrapped) and elevation
/// over `times`, its value and rate at `epoch` carried to Cartesian position and velocity by
/// (8.5.6)-(8.5.7); the states past the sixth are set to zero.
///
/// ```
/// use seqsmooth::estimate::bootstrap;
/// use seqsmooth::model::radar::Radar;
/// // A target moving at 100 along +y from (10 000, 0, 1 000), seen from the origin.
/// let radar = Radar::new([0.0; 3], 6).unwrap();
/// let times: Vec<f64> = (0..10).map(f64::from).collect();
/// let rows: Vec<[f64; 3]> = times.iter().map(|&t| {
///     let (x, y, z) = (10_000.0_f64, 100.0 * t, 1_000.0_f64);
///     [(x * x + y * y + z * z).sqrt(), y.atan2(x), z.atan2(x.hypot(y))]
/// }).collect();
/// let x = bootstrap::radar(&radar, &times, &rows, 0.0, 2).unwrap();
/// assert!((x[0] - 10_000.0).abs() < 1.0 && (x[4] - 100.0).abs() < 0.5);
/// ```
pub fn radar(
    radar: &Radar,
    times: &[f64],
    measured: &[[f64; 3]],
    epoch: f64,
    degree: usize,
) -> Result<DVector<f64>, Error> {
    if times.len() != measured.len() {
        return Err(Error::InvalidParameter {
            name: "input lengths",
            value: format!("{} times, {} measurements", times.len(), measured.len()),
            reason: "must be equal".into(),
        });
    }
    if radar.state_dimension() < 6 {
        return Err(Error::InvalidParameter {
            name: "state dimension",
            value: radar.state_dimension().to_string(),
            reason: "the nominal state of (8.5.7) needs the velocity as states 3-5".into(),
        });
    }
    let degree = degree.max(1);
    let mut unwrapped = Vec::with_capacity(measured.len());
    let mut previous: Option<f64> = None;
    for m in measured {
        let psi = match previous {
            Some(p) => p + wrap(m[1] - p),
            None => m[1],
        };
        unwrapped.push(psi);
        previous = Some(psi);
    }
    let column = |k: usize| -> Vec<f64> { measured.iter().map(|m| m[k]).collect() };
    let at = |values: &[f64]| -> Result<(f64, f64), Error> {
        let d = PolynomialFit::new(times, values, None, degree)?.derivatives_at(epoch);
        Ok((d[0], d[1]))
    };
    let (rho, rho_dot) = at(&column(0))?;
    let (psi, psi_dot) = at(&unwrapped)?;
    let (theta, theta_dot) = at(&column(2))?;
    let (sp, cp) = psi.sin_cos();
    let (st, ct) = theta.sin_cos();
    let mut x = DVector::zeros(radar.state_dimension());
    let [s0, s1, s2] = radar.site();
    x[0] = s0 + rho * ct * cp; // (8.5.6)
    x[1] = s1 + rho * ct * sp;
    x[2] = s2 + rho * st;
    x[3] = rho_dot * ct * cp - theta_dot * rho * st * cp - psi_dot * rho * ct * sp; // (8.5.7)
    x[4] = rho_dot * ct * sp - theta_dot * rho * st * sp + psi_dot * rho * ct * cp;
    x[5] = rho_dot * st + theta_dot * rho * ct;
    match x.iter().find(|v| !v.is_finite()) {
        Some(&value) => Err(Error::NonFinite {
            what: "nominal state entry",
            value,
        }),
        None => Ok(x),
    }
}
