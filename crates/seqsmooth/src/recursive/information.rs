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
        debug_assert_eq!(a.len(), p);
        let sw = weight.sqrt();
        self.scratch.clear();
        self.scratch.extend(a.iter().map(|v| v * sw));
        let mut y = b * sw;
        for i in 0..p {
            let ai = self.scratch[i];
            if ai == 0.0 {
                continue;
            }
            let rii = self.r[(i, i)];
            let h = rii.hypot(ai);
            let c = rii / h;
            let s = ai / h;
            self.r[(i, i)] = h;
            self.scratch[i] = 0.0;
            for j in i + 1..p {
                let rij = self.r[(i, j)];
                let aj = self.scratch[j];
                self.r[(i, j)] = c * rij + s * aj;
                self.scratch[j] = c * aj - s * rij;
            }
            let di = self.rhs[i];
            self.rhs[i] = c * di + s * y;
            y = c * y - s * di;
        }
        self.residual_sq += y * y;
    }

    /// Multiplies the accumulated Gram matrix by `f ≥ 0` (a fading-memory discount).
    pub fn discount(&mut self, f: f64) {
        let s = f.sqrt();
        self.r *= s;
        self.rhs *= s;
        self.residual_sq *= f;
    }

    /// Change of variables `x_old = A x_new`: `R ← R A`. When `A` is upper triangular the result
    /// stays triangular (the polynomial re-centring case); otherwise it is re-triangularised by
    /// a Householder QR of `[R A | d]`.
    pub fn change_variables(&mut self, a: &DMatrix<f64>) {
        let p = self.dim();
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

    /// Re-expresses the state in new variables, `x_old = A x_new`.
    pub fn change_variables(&mut self, a: &DMatrix<f64>) {
        self.info.change_variables(a);
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
