//! Choosing a fixed-memory filter's span (Morrison §7.6, §7.13): the shortest span that meets a
//! target 1σ ((7.6.1)-(7.6.3)), the sampling interval that does ((7.6.4)-(7.6.5)), and the span
//! that balances the dominant bias against the random error ((7.13.8)-(7.13.10)). The searches
//! use the exact VRF of [`covariance`], not its large-`L` approximation.

use super::bias::dominant_bias;
use super::covariance::covariance;
use super::{check_span, Lead};
use crate::error::{Error, Param};
use crate::polynomial::options::{check_degree, check_tau};

/// A span design problem: a fixed-memory filter of degree `degree` whose estimate is wanted at
/// `lead`, on samples `tau` apart carrying white noise of 1σ `sigma_nu` (named fields, so that
/// the three numbers cannot trade places).
///
/// ```
/// use seqsmooth::polynomial::fixed::{Design, Lead};
/// // Morrison (7.6.1)-(7.6.2) (T7-16): σ_ν = 10, m = 1, one-step prediction, σ(x) = 3 -> L = 45
/// let design = Design { degree: 1, lead: Lead::Steps(1.0), tau: 1.0, sigma_nu: 10.0 };
/// assert_eq!(design.min_span_for_sigma(0, 3.0).unwrap(), 45);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Design {
    /// The filter's degree `m`.
    pub degree: usize,
    /// Where the estimate is wanted.
    pub lead: Lead,
    /// The sampling interval `τ`, in the caller's time units.
    pub tau: f64,
    /// The 1σ of the white measurement noise.
    pub sigma_nu: f64,
}

impl Design {
    fn check(&self) -> Result<(), Error> {
        check_degree(self.degree)?;
        check_tau(self.tau)?;
        check_positive(Param::NoiseSigma, self.sigma_nu)?;
        self.lead.check()
    }

    /// The smallest memory span `L` (window of `L+1` samples) for which the 1σ error of the
    /// unscaled `derivative` at the lead is at most `target_sigma` (Morrison §7.6,
    /// (7.6.1)-(7.6.3)). The variance decreases with `L` for the end point, predictions and the
    /// centre; the search doubles `L` and then bisects.
    ///
    /// ```
    /// use seqsmooth::polynomial::fixed::{Design, Lead};
    /// let design = Design { degree: 2, lead: Lead::Steps(0.0), tau: 1.0, sigma_nu: 1.0 };
    /// let l = design.min_span_for_sigma(0, 0.1).unwrap();
    /// assert!(l > 2);
    /// ```
    pub fn min_span_for_sigma(&self, derivative: usize, target_sigma: f64) -> Result<u64, Error> {
        self.check()?;
        let m = self.degree;
        check_derivative(m, derivative)?;
        check_positive(Param::TargetSigma, target_sigma)?;
        let ok = |l: u64| -> Result<bool, Error> {
            let v = unscaled_variance(m, l, self.lead, derivative, self.tau)?;
            Ok(self.sigma_nu * v.sqrt() <= target_sigma)
        };
        let first = m as u64;
        if ok(first)? {
            return Ok(first);
        }
        match last_holding(first, |l| Ok(!ok(l)?))? {
            Some(last_short) => Ok(last_short + 1),
            None => Err(Error::InvalidParameter {
                name: Param::TargetSigma,
                value: target_sigma.to_string(),
                reason: format!("not reached with a window of up to 2^40 samples (degree {m})"),
            }),
        }
    }

    /// Balances systematic against random error (Morrison §7.13, (7.13.8)-(7.13.10)): the
    /// largest span `L` for which the dominant-term bias of the value at the lead,
    /// `|a_{m+1}| τ^(m+1) L^(m+1) |p_{m+1}(L+h)| / C(2m+2, m+1)`, is at most `ratio` times its
    /// random 1σ error `σ_ν √VRF(L)` (the book balances at `ratio = 1`, Ex 9.19b uses 0.1).
    /// The bias grows and the random error falls with `L` at the end point, for predictions
    /// and at the centre; the search doubles `L` and then bisects. At the centre the dominant
    /// bias vanishes for even `m` (`p_{m+1}(L/2) = 0`), so there is nothing to balance: an
    /// error.
    ///
    /// ```
    /// use seqsmooth::polynomial::fixed::{Design, Lead};
    /// // Ex 7.26 (T7-23): m = 1, σ_ν = 200 ft, R'' = 32 ft/s² (a2 = 16), τ = 1 s, end point:
    /// // L = 7 (L = 7: σ 129.1, bias 112.0; L = 8: σ 122.9 < bias 149.3)
    /// let design = Design { degree: 1, lead: Lead::Steps(0.0), tau: 1.0, sigma_nu: 200.0 };
    /// assert_eq!(design.balance_span(16.0, 1.0).unwrap().span, 7);
    /// ```
    pub fn balance_span(&self, a_next: f64, ratio: f64) -> Result<Balance, Error> {
        self.check()?;
        let m = self.degree;
        for (name, v) in [(Param::ANext, a_next.abs()), (Param::Ratio, ratio)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::InvalidParameter {
                    name,
                    value: v.to_string(),
                    reason: "must be a non-zero finite number (positive for the ratio)".into(),
                });
            }
        }
        if matches!(self.lead, Lead::Centre) && m.is_multiple_of(2) {
            return Err(Error::InvalidParameter {
                name: Param::Lead,
                value: "centre".into(),
                reason: format!(
                    "the dominant bias p_{}(L/2) vanishes at the centre for even degree {m}",
                    m + 1
                ),
            });
        }
        let eval = |l: u64| -> Result<Balance, Error> {
            let h = self.lead.steps(l);
            let var = unscaled_variance(m, l, self.lead, 0, self.tau)?;
            let b = dominant_bias::<f64>(m, l, h, self.tau, a_next)?[0].abs();
            Ok(Balance {
                span: l,
                random_sigma: self.sigma_nu * var.sqrt(),
                bias: b,
            })
        };
        let ok = |b: &Balance| b.bias <= ratio * b.random_sigma;
        let first = eval(m as u64)?;
        if !ok(&first) {
            return Err(Error::InvalidParameter {
                name: Param::ANext,
                value: a_next.to_string(),
                reason: format!(
                    "even the shortest window (L = {m}) has bias {} above {ratio} × σ = {}",
                    first.bias,
                    ratio * first.random_sigma
                ),
            });
        }
        match last_holding(m as u64, |l| Ok(ok(&eval(l)?)))? {
            Some(span) if span == first.span => Ok(first),
            Some(span) => eval(span),
            None => Err(Error::InvalidParameter {
                name: Param::ANext,
                value: a_next.to_string(),
                reason: "the bias stays below the random error up to 2^40 samples".into(),
            }),
        }
    }
}

/// The result of [`Design::balance_span`]: the span and, at it, the random and systematic
/// errors of the value at the lead.
///
/// ```
/// use seqsmooth::polynomial::fixed::{Design, Lead};
/// let design = Design { degree: 2, lead: Lead::Steps(0.0), tau: 1.0, sigma_nu: 0.5 };
/// let b = design.balance_span(1e-6, 1.0).unwrap();
/// assert!(b.bias <= b.random_sigma && b.span > 2);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Balance {
    /// The memory span `L` (window of `L+1` samples).
    pub span: u64,
    /// 1σ random error of the value at the lead for this span.
    pub random_sigma: f64,
    /// Magnitude of the dominant-term bias of the value at the lead for this span.
    pub bias: f64,
}

/// The sampling interval `τ` at which the unscaled `derivative` (`≥ 1`) of a fixed-memory
/// filter with span `L` has 1σ error `target_sigma` for white noise `sigma_nu`:
/// `Var(x^(i)) = σ_ν² (i!)² [W Wᵀ]_ii / τ^(2i)` (Morrison (7.5.28), (7.6.4)-(7.6.5)) solved for `τ`.
///
/// ```
/// use seqsmooth::polynomial::fixed::{tau_for_derivative_sigma, Lead};
/// // T7-16 / (7.6.4)-(7.6.5): L = 45, m = 1, 1-step, σ_ν = 10, σ(x') = 4 -> τ = 0.0278 s
/// // (the book prints 0.029; 0.0278 s is the exact value, about 36 samples/s)
/// let tau = tau_for_derivative_sigma(1, 45, Lead::Steps(1.0), 1, 10.0, 4.0).unwrap();
/// assert!((tau - 0.02777).abs() < 1e-5);
/// ```
pub fn tau_for_derivative_sigma(
    m: usize,
    span: u64,
    lead: Lead,
    derivative: usize,
    sigma_nu: f64,
    target_sigma: f64,
) -> Result<f64, Error> {
    check_span(m, span)?;
    check_derivative(m, derivative)?;
    if derivative == 0 {
        return Err(Error::InvalidParameter {
            name: Param::Derivative,
            value: "0".into(),
            reason: "the variance of the value does not depend on τ; choose a derivative ≥ 1"
                .into(),
        });
    }
    check_positive(Param::NoiseSigma, sigma_nu)?;
    check_positive(Param::TargetSigma, target_sigma)?;
    lead.check()?;
    let v = unscaled_variance(m, span, lead, derivative, 1.0)?;
    let ratio = sigma_nu * sigma_nu * v / (target_sigma * target_sigma);
    Ok(ratio.powf(1.0 / (2 * derivative) as f64))
}

/// Largest memory span the design searches consider.
const MAX_SEARCH_SPAN: u64 = 1 << 40;

/// The design searches' one search: for a predicate `holds` that is true at `first` and from
/// some span on false, the last span at which it holds, found by doubling from
/// `2·max(first, 1)` and then bisecting; `None` when it still holds beyond
/// [`MAX_SEARCH_SPAN`].
fn last_holding(
    first: u64,
    mut holds: impl FnMut(u64) -> Result<bool, Error>,
) -> Result<Option<u64>, Error> {
    let mut lo = first;
    let mut hi = first.max(1) * 2;
    while holds(hi)? {
        lo = hi;
        hi *= 2;
        if hi > MAX_SEARCH_SPAN {
            return Ok(None);
        }
    }
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        if holds(mid)? {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Ok(Some(lo))
}

/// Variance of the unscaled `derivative` (unit input variance) for span `L` and the lead.
fn unscaled_variance(
    m: usize,
    span: u64,
    lead: Lead,
    derivative: usize,
    tau: f64,
) -> Result<f64, Error> {
    let h = lead.steps(span);
    let s = covariance::<f64>(m, span, h)?;
    let f = crate::model::taylor::scaling_diagonal::<f64>(derivative, tau)[derivative];
    Ok(s[(derivative, derivative)] * f * f)
}

fn check_derivative(m: usize, derivative: usize) -> Result<(), Error> {
    if derivative > m {
        return Err(Error::InvalidParameter {
            name: Param::Derivative,
            value: derivative.to_string(),
            reason: format!("a degree-{m} filter estimates derivatives 0..={m}"),
        });
    }
    Ok(())
}

fn check_positive(name: Param, v: f64) -> Result<(), Error> {
    if !(v.is_finite() && v > 0.0) {
        return Err(Error::InvalidParameter {
            name,
            value: v.to_string(),
            reason: "must be a positive finite number".into(),
        });
    }
    Ok(())
}
