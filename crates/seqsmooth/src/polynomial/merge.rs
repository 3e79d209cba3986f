//! Exact merges: a long series cut into partitions, each reduced to its least-squares
//! information, and the informations added ([`Information`]).
//!
//! Expanding memory, batch least squares and the Bayes filter of Morrison ch. 10 with no
//! driving noise all minimise a sum over the samples, `Σ (y_k − p(t_k))²` (plus the prior's
//! `(X − x)ᵀ P⁻¹ (X − x)` for Bayes, (10.3.8)): the information `TᵀT`, `TᵀY` of disjoint sets
//! of samples add, (10.2.42)-(10.2.44) applied to one set after the other. Each partition is
//! reduced to the square-root information `[R | d]` of the coefficients of a common basis —
//! the Legendre polynomials on the whole series' span `[start, end]` mapped to `[−1, 1]`, the
//! basis of the batch fit [`PolynomialFit`] (condition of order `√(2m+1)`, not the
//! monomials' `~10^(0.6 m)`), so that every partition's information is at the same epoch
//! and scale without a shift of a reduced factor — and two reductions merge by folding one's
//! rows into the other (Gentleman's rotations: `R₁ᵀR₁ + R₂ᵀR₂`, `R₁ᵀd₁ + R₂ᵀd₂`, exactly the
//! sum, computed orthogonally). The estimate at any time `t` is the fit's derivatives there:
//! the transition `Φ` from the basis' epoch to `t` (the Legendre-to-Taylor table and the
//! scaling `D(τ)`, Morrison's shift of origin (5.3.x), [`PolynomialFit::derivatives_at`]).
//!
//! ```
//! use seqsmooth::polynomial::merge::Information;
//! let t: Vec<f64> = (0..100).map(f64::from).collect();
//! let y: Vec<f64> = t.iter().map(|t| 1.0 + 0.5 * t).collect();
//! let mut a = Information::new(1, 0.0, 99.0, None)?;
//! let mut b = a.clone();
//! a.reduce(&t[..40], &y[..40])?; // two partitions, anywhere
//! b.reduce(&t[40..], &y[40..])?;
//! a.merge(&b)?;
//! let d = a.estimate(99.0)?.derivatives;
//! assert!((d[0] - 50.5).abs() < 1e-12 && (d[1] - 0.5).abs() < 1e-14);
//! # Ok::<(), seqsmooth::Error>(())
//! ```

use crate::error::{check_sample, Error, Param};
use crate::estimate::PolynomialFit;
use crate::model::state::PolynomialState;
use crate::polynomial::options::MAX_DEGREE;
use crate::polynomial::prior::Prior;
use crate::recursive::TriangularFactor;
use nalgebra::{DMatrix, DVector};

/// Rows reduced on their own before they are folded in (see [`Information::reduce`]).
const BLOCK: usize = 256;

/// The least-squares information of samples of a polynomial of degree `m` (see the module
/// doc): the square-root information of its Legendre coefficients on the span `[start, end]`,
/// the sample count, and the noise σ when given (the estimate then carries its covariance).
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Information {
    degree: usize,
    start: f64,
    end: f64,
    sigma: Option<f64>,
    factor: TriangularFactor,
    samples: u64,
    /// Whether a prior is in (it must be added once, not once per partition).
    prior: bool,
}

impl Information {
    /// No information yet on a polynomial of `degree` over the series' span `[start, end]`
    /// (finite, `start < end`, or a single instant `start = end`), samples of noise `sigma`
    /// (positive and finite) if given.
    pub fn new(degree: usize, start: f64, end: f64, sigma: Option<f64>) -> Result<Self, Error> {
        if degree > MAX_DEGREE {
            return Err(Error::DegreeOutOfRange {
                degree,
                max: MAX_DEGREE,
            });
        }
        if !(start.is_finite() && end.is_finite() && start <= end) {
            return Err(Error::InvalidParameter {
                name: Param::Span,
                value: format!("[{start}, {end}]"),
                reason: "the series' span must be finite numbers, start <= end".into(),
            });
        }
        if let Some(s) = sigma {
            if !crate::model::measurement::is_usable_sigma(s) {
                return Err(Error::InvalidParameter {
                    name: Param::Sigma,
                    value: s.to_string(),
                    reason: "must be positive and finite".into(),
                });
            }
        }
        Ok(Self {
            degree,
            start,
            end,
            sigma,
            factor: TriangularFactor::new(degree + 1),
            samples: 0,
            prior: false,
        })
    }

    /// The basis' centre and half width.
    fn basis(&self) -> (f64, f64) {
        let half = 0.5 * (self.end - self.start);
        (
            0.5 * (self.start + self.end),
            if half > 0.0 { half } else { 1.0 },
        )
    }

    /// Adds the samples `(t_k, z_k)` (finite; in any order, times anywhere, best inside the
    /// span): each a row of Legendre values folded into the factor. On error (the first bad
    /// sample's index) nothing is added.
    pub fn reduce(&mut self, t: &[f64], z: &[f64]) -> Result<(), Error> {
        if t.len() != z.len() {
            return Err(Error::InvalidParameter {
                name: Param::InputLengths,
                value: format!("{} times, {} values", t.len(), z.len()),
                reason: "times and values must have the same length".into(),
            });
        }
        for (index, (&t, &y)) in t.iter().zip(z).enumerate() {
            check_sample(t, y, None).map_err(|e| Error::InBatch {
                index,
                source: Box::new(e),
            })?;
        }
        let (centre, half) = self.basis();
        // Blocks of rows reduced on their own and folded in: the rounding of a long run of
        // rotations into one factor grows with its length; by blocks it grows with the block's.
        for (t, z) in t.chunks(BLOCK).zip(z.chunks(BLOCK)) {
            let mut block = TriangularFactor::new(self.degree + 1);
            for (&t, &y) in t.iter().zip(z) {
                let row = crate::basis::legendre::values(self.degree, (t - centre) / half);
                block.add_row(&row, y, 1.0);
            }
            self.fold(&block);
        }
        self.samples += t.len() as u64;
        Ok(())
    }

    /// Adds `other`'s information (the same degree, span and σ): the merge of two partitions,
    /// in any order and grouping (the sums are the same).
    pub fn merge(&mut self, other: &Information) -> Result<(), Error> {
        let same = self.degree == other.degree
            && self.start.to_bits() == other.start.to_bits()
            && self.end.to_bits() == other.end.to_bits()
            && self.sigma.map(f64::to_bits) == other.sigma.map(f64::to_bits);
        if !same {
            return Err(Error::InvalidParameter {
                name: Param::Configuration,
                value: format!(
                    "degree {}, span [{}, {}], sigma {:?}",
                    other.degree, other.start, other.end, other.sigma
                ),
                reason: format!(
                    "merged into degree {}, span [{}, {}], sigma {:?}: informations merge only \
                     with the same degree, span and sigma",
                    self.degree, self.start, self.end, self.sigma
                ),
            });
        }
        if self.prior && other.prior {
            return Err(Error::InvalidParameter {
                name: Param::Prior,
                value: "in both".into(),
                reason: "a prior is added once: merge it into one partition's information".into(),
            });
        }
        self.fold(&other.factor);
        self.samples += other.samples;
        self.prior |= other.prior;
        Ok(())
    }

    /// Folds the rows `[R | d]` of `other` into the factor, and its residual.
    fn fold(&mut self, other: &TriangularFactor) {
        let (r, d) = (other.r(), other.rhs());
        let mut row = vec![0.0; self.degree + 1];
        for i in 0..=self.degree {
            row.iter_mut()
                .zip(r.row(i).iter())
                .for_each(|(a, b)| *a = *b);
            self.factor.add_row(&row, d[i], 1.0);
        }
        self.factor.add_residual_sq(other.residual_sq());
    }

    /// Adds a prior (the Bayes filter, Morrison ch. 10: derivatives at a time with their
    /// covariance; needs σ): `m + 1` whitened pseudo-observations `σ L⁻¹ J c ≈ σ L⁻¹ x`
    /// (`P = L Lᵀ`, `J` the derivatives at the prior's time from the coefficients), as the
    /// expanding-memory filter's prior ([`Prior`]).
    pub fn add_prior(&mut self, prior: &Prior) -> Result<(), Error> {
        prior.check_degree(self.degree)?;
        let Some(sigma) = self.sigma else {
            return Err(Error::InvalidParameter {
                name: Param::Prior,
                value: "without the noise sigma".into(),
                reason: "the prior is weighed against the samples by their noise: give sigma"
                    .into(),
            });
        };
        if self.prior {
            return Err(Error::InvalidParameter {
                name: Param::Prior,
                value: "a second prior".into(),
                reason: "a prior is added once".into(),
            });
        }
        let p = self.degree + 1;
        let (rows, values) = prior.rows(sigma);
        // The prior's rows act on Taylor coefficients a at its time (x = D a): a = D⁻¹ J c.
        let j = self.fit_shape().jacobian_at(prior.time);
        let dinv = DMatrix::from_fn(p, p, |i, k| {
            if i == k {
                1.0 / crate::calculus::factorial::<f64>(i)
            } else {
                0.0
            }
        });
        let w = rows * dinv * j;
        let mut row = vec![0.0; p];
        for i in 0..p {
            row.iter_mut()
                .zip(w.row(i).iter())
                .for_each(|(a, b)| *a = *b);
            self.factor.add_row(&row, values[i], 1.0);
        }
        self.prior = true;
        Ok(())
    }

    /// A fit of this basis with no coefficients: its Jacobian maps coefficients to derivatives.
    fn fit_shape(&self) -> PolynomialFit {
        let (centre, half) = self.basis();
        let p = self.degree + 1;
        PolynomialFit::from_parts(
            self.degree,
            (centre, half),
            DVector::zeros(p),
            DMatrix::identity(p, p),
            0.0,
            0,
        )
    }

    /// The samples in.
    pub fn samples(&self) -> u64 {
        self.samples
    }

    /// The least-squares fit of every sample in (with the prior): its coefficients `R⁻¹ d`,
    /// refused ([`Error::TooFewSamples`]) while they do not determine the polynomial.
    pub fn fit(&self) -> Result<PolynomialFit, Error> {
        let p = self.degree + 1;
        let mut c = vec![0.0; p];
        if !self.factor.solve_into(&mut c) {
            return Err(Error::TooFewSamples {
                needed: p,
                got: self.samples as usize,
            });
        }
        let (centre, half) = self.basis();
        Ok(PolynomialFit::from_parts(
            self.degree,
            (centre, half),
            DVector::from_vec(c),
            self.factor.r(),
            self.factor.residual_sq(),
            self.samples as usize,
        ))
    }

    /// The derivatives `x, x', …, x^(m)` at `t` and, with σ, their covariance
    /// (`σ² J (RᵀR)⁻¹ Jᵀ`), every number finite or refused.
    pub fn estimate(&self, t: f64) -> Result<PolynomialState, Error> {
        let fit = self.fit()?;
        let covariance = self.sigma.map(|s| fit.covariance_at(t) * (s * s));
        PolynomialState {
            time: t,
            derivatives: fit.derivatives_at(t),
            covariance,
        }
        .checked()
    }

    /// The invariants of a restored value ([`crate::persist`]).
    pub(crate) fn check_saved(&self) -> Result<(), String> {
        let sigma_ok = self
            .sigma
            .is_none_or(crate::model::measurement::is_usable_sigma);
        let span_ok = self.start.is_finite() && self.end.is_finite() && self.start <= self.end;
        if self.degree > MAX_DEGREE || !sigma_ok || !span_ok {
            return Err("degree, span or sigma out of range".into());
        }
        if self.factor.dim() != self.degree + 1 {
            return Err("factor of another dimension than the degree".into());
        }
        self.factor.check_saved()
    }
}
