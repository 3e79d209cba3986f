use crate::linalg::{solve_upper_in_place, solve_upper_transpose_in_place};
use nalgebra::{DMatrix, DVector};

/// An upper-triangular factor `R` of an accumulated Gram matrix `RᵀR = Σ_k c_k a_k a_kᵀ`, kept
/// up to date row by row with Givens rotations, with an optional right-hand column.
///
/// ```
/// use seqsmooth::recursive::TriangularFactor;
/// let mut f = TriangularFactor::new(2);
/// f.add_row(&[1.0, 0.0], 0.0, 4.0);
/// f.add_row(&[1.0, 1.0], 0.0, 1.0);
/// let g = f.gram();
/// assert!((g[(0, 0)] - 5.0).abs() < 1e-12 && (g[(1, 1)] - 1.0).abs() < 1e-12);
/// ```
#[derive(Clone, Debug)]
pub struct TriangularFactor {
    r: DMatrix<f64>,
    rhs: DVector<f64>,
    residual_sq: f64,
    scratch: Vec<f64>,
}

impl TriangularFactor {
    /// The zero factor of dimension `p`.
    pub fn new(p: usize) -> Self {
        Self {
            r: DMatrix::zeros(p, p),
            rhs: DVector::zeros(p),
            residual_sq: 0.0,
            scratch: vec![0.0; p],
        }
    }

    /// Dimension `p`.
    pub fn dim(&self) -> usize {
        self.rhs.len()
    }

    /// The factor `R`.
    pub fn r(&self) -> &DMatrix<f64> {
        &self.r
    }

    /// The right-hand vector `d` (`Rᵀd = Σ c_k a_k b_k`).
    pub fn rhs(&self) -> &DVector<f64> {
        &self.rhs
    }

    /// The part of `Σ c_k b_k²` that no linear combination of the rows explains: the (weighted)
    /// residual sum of squares of the least-squares fit.
    pub fn residual_sq(&self) -> f64 {
        self.residual_sq
    }

    /// `RᵀR`.
    pub fn gram(&self) -> DMatrix<f64> {
        self.r.transpose() * &self.r
    }

    /// Folds the row `√c·[a | b]` into `[R | d]` by Givens rotations: `O(p²)`.
    pub fn add_row(&mut self, a: &[f64], b: f64, weight: f64) {
        let p = self.dim();
        assert_eq!(a.len(), p, "row of the wrong length");
        let sw = if weight == 1.0 { 1.0 } else { weight.sqrt() };
        // Fixed sizes unroll completely (the polynomial filters' common degrees).
        match p {
            1 => self.add_row_n::<1>(a, b, sw),
            2 => self.add_row_n::<2>(a, b, sw),
            3 => self.add_row_n::<3>(a, b, sw),
            4 => self.add_row_n::<4>(a, b, sw),
            5 => self.add_row_n::<5>(a, b, sw),
            6 => self.add_row_n::<6>(a, b, sw),
            7 => self.add_row_n::<7>(a, b, sw),
            8 => self.add_row_n::<8>(a, b, sw),
            9 => self.add_row_n::<9>(a, b, sw),
            _ => self.add_row_any(a, b, sw),
        }
    }

    #[inline(always)]
    fn add_row_n<const N: usize>(&mut self, a: &[f64], b: f64, sw: f64) {
        let mut row = [0.0; N];
        for (v, x) in row.iter_mut().zip(a) {
            *v = x * sw;
        }
        let mut y = b * sw;
        // `R` is column-major: entry (i, j) at `i + j·N`.
        let r: &mut [f64] = &mut self.r.as_mut_slice()[..N * N];
        let rhs: &mut [f64] = &mut self.rhs.as_mut_slice()[..N];
        for i in 0..N {
            let ai = row[i];
            let rii = r[i + i * N];
            let h = rotation_norm(rii, ai);
            // ai = 0 leaves the row as it is (c = 1, s = 0), also when R_ii = 0.
            let (c, s) = if ai != 0.0 {
                (rii / h, ai / h)
            } else {
                (1.0, 0.0)
            };
            r[i + i * N] = if ai != 0.0 { h } else { rii };
            for j in i + 1..N {
                let rij = r[i + j * N];
                let aj = row[j];
                r[i + j * N] = c * rij + s * aj;
                row[j] = c * aj - s * rij;
            }
            let di = rhs[i];
            rhs[i] = c * di + s * y;
            y = c * y - s * di;
        }
        self.residual_sq += y * y;
    }

    fn add_row_any(&mut self, a: &[f64], b: f64, sw: f64) {
        let p = self.dim();
        self.scratch.clear();
        self.scratch.extend(a.iter().map(|v| v * sw));
        let mut y = b * sw;
        // `R` is column-major: entry (i, j) at `i + j·p`.
        let r = self.r.as_mut_slice();
        let rhs = self.rhs.as_mut_slice();
        let row = &mut self.scratch[..p];
        for i in 0..p {
            let ai = row[i];
            if ai == 0.0 {
                continue;
            }
            let rii = r[i + i * p];
            let h = rotation_norm(rii, ai);
            let c = rii / h;
            let s = ai / h;
            r[i + i * p] = h;
            row[i] = 0.0;
            for j in i + 1..p {
                let rij = r[i + j * p];
                let aj = row[j];
                r[i + j * p] = c * rij + s * aj;
                row[j] = c * aj - s * rij;
            }
            let di = rhs[i];
            rhs[i] = c * di + s * y;
            y = c * y - s * di;
        }
        self.residual_sq += y * y;
    }

    /// Multiplies the accumulated Gram matrix by `f ≥ 0` (a fading-memory discount).
    pub fn discount(&mut self, f: f64) {
        self.discount_root(f.sqrt());
    }

    /// [`discount`](Self::discount) by `f = s²`, given `s ≥ 0` (saves the square root when the
    /// caller caches it).
    pub fn discount_root(&mut self, s: f64) {
        self.r.as_mut_slice().iter_mut().for_each(|v| *v *= s);
        self.rhs.as_mut_slice().iter_mut().for_each(|v| *v *= s);
        self.residual_sq *= s * s;
    }

    /// [`change_variables`](Self::change_variables) for an upper-triangular `A` (only its upper
    /// triangle is read): `R ← R A` in place, row by row from the right (entry `(i, j)` needs
    /// `R_ik` for `i ≤ k ≤ j`, still the old values), `O(p³/6)`, no allocation.
    pub fn change_variables_upper(&mut self, a: &DMatrix<f64>) {
        let p = self.dim();
        assert_eq!(a.shape(), (p, p), "change of variables of the wrong size");
        let a = a.as_slice();
        let r = self.r.as_mut_slice();
        for i in 0..p {
            for j in (i..p).rev() {
                let mut acc = 0.0;
                for k in i..=j {
                    acc += r[i + k * p] * a[k + j * p];
                }
                r[i + j * p] = acc;
            }
        }
    }

    /// Change of variables `x_old = A x_new`: `R ← R A`. When `A` is upper triangular the result
    /// stays triangular (the polynomial re-centring case); otherwise it is re-triangularised by
    /// a Householder QR of `[R A | d]`.
    pub fn change_variables(&mut self, a: &DMatrix<f64>) {
        let p = self.dim();
        if (0..p).all(|i| (0..i).all(|j| a[(i, j)] == 0.0)) {
            self.change_variables_upper(a);
            return;
        }
        let ra = &self.r * a;
        let upper = (0..p).all(|i| (0..i).all(|j| ra[(i, j)] == 0.0));
        if upper {
            self.r = ra;
            return;
        }
        let mut aug = DMatrix::zeros(p, p + 1);
        aug.view_mut((0, 0), (p, p)).copy_from(&ra);
        aug.set_column(p, &self.rhs);
        let qr = aug.qr();
        let r = qr.r();
        self.r = r.view((0, 0), (p, p)).into_owned();
        self.rhs = r.column(p).into_owned();
        for i in 0..p {
            for j in 0..i {
                self.r[(i, j)] = 0.0;
            }
        }
    }
}

/// `√(a² + b²)` for a Givens rotation: the plain formula (a few times faster than `hypot`),
/// falling back to `hypot` when the squares overflow or underflow.
#[inline]
fn rotation_norm(a: f64, b: f64) -> f64 {
    let h = (a * a + b * b).sqrt();
    if h.is_finite() && h > 1e-150 {
        h
    } else {
        a.hypot(b)
    }
}

/// The square-root information filter (see the [module docs](crate::recursive)): estimate
/// `x = R⁻¹d` of a linear model observed through rows `y_k = h_kᵀ x + ν_k` with weights `w_k`.
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
#[derive(Clone, Debug)]
pub struct InformationFilter {
    info: TriangularFactor,
}

impl InformationFilter {
    /// A filter for a `p`-dimensional state with no prior information.
    pub fn new(p: usize) -> Self {
        Self {
            info: TriangularFactor::new(p),
        }
    }

    /// A Bayes filter with prior estimate `mean` and prior information factor `r_prior`
    /// (`r_priorᵀ r_prior` = inverse prior covariance; upper triangular).
    pub fn with_prior(mean: &DVector<f64>, r_prior: &DMatrix<f64>) -> Self {
        let p = mean.len();
        let mut info = TriangularFactor::new(p);
        info.r = r_prior.clone();
        info.rhs = r_prior * mean;
        Self { info }
    }

    /// State dimension.
    pub fn dim(&self) -> usize {
        self.info.dim()
    }

    /// The square-root information factor.
    pub fn factor(&self) -> &TriangularFactor {
        &self.info
    }

    /// Folds in the observation `y = hᵀx + ν` with weight `w` (`1/σ²` for minimum variance).
    pub fn observe(&mut self, h: &[f64], y: f64, weight: f64) {
        self.info.add_row(h, y, weight);
    }

    /// Discounts all information so far by the factor `f ∈ (0, 1]` (fading memory,
    /// Morrison ch. 13-14: old observations weigh `f` times less).
    pub fn discount(&mut self, f: f64) {
        self.info.discount(f);
    }

    /// [`discount`](Self::discount) by `f = s²`, given `s`.
    pub fn discount_root(&mut self, s: f64) {
        self.info.discount_root(s);
    }

    /// Re-expresses the state in new variables, `x_old = A x_new`.
    pub fn change_variables(&mut self, a: &DMatrix<f64>) {
        self.info.change_variables(a);
    }

    /// [`change_variables`](Self::change_variables) for an upper-triangular `A`.
    pub fn change_variables_upper(&mut self, a: &DMatrix<f64>) {
        self.info.change_variables_upper(a);
    }

    /// True when every diagonal entry of `R` is non-zero (the state is determined).
    pub fn is_determined(&self) -> bool {
        (0..self.dim()).all(|i| self.info.r[(i, i)] != 0.0)
    }

    /// The estimate `R⁻¹ d`, or `None` while the state is not determined.
    pub fn solve(&self) -> Option<DVector<f64>> {
        let mut x: Vec<f64> = self.info.rhs.iter().copied().collect();
        solve_upper_in_place(&self.info.r, &mut x).then(|| DVector::from_vec(x))
    }

    /// `J R⁻¹` for a given `J` (rows are linear functionals of the state): the building block of
    /// covariances `J (RᵀR)⁻¹ Jᵀ = (J R⁻¹)(J R⁻¹)ᵀ`.
    pub fn right_divide(&self, j: &DMatrix<f64>) -> Option<DMatrix<f64>> {
        let p = self.dim();
        let mut out = DMatrix::zeros(j.nrows(), p);
        let mut row = vec![0.0; p];
        for r in 0..j.nrows() {
            for (c, v) in row.iter_mut().enumerate() {
                *v = j[(r, c)];
            }
            // (J R⁻¹)ᵀ = R⁻ᵀ Jᵀ: forward substitution with Rᵀ.
            if !solve_upper_transpose_in_place(&self.info.r, &mut row) {
                return None;
            }
            for (c, v) in row.iter().enumerate() {
                out[(r, c)] = *v;
            }
        }
        Some(out)
    }

    /// Covariance `(RᵀR)⁻¹` of the estimate when the weights are inverse variances.
    pub fn covariance(&self) -> Option<DMatrix<f64>> {
        let p = self.dim();
        let ri = self.right_divide(&DMatrix::identity(p, p))?;
        Some(&ri * ri.transpose())
    }
}
