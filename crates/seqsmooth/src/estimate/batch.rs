//! Batch estimation of a state from stacked linear observations `Y = T X + N`,
//! `Cov(N) = R` (Morrison ch. 6 and §8.2):
//!
//! | estimator | estimate | covariance | source |
//! |---|---|---|---|
//! | minimum variance | `X° = (Tᵀ R⁻¹ T)⁻¹ Tᵀ R⁻¹ Y` | `S° = (Tᵀ R⁻¹ T)⁻¹` | (6.6.x), (8.2.7)-(8.2.9) |
//! | least squares | `X̂ = (Tᵀ T)⁻¹ Tᵀ Y` | `Ŝ = W R Wᵀ`, `W = (Tᵀ T)⁻¹ Tᵀ` | (6.5.x), (8.2.11)-(8.2.12) |
//!
//! Both are computed by a Householder QR of the system (whitened by `R = L Lᵀ` for minimum
//! variance: `L⁻¹ T`, `L⁻¹ Y`), never by forming the normal equations, whose condition number is
//! the square of `T`'s. The numerical rank of `T` is checked first (singular values of the QR
//! factor; a singular value at most `max(N, n) ε σ_max` counts as zero, as numpy's
//! `matrix_rank` does; [`observability`](mod@super::observability)): a `T` that does not determine the state is [`Error::Unobservable`],
//! naming the rank. The residual `χ² = (Y − T X)ᵀ R⁻¹ (Y − T X)` has `N − n` degrees of
//! freedom for the minimum-variance estimate (6.10.x). [`correlation_determinant`] is §8.8's
//! conditioning test of a covariance, `det R'`.

use super::observability::numerical_rank;
use crate::error::{Error, Param};
pub use crate::model::measurement::{is_usable_sigma, NoiseCovariance};
use nalgebra::{Cholesky, DMatrix, DVector};

/// A batch estimate: the state, its covariance, and how well the data fit.
#[derive(Clone, Debug, PartialEq)]
pub struct BatchEstimate {
    /// `X`, at the epoch the rows of `T` refer to.
    pub state: DVector<f64>,
    /// Its covariance (symmetric).
    pub covariance: DMatrix<f64>,
    /// `(Y − T X)ᵀ R⁻¹ (Y − T X)`.
    pub chi_squared: f64,
    /// `N − n`: observations less states.
    pub degrees_of_freedom: usize,
    /// `σ_max/σ_min` of the whitened `T` (of `T` for least squares).
    pub condition_number: f64,
}

/// The minimum-variance (Gauss–Markov) estimate from `Y = T X + N`, `Cov(N) = R`.
///
/// ```
/// use nalgebra::{DMatrix, DVector};
/// use seqsmooth::estimate::batch::{minimum_variance, NoiseCovariance};
/// // Morrison (6.6.36)-(6.6.39): T rows M Φ(−k), R = diag(1, 2, 2).
/// let t = DMatrix::from_row_slice(3, 2, &[1.0, 0.0, 1.0, -1.0, 1.0, -2.0]);
/// let y = DVector::from_vec(vec![3.1, 2.2, 0.9]);
/// let e = minimum_variance(&t, &y, &NoiseCovariance::Variances(vec![1.0, 2.0, 2.0])).unwrap();
/// assert!((e.covariance[(0, 0)] - 10.0 / 11.0).abs() < 1e-15);
/// assert!((e.state[0] - 69.0 / 22.0).abs() < 1e-14);
/// ```
pub fn minimum_variance(
    t: &DMatrix<f64>,
    y: &DVector<f64>,
    noise: &NoiseCovariance,
) -> Result<BatchEstimate, Error> {
    check(t, y, noise)?;
    let whitener = Whitener::new(noise)?;
    let solved = solve_whitened(whitener.apply(t), whitener.apply(y))?;
    let covariance = solved.covariance();
    finish(
        solved.x,
        covariance,
        solved.chi_squared,
        solved.degrees_of_freedom,
        solved.condition_number,
    )
}

/// The least-squares estimate `X̂ = (Tᵀ T)⁻¹ Tᵀ Y`, with its covariance `W R Wᵀ` under the
/// noise `R` (Morrison (8.2.11)-(8.2.12)); equal to [`minimum_variance`] when `R = σ² I`.
///
/// ```
/// use nalgebra::{DMatrix, DVector};
/// use seqsmooth::estimate::batch::{least_squares, NoiseCovariance};
/// // Morrison (6.5.15)-(6.5.23): X̂ = (19/6, 1.1); with R = diag(1, 2, 2), Ŝ = (1/36)[[35, 21], [21, 27]].
/// let t = DMatrix::from_row_slice(3, 2, &[1.0, 0.0, 1.0, -1.0, 1.0, -2.0]);
/// let y = DVector::from_vec(vec![3.1, 2.2, 0.9]);
/// let e = least_squares(&t, &y, &NoiseCovariance::Variances(vec![1.0, 2.0, 2.0])).unwrap();
/// assert!((e.state[0] - 19.0 / 6.0).abs() < 1e-14 && (e.state[1] - 1.1).abs() < 1e-14);
/// assert!((e.covariance[(0, 1)] - 21.0 / 36.0).abs() < 1e-15);
/// ```
pub fn least_squares(
    t: &DMatrix<f64>,
    y: &DVector<f64>,
    noise: &NoiseCovariance,
) -> Result<BatchEstimate, Error> {
    check(t, y, noise)?;
    let whitener = Whitener::new(noise)?;
    let fit = Fit::new(t.clone(), y)?;
    // W = R⁻¹ Qᵀ (the QR's factors), S = W R Wᵀ.
    let w = fit.weights();
    let covariance = match noise {
        NoiseCovariance::Identity => &w * w.transpose(),
        NoiseCovariance::Variances(v) => {
            let mut wr = w.clone();
            for (mut col, v) in wr.column_iter_mut().zip(v) {
                col *= *v;
            }
            wr * w.transpose()
        }
        NoiseCovariance::Full(r) => &w * r * w.transpose(),
    };
    let residual = y - t * &fit.x;
    let chi_squared = whitener.apply(&residual).norm_squared();
    let (rows, states) = fit.t.shape();
    finish(
        fit.x,
        symmetric(covariance),
        chi_squared,
        rows - states,
        fit.condition_number,
    )
}

/// Morrison's conditioning test of a covariance before it is inverted (§8.8, (8.8.7)-(8.8.8)):
/// `det R'` of the unit-diagonal `R' = P^{−1/2} R P^{−1/2}`, `P = diag(R)`. For a positive
/// definite `R`, `0 < det R' ≤ 1`, with 1 exactly when `R` is diagonal (Ex. 8.16) and values near
/// 0 warning of a nearly singular `R`; a value at or below 0 says `R` is not positive definite.
/// `R` must be square, symmetric and finite with a positive diagonal.
///
/// ```
/// use nalgebra::DMatrix;
/// use seqsmooth::estimate::batch::correlation_determinant;
/// // Ex. 8.17 at α = 1: det R' = 0.0740741 (= 2/27).
/// let a = DMatrix::from_row_slice(3, 3, &[6.0, 5.0, 5.0, 5.0, 6.0, 5.0, 5.0, 5.0, 6.0]);
/// assert!((correlation_determinant(&a).unwrap() - 16.0 / 216.0).abs() < 1e-15);
/// ```
pub fn correlation_determinant(r: &DMatrix<f64>) -> Result<f64, Error> {
    let bad = |reason: &str| Error::InvalidParameter {
        name: Param::Covariance,
        value: format!("{r:?}"),
        reason: reason.into(),
    };
    if !r.is_square() || r.is_empty() {
        return Err(bad("must be a square matrix with at least one row"));
    }
    if let Some(&value) = r.iter().find(|v| !v.is_finite()) {
        return Err(Error::NonFinite {
            what: "covariance entry",
            value,
        });
    }
    if (r - r.transpose()).abs().max() > 1e-12 * r.abs().max() {
        return Err(bad("must be symmetric"));
    }
    if r.diagonal().iter().any(|&d| d <= 0.0) {
        return Err(bad("its diagonal (the variances) must be positive"));
    }
    let scale = r.diagonal().map(|d| 1.0 / d.sqrt());
    let unit = DMatrix::from_fn(r.nrows(), r.ncols(), |i, j| r[(i, j)] * scale[i] * scale[j]);
    Ok(unit.determinant())
}

/// The least-squares solution of a whitened system `t x ≈ y` by Householder QR, `Q` never
/// formed (`Qᵀ y` by the reflectors): the state, the triangular factor `R`, `|Qᵀ y|` over the
/// first `n` rows (`|t x|`, the part of `y` the fit explains) and over the rest (the residual
/// `χ²`), after the rank check of `R`'s singular values (those of `t`). What
/// [`minimum_variance`] and each Gauss–Newton correction solve.
pub(crate) struct Solved {
    /// `x`.
    pub(crate) x: DVector<f64>,
    /// `R`, `n × n` (`t = Q R`).
    r: DMatrix<f64>,
    /// `|t x| = |R x|`.
    pub(crate) explained: f64,
    /// `|y − t x|²`.
    pub(crate) chi_squared: f64,
    /// Rows less states.
    pub(crate) degrees_of_freedom: usize,
    /// `σ_max/σ_min` of `t`.
    pub(crate) condition_number: f64,
}

/// Solves the whitened `t x ≈ y` (see [`Solved`]); [`Error::Unobservable`] when `t` is
/// rank-deficient.
pub(crate) fn solve_whitened(t: DMatrix<f64>, y: DVector<f64>) -> Result<Solved, Error> {
    Factored::new(t, y).solve(0.0)
}

/// The whitened system after its Householder QR: `R` and `Qᵀ y`, for a step without the rank
/// check ([`Factored::step`]) or the solve with it ([`Factored::solve`]).
pub(crate) struct Factored {
    r: DMatrix<f64>,
    /// `Qᵀ y`.
    rotated: DVector<f64>,
    rows: usize,
    states: usize,
}

impl Factored {
    pub(crate) fn new(mut t: DMatrix<f64>, mut y: DVector<f64>) -> Self {
        let (rows, states) = t.shape();
        let mut r = DMatrix::zeros(rows.min(states), states);
        factor_in_place(&mut t, &mut y, &mut r);
        Self {
            r,
            rotated: y,
            rows,
            states,
        }
    }

    /// `x` and `|R x| = |(Qᵀ y)_head|` without the rank check (the caller makes it where its
    /// steps end), or `None` when `R` has a zero or non-finite pivot.
    pub(crate) fn step(&self) -> Option<(DVector<f64>, f64)> {
        if self
            .r
            .diagonal()
            .iter()
            .any(|d| *d == 0.0 || !d.is_finite())
        {
            return None;
        }
        let head = self.rotated.rows(0, self.states).into_owned();
        let x = self.r.solve_upper_triangular(&head)?;
        Some((x, head.norm()))
    }

    /// The solve after the rank check: [`Error::Unobservable`] when a singular value is at or
    /// below `floor` of the largest (or the rounding level, whichever is larger).
    pub(crate) fn solve(self, floor: f64) -> Result<Solved, Error> {
        let (rows, states) = (self.rows, self.states);
        let condition_number = full_rank(&self.r, rows, states, floor)?;
        let head = self.rotated.rows(0, states).into_owned();
        let x = self
            .r
            .solve_upper_triangular(&head)
            .expect("R is non-singular at full rank");
        Ok(Solved {
            x,
            explained: head.norm(),
            chi_squared: self.rotated.rows(states, rows - states).norm_squared(),
            degrees_of_freedom: rows - states,
            condition_number,
            r: self.r,
        })
    }
}

/// The condition number `σ_max/σ_min` of `T = Q R` from `R`'s singular values (those of
/// `T`), or [`Error::Unobservable`] when its numerical rank is below `states`, singular
/// values at or below `floor` of the largest counting as zero too.
pub(crate) fn full_rank(
    r: &DMatrix<f64>,
    rows: usize,
    states: usize,
    floor: f64,
) -> Result<f64, Error> {
    let sv = crate::linalg::singular_values(r)?;
    let largest = sv.max();
    let smallest = if rows < states { 0.0 } else { sv.min() };
    let rank = numerical_rank(sv.as_slice(), rows, states)
        .min(sv.iter().filter(|&&s| s > floor * largest).count());
    if rank < states {
        return Err(Error::Unobservable {
            rank,
            states,
            smallest_singular_value: smallest,
            largest_singular_value: largest,
        });
    }
    Ok(largest / smallest)
}

impl Solved {
    /// `(Rᵀ R)⁻¹ = R⁻¹ R⁻ᵀ`, the inverse of the Gram matrix `tᵀ t`: the covariance of `x`.
    pub(crate) fn covariance(&self) -> DMatrix<f64> {
        covariance_of(&self.r)
    }
}

/// `(Rᵀ R)⁻¹ = R⁻¹ R⁻ᵀ` for the `R` of a full-rank system ([`Solved::covariance`]).
pub(crate) fn covariance_of(r: &DMatrix<f64>) -> DMatrix<f64> {
    let n = r.ncols();
    let r_inv = r
        .solve_upper_triangular(&DMatrix::identity(n, n))
        .expect("R is non-singular at full rank");
    symmetric(&r_inv * r_inv.transpose())
}

/// The Householder QR of `t` (`rows × states`) in place, nalgebra's `QR::new` reflection by
/// reflection (its `householder::clear_column_unchecked`), each reflection applied to `y` as
/// soon as it is made (its `q_tr_mul`: the same operations on `y` in the same order, so
/// `y ← Qᵀ y`), and `R` into `r` (`min(rows, states) × states`: `QR::r`, the upper triangle
/// with the moduli of the reflections' signed norms on the diagonal). The numbers of
/// `t.qr()`, `q_tr_mul` and `r()`, with nothing allocated: what an iteration reuses its
/// buffers for ([`super::gauss_newton`]).
pub(crate) fn factor_in_place(t: &mut DMatrix<f64>, y: &mut DVector<f64>, r: &mut DMatrix<f64>) {
    use nalgebra::{Reflection, Unit};
    let (rows, states) = t.shape();
    let dim = rows.min(states);
    debug_assert_eq!((r.shape(), y.len()), ((dim, states), rows));
    r.fill(0.0);
    for i in 0..dim {
        let signed_norm = nalgebra::linalg::householder::clear_column_unchecked(t, i, 0, None);
        let axis = t.view_range(i.., i);
        let reflection = Reflection::new(Unit::new_unchecked(axis), 0.0);
        reflection.reflect_with_sign(&mut y.rows_range_mut(i..), signed_norm.signum());
        r[(i, i)] = signed_norm.abs();
    }
    for j in 0..states {
        for i in 0..dim.min(j) {
            r[(i, j)] = t[(i, j)];
        }
    }
}

/// [`Factored::solve`] on the factors of [`factor_in_place`] (`r`, and `rotated = Qᵀ y`),
/// `x` into the caller's buffer: the rank check, `x = R⁻¹ (Qᵀ y)_head`, `|R x|`, `χ²`.
pub(crate) fn solve_factored(
    r: &DMatrix<f64>,
    rotated: &DVector<f64>,
    floor: f64,
    x: &mut DVector<f64>,
) -> Result<SolvedStep, Error> {
    let (rows, states) = (rotated.len(), r.ncols());
    let condition_number = full_rank(r, rows, states, floor)?;
    solve_step(r, rotated, condition_number, x)
}

/// [`solve_factored`] after its rank check, `condition_number` the caller's (`NaN` where the
/// caller has not computed it yet: [`certainly_full_rank`]).
pub(crate) fn solve_step(
    r: &DMatrix<f64>,
    rotated: &DVector<f64>,
    condition_number: f64,
    x: &mut DVector<f64>,
) -> Result<SolvedStep, Error> {
    let (rows, states) = (rotated.len(), r.ncols());
    let head = rotated.rows(0, states);
    x.copy_from(&head);
    if !r.solve_upper_triangular_mut(x) {
        return Err(Error::EstimateOutOfRange {
            what: "correction (a zero pivot at full rank)".into(),
        });
    }
    Ok(SolvedStep {
        explained: head.norm(),
        chi_squared: rotated.rows(states, rows - states).norm_squared(),
        degrees_of_freedom: rows - states,
        condition_number,
    })
}

/// Whether `R` (`states × states`, upper triangular, from [`factor_in_place`] of a system of
/// `rows` rows) certainly passes [`full_rank`]'s test with `floor`, found without its singular
/// values: `σ_max ≤ ‖R‖_F` and `σ_min ≥ 1/‖R⁻¹‖_F` (`R⁻¹`'s columns by back substitution, on
/// the stack), so `κ ≤ ‖R‖_F ‖R⁻¹‖_F`; `true` when that bound, times a margin of 2¹⁰ for the
/// roundings of the bound and of the singular values, is below both thresholds of the test
/// (`1/(max(rows, states) ε)` of [`numerical_rank`] and `1/floor`). `false` means only "not
/// known": the caller then makes the test itself. More than [`BOUND_STATES`] states, fewer
/// rows than states, or a number that is not finite: `false`.
pub(crate) fn certainly_full_rank(r: &DMatrix<f64>, rows: usize, floor: f64) -> bool {
    let states = r.ncols();
    if states > BOUND_STATES || rows < states || r.nrows() != states {
        return false;
    }
    let norm2: f64 = (0..states)
        .map(|j| (0..=j).map(|i| r[(i, j)] * r[(i, j)]).sum::<f64>())
        .sum();
    let mut inverse2 = 0.0;
    let mut column = [0.0; BOUND_STATES];
    for c in 0..states {
        // Column c of R⁻¹: R z = e_c, only its first c + 1 entries non-zero.
        for i in (0..=c).rev() {
            let mut acc = if i == c { 1.0 } else { 0.0 };
            for l in i + 1..=c {
                acc -= r[(i, l)] * column[l];
            }
            column[i] = acc / r[(i, i)];
            inverse2 += column[i] * column[i];
        }
    }
    let bound = (norm2 * inverse2).sqrt() * 1024.0;
    let threshold = 1.0 / (rows.max(states) as f64 * f64::EPSILON);
    bound.is_finite() && bound < threshold && bound * floor < 1.0
}

/// The most states [`certainly_full_rank`] bounds.
const BOUND_STATES: usize = 16;

/// [`Solved`] without `x` and `R` (the caller's buffers hold them): [`solve_factored`].
pub(crate) struct SolvedStep {
    /// `|t x| = |R x|`.
    pub(crate) explained: f64,
    /// `|y − t x|²`.
    pub(crate) chi_squared: f64,
    /// Rows less states.
    pub(crate) degrees_of_freedom: usize,
    /// `σ_max/σ_min` of `t`.
    pub(crate) condition_number: f64,
}

/// The QR of a system, with `Q` formed (least squares needs `W = R⁻¹ Qᵀ`), and its solution.
struct Fit {
    t: DMatrix<f64>,
    q: DMatrix<f64>,
    r: DMatrix<f64>,
    x: DVector<f64>,
    condition_number: f64,
}

impl Fit {
    /// Factors `t`, checks its rank, solves `t x ≈ y`.
    fn new(t: DMatrix<f64>, y: &DVector<f64>) -> Result<Self, Error> {
        let (rows, states) = t.shape();
        let qr = t.clone().qr();
        let (q, r) = (qr.q(), qr.r());
        let condition_number = full_rank(&r, rows, states, 0.0)?;
        let qty = q.transpose() * y;
        let x = r
            .solve_upper_triangular(&qty)
            .expect("R is non-singular at full rank");
        Ok(Self {
            t,
            q,
            r,
            x,
            condition_number,
        })
    }

    /// `W = R⁻¹ Qᵀ = (tᵀ t)⁻¹ tᵀ`.
    fn weights(&self) -> DMatrix<f64> {
        self.r
            .solve_upper_triangular(&self.q.transpose())
            .expect("R is non-singular at full rank")
    }
}

fn finish(
    state: DVector<f64>,
    covariance: DMatrix<f64>,
    chi_squared: f64,
    degrees_of_freedom: usize,
    condition_number: f64,
) -> Result<BatchEstimate, Error> {
    let out_of_range = |what: &str| Error::EstimateOutOfRange { what: what.into() };
    if !state.iter().all(|v| v.is_finite()) {
        return Err(out_of_range("state"));
    }
    if !covariance.iter().all(|v| v.is_finite()) {
        return Err(out_of_range("covariance"));
    }
    if !chi_squared.is_finite() {
        return Err(out_of_range("residual chi-squared"));
    }
    Ok(BatchEstimate {
        state,
        covariance,
        chi_squared,
        degrees_of_freedom,
        condition_number,
    })
}

/// `(a + aᵀ)/2`.
fn symmetric(a: DMatrix<f64>) -> DMatrix<f64> {
    (&a + a.transpose()) * 0.5
}

/// `x ↦ L⁻¹ x` for `R = L Lᵀ`: the identity, `1/σ_k` per row, or the Cholesky factor's
/// triangular solve.
enum Whitener {
    Identity,
    Sigmas(Vec<f64>),
    Cholesky(DMatrix<f64>),
}

impl Whitener {
    fn new(noise: &NoiseCovariance) -> Result<Self, Error> {
        Ok(match noise {
            NoiseCovariance::Identity => Self::Identity,
            NoiseCovariance::Variances(v) => Self::Sigmas(v.iter().map(|v| v.sqrt()).collect()),
            NoiseCovariance::Full(r) => Self::Cholesky(
                Cholesky::new(r.clone())
                    .ok_or_else(|| Error::InvalidParameter {
                        name: Param::NoiseCovariance,
                        value: format!("{r}").trim().replace('\n', " "),
                        reason: "must be symmetric positive definite (its Cholesky \
                                 factorisation failed)"
                            .into(),
                    })?
                    .l(),
            ),
        })
    }

    /// `L⁻¹ x` for a matrix (or a vector) `x` with one row per observation.
    fn apply<C: nalgebra::Dim>(
        &self,
        x: &nalgebra::OMatrix<f64, nalgebra::Dyn, C>,
    ) -> nalgebra::OMatrix<f64, nalgebra::Dyn, C>
    where
        nalgebra::DefaultAllocator: nalgebra::allocator::Allocator<nalgebra::Dyn, C>,
    {
        match self {
            Self::Identity => x.clone(),
            Self::Sigmas(s) => {
                let mut w = x.clone();
                for (k, s) in s.iter().enumerate() {
                    w.row_mut(k).unscale_mut(*s);
                }
                w
            }
            Self::Cholesky(l) => l
                .solve_lower_triangular(x)
                .expect("a Cholesky factor is non-singular"),
        }
    }
}

/// Shapes agree, every number is finite, variances are positive, `R` is symmetric.
fn check(t: &DMatrix<f64>, y: &DVector<f64>, noise: &NoiseCovariance) -> Result<(), Error> {
    let bad = |name: Param, value: String, reason: &str| Error::InvalidParameter {
        name,
        value,
        reason: reason.into(),
    };
    let (rows, states) = t.shape();
    if states == 0 || rows == 0 {
        return Err(bad(
            Param::ObservationMatrixT,
            format!("{rows}x{states}"),
            "must have at least one row and one column",
        ));
    }
    if y.len() != rows {
        return Err(bad(
            Param::ObservationsY,
            format!("of length {}", y.len()),
            &format!("must have one value per row of T ({rows})"),
        ));
    }
    if let Some((k, v)) = t.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        let (i, j) = (k % rows, k / rows);
        return Err(bad(
            Param::ObservationMatrixT,
            format!("entry [{i}, {j}] = {v}"),
            "must be finite",
        ));
    }
    if let Some((k, v)) = y.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(bad(
            Param::ObservationsY,
            format!("entry {k} = {v}"),
            "must be finite",
        ));
    }
    match noise {
        NoiseCovariance::Identity => {}
        NoiseCovariance::Variances(v) => {
            if v.len() != rows {
                return Err(bad(
                    Param::NoiseVariances,
                    format!("of length {}", v.len()),
                    &format!("must have one variance per row of T ({rows})"),
                ));
            }
            if let Some((k, v)) = v
                .iter()
                .enumerate()
                .find(|(_, v)| !(v.is_finite() && **v > 0.0))
            {
                return Err(bad(
                    Param::NoiseVariance,
                    format!("{v} (observation {k})"),
                    "must be positive and finite",
                ));
            }
        }
        NoiseCovariance::Full(r) => {
            if r.shape() != (rows, rows) {
                return Err(bad(
                    Param::NoiseCovariance,
                    format!("{}x{}", r.nrows(), r.ncols()),
                    &format!("must be {rows}x{rows}, one row and column per row of T"),
                ));
            }
            if let Some((k, v)) = r.iter().enumerate().find(|(_, v)| !v.is_finite()) {
                return Err(bad(
                    Param::NoiseCovariance,
                    format!("entry [{}, {}] = {v}", k % rows, k / rows),
                    "must be finite",
                ));
            }
            let asymmetry = (r - r.transpose()).amax();
            if asymmetry > 1e-12 * r.amax() {
                return Err(bad(
                    Param::NoiseCovariance,
                    format!("with |R - Rᵀ| = {asymmetry:e}"),
                    "must be symmetric",
                ));
            }
        }
    }
    Ok(())
}
