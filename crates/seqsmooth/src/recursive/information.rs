//! The square-root information (Bayes) recursion, with fading memory and its true covariance:
//! the one recursion under the exact polynomial engine and the Bayes filter
//! ([`InformationFilter`]: its steps, their sources in Morrison (1969), the lazy discount).

use super::factor::TriangularFactor;
use crate::linalg::{solve_upper_in_place, solve_upper_transpose_in_place};
use crate::numeric::unrolled::{each_index, unrolled_sizes, Any, Fixed, Size};
use nalgebra::{DMatrix, DVector};

/// When the lazy discount's row scale exceeds this, it is folded into the factors.
const RENORMALISE: f64 = 1e30;

/// The square-root information filter: estimate `x = R⁻¹d` of a linear model observed through
/// rows `y_k = h_kᵀ x + ν_k` with weights `c_k`, optionally fading.
///
/// | step | | source |
/// |---|---|---|
/// | observe `y = hᵀx + ν` with weight `c` (`1/σ²`) | a row `√c·[hᵀ ∣ y]` folded into `[R ∣ d]` | (10.2.42)-(10.2.44), (11.3.4) |
/// | change of state variables `x_old = A x_new` (a transition) | `R ← R A` | (10.2.40)-(10.2.41), (11.3.3) |
/// | fade: all information so far times `f ∈ (0, 1]` | `RᵀR ← f RᵀR` (lazily) | (14.4.26)-(14.4.27), (13.2.1) |
/// | estimate | `R x = d` | (10.2.33) |
/// | covariance, plain | `(RᵀR)⁻¹` | (10.2.34) |
/// | covariance, fading (true) | `(RᵀR)⁻¹ (QᵀQ) (RᵀR)⁻¹`, `QᵀQ = Σ c_k w_k² h_k h_kᵀ` | (14.3.11)-(14.3.13), (13.6.4) |
///
/// With fading memory each row's information weighs `w_k c_k`, where `w_k` is the product of
/// the discounts since it came in, so `(RᵀR)⁻¹` is the recursion's own matrix `P` (14.3.13),
/// not the estimate's covariance; the estimate's is the sandwich above, whose middle factor
/// `Q` is kept alongside `R` (rows `√c·w_k·hᵀ`, no right-hand side) when asked
/// ([`InformationFilter::with_true_covariance`]).
///
/// The discount is applied lazily: instead of multiplying `R` by `√f` at each step, new rows get
/// the weight `1/Π f` (a scale folded back into the factors when its square root passes 1e30:
/// the rows' weights are its square, `Q`'s its fourth power, ≤ 1e120, far from overflow in the
/// squares the square-root-free rotations form). The estimate and the sandwich do not depend on
/// that common scale.
///
/// ```
/// use seqsmooth::recursive::InformationFilter;
/// // fit y = a + b u to three points
/// let mut f = InformationFilter::new(2);
/// for (u, y) in [(0.0, 1.0), (1.0, 3.0), (2.0, 5.0)] {
///     f.observe(&[1.0, u], y, 1.0);
/// }
/// let x = f.solve().unwrap();
/// assert!((x[0] - 1.0).abs() < 1e-12 && (x[1] - 2.0).abs() < 1e-12);
/// ```
#[derive(Debug, serde::Serialize, serde::Deserialize)]
pub struct InformationFilter {
    info: TriangularFactor,
    /// `Q` with `QᵀQ = Σ c_k w_k² h_k h_kᵀ`, when the true covariance is kept.
    spread: Option<TriangularFactor>,
    /// The lazy discount: the true `R` is the stored one divided by `scale` (`Q` by `scale²`),
    /// and each new row gets the weight `c·scale²` (`Q`'s `c·scale⁴`).
    scale: f64,
}

// Field by field, `clone_from` too (the automatic filter's review keeps copies of it).
field_clone!(InformationFilter {
    info,
    spread,
    scale
});

impl InformationFilter {
    /// A filter for a `p`-dimensional state with no prior information.
    pub fn new(p: usize) -> Self {
        Self {
            info: TriangularFactor::new(p),
            spread: None,
            scale: 1.0,
        }
    }

    /// A Bayes filter with prior estimate `mean` and prior information factor `r_prior`
    /// (`r_priorᵀ r_prior` = inverse prior covariance; upper triangular).
    ///
    /// ```
    /// use nalgebra::{DMatrix, DVector};
    /// use seqsmooth::recursive::InformationFilter;
    /// let f = InformationFilter::with_prior(&DVector::from_vec(vec![1.0, 2.0]), &(DMatrix::identity(2, 2) * 2.0));
    /// assert!((f.covariance().unwrap()[(1, 1)] - 0.25).abs() < 1e-15);
    /// ```
    pub fn with_prior(mean: &DVector<f64>, r_prior: &DMatrix<f64>) -> Self {
        Self {
            info: TriangularFactor::from_r(r_prior, &(r_prior * mean)),
            spread: None,
            scale: 1.0,
        }
    }

    /// Keeps the middle factor `Q` of the true covariance from here on (the information so far,
    /// a prior, counts as one more whitened observation: its `Q` is its `R`, exact before the
    /// first [`fade`](Self::fade)). A second call changes nothing.
    ///
    /// ```
    /// use seqsmooth::recursive::InformationFilter;
    /// // Fading memory on a constant: weights 1/4, 1/2, 1 (f = 1/2 per step).
    /// let mut f = InformationFilter::new(1).with_true_covariance();
    /// for y in [1.0, 2.0, 3.0] {
    ///     f.fade(2f64.sqrt());
    ///     f.observe(&[1.0], y, 1.0);
    /// }
    /// // Σw = 7/4, Σw² = 21/16: variance (21/16)/(7/4)² = 3/7; P = 1/Σw = 4/7.
    /// assert!((f.covariance().unwrap()[(0, 0)] - 3.0 / 7.0).abs() < 1e-15);
    /// assert!((f.information_covariance().unwrap()[(0, 0)] - 4.0 / 7.0).abs() < 1e-15);
    /// ```
    pub fn with_true_covariance(mut self) -> Self {
        if self.spread.is_none() {
            let mut q = self.info.clone();
            // Stored Q is s² times the true one where R is s times: Q_true = R_true.
            q.discount_root(self.scale);
            self.spread = Some(q);
        }
        self
    }

    /// State dimension.
    pub fn dim(&self) -> usize {
        self.info.dim()
    }

    /// The square-root information factor as stored: `scale·R` for the lazy discount's
    /// current scale, which cancels in the estimate ([`solve`](Self::solve)).
    pub fn factor(&self) -> &TriangularFactor {
        &self.info
    }

    /// Folds in the observation `y = hᵀx + ν` with weight `c` (`1/σ²` for minimum variance).
    #[inline]
    pub fn observe(&mut self, h: &[f64], y: f64, c: f64) {
        let w = c * (self.scale * self.scale);
        self.info.add_row(h, y, w);
        if let Some(q) = &mut self.spread {
            q.add_row(h, 0.0, w * (self.scale * self.scale));
        }
    }

    /// [`observe`](Self::observe) with `h = (1, v, v², …)`: a polynomial's coefficients
    /// observed at `v` ([`TriangularFactor::add_row_powers`]).
    ///
    /// ```
    /// use seqsmooth::recursive::InformationFilter;
    /// let mut f = InformationFilter::new(2);
    /// f.observe_powers(0.0, 1.0, 1.0);
    /// f.observe_powers(2.0, 5.0, 1.0);
    /// assert!((f.solve().unwrap()[1] - 2.0).abs() < 1e-15);
    /// ```
    #[inline]
    pub fn observe_powers(&mut self, v: f64, y: f64, c: f64) {
        let w = c * (self.scale * self.scale);
        self.info.add_row_powers(v, y, w);
        if let Some(q) = &mut self.spread {
            q.add_row_powers(v, 0.0, w * (self.scale * self.scale));
        }
    }

    /// Fading memory: all information so far weighs `f = 1/g²` times as much from now on
    /// (`g = 1/√f ≥ 1`, given so that a constant discount costs one multiplication per step;
    /// (14.4.26)-(14.4.27) with `f = β^(t_n − t_(n−1))` or `θ`). Applied lazily (module docs).
    ///
    /// ```
    /// use seqsmooth::recursive::InformationFilter;
    /// let mut f = InformationFilter::new(1);
    /// f.observe(&[1.0], 0.0, 1.0);
    /// f.fade(3.0); // the first observation now weighs 1/9
    /// f.observe(&[1.0], 10.0, 1.0);
    /// assert!((f.solve().unwrap()[0] - 9.0).abs() < 1e-14);
    /// ```
    #[inline]
    pub fn fade(&mut self, g: f64) {
        self.scale *= g;
        if self.scale > RENORMALISE {
            let f = 1.0 / (self.scale * self.scale);
            self.info.discount(f);
            if let Some(q) = &mut self.spread {
                q.discount(f * f);
            }
            self.scale = 1.0;
        }
    }

    /// Discounts all information so far by the factor `f ∈ (0, 1]` at once (the eager form of
    /// [`fade`](Self::fade) by `1/√f`).
    ///
    /// ```
    /// use seqsmooth::recursive::InformationFilter;
    /// let mut f = InformationFilter::new(1);
    /// f.observe(&[1.0], 2.0, 1.0);
    /// f.discount(0.25);
    /// assert!((f.covariance().unwrap()[(0, 0)] - 4.0).abs() < 1e-15);
    /// ```
    pub fn discount(&mut self, f: f64) {
        self.info.discount(f);
        if let Some(q) = &mut self.spread {
            q.discount(f * f);
        }
    }

    /// [`discount`](Self::discount) by `f = s²`, given `s`.
    ///
    /// ```
    /// use seqsmooth::recursive::InformationFilter;
    /// let mut f = InformationFilter::new(1);
    /// f.observe(&[1.0], 2.0, 1.0);
    /// f.discount_root(0.5);
    /// assert!((f.covariance().unwrap()[(0, 0)] - 4.0).abs() < 1e-15);
    /// ```
    pub fn discount_root(&mut self, s: f64) {
        self.discount(s * s);
    }

    /// Re-expresses the state in new variables, `x_old = A x_new` (`R ← R A`): a transition
    /// `A = Φ(t_old, t_new)` carries the information to `t_new`.
    ///
    /// ```
    /// use nalgebra::DMatrix;
    /// use seqsmooth::recursive::InformationFilter;
    /// let mut f = InformationFilter::new(2);
    /// f.observe(&[1.0, 0.0], 1.0, 1.0);
    /// f.observe(&[0.0, 1.0], 2.0, 1.0);
    /// // x_old = (x_new swapped)
    /// f.change_variables(&DMatrix::from_row_slice(2, 2, &[0.0, 1.0, 1.0, 0.0]));
    /// let x = f.solve().unwrap();
    /// assert!((x[0] - 2.0).abs() < 1e-15 && (x[1] - 1.0).abs() < 1e-15);
    /// ```
    pub fn change_variables(&mut self, a: &DMatrix<f64>) {
        self.info.change_variables(a);
        if let Some(q) = &mut self.spread {
            q.change_variables(a);
        }
    }

    /// Driving noise over a transition (after [`change_variables`](Self::change_variables) to
    /// the new time): the state becomes `x + G v` with `v ~ N(0, I)`, so the information
    /// `R x ≈ d` on the state without the noise becomes `R (x − G v) ≈ d`, and `v` brings its
    /// own `I v ≈ 0`. An orthogonal triangularisation of the stacked rows
    /// `[[I, 0 | 0], [−R G, R | d]]` leaves the information on the new state in its lower
    /// right block: the square-root information filter's time update with process noise
    /// (Bierman's SRIF; Morrison (15.4.11) `S ← Φ S Φᵀ + Q` in information form, `Q = G Gᵀ`),
    /// which needs no inverse of `Q` or of the covariance and holds from zero information
    /// (none stays none). Not with the true covariance of fading memory
    /// ([`with_true_covariance`](Self::with_true_covariance)): the caller refuses that pair.
    ///
    /// ```
    /// use nalgebra::DMatrix;
    /// use seqsmooth::recursive::InformationFilter;
    /// let mut f = InformationFilter::new(1);
    /// f.observe(&[1.0], 2.0, 4.0); // variance 1/4
    /// f.diffuse(&DMatrix::from_element(1, 1, 0.5)); // plus 1/4
    /// assert!((f.covariance().unwrap()[(0, 0)] - 0.5).abs() < 1e-15);
    /// assert!((f.solve().unwrap()[0] - 2.0).abs() < 1e-15);
    /// ```
    pub fn diffuse(&mut self, g: &DMatrix<f64>) {
        debug_assert!(
            self.spread.is_none(),
            "driving noise with the true covariance"
        );
        let n = self.dim();
        let (r, d) = (self.info.r(), self.info.rhs());
        // The stored R is `scale` times the true one: so are the noise rows.
        let mut a = DMatrix::zeros(2 * n, 2 * n + 1);
        a.view_mut((0, 0), (n, n)).fill_diagonal(self.scale);
        a.view_mut((n, 0), (n, n)).copy_from(&(-(&r * g)));
        a.view_mut((n, n), (n, n)).copy_from(&r);
        a.view_mut((n, 2 * n), (n, 1)).copy_from(&d);
        let t = a.qr().r();
        let r_new = t.view((n, n), (n, n)).into_owned();
        let d_new: Vec<f64> = t.view((n, 2 * n), (n, 1)).iter().copied().collect();
        // Row by row (a row with a zero pivot may still carry information to its right, which
        // `TriangularFactor::from_r` cannot hold).
        let mut info = TriangularFactor::new(n);
        let mut row = vec![0.0; n];
        for (i, &d) in d_new.iter().enumerate() {
            row.iter_mut()
                .zip(r_new.row(i).iter())
                .for_each(|(a, b)| *a = *b);
            info.add_row(&row, d, 1.0);
        }
        self.info = info;
    }

    /// [`change_variables`](Self::change_variables) for an upper-triangular `A`.
    ///
    /// ```
    /// use nalgebra::DMatrix;
    /// use seqsmooth::recursive::InformationFilter;
    /// let mut f = InformationFilter::new(2);
    /// f.observe(&[1.0, 0.0], 1.0, 1.0);
    /// f.observe(&[1.0, 1.0], 3.0, 1.0);
    /// // x_old = A x_new with A = [[1, −1], [0, 1]]: the line 1 + 2u about u = 1.
    /// f.change_variables_upper(&DMatrix::from_row_slice(2, 2, &[1.0, -1.0, 0.0, 1.0]));
    /// let x = f.solve().unwrap(); // its value one unit on, and its slope
    /// assert!((x[0] - 3.0).abs() < 1e-15 && (x[1] - 2.0).abs() < 1e-15);
    /// ```
    pub fn change_variables_upper(&mut self, a: &DMatrix<f64>) {
        self.info.change_variables_upper(a);
        if let Some(q) = &mut self.spread {
            q.change_variables_upper(a);
        }
    }

    /// [`TriangularFactor::change_variables_polynomial`]: the state holds polynomial
    /// coefficients in `v = α v' + β`.
    ///
    /// ```
    /// use seqsmooth::recursive::InformationFilter;
    /// let mut f = InformationFilter::new(2);
    /// f.observe_powers(0.0, 1.0, 1.0);
    /// f.observe_powers(1.0, 3.0, 1.0);
    /// f.change_variables_polynomial(2.0, 1.0); // v = 2v' + 1
    /// let x = f.solve().unwrap(); // 1 + 2v = 3 + 4v'
    /// assert!((x[0] - 3.0).abs() < 1e-15 && (x[1] - 4.0).abs() < 1e-15);
    /// ```
    #[inline]
    pub fn change_variables_polynomial(&mut self, alpha: f64, beta: f64) {
        self.info.change_variables_polynomial(alpha, beta);
        if let Some(q) = &mut self.spread {
            q.change_variables_polynomial(alpha, beta);
        }
    }

    /// True when every diagonal entry of `R` is non-zero (the state is determined).
    pub fn is_determined(&self) -> bool {
        self.info.is_determined()
    }

    /// The estimate `R⁻¹ d`, or `None` while the state is not determined.
    pub fn solve(&self) -> Option<DVector<f64>> {
        let mut x = vec![0.0; self.dim()];
        self.info.solve_into(&mut x).then(|| DVector::from_vec(x))
    }

    /// `J R⁻¹` for a given `J` (rows are linear functionals of the state), with `R` as stored
    /// ([`factor`](Self::factor)): the building block of `J (RᵀR)⁻¹ Jᵀ = (J R⁻¹)(J R⁻¹)ᵀ`.
    ///
    /// ```
    /// use nalgebra::DMatrix;
    /// use seqsmooth::recursive::InformationFilter;
    /// let mut f = InformationFilter::new(1);
    /// f.observe(&[1.0], 0.0, 4.0); // R = 2
    /// assert_eq!(f.right_divide(&DMatrix::from_element(1, 1, 1.0)).unwrap()[(0, 0)], 0.5);
    /// ```
    pub fn right_divide(&self, j: &DMatrix<f64>) -> Option<DMatrix<f64>> {
        let p = self.dim();
        let factor = self.info.r();
        let mut out = DMatrix::zeros(j.nrows(), p);
        let mut row = vec![0.0; p];
        for r in 0..j.nrows() {
            for (c, v) in row.iter_mut().enumerate() {
                *v = j[(r, c)];
            }
            // (J R⁻¹)ᵀ = R⁻ᵀ Jᵀ: forward substitution with Rᵀ.
            if !solve_upper_transpose_in_place(&factor, &mut row) {
                return None;
            }
            for (c, v) in row.iter().enumerate() {
                out[(r, c)] = *v;
            }
        }
        Some(out)
    }

    /// The variances of `j·X` for the rows `j` of `rows` (`p` values each, row-major;
    /// overwritten), into `out`: the diagonal of [`Self::covariance_of`], the true covariance's
    /// when it is kept, without allocating (the batch σ path of the polynomial filters). `false`
    /// while not determined. `inv` is scratch of `p` values.
    pub(crate) fn variances_of_rows(
        &self,
        rows: &mut [f64],
        inv: &mut [f64],
        out: &mut [f64],
    ) -> bool {
        // The sizes compiled in with their loops unrolled (the same operations in the same
        // order as the general path).
        unrolled_sizes!(self.dim(), N => self.variances_of_rows_with(Fixed::<N>, rows, inv, out), p => self.variances_of_rows_with(Any(p), rows, inv, out))
    }

    #[inline(always)]
    fn variances_of_rows_with(
        &self,
        size: impl Size,
        rows: &mut [f64],
        inv: &mut [f64],
        out: &mut [f64],
    ) -> bool {
        let mut out = out.iter_mut();
        self.for_each_solved_row(size, rows, inv, |j, spread| {
            let Some(o) = out.next() else { return };
            *o = match spread {
                None => j.iter().map(|v| v * v).sum::<f64>() * (self.scale * self.scale),
                // The variance ‖Q k‖² (the lazy scale cancels).
                Some(q) => q.norm_sq_of(size, j),
            };
        })
    }

    /// The covariance `J C Jᵀ` of the `n` rows `j` of `rows` (`p` values each, row-major;
    /// overwritten) into `out` (`n × n`, row-major): [`Self::covariance_of`] without allocating
    /// (the true covariance's when it is kept: `Σ_i q_i (U_Q k_a)_i (U_Q k_b)_i` for
    /// `k = (RᵀR)⁻¹ jᵀ` and `Q = D_Q^½ U_Q`). `false` while not determined. `inv` is scratch of
    /// `p` values.
    pub(crate) fn covariance_of_rows(
        &self,
        rows: &mut [f64],
        inv: &mut [f64],
        out: &mut [f64],
    ) -> bool {
        // As in `variances_of_rows`: the sizes compiled in, the same operations in order.
        unrolled_sizes!(self.dim(), N => self.covariance_of_rows_with(Fixed::<N>, rows, inv, out, true), p => self.covariance_of_rows_with(Any(p), rows, inv, out, true))
    }

    /// Both: with `full` the whole `n × n` matrix, else its diagonal alone (`n` values),
    /// each entry by the same operations.
    #[inline(always)]
    fn covariance_of_rows_with(
        &self,
        size: impl Size,
        rows: &mut [f64],
        inv: &mut [f64],
        out: &mut [f64],
        full: bool,
    ) -> bool {
        let p = size.get();
        let solved = self.for_each_solved_row(size, rows, inv, |j, spread| match spread {
            None => j.iter_mut().for_each(|v| *v *= self.scale),
            // U_Q k (the lazy scale cancels).
            Some(q) => q.unit_upper_times(size, j),
        });
        if !solved {
            return false;
        }
        let n = rows.len() / p;
        let weight = |i: usize| self.spread.as_ref().map_or(1.0, |q| q.pivot(i));
        for a in 0..n {
            for b in (if full { 0 } else { a })..=a {
                let (ra, rb) = (&rows[a * p..(a + 1) * p], &rows[b * p..(b + 1) * p]);
                let v = (0..p).map(|i| weight(i) * ra[i] * rb[i]).sum();
                if full {
                    out[a * n + b] = v;
                    out[b * n + a] = v;
                } else {
                    out[a] = v;
                }
            }
        }
        true
    }

    /// The diagonal of [`Self::covariance_of_rows`] alone (`n` values into `out`), each entry
    /// by the same operations in the same order (bit for bit), without the products of
    /// different rows: the rows' variances where only they are wanted (the automatic filter's
    /// reported 1σ). `false` while not determined.
    pub(crate) fn covariance_diagonal_of_rows(
        &self,
        rows: &mut [f64],
        inv: &mut [f64],
        out: &mut [f64],
    ) -> bool {
        unrolled_sizes!(self.dim(), N => self.covariance_of_rows_with(Fixed::<N>, rows, inv, out, false), p => self.covariance_of_rows_with(Any(p), rows, inv, out, false))
    }

    /// Each row `j` of `rows` (`p` values) replaced by `(J R⁻¹)ᵀ` from the stored factor (`R`
    /// times the lazy scale), or with the true covariance kept by `kᵀ = R⁻¹ (J R⁻¹)ᵀ`, and
    /// handed to `f` with `Q` when it is kept; `false` (and no row touched) while not
    /// determined. `inv` is scratch of `p` values; `size` is `p`.
    #[inline(always)]
    fn for_each_solved_row(
        &self,
        size: impl Size,
        rows: &mut [f64],
        inv: &mut [f64],
        mut f: impl FnMut(&mut [f64], Option<&TriangularFactor>),
    ) -> bool {
        let p = size.get();
        if !self.info.inverse_sqrt_pivots(size, &mut inv[..p]) {
            return false;
        }
        for j in rows.chunks_exact_mut(p) {
            self.info.right_divide_row(size, j, inv);
            if self.spread.is_some() {
                self.info.left_solve(size, j, inv);
            }
            f(j, self.spread.as_ref());
        }
        true
    }

    /// [`Self::variances_of_rows`] for the `p` rows of an upper-triangular `J` (`p × p`, its
    /// entry `J_ik`, `k ≥ i`, given by `entry(i, k)`): the variances of `(J x)_i`
    /// into `out`, for a dimension `p ≤ N` (`N`, the size of the kernel's stack arrays, is `p`
    /// itself where the caller knows it at compile time: its loops then unroll). `false` while
    /// not determined.
    ///
    /// With `R = D^½ U`, `(RᵀR)⁻¹ Jᵀ = U⁻¹ D⁻¹ Y` for `Y = U⁻ᵀ Jᵀ`, which is lower triangular
    /// (both factors are): `Uᵀ Y = Jᵀ` by forward substitution (`p³/6` in all). The plain
    /// covariance's diagonal is then `Σ_k Y_ki²/d_k`; the true (sandwich) covariance's,
    /// `‖Q (RᵀR)⁻¹ Jᵀ‖²` column by column with `Q = D_Q^½ U_Q`, is `Σ_r (D_Q)_r (T D⁻¹ Y)_ri²`
    /// with the unit upper triangle `T = U_Q U⁻¹` (`T U = U_Q`, `p³/6`; the product with the
    /// triangle `D⁻¹ Y`, `p³/3`): no square root, and `p` divisions independent of each other.
    /// The lazy scale cancels as in [`Self::covariance_of`].
    ///
    /// Every triangle is computed a row of `Y` (a column of `T`, a row of `T D⁻¹ Y`) at a
    /// time, each step one multiple of an earlier row subtracted from all of a row's entries
    /// at once: the entries of a row do not wait for each other (the processor overlaps them,
    /// the compiler packs neighbours into one vector operation), where one entry's
    /// substitution is a chain of dependent steps. Each entry still sees its own terms in the
    /// same order, from the diagonal outwards, so the result is the entry-by-entry
    /// substitution's to the bit. The row index is a constant in each step (`each_index!`),
    /// so that the steps' short loops unroll at every size compiled in, not only the smallest.
    ///
    /// With `FUSED` each multiply-add is one fused operation (`f64::mul_add`: one rounding
    /// instead of two); the caller instantiates it only inside a function compiled for a
    /// processor with fused multiply-add (elsewhere `mul_add` is a library call). The terms
    /// and their order are the same, so the two differ by rounding alone.
    #[inline(always)]
    pub(crate) fn variances_of_upper_rows<const N: usize, const FUSED: bool>(
        &self,
        p: usize,
        entry: impl Fn(usize, usize) -> f64 + Copy,
        out: &mut [f64],
    ) -> bool {
        assert!(p <= N && p == self.dim(), "rows of the wrong size");
        let out = &mut out[..p];
        let mut inv_d = [0.0; N];
        if !self.info.inverse_pivots(&mut inv_d[..p]) {
            return false;
        }
        let u = self.info.unit_triangle(p);
        // y[k][i] = Y_ki (i ≤ k): row k of Y is row k of Jᵀ less the earlier rows j < k times
        // U_jk (Uᵀ Y = Jᵀ).
        let mut y = [[0.0; N]; N];
        each_index!(p, k => {
            let (done, rest) = y.split_at_mut(k);
            let row = &mut rest[0][..k + 1];
            for (i, v) in row.iter_mut().enumerate() {
                *v = entry(i, k);
            }
            for (j, earlier) in done.iter().enumerate() {
                let c = u[j * p + k];
                for (v, e) in row[..j + 1].iter_mut().zip(&earlier[..j + 1]) {
                    *v = sub_mul::<FUSED>(*v, c, *e);
                }
            }
        });
        let mut sum = [0.0; N];
        match &self.spread {
            None => {
                each_index!(p, k => {
                    for (s, v) in sum[..k + 1].iter_mut().zip(&y[k][..k + 1]) {
                        *s = add_mul::<FUSED>(*s, v * v, inv_d[k]);
                    }
                });
                let s2 = self.scale * self.scale;
                for (o, s) in out.iter_mut().zip(&sum) {
                    *o = s * s2;
                }
            }
            Some(q) => {
                let mut dq = [0.0; N];
                q.pivots_into(&mut dq[..p]);
                // tc[k][r] = T_rk (r ≤ k, T_kk = 1): column k of T is column k of U_Q less the
                // earlier columns j < k times U_jk (T U = U_Q).
                let uq = q.unit_triangle(p);
                let mut tc = [[0.0; N]; N];
                each_index!(p, k => {
                    let (done, rest) = tc.split_at_mut(k);
                    let col = &mut rest[0][..k + 1];
                    for (r, v) in col[..k].iter_mut().enumerate() {
                        *v = uq[r * p + k];
                    }
                    col[k] = 1.0;
                    for (j, earlier) in done.iter().enumerate() {
                        let c = u[j * p + k];
                        for (v, e) in col[..j].iter_mut().zip(&earlier[..j]) {
                            *v = sub_mul::<FUSED>(*v, c, *e);
                        }
                        // `earlier[j] = T_jj = 1`: `c · 1` is `c`, bit for bit.
                        col[j] -= c;
                    }
                });
                // W = D⁻¹ Y, row by row.
                each_index!(p, k => {
                    let e = inv_d[k];
                    for v in &mut y[k][..k + 1] {
                        *v *= e;
                    }
                });
                // Row r of Z = T W (entries z_ri = Σ_(k ≥ max(r, i)) T_rk W_ki), then the
                // variances Σ_r (D_Q)_r z_ri².
                each_index!(p, r => {
                    // The term k = r first: `T_rr = 1`, so it is row r of W itself (zero
                    // beyond its diagonal), bit for bit what `0 + 1 · w` gives once squared.
                    let mut z = y[r];
                    for k in r + 1..p {
                        let c = tc[k][r];
                        for (v, w) in z[..k + 1].iter_mut().zip(&y[k][..k + 1]) {
                            *v = add_mul::<FUSED>(*v, c, *w);
                        }
                    }
                    for (s, v) in sum[..p].iter_mut().zip(&z) {
                        *s = add_mul::<FUSED>(*s, dq[r] * v, *v);
                    }
                });
                out.copy_from_slice(&sum[..p]);
            }
        }
        true
    }

    /// The largest variance inflation `max_i P_ii (RᵀR)_ii` (`P = (RᵀR)⁻¹`): 1 for a component
    /// whose information is independent of the others', `1/(1 − ρ_i²)` for one whose estimate
    /// correlates with the rest by the multiple correlation `ρ_i`, and without bound as a
    /// direction loses its information (an unobserved direction under fading memory). It does
    /// not depend on the state's units; the rounding error of the estimate, in its σ, grows
    /// with it (measured 0.1-1.1 `ε` times it: the polynomial model to degree 8, Morrison's
    /// Ex. 14.9a). `None` while not determined.
    ///
    /// ```
    /// use seqsmooth::recursive::InformationFilter;
    /// let mut f = InformationFilter::new(2);
    /// f.observe(&[1.0, 0.0], 0.0, 1.0);
    /// f.observe(&[0.0, 1e6], 0.0, 1.0);
    /// assert!((f.variance_inflation().unwrap() - 1.0).abs() < 1e-12); // units don't matter
    /// f.observe(&[1.0, 1e6], 0.0, 1e6);
    /// assert!(f.variance_inflation().unwrap() > 1e5); // the two now move together
    /// ```
    pub fn variance_inflation(&self) -> Option<f64> {
        let p = self.dim();
        let ri = self.right_divide(&DMatrix::identity(p, p))?;
        let r = self.info.r();
        Some((0..p).fold(0.0, |worst: f64, i| {
            worst.max(ri.row(i).norm_squared() * r.column(i).norm_squared())
        }))
    }

    /// The recursion's own matrix `P = (RᵀR)⁻¹` (14.3.13): the covariance when the weights
    /// are inverse variances and nothing faded.
    ///
    /// ```
    /// use seqsmooth::recursive::InformationFilter;
    /// let mut f = InformationFilter::new(1);
    /// f.observe(&[1.0], 2.0, 4.0);
    /// f.fade(2.0);
    /// assert!((f.information_covariance().unwrap()[(0, 0)] - 1.0).abs() < 1e-15);
    /// ```
    pub fn information_covariance(&self) -> Option<DMatrix<f64>> {
        let p = self.dim();
        let ri = self.right_divide(&DMatrix::identity(p, p))?;
        Some(&ri * ri.transpose() * (self.scale * self.scale))
    }

    /// The estimate's covariance: the sandwich `P (QᵀQ) P` when the true covariance is kept
    /// ([`with_true_covariance`](Self::with_true_covariance)), else `P`.
    ///
    /// ```
    /// use seqsmooth::recursive::InformationFilter;
    /// let mut f = InformationFilter::new(1);
    /// f.observe(&[1.0], 2.0, 4.0);
    /// assert!((f.covariance().unwrap()[(0, 0)] - 0.25).abs() < 1e-15);
    /// ```
    pub fn covariance(&self) -> Option<DMatrix<f64>> {
        let p = self.dim();
        self.covariance_of(&DMatrix::identity(p, p))
    }

    /// The covariance of `J x`: `J C Jᵀ` for the estimate's covariance `C`
    /// ([`covariance`](Self::covariance)), without forming `C`.
    ///
    /// ```
    /// use nalgebra::DMatrix;
    /// use seqsmooth::recursive::InformationFilter;
    /// let mut f = InformationFilter::new(2);
    /// f.observe(&[1.0, 0.0], 0.0, 1.0);
    /// f.observe(&[0.0, 1.0], 0.0, 1.0);
    /// let c = f.covariance_of(&DMatrix::from_row_slice(1, 2, &[1.0, 1.0])).unwrap();
    /// assert!((c[(0, 0)] - 2.0).abs() < 1e-15);
    /// ```
    pub fn covariance_of(&self, j: &DMatrix<f64>) -> Option<DMatrix<f64>> {
        let jr = self.right_divide(j)?;
        match &self.spread {
            None => Some(&jr * jr.transpose() * (self.scale * self.scale)),
            Some(q) => {
                // K = J (RᵀR)⁻¹, Kᵀ = R⁻¹ (J R⁻¹)ᵀ; the covariance is K QᵀQ Kᵀ. The lazy
                // scale cancels: R and Q are stored times s and s².
                let mut kt = jr.transpose();
                let r = self.info.r();
                let mut c = vec![0.0; r.nrows()];
                for mut col in kt.column_iter_mut() {
                    c.iter_mut().zip(col.iter()).for_each(|(a, b)| *a = *b);
                    if !solve_upper_in_place(&r, &mut c) {
                        return None;
                    }
                    col.copy_from_slice(&c);
                }
                let qk = q.r() * kt;
                Some(qk.transpose() * qk)
            }
        }
    }
}

impl InformationFilter {
    /// The filter of the first `q` state components alone, into `out` (dimension `q`, smaller
    /// than this one's): the leading blocks of `R` and of the true covariance's `Q`
    /// ([`TriangularFactor::leading_into`]), and the lazy discount's scale. Where the rows
    /// `h_k` of this filter extend those of a smaller model by further columns (a polynomial of
    /// degree `m + 1` and one of degree `m` on the same samples and weights), `out` is that
    /// model's filter: the same discounted least squares (14.3.11)-(14.3.13) restricted to
    /// its columns. `false` (and `out` untouched) unless `out` is smaller and keeps the true
    /// covariance exactly when this one does.
    ///
    /// ```
    /// use seqsmooth::recursive::InformationFilter;
    /// let mut line = InformationFilter::new(2).with_true_covariance();
    /// let mut constant = InformationFilter::new(1).with_true_covariance();
    /// for (u, y) in [(0.0, 1.0), (1.0, 3.0), (2.0, 2.0)] {
    ///     for f in [&mut line, &mut constant] {
    ///         f.fade(2.0);
    ///     }
    ///     line.observe_powers(u, y, 1.0);
    ///     constant.observe_powers(u, y, 1.0);
    /// }
    /// let mut lead = InformationFilter::new(1).with_true_covariance();
    /// assert!(line.leading_into(&mut lead));
    /// let (a, b) = (lead.solve().unwrap()[0], constant.solve().unwrap()[0]);
    /// assert!((a - b).abs() < 1e-14);
    /// let (va, vb) = (lead.covariance().unwrap()[(0, 0)], constant.covariance().unwrap()[(0, 0)]);
    /// assert!((va - vb).abs() < 1e-14);
    /// ```
    pub fn leading_into(&self, out: &mut InformationFilter) -> bool {
        if out.dim() >= self.dim() || out.spread.is_some() != self.spread.is_some() {
            return false;
        }
        if let (Some(q), Some(lead)) = (&self.spread, &mut out.spread) {
            q.leading_into(lead);
        }
        self.info.leading_into(&mut out.info);
        out.scale = self.scale;
        true
    }
}

impl InformationFilter {
    /// The invariants of a restored filter ([`crate::persist`]): its factors valid and of one
    /// dimension, the discount's scale finite and positive.
    pub(crate) fn check_saved(&self) -> Result<(), String> {
        self.info.check_saved()?;
        if let Some(s) = &self.spread {
            s.check_saved()?;
            if s.dim() != self.info.dim() {
                return Err("information filter's factors differ in dimension".into());
            }
        }
        if !(self.scale.is_finite() && self.scale > 0.0) {
            return Err(format!(
                "information filter's scale {} is not positive",
                self.scale
            ));
        }
        Ok(())
    }
}

/// `v − c·e`: one fused multiply-add with `FUSED`, else the product rounded, then the
/// difference ([`InformationFilter::variances_of_upper_rows`]).
#[inline(always)]
fn sub_mul<const FUSED: bool>(v: f64, c: f64, e: f64) -> f64 {
    if FUSED {
        (-c).mul_add(e, v)
    } else {
        v - c * e
    }
}

/// `s + a·b`: one fused multiply-add with `FUSED`, else the product rounded, then the sum.
#[inline(always)]
fn add_mul<const FUSED: bool>(s: f64, a: f64, b: f64) -> f64 {
    if FUSED {
        a.mul_add(b, s)
    } else {
        s + a * b
    }
}
