//! Exact merges: a long series cut into partitions, each reduced to its least-squares
//! information, and the informations added ([`Information`]).
//!
//! Expanding memory, batch least squares and the Bayes filter of Morrison ch. 10 with no
//! driving noise all minimise a sum over the samples, `Σ (y_k − p(t_k))²` (plus the prior's
//! `(X − x)ᵀ P⁻¹ (X − x)` for Bayes, (10.3.8)): the information `TᵀT`, `TᵀY` of disjoint sets
//! of samples add, (10.2.42)-(10.2.44) applied to one set after the other. Each partition is
//! reduced to the moments of the augmented rows `[T | Y]` — `TᵀT`, `TᵀY` and `YᵀY` — in a
//! common basis: the Legendre polynomials on the whole series' span `[start, end]` mapped to
//! `[−1, 1]`, the basis of the batch fit [`PolynomialFit`] (the Gram matrix's condition of
//! order `2m + 1` on samples spread over the span, not the monomials' `~10^(1.2 m)`), so that
//! every partition's information is at the same epoch and scale without a shift. The moments
//! are sums of products of the rows' doubles, kept as double words (Dekker's exact product,
//! Knuth's error-free sum: the dot product "as if in twice the working precision" of Ogita,
//! Rump & Oishi 2005), so that the sum over a partition, and the merge of partitions (the
//! double-word sum of their moments), are exact to about `2⁻¹⁰⁶` relative whatever the order
//! and grouping: the merged moments are the single pass's. The estimate solves the normal
//! equations by a double-word Cholesky factorisation of the augmented moments
//! (`[[TᵀT, TᵀY], [YᵀT, YᵀY]] = L Lᵀ`: `L`'s leading block is `Rᵀ`, its last row `[dᵀ, ρ]`
//! with `R c = d` and `ρ²` the residual sum of squares, (4.2.x)'s `R` and `d` of the square-root
//! form); only the coefficients `c` are rounded to doubles. The estimate at any time `t` is the
//! fit's derivatives there: the transition `Φ` from the basis' epoch to `t` (the
//! Legendre-to-Taylor table and the scaling `D(τ)`, Morrison's shift of origin (5.3.x),
//! [`PolynomialFit::derivatives_at`]).
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
use crate::numeric::double_word::{self, two_sum, DoubleWord};
use crate::polynomial::options::MAX_DEGREE;
use crate::polynomial::prior::Prior;
use nalgebra::{DMatrix, DVector};

/// Rows summed in plain double words before the block's sums are added to the total: Dot2's
/// error bound grows with the square of the rows summed that way (`n² ε² Σ|x_k|`), the
/// blocks' double-word total with their number (`2⁻¹⁰⁵` each), so that over `10⁸` samples the
/// moments are within about `10⁻²⁶` of their exact values relative to their magnitudes.
const BLOCK: usize = 256;

/// A Cholesky pivot (the Schur complement's diagonal) at or below this fraction of its
/// moment's diagonal is no information: the moments' rounding is about `10⁻²⁶` of them
/// ([`BLOCK`]), so a pivot this small may be rounding alone — a direction the samples do
/// not determine (fewer distinct times than coefficients; a coefficient's variance inflated
/// `10²⁰` times by the others).
const PIVOT_FLOOR: f64 = 1e-20;

/// The least-squares information of samples of a polynomial of degree `m` (see the module
/// doc): the moments of the augmented rows (Legendre values on the span `[start, end]` and
/// the value) as double words, the sample count, and the noise σ when given (the estimate
/// then carries its covariance).
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Information {
    degree: usize,
    start: f64,
    end: f64,
    sigma: Option<f64>,
    /// `[T | Y]ᵀ[T | Y]`, its upper triangle row by row (`(m + 2)(m + 3)/2` double words).
    moments: Vec<DoubleWord>,
    samples: u64,
    /// Whether a prior is in (it must be added once, not once per partition).
    prior: bool,
}

/// The packed index of `(i, j)`, `i ≤ j < n`, in an upper triangle of side `n` stored by rows.
fn packed(n: usize, i: usize, j: usize) -> usize {
    i * n - i * (i + 1) / 2 + j
}

/// Veltkamp's splitting `x = hi + lo` (each half 26 bits), as in
/// [`two_prod`](double_word::two_prod).
#[inline(always)]
fn split(x: f64) -> (f64, f64) {
    const SPLIT: f64 = 134_217_729.0; // 2^27 + 1
    let c = SPLIT * x;
    let hi = c - (c - x);
    (hi, x - hi)
}

/// Running sums of products, each an unnormalised double word `hi + lo` (Ogita, Rump & Oishi's
/// Dot2: the products exact by Dekker, the sums by Knuth, the errors summed in `lo`).
struct Sums {
    hi: Vec<f64>,
    lo: Vec<f64>,
}

impl Sums {
    fn new(len: usize) -> Self {
        Self {
            hi: vec![0.0; len],
            lo: vec![0.0; len],
        }
    }

    /// Adds the products `r_i r_j`, `i ≤ j`, of one row `r`.
    #[inline(always)]
    fn add_row(&mut self, r: &[f64], parts: &mut [(f64, f64)]) {
        for (p, &x) in parts.iter_mut().zip(r) {
            *p = split(x);
        }
        let mut k = 0;
        for (i, (&ri, &(ah, al))) in r.iter().zip(parts.iter()).enumerate() {
            for (&rj, &(bh, bl)) in r[i..].iter().zip(&parts[i..]) {
                let p = ri * rj;
                let e = ((ah * bh - p) + ah * bl + al * bh) + al * bl;
                let (s, se) = two_sum(self.hi[k], p);
                self.hi[k] = s;
                self.lo[k] += se + e;
                k += 1;
            }
        }
    }

    /// The sums as normalised double words.
    fn words(&self) -> impl Iterator<Item = DoubleWord> + '_ {
        self.hi.iter().zip(&self.lo).map(|(&h, &l)| two_sum(h, l))
    }
}

/// The double-word Cholesky factor of a packed symmetric matrix of side `n` (`A = L Lᵀ`, `L`
/// row-major lower, full `n × n`) and whether each of the first `determined` pivots is
/// above [`PIVOT_FLOOR`] of its diagonal (a later pivot at or below zero is taken as zero:
/// the last, `ρ²`, may round below zero on an exact fit).
fn cholesky(a: &[DoubleWord], n: usize, determined: usize) -> Option<Vec<DoubleWord>> {
    let zero = (0.0, 0.0);
    let mut l = vec![zero; n * n];
    for j in 0..n {
        let mut d = a[packed(n, j, j)];
        for k in 0..j {
            d = double_word::sub(d, double_word::mul(l[j * n + k], l[j * n + k]));
        }
        if j < determined {
            if d.0.is_nan() || d.0 <= PIVOT_FLOOR * a[packed(n, j, j)].0 {
                return None;
            }
        } else if d.0.is_nan() || d.0 <= 0.0 {
            l[j * n + j] = zero;
            continue;
        }
        let root = double_word::sqrt(d);
        l[j * n + j] = root;
        for i in j + 1..n {
            let mut s = a[packed(n, j, i)];
            for k in 0..j {
                s = double_word::sub(s, double_word::mul(l[i * n + k], l[j * n + k]));
            }
            l[i * n + j] = double_word::div(s, root);
        }
    }
    Some(l)
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
        let n = degree + 2;
        Ok(Self {
            degree,
            start,
            end,
            sigma,
            moments: vec![(0.0, 0.0); n * (n + 1) / 2],
            samples: 0,
            prior: false,
        })
    }

    /// The polynomial's degree `m`.
    pub fn degree(&self) -> usize {
        self.degree
    }

    /// The series' span `(start, end)` the basis is on.
    pub fn span(&self) -> (f64, f64) {
        (self.start, self.end)
    }

    /// The samples' noise σ, if given.
    pub fn sigma(&self) -> Option<f64> {
        self.sigma
    }

    /// Whether a prior is in.
    pub fn has_prior(&self) -> bool {
        self.prior
    }

    /// The basis' centre and half width (those of [`PolynomialFit::new`] on samples spanning
    /// `[start, end]`, so that both evaluate the same Legendre rows).
    fn basis(&self) -> (f64, f64) {
        let half = 0.5 * (self.end - self.start);
        (
            0.5 * (self.start + self.end),
            if half > 0.0 { half } else { 1.0 },
        )
    }

    /// Adds the moments `words` (of rows over this basis) to the information, refused if a
    /// sum left the double range (values beyond `~1e154`); nothing is added then.
    fn add_words(&mut self, words: &[DoubleWord]) -> Result<(), Error> {
        let new: Vec<DoubleWord> = self
            .moments
            .iter()
            .zip(words)
            .map(|(&a, &b)| double_word::add(a, b))
            .collect();
        if let Some(v) = new.iter().map(|w| w.0 + w.1).find(|v| !v.is_finite()) {
            return Err(Error::NonFinite {
                what: "information",
                value: v,
            });
        }
        self.moments = new;
        Ok(())
    }

    /// Adds the samples `(t_k, z_k)` (finite; in any order, times anywhere, best inside the
    /// span): each the augmented row `[P_0(u), …, P_m(u), z]` (`u` the time mapped to
    /// `[−1, 1]`) whose products are summed into the moments. On error (the first bad
    /// sample's index, or values so large their squares overflow) nothing is added.
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
        let n = self.degree + 2;
        let mut total = vec![(0.0, 0.0); self.moments.len()];
        let mut row = vec![0.0; n];
        let mut parts = vec![(0.0, 0.0); n];
        for (block, (t, z)) in t.chunks(BLOCK).zip(z.chunks(BLOCK)).enumerate() {
            let mut sums = Sums::new(total.len());
            for (k, (&t, &y)) in t.iter().zip(z).enumerate() {
                // The batch fit's rows, bit for bit.
                let v = crate::basis::legendre::values(self.degree, (t - centre) / half);
                row[..n - 1].copy_from_slice(&v);
                row[n - 1] = y;
                if let Some(&v) = row.iter().find(|v| !(*v * *v).is_finite()) {
                    return Err(Error::InBatch {
                        index: block * BLOCK + k,
                        source: Box::new(Error::NonFinite {
                            what: "square of a sample's basis value or value",
                            value: v * v,
                        }),
                    });
                }
                sums.add_row(&row, &mut parts);
            }
            for (w, s) in total.iter_mut().zip(sums.words()) {
                *w = double_word::add(*w, s);
            }
        }
        self.add_words(&total)?;
        self.samples += t.len() as u64;
        Ok(())
    }

    /// Adds `other`'s information (the same degree, span and σ): the merge of two partitions,
    /// in any order and grouping (the double-word sums are the same to `~2⁻¹⁰⁶`).
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
        self.add_words(&other.moments)?;
        self.samples += other.samples;
        self.prior |= other.prior;
        Ok(())
    }

    /// Adds a prior (the Bayes filter, Morrison ch. 10: derivatives at a time with their
    /// covariance; needs σ): `m + 1` whitened pseudo-observations `σ L⁻¹ J c ≈ σ L⁻¹ x`
    /// (`P = L Lᵀ`, `J` the derivatives at the prior's time from the coefficients), as the
    /// expanding-memory filter's prior ([`Prior`]), their products summed into the moments.
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
        let mut sums = Sums::new(self.moments.len());
        let mut row = vec![0.0; p + 1];
        let mut parts = vec![(0.0, 0.0); p + 1];
        for i in 0..p {
            row.iter_mut()
                .zip(w.row(i).iter())
                .for_each(|(a, b)| *a = *b);
            row[p] = values[i];
            sums.add_row(&row, &mut parts);
        }
        let words: Vec<DoubleWord> = sums.words().collect();
        self.add_words(&words)?;
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

    /// The least-squares fit of every sample in (with the prior): the double-word Cholesky
    /// factor of the augmented moments gives `R`, `d` and `ρ²` (see the module doc) and the
    /// coefficients `R⁻¹ d`, rounded once to doubles; refused while they do not determine the
    /// polynomial: [`Error::TooFewSamples`] with fewer samples than coefficients,
    /// [`Error::NotDetermined`] with enough samples at too few distinct times.
    pub fn fit(&self) -> Result<PolynomialFit, Error> {
        let p = self.degree + 1;
        let n = p + 1;
        let not_determined = || {
            if self.samples < p as u64 {
                Error::TooFewSamples {
                    needed: p,
                    got: self.samples as usize,
                }
            } else {
                Error::NotDetermined {
                    samples: self.samples,
                    why: format!(
                        "the samples' times do not determine a polynomial of degree {} (fewer \
                         than {p} distinct times, or times too close together for the span): \
                         lower the degree or add samples at other times",
                        self.degree
                    ),
                }
            }
        };
        let l = cholesky(&self.moments, n, p).ok_or_else(not_determined)?;
        // Rᵀ = L's leading block, d = L's last row: back substitution R c = d.
        let mut c = vec![(0.0, 0.0); p];
        for i in (0..p).rev() {
            let mut s = l[p * n + i];
            for k in i + 1..p {
                s = double_word::sub(s, double_word::mul(l[k * n + i], c[k]));
            }
            c[i] = double_word::div(s, l[i * n + i]);
        }
        let rho = l[p * n + p];
        let residual_sq = double_word::mul(rho, rho);
        let r = DMatrix::from_fn(p, p, |i, j| if j >= i { l[j * n + i].0 } else { 0.0 });
        let (centre, half) = self.basis();
        Ok(PolynomialFit::from_parts(
            self.degree,
            (centre, half),
            DVector::from_iterator(p, c.iter().map(|w| w.0 + w.1)),
            r,
            residual_sq.0 + residual_sq.1,
            self.samples as usize,
        ))
    }

    /// The derivatives `x, x', …, x^(m)` at `t` and, with σ, their covariance
    /// (`σ² J (RᵀR)⁻¹ Jᵀ`), every number finite or refused.
    pub fn estimate(&self, t: f64) -> Result<PolynomialState, Error> {
        if !t.is_finite() {
            return Err(Error::NonFinite {
                what: "time",
                value: t,
            });
        }
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
        let n = self.degree + 2;
        if self.moments.len() != n * (n + 1) / 2 {
            return Err("moments of another size than the degree's".into());
        }
        if self.moments.iter().any(|w| !(w.0 + w.1).is_finite()) {
            return Err("moments not finite".into());
        }
        // The diagonal of a Gram matrix is a sum of squares.
        if (0..n).any(|i| self.moments[packed(n, i, i)].0 < 0.0) {
            return Err("negative moments on the diagonal".into());
        }
        if self.prior && self.sigma.is_none() {
            return Err("a prior without the noise sigma it is weighed by".into());
        }
        if self.samples == 0 && !self.prior && self.moments.iter().any(|w| w.0 != 0.0) {
            return Err("moments without samples".into());
        }
        // Cauchy–Schwarz for a Gram matrix, `m_ij² ≤ m_ii m_jj` (a necessary condition of
        // positive semi-definiteness), with room for the rounding of the sums.
        let entry = |i: usize, j: usize| {
            let w = self.moments[packed(n, i.min(j), i.max(j))];
            w.0 + w.1
        };
        for i in 0..n {
            for j in i + 1..n {
                let (mij, mii, mjj) = (entry(i, j), entry(i, i), entry(j, j));
                if mij.abs() > (mii.sqrt() * mjj.sqrt()) * (1.0 + 1e-9) {
                    return Err("moments that are not a Gram matrix's".into());
                }
            }
        }
        Ok(())
    }
}
