//! Radar geometry (Morrison §8.5, (8.5.3)-(8.5.7)): the range, azimuth and elevation (and,
//! optionally, the range rate) of a Cartesian state seen from a site, their Jacobian, the
//! conversion of a measurement to Cartesian position with its covariance (the nominal state of
//! §8.5 from polynomial fits is `estimate::bootstrap`).
//!
//! Conventions, once: the state's first three components are the position `(x, y, z)` and the
//! next three the velocity (the order of [`super::dynamics::PolynomialDynamics`] on 3 axes);
//! with `p = position − site`,
//!
//! | component | definition | range of values |
//! |---|---|---|
//! | range `ρ` | `|p|` | `ρ > 0` |
//! | azimuth `ψ` | from `+x` towards `+y`, `atan2(p_y, p_x)` | `(−π, π]` radians |
//! | elevation `θ` | from the `x-y` plane, `atan2(p_z, sqrt(p_x² + p_y²))` | `[−π/2, π/2]` radians |
//! | range rate `ρ̇` | `p · v / ρ` | |
//!
//! An azimuth residual is wrapped to `(−π, π]`. Directly above or below the site (`p_x = p_y =
//! 0`) the azimuth is undefined and a prediction there is refused.

use super::observation::{check_state, Observation, Predicted};
use crate::error::{Error, Param};
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// A radar at `site` measuring range, azimuth, elevation and, optionally, range rate.
///
/// ```
/// use nalgebra::DVector;
/// use seqsmooth::model::observation::Observation;
/// use seqsmooth::model::radar::Radar;
/// let radar = Radar::new([0.0, 0.0, 0.0], 6).unwrap();
/// let p = radar.predict(&DVector::from_vec(vec![0.0, 3.0, 4.0, 1.0, 0.0, 0.0]), 0.0).unwrap();
/// assert_eq!(p.value[0], 5.0);
/// assert!((p.value[1] - std::f64::consts::FRAC_PI_2).abs() < 1e-15); // +y: azimuth π/2
/// assert!((p.value[2] - (4.0_f64 / 3.0).atan()).abs() < 1e-15);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Radar {
    site: [f64; 3],
    states: usize,
    range_rate: bool,
}

impl Radar {
    /// A radar at `site` (finite) for a state of `states ≥ 3` components.
    ///
    /// ```
    /// use seqsmooth::model::radar::Radar;
    /// assert!(Radar::new([0.0, 0.0, f64::NAN], 6).is_err());
    /// assert!(Radar::new([0.0; 3], 2).is_err());
    /// ```
    pub fn new(site: [f64; 3], states: usize) -> Result<Self, Error> {
        check_site(site)?;
        if states < 3 {
            return Err(Error::InvalidParameter {
                name: Param::StateDimension,
                value: states.to_string(),
                reason: "a radar needs the position (x, y, z) as the first three states".into(),
            });
        }
        Ok(Self {
            site,
            states,
            range_rate: false,
        })
    }

    /// A radar at `site` observing the polynomial model `dynamics` (the state ordered
    /// derivative, then axis): its first three states are the position `(x, y, z)` only on
    /// three axes, so any other number of axes is refused (on one axis the radar would read
    /// `(x, x', x'')` as `(x, y, z)`).
    ///
    /// ```
    /// use seqsmooth::model::dynamics::PolynomialDynamics;
    /// use seqsmooth::model::radar::Radar;
    /// assert!(Radar::of_polynomial([0.0; 3], &PolynomialDynamics::new(1, 3)).is_ok());
    /// assert!(Radar::of_polynomial([0.0; 3], &PolynomialDynamics::new(2, 1)).is_err());
    /// ```
    pub fn of_polynomial(
        site: [f64; 3],
        dynamics: &super::dynamics::PolynomialDynamics,
    ) -> Result<Self, Error> {
        if dynamics.axes() != 3 {
            return Err(Error::InvalidParameter {
                name: Param::Axes,
                value: dynamics.axes().to_string(),
                reason: "a radar observes the position (x, y, z): the model needs 3 axes".into(),
            });
        }
        Self::new(site, (dynamics.degree() + 1) * 3)
    }

    /// Also measure the range rate `ρ̇ = p · v / ρ` (needs the velocity as states 3-5).
    ///
    /// ```
    /// use seqsmooth::model::observation::Observation;
    /// use seqsmooth::model::radar::Radar;
    /// assert_eq!(Radar::new([0.0; 3], 6).unwrap().with_range_rate().unwrap().components(), 4);
    /// assert!(Radar::new([0.0; 3], 3).unwrap().with_range_rate().is_err());
    /// ```
    pub fn with_range_rate(mut self) -> Result<Self, Error> {
        if self.states < 6 {
            return Err(Error::InvalidParameter {
                name: Param::StateDimension,
                value: self.states.to_string(),
                reason: "the range rate needs the velocity as states 3-5".into(),
            });
        }
        self.range_rate = true;
        Ok(self)
    }

    /// The site.
    ///
    /// ```
    /// use seqsmooth::model::radar::Radar;
    /// assert_eq!(Radar::new([1.0, 2.0, 3.0], 6).unwrap().site(), [1.0, 2.0, 3.0]);
    /// ```
    pub fn site(&self) -> [f64; 3] {
        self.site
    }

    /// The Cartesian position (absolute) of a measurement `(ρ, ψ, θ)` and, to first order, its
    /// covariance `J R Jᵀ`, `J = ∂(x, y, z)/∂(ρ, ψ, θ)` at the measurement (8.5.6).
    ///
    /// Valid while the angle errors are small: the converted mean is biased towards the site by
    /// about `ρ (σ_ψ² cos²θ + σ_θ²)/2` (from `E[cos e] = e^{−σ²/2}` for a Gaussian angle error
    /// `e`), and the first-order covariance is consistent while that bias is small against the
    /// smallest standard deviation it reports; [`Converted::bias`] gives the bias to compare.
    ///
    /// ```
    /// use nalgebra::Matrix3;
    /// use seqsmooth::model::radar::Radar;
    /// let radar = Radar::new([0.0; 3], 6).unwrap();
    /// let r = Matrix3::from_diagonal(&[100.0, 1e-6, 1e-6].into()); // σ 10 m, 1 mrad
    /// let c = radar.to_cartesian([10_000.0, 0.0, 0.0], &r).unwrap();
    /// assert!((c.position[0] - 10_000.0).abs() < 1e-9);
    /// assert!((c.covariance[(1, 1)] - 100.0).abs() < 1e-9); // (ρ σ_ψ)²
    /// assert!(c.bias < 0.011);
    /// ```
    pub fn to_cartesian(
        &self,
        measured: [f64; 3],
        covariance: &Matrix3<f64>,
    ) -> Result<Converted, Error> {
        if let Some(&value) = measured
            .iter()
            .chain(covariance.iter())
            .find(|v| !v.is_finite())
        {
            return Err(Error::NonFinite {
                what: "radar measurement or covariance entry",
                value,
            });
        }
        let [rho, psi, theta] = measured;
        if rho <= 0.0 {
            return Err(Error::InvalidParameter {
                name: Param::Range,
                value: rho.to_string(),
                reason: "must be positive".into(),
            });
        }
        if covariance.cholesky().is_none()
            || (covariance - covariance.transpose()).abs().max() > 1e-12 * covariance.abs().max()
        {
            return Err(Error::InvalidParameter {
                name: Param::MeasurementCovariance,
                value: format!("{covariance:?}"),
                reason: "must be symmetric positive definite".into(),
            });
        }
        let (sp, cp) = psi.sin_cos();
        let (st, ct) = theta.sin_cos();
        let direction = Vector3::new(ct * cp, ct * sp, st);
        let position = Vector3::from(self.site) + direction * rho;
        let j = Matrix3::new(
            ct * cp,
            -rho * ct * sp,
            -rho * st * cp, //
            ct * sp,
            rho * ct * cp,
            -rho * st * sp, //
            st,
            0.0,
            rho * ct,
        );
        let bias = 0.5 * rho * (covariance[(1, 1)] * ct * ct + covariance[(2, 2)]);
        let covariance = j * covariance * j.transpose();
        let covariance = (covariance + covariance.transpose()) * 0.5;
        Ok(Converted {
            position,
            covariance,
            bias,
        })
    }
}

/// The range, azimuth and elevation of a position and their Jacobian `J = ∂(ρ, ψ, θ)/∂(x, y, z)`
/// ((8.5.3)-(8.5.5)), the arithmetic of [`Radar::predict_into`] (and of the Kalman filter's
/// fixed-size radar update, which must give its numbers).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Look {
    /// `(ρ, ψ, θ)`.
    pub(crate) value: [f64; 3],
    /// `J`, by rows (`J[1][2] = 0`).
    pub(crate) jacobian: [[f64; 3]; 3],
    /// `p = position − site`.
    pub(crate) offset: [f64; 3],
    /// `ρ²`.
    pub(crate) range_squared: f64,
}

impl Radar {
    /// Whether the radar measures the range rate too (4 components, not 3).
    pub(crate) fn has_range_rate(&self) -> bool {
        self.range_rate
    }

    /// [`Look`] at `position` (absolute), or `None` at the site or directly above or below it
    /// (`√(p_x² + p_y²)` not positive, or a length that is not finite), where the azimuth is
    /// undefined. The values and the Jacobian may still hold a number that is not finite; the
    /// caller checks.
    #[inline(always)]
    pub(crate) fn look(&self, position: [f64; 3]) -> Option<Look> {
        let p = [
            position[0] - self.site[0],
            position[1] - self.site[1],
            position[2] - self.site[2],
        ];
        let h2 = p[0] * p[0] + p[1] * p[1];
        let rho2 = h2 + p[2] * p[2];
        let (h, rho) = (h2.sqrt(), rho2.sqrt());
        if !(h > 0.0 && h.is_finite() && rho.is_finite()) {
            return None;
        }
        Some(Look {
            // + 0.0: atan2(−0, x < 0) is −π, outside (−π, π].
            value: [rho, (p[1] + 0.0).atan2(p[0]), p[2].atan2(h)],
            jacobian: [
                [p[0] / rho, p[1] / rho, p[2] / rho],
                [-p[1] / h2, p[0] / h2, 0.0],
                [
                    -p[0] * p[2] / (rho2 * h),
                    -p[1] * p[2] / (rho2 * h),
                    h / rho2,
                ],
            ],
            offset: p,
            range_squared: rho2,
        })
    }
}

/// A radar measurement in Cartesian position, with its first-order covariance.
#[derive(Clone, Debug, PartialEq)]
pub struct Converted {
    /// The position `site + ρ (cos θ cos ψ, cos θ sin ψ, sin θ)`.
    pub position: Vector3<f64>,
    /// `J R Jᵀ`.
    pub covariance: Matrix3<f64>,
    /// `ρ (σ_ψ² cos²θ + σ_θ²)/2`, the conversion's bias to second order, to compare with the
    /// reported standard deviations.
    pub bias: f64,
}

/// The measured components of a radar row, in the observation's order.
pub const COMPONENTS: [&str; 3] = ["range", "azimuth", "elevation"];

/// The rule for a measured component of a radar row (`k`: 0 range, 1 azimuth, 2 elevation, as
/// in [`COMPONENTS`]), the one every front end applies to its input: a finite range above 0,
/// an azimuth within `[−2π, 2π]` and an elevation within `[−π/2, π/2]`, both in radians (the
/// table above, with an azimuth of either turn). `Err` holds why, as words that follow the
/// value (`"range -5 is not positive"`).
///
/// ```
/// use seqsmooth::model::radar::check_component;
/// assert_eq!(check_component(0, 1000.0), Ok(1000.0));
/// assert_eq!(check_component(0, -5.0), Err("is not positive"));
/// assert!(check_component(1, 7.0).unwrap_err().contains("[-2pi, 2pi]"));
/// assert!(check_component(2, 1.6).unwrap_err().contains("[-pi/2, pi/2]"));
/// assert!(check_component(1, f64::NAN).is_err());
/// ```
pub fn check_component(k: usize, v: f64) -> Result<f64, &'static str> {
    if !v.is_finite() {
        return Err("is not a finite number");
    }
    match k {
        0 if v <= 0.0 => Err("is not positive"),
        1 if v.abs() > TAU => Err("is outside [-2pi, 2pi]: azimuths are in radians"),
        2 if v.abs() > FRAC_PI_2 => {
            Err("is outside [-pi/2, pi/2]: elevations are in radians from the x-y plane")
        }
        _ => Ok(v),
    }
}

/// The range of a radar's site: three finite coordinates ([`Radar::new`]'s check, and every
/// front end's).
///
/// ```
/// use seqsmooth::model::radar::check_site;
/// assert!(check_site([1.0, -2.0, 0.5]).is_ok() && check_site([0.0, f64::NAN, 0.0]).is_err());
/// ```
pub fn check_site(site: [f64; 3]) -> Result<(), Error> {
    if let Some(&value) = site.iter().find(|v| !v.is_finite()) {
        return Err(Error::InvalidParameter {
            name: Param::Site,
            value: value.to_string(),
            reason: "a radar site's coordinates must be finite".into(),
        });
    }
    Ok(())
}

/// How an input's azimuths are measured: from `+x` towards `+y` (the library's, the default),
/// or as bearings (from `+y` clockwise: `x` east, `y` north; [`from_bearing`]). Its
/// [`name`](Self::name)s are the words of every front end (`--azimuth bearing`,
/// `azimuth="bearing"`).
///
/// ```
/// use seqsmooth::model::radar::AzimuthConvention;
/// assert_eq!(AzimuthConvention::from_name("bearing").unwrap(), AzimuthConvention::Bearing);
/// assert_eq!(AzimuthConvention::default().name(), "from-x");
/// assert!(AzimuthConvention::from_name("north").is_err());
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum AzimuthConvention {
    /// From `+x` towards `+y`.
    #[default]
    FromX,
    /// Clockwise from north (`+y`), with `x` east and `y` north.
    Bearing,
}

impl AzimuthConvention {
    /// Every convention, in the order of their declaration.
    pub const ALL: [AzimuthConvention; 2] = [AzimuthConvention::FromX, AzimuthConvention::Bearing];

    /// Every convention's name, in the order of [`ALL`](Self::ALL).
    pub const NAMES: [&'static str; 2] = ["from-x", "bearing"];

    /// The convention's name (`from-x`, `bearing`).
    pub fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }

    /// The convention called `name`; any other name refused
    /// ([`Param::AzimuthConvention`]).
    pub fn from_name(name: &str) -> Result<Self, Error> {
        Self::ALL
            .into_iter()
            .find(|c| c.name() == name)
            .ok_or_else(|| Error::InvalidParameter {
                name: Param::AzimuthConvention,
                value: format!("{name:?}"),
                reason: format!("must be one of '{}'", Self::NAMES.join("', '")),
            })
    }

    /// Whether the azimuths are bearings (to be turned by [`from_bearing`]).
    pub fn is_bearing(self) -> bool {
        self == AzimuthConvention::Bearing
    }
}

impl std::fmt::Display for AzimuthConvention {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The azimuth from `+x` towards `+y` of a bearing `b` (from `+y` clockwise: `x` east, `y`
/// north), wrapped to `(−π, π]`.
///
/// ```
/// use seqsmooth::model::radar::from_bearing;
/// assert_eq!(from_bearing(0.0), std::f64::consts::FRAC_PI_2); // north
/// assert_eq!(from_bearing(std::f64::consts::FRAC_PI_2), 0.0); // east
/// ```
pub fn from_bearing(b: f64) -> f64 {
    wrap(FRAC_PI_2 - b)
}

/// `a` wrapped to `(−π, π]`.
///
/// ```
/// use seqsmooth::model::radar::wrap;
/// assert!((wrap(3.0 * std::f64::consts::PI / 2.0) + std::f64::consts::FRAC_PI_2).abs() < 1e-15);
/// assert_eq!(wrap(std::f64::consts::PI), std::f64::consts::PI);
/// assert_eq!(wrap(-std::f64::consts::PI), std::f64::consts::PI);
/// ```
pub fn wrap(a: f64) -> f64 {
    let w = a - TAU * (a / TAU).round();
    if w <= -PI {
        w + TAU
    } else if w > PI {
        w - TAU
    } else {
        w
    }
}

impl Observation for Radar {
    fn components(&self) -> usize {
        if self.range_rate {
            4
        } else {
            3
        }
    }

    fn state_dimension(&self) -> usize {
        self.states
    }

    fn predict(&self, state: &DVector<f64>, t: f64) -> Result<Predicted, Error> {
        let (rows, states) = (self.components(), self.states);
        let mut p = Predicted {
            value: DVector::zeros(rows),
            jacobian: DMatrix::zeros(rows, states),
        };
        self.predict_into(state, t, &mut p.value, &mut p.jacobian)?;
        Ok(p)
    }

    fn predict_into(
        &self,
        state: &DVector<f64>,
        t: f64,
        value: &mut DVector<f64>,
        jacobian: &mut DMatrix<f64>,
    ) -> Result<(), Error> {
        check_state(self.states, state)?;
        let position = [state[0], state[1], state[2]];
        let Some(look) = self.look(position) else {
            return Err(Error::InvalidParameter {
                name: Param::RadarGeometry,
                value: format!(
                    "position ({}, {}, {}) at t = {t}",
                    state[0], state[1], state[2]
                ),
                reason: "at the site or directly above or below it: the azimuth is undefined"
                    .into(),
            });
        };
        let rows = self.components();
        if value.len() != rows {
            *value = DVector::zeros(rows);
        }
        if jacobian.shape() != (rows, self.states) {
            *jacobian = DMatrix::zeros(rows, self.states);
        } else {
            jacobian.as_mut_slice().fill(0.0);
        }
        for c in 0..3 {
            value[c] = look.value[c];
            for k in 0..3 {
                jacobian[(c, k)] = look.jacobian[c][k];
            }
        }
        let (p, rho, rho2) = (look.offset, look.value[0], look.range_squared);
        if self.range_rate {
            let v = [state[3], state[4], state[5]];
            let pv = p[0] * v[0] + p[1] * v[1] + p[2] * v[2];
            value[3] = pv / rho;
            for k in 0..3 {
                jacobian[(3, k)] = v[k] / rho - pv * p[k] / (rho2 * rho);
                jacobian[(3, 3 + k)] = p[k] / rho;
            }
        }
        let (values, entries) = (value.as_slice(), jacobian.as_slice());
        let finite = |a: &[f64]| a.iter().fold(true, |ok, v| ok & v.is_finite());
        if finite(values) && finite(entries) {
            return Ok(());
        }
        if let Some(&v) = values.iter().chain(entries).find(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                what: "radar prediction",
                value: v,
            });
        }
        Ok(())
    }

    fn as_radar(&self) -> Option<&Radar> {
        Some(self)
    }

    fn residual(&self, component: usize, measured: f64, predicted: f64) -> f64 {
        if component == 1 {
            wrap(measured - predicted)
        } else {
            measured - predicted
        }
    }
}
