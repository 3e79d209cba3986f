//! The Kalman filter's reading of a measurement (Morrison (12.2.17)'s `Y_n` and `R_n`): its
//! present components and values, and `R` on them, into the work buffers, with `R` checked
//! (finite, symmetric, non-negative variances; a perfect observation allowed).

use super::KalmanFilter;
use crate::error::{Error, Param};
use crate::kalman::correct::noise_entries;
use crate::model::dynamics::Dynamics;
use crate::model::measurement::{Measurement, NoiseCovariance};
use crate::model::observation::Observation;
use nalgebra::DMatrix;

impl<D: Dynamics, O: Observation> KalmanFilter<D, O> {
    /// The measurement's present components and values, and `R` on them, into the work
    /// buffers; their number. The checks are [`Measurement::present`]'s (called for its
    /// refusal when this measurement fails them) and, on the whole `R`: finite, symmetric,
    /// non-negative variances (a perfect observation is allowed).
    pub(super) fn measure(&mut self, m: &Measurement) -> Result<usize, Error> {
        let p = self.observation.components();
        let w = &mut self.work;
        w.present.clear();
        w.values.clear();
        let accepted = m.time.is_finite()
            && m.values.len() == p
            && m.values.iter().all(|v| v.is_none_or(f64::is_finite));
        if accepted {
            for (c, v) in m.values.iter().enumerate() {
                if let Some(v) = *v {
                    w.present.push(c);
                    w.values.push(v);
                }
            }
        } else {
            (w.present, w.values) = m.present(p)?;
        }
        // The common R, its identity or variances (finite and not negative), written at once;
        // anything else (or a refusal) by the general check below.
        let k = w.present.len();
        let variances = match &m.noise {
            NoiseCovariance::Identity => None,
            NoiseCovariance::Variances(v)
                if v.len() == p && v.iter().all(|v| *v >= 0.0 && v.is_finite()) =>
            {
                Some(v)
            }
            _ => return self.measure_full(m),
        };
        let r = &mut w.r[..k * k];
        r.fill(0.0);
        for (c, &a) in w.present.iter().enumerate() {
            r[c + c * k] = variances.map_or(1.0, |v| v[a]);
        }
        Ok(k)
    }

    /// [`Self::measure`]'s `R` past the identity and variances: every entry checked (finite,
    /// symmetric, non-negative variances), then `R` on the present components.
    fn measure_full(&mut self, m: &Measurement) -> Result<usize, Error> {
        let p = self.observation.components();
        let w = &mut self.work;
        let entry = noise_entries(p, &m.noise)?;
        // Column by column; off the diagonal only a full R has entries other than 0.
        let full = matches!(m.noise, NoiseCovariance::Full(_));
        let (mut largest, mut asymmetry, mut negative) = (0.0_f64, 0.0_f64, false);
        for j in 0..p {
            for i in if full { 0..p } else { j..j + 1 } {
                let v = entry(i, j);
                if !v.is_finite() {
                    return Err(Error::NonFinite {
                        what: "measurement noise entry",
                        value: v,
                    });
                }
                largest = largest.max(v.abs());
                asymmetry = asymmetry.max((v - entry(j, i)).abs());
                negative |= i == j && v < 0.0;
            }
        }
        if asymmetry > 1e-12 * largest || negative {
            return Err(Error::InvalidParameter {
                name: Param::MeasurementNoise,
                value: format!("{:?}", DMatrix::from_fn(p, p, entry)),
                reason: "must be symmetric with non-negative variances".into(),
            });
        }
        let k = w.present.len();
        for (j, &b) in w.present.iter().enumerate() {
            for (i, &a) in w.present.iter().enumerate() {
                w.r[i + j * k] = entry(a, b);
            }
        }
        Ok(k)
    }
}
