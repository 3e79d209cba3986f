use crate::linalg::solve_upper_transpose_in_place;
use nalgebra::{DMatrix, DVector};

/// An upper-triangular factor `R` of an accumulated Gram matrix `RᵀR = Σ_k c_k a_k a_kᵀ`, kept
/// up to date row by row, with a right-hand column `d` (`Rᵀd = Σ_k c_k a_k b_k`).
///
/// Stored in Gentleman's square-root-free form (W. M. Gentleman, *Least squares computations by
/// Givens transformations without square roots*, 1973): `R = D^½ U` and `d = D^½ ū` with `U`
/// unit upper triangular and `D ≥ 0` diagonal. A new row is folded in by the square-root-free
/// Givens rotations: per pivot `i`, `d_i' = d_i + δ a_i²`, `c̄ = d_i/d_i'`, `s̄ = δ a_i/d_i'`,
/// `a_j ← a_j − a_i u_ij`, `u_ij ← c̄ u_ij + s̄ a_j`, `δ ← δ c̄` (a zero pivot `d_i' = 0` leaves
/// everything as it is) — the same orthogonal
/// transformations as with square roots, without them, and with the next pivot's row entry
/// only a multiply-subtract away (a shorter dependency chain). A discount scales `D` alone.
///
/// ```
/// use seqsmooth::recursive::TriangularFactor;
/// let mut f = TriangularFactor::new(2);
/// f.add_row(&[1.0, 0.0], 0.0, 4.0);
/// f.add_row(&[1.0, 1.0], 0.0, 1.0);
/// let g = f.gram();
/// assert!((g[(0, 0)] - 5.0).abs() < 1e-12 && (g[(1, 1)] - 1.0).abs() < 1e-12);
/// let r = f.r(); // upper triangular with RᵀR = the Gram matrix
/// assert!((r[(0, 0)] - 5f64.sqrt()).abs() < 1e-12 && r[(1, 0)] == 0.0);
/// ```
#[derive(Clone, Debug)]
pub struct TriangularFactor {
    /// `D`, the squares of `R`'s diagonal.
    d: Vec<f64>,
    /// `U`, unit upper triangular, row-major (`u[i·p + j]`, `j > i`; the rest unused).
    u: Vec<f64>,
    /// `ū = D^-½ d`.
    ubar: Vec<f64>,
    residual_sq: f64,
    scratch: Vec<f64>,
}

impl TriangularFactor {
    /// The zero factor of dimension `p`.
    pub fn new(p: usize) -> Self {
        Self {
            d: vec![0.0; p],
            u: vec![0.0; p * p],
            ubar: vec![0.0; p],
            residual_sq: 0.0,
            scratch: vec![0.0; p],
        }
    }

    /// The factor of a given upper-triangular `R` and right-hand side `rhs` (rows of `R` with a
    /// zero diagonal carry no information and must be zero).
    pub fn from_r(r: &DMatrix<f64>, rhs: &DVector<f64>) -> Self {
        let p = rhs.len();
        let mut f = Self::new(p);
        for i in 0..p {
            let rii = r[(i, i)];
            if rii == 0.0 {
                continue;
            }
            f.d[i] = rii * rii;
            f.ubar[i] = rhs[i] / rii;
            for j in i + 1..p {
                f.u[i * p + j] = r[(i, j)] / rii;
            }
        }
        f
    }

    /// Dimension `p`.
    pub fn dim(&self) -> usize {
        self.d.len()
    }

    /// The factor `R = D^½ U` (computed).
    pub fn r(&self) -> DMatrix<f64> {
        let p = self.dim();
        DMatrix::from_fn(p, p, |i, j| {
            let s = self.d[i].sqrt();
            match j.cmp(&i) {
                std::cmp::Ordering::Less => 0.0,
                std::cmp::Ordering::Equal => s,
                std::cmp::Ordering::Greater => s * self.u[i * p + j],
            }
        })
    }

    /// The right-hand vector `d = D^½ ū` (`Rᵀd = Σ c_k a_k b_k`; computed).
    pub fn rhs(&self) -> DVector<f64> {
        DVector::from_iterator(
            self.dim(),
            self.d.iter().zip(&self.ubar).map(|(d, u)| d.sqrt() * u),
        )
    }

    /// The part of `Σ c_k b_k²` that no linear combination of the rows explains: the (weighted)
    /// residual sum of squares of the least-squares fit.
    pub fn residual_sq(&self) -> f64 {
        self.residual_sq
    }

    /// `RᵀR = UᵀDU`.
    pub fn gram(&self) -> DMatrix<f64> {
        let r = self.r();
        r.transpose() * &r
    }

    /// True when every diagonal entry of `R` is non-zero.
    pub fn is_determined(&self) -> bool {
        self.d.iter().all(|&d| d > 0.0)
    }

    /// Solves `R x = d` into `x` (`U x = ū`, no divisions); false while not determined.
    pub fn solve_into(&self, x: &mut [f64]) -> bool {
        match self.dim() {
            1 => self.solve_n::<1>(x),
            2 => self.solve_n::<2>(x),
            3 => self.solve_n::<3>(x),
            4 => self.solve_n::<4>(x),
            5 => self.solve_n::<5>(x),
            6 => self.solve_n::<6>(x),
            7 => self.solve_n::<7>(x),
            8 => self.solve_n::<8>(x),
            9 => self.solve_n::<9>(x),
            p => self.solve_any(p, x),
        }
    }

    #[inline(always)]
    fn solve_n<const N: usize>(&self, x: &mut [f64]) -> bool {
        self.solve_any(N, x)
    }

    #[inline(always)]
    fn solve_any(&self, p: usize, x: &mut [f64]) -> bool {
        if !self.d[..p].iter().all(|&v| v > 0.0) {
            return false;
        }
        let u: &[f64] = &self.u[..p * p];
        let ubar: &[f64] = &self.ubar[..p];
        let x: &mut [f64] = &mut x[..p];
        for i in (0..p).rev() {
            let mut s = ubar[i];
            for (uij, xj) in u[i * p + i + 1..(i + 1) * p].iter().zip(&x[i + 1..]) {
                s -= uij * xj;
            }
            x[i] = s;
        }
        true
    }

    /// Folds the row `√c·[a | b]` into `[R | d]`: `O(p²)`, no square roots.
    pub fn add_row(&mut self, a: &[f64], b: f64, weight: f64) {
        let p = self.dim();
        assert_eq!(a.len(), p, "row of the wrong length");
        // Fixed sizes unroll completely (the polynomial filters' common degrees).
        match p {
            1 => self.add_row_n::<1>(a, b, weight),
            2 => self.add_row_n::<2>(a, b, weight),
            3 => self.add_row_n::<3>(a, b, weight),
            4 => self.add_row_n::<4>(a, b, weight),
            5 => self.add_row_n::<5>(a, b, weight),
            6 => self.add_row_n::<6>(a, b, weight),
            7 => self.add_row_n::<7>(a, b, weight),
            8 => self.add_row_n::<8>(a, b, weight),
            9 => self.add_row_n::<9>(a, b, weight),
            _ => self.add_row_any(a, b, weight),
        }
    }

    #[inline(always)]
    fn add_row_n<const N: usize>(&mut self, a: &[f64], b: f64, weight: f64) {
        let mut x = [0.0; N];
        x.copy_from_slice(&a[..N]);
        let mut y = b;
        let mut delta = weight;
        let d: &mut [f64] = &mut self.d[..N];
        let u: &mut [f64] = &mut self.u[..N * N];
        let ubar: &mut [f64] = &mut self.ubar[..N];
        for i in 0..N {
            let xi = x[i];
            let dx = delta * xi;
            let dp = d[i] + dx * xi;
            // A zero pivot (no information yet and a zero entry) leaves everything as it is.
            let (cbar, sbar) = if dp > 0.0 {
                (d[i] / dp, dx / dp)
            } else {
                (1.0, 0.0)
            };
            delta *= cbar;
            d[i] = dp;
            for j in i + 1..N {
                let xj = x[j];
                let uij = u[i * N + j];
                x[j] = xj - xi * uij;
                u[i * N + j] = cbar * uij + sbar * xj;
            }
            let ui = ubar[i];
            ubar[i] = cbar * ui + sbar * y;
            y -= xi * ui;
        }
        self.residual_sq += delta * y * y;
    }

    fn add_row_any(&mut self, a: &[f64], b: f64, weight: f64) {
        let p = self.dim();
        self.scratch.clear();
        self.scratch.extend_from_slice(a);
        let x = &mut self.scratch[..p];
        let mut y = b;
        let mut delta = weight;
        for i in 0..p {
            let xi = x[i];
            let dx = delta * xi;
            let dp = self.d[i] + dx * xi;
            let (cbar, sbar) = if dp > 0.0 {
                (self.d[i] / dp, dx / dp)
            } else {
                (1.0, 0.0)
            };
            delta *= cbar;
            self.d[i] = dp;
            let row = &mut self.u[i * p + i + 1..(i + 1) * p];
            for (xj, uij) in x[i + 1..p].iter_mut().zip(row.iter_mut()) {
                let (a, u) = (*xj, *uij);
                *xj = a - xi * u;
                *uij = cbar * u + sbar * a;
            }
            let ui = self.ubar[i];
            self.ubar[i] = cbar * ui + sbar * y;
            y -= xi * ui;
        }
        self.residual_sq += delta * y * y;
    }

    /// Multiplies the accumulated Gram matrix by `f ≥ 0` (a fading-memory discount): `D ← fD`.
    pub fn discount(&mut self, f: f64) {
        self.d.iter_mut().for_each(|v| *v *= f);
        self.residual_sq *= f;
    }

    /// [`discount`](Self::discount) by `f = s²`, given `s ≥ 0`.
    pub fn discount_root(&mut self, s: f64) {
        self.discount(s * s);
    }

    /// [`change_variables`](Self::change_variables) for an upper-triangular `A` with a positive
    /// or negative (non-zero) diagonal (only its upper triangle is read): `U ← diag(A)⁻¹ U A`,
    /// `D ← D diag(A)²`, `ū ← diag(A)⁻¹ ū`, in place, `O(p³/6)`, no allocation.
    pub fn change_variables_upper(&mut self, a: &DMatrix<f64>) {
        let p = self.dim();
        assert_eq!(a.shape(), (p, p), "change of variables of the wrong size");
        let a = a.as_slice();
        for i in 0..p {
            // Row i of U A from the right (entry (i, j) needs U_ik for i ≤ k ≤ j, still old;
            // U_ii = 1).
            let aii = a[i + i * p];
            for j in (i + 1..p).rev() {
                let mut acc = a[i + j * p];
                for k in i + 1..=j {
                    acc += self.u[i * p + k] * a[k + j * p];
                }
                self.u[i * p + j] = acc / aii;
            }
            self.d[i] *= aii * aii;
            self.ubar[i] /= aii;
        }
    }

    /// Change of variables `x_old = A x_new`: `R ← R A`. When `A` is upper triangular the result
    /// stays triangular (the polynomial re-centring case); otherwise it is re-triangularised by
    /// a Householder QR of `[R A | d]`.
    pub fn change_variables(&mut self, a: &DMatrix<f64>) {
        let p = self.dim();
        if (0..p).all(|i| (0..i).all(|j| a[(i, j)] == 0.0) && a[(i, i)] != 0.0) {
            self.change_variables_upper(a);
            return;
        }
        let ra = self.r() * a;
        let mut aug = DMatrix::zeros(p, p + 1);
        aug.view_mut((0, 0), (p, p)).copy_from(&ra);
        aug.set_column(p, &self.rhs());
        let qr = aug.qr();
        let r = qr.r();
        let mut rr: DMatrix<f64> = r.view((0, 0), (p, p)).into_owned();
        for i in 0..p {
            for j in 0..i {
                rr[(i, j)] = 0.0;
            }
        }
        let residual = self.residual_sq;
        *self = Self::from_r(&rr, &r.column(p).into_owned());
        self.residual_sq = residual;
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
        Self {
            info: TriangularFactor::from_r(r_prior, &(r_prior * mean)),
        }
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
        self.info.is_determined()
    }

    /// The estimate `R⁻¹ d`, or `None` while the state is not determined.
    pub fn solve(&self) -> Option<DVector<f64>> {
        let mut x = vec![0.0; self.dim()];
        self.info.solve_into(&mut x).then(|| DVector::from_vec(x))
    }

    /// `J R⁻¹` for a given `J` (rows are linear functionals of the state): the building block of
    /// covariances `J (RᵀR)⁻¹ Jᵀ = (J R⁻¹)(J R⁻¹)ᵀ`.
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

    /// Covariance `(RᵀR)⁻¹` of the estimate when the weights are inverse variances.
    pub fn covariance(&self) -> Option<DMatrix<f64>> {
        let p = self.dim();
        let ri = self.right_divide(&DMatrix::identity(p, p))?;
        Some(&ri * ri.transpose())
    }
}
