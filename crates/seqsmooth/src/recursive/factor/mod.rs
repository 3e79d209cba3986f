use crate::numeric::inline::InlineVec;
use crate::numeric::unrolled::{each_index, unrolled_sizes, Size};
use nalgebra::{DMatrix, DVector};

/// The largest dimension whose factor is stored inline ([`InlineVec`]): a copy of it allocates
/// nothing (the automatic filter copies its filters' state, degree `m + 1 ≤ 4` for its
/// companions, where a decision may go back).
const INLINE_P: usize = 5;

/// An upper-triangular factor `R` of an accumulated Gram matrix `RᵀR = Σ_k c_k a_k a_kᵀ`, kept
/// up to date row by row, with a right-hand column `d` (`Rᵀd = Σ_k c_k a_k b_k`).
///
/// Stored in Gentleman's square-root-free form (W. M. Gentleman, *Least squares computations by
/// Givens transformations without square roots*, J. Inst. Maths Applics 12, 329–336, 1973):
/// `R = D^½ U` and `d = D^½ ū` with `U` unit upper triangular and `D ≥ 0` diagonal. A row `a`
/// with weight `δ_0 = c` is folded in by the square-root-free Givens rotations: per pivot
/// `i = 0, 1, …`, with `x_i` the row's entry `i` after the previous pivots,
///
/// `d_i' = d_i + δ_i x_i²`, `c̄_i = d_i/d_i'`, `s̄_i = δ_i x_i/d_i'`, `δ_(i+1) = δ_i c̄_i`,
/// `x_j ← x_j − x_i u_ij`, `u_ij ← c̄_i u_ij + s̄_i x_j` (`j > i`, old `x_j` and `u_ij`),
///
/// and likewise for `b` against `ū`; finally the residual sum of squares grows by
/// `δ_p b_p²` (`b_p`: `b` after all pivots). A zero pivot `d_i' = 0` leaves everything as it
/// is. These are the same orthogonal transformations as with square roots, without them. A
/// discount scales `D` alone.
///
/// Written that way each pivot waits for the previous one's two divisions. But the row entries
/// `x_i` do not depend on the weights (`x = U⁻ᵀ a`, a forward substitution with the old `U`),
/// and when every `d_i > 0` the reciprocal weights `η_i = 1/δ_i` obey
/// `η_(i+1) = η_i + x_i²/d_i` (from `δ_(i+1) = δ_i d_i/(d_i + δ_i x_i²)`): a prefix sum of
/// non-negative terms, `η_0 = 1/c`. With `δ_(i+1) = 1/η_(i+1)`,
///
/// `d_i' = d_i + δ_i x_i²`, `s̄_i = δ_(i+1) x_i/d_i` (`= δ_i x_i/d_i'`),
/// `u_ij ← u_ij + s̄_i x_j'`, `ū_i ← ū_i + s̄_i b'`,
///
/// where `x_j' = x_j − x_i u_ij` and `b'` are the entries after pivot `i` (the same update, as
/// `c̄_i = 1 − s̄_i x_i`). The row then costs `2p+1` divisions (`1/d_i`, `1/c`, `1/η_(i+1)`)
/// of which none waits for another, instead of a chain of `2p`, and one multiplication fewer
/// per entry. The old `u_ij` is kept and only the increment rounded: when the row adds little
/// to much information (`c̄ ≈ 1`, a long memory) that is about `ε|u'|` per row against several
/// `ε|u|` in the first form (`c̄` itself, its product, the sum), and for any `c̄` within a few
/// `ε(|u| + |u'| + s̄|x_j|)`. This form is used whenever every `d_i` and the weight are normal
/// positive numbers (from the first `p` independent rows on); Gentleman's sequential form
/// otherwise.
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
#[derive(Debug, serde::Serialize, serde::Deserialize)]
pub struct TriangularFactor {
    /// `D`, the squares of `R`'s diagonal, each in its own 16-byte slot ([`Pivot`]).
    d: InlineVec<Pivot, INLINE_P>,
    /// `U`, unit upper triangular, row-major (`u[i·p + j]`, `j > i`; the rest unused).
    u: InlineVec<f64, { INLINE_P * INLINE_P }>,
    /// `ū = D^-½ d`.
    ubar: InlineVec<f64, INLINE_P>,
    residual_sq: f64,
    /// Every `d_i` is a normal positive number (the rows' reciprocal form applies).
    positive: bool,
    scratch: Vec<f64>,
}

// Field by field, `clone_from` too (the automatic filter's review keeps copies of it).
field_clone! { TriangularFactor { d, u, ubar, residual_sq, positive, scratch } }

/// A pivot `d_i` alone in a 16-byte slot, so that no two pivots share a (vectorised) load or
/// store. In the reciprocal form of [`TriangularFactor::add_row`] the next row's `1/d_i` is
/// the first thing it computes, while `d_(i+1)` is updated only after `δ_(i+1) = 1/η_(i+1)`,
/// which depends on `1/d_i`: stored as one pair, `d_i` would wait for `d_(i+1)` and every row
/// for two divisions of the previous one (measured: see BENCHMARKS.md). And a
/// 16-byte load spanning two 8-byte stores cannot be forwarded from the store buffer.
#[derive(Clone, Copy, Debug, Default, serde::Serialize, serde::Deserialize)]
#[repr(align(16))]
struct Pivot(f64);

impl TriangularFactor {
    /// The zero factor of dimension `p`.
    pub fn new(p: usize) -> Self {
        Self {
            d: InlineVec::filled(Pivot(0.0), p),
            u: InlineVec::filled(0.0, p * p),
            ubar: InlineVec::filled(0.0, p),
            residual_sq: 0.0,
            positive: p == 0,
            // Grown on first use, by the sizes without unrolled code only.
            scratch: Vec::new(),
        }
    }

    /// Recomputes [`positive`](Self::positive) after `d` changed other than by a row in the
    /// reciprocal form (which only increases `d`).
    fn refresh_positive(&mut self) {
        self.positive = self.d.iter().all(|v| v.0 >= f64::MIN_POSITIVE);
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
            f.d[i].0 = rii * rii;
            f.ubar[i] = rhs[i] / rii;
            for j in i + 1..p {
                f.u[i * p + j] = r[(i, j)] / rii;
            }
        }
        f.refresh_positive();
        f
    }

    /// Dimension `p`.
    pub fn dim(&self) -> usize {
        self.d.len()
    }

    /// `1/√d_i` for every pivot into `out`, or `false` when a pivot is not positive (the factor
    /// does not determine the state): the one set of square roots and divisions that
    /// [`Self::right_divide_row`] and [`Self::left_solve`] share across rows. `size` is the
    /// dimension (a [`Fixed`](crate::numeric::unrolled::Fixed) one unrolls the loop).
    #[inline(always)]
    pub(crate) fn inverse_sqrt_pivots(&self, size: impl Size, out: &mut [f64]) -> bool {
        for (o, d) in out[..size.get()].iter_mut().zip(&self.d[..size.get()]) {
            // NaN fails too.
            if d.0.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                return false;
            }
            *o = 1.0 / d.0.sqrt();
        }
        true
    }

    /// `1/d_i` for every pivot into `out`, or `false` when a pivot is not positive (the factor
    /// does not determine the state); no square roots, the divisions independent of each other.
    #[inline(always)]
    pub(crate) fn inverse_pivots(&self, out: &mut [f64]) -> bool {
        let mut ok = true;
        for (o, d) in out.iter_mut().zip(&self.d) {
            // NaN fails too; no early exit, so that the divisions overlap.
            ok &= d.0 > 0.0;
            *o = 1.0 / d.0;
        }
        ok
    }

    /// The pivots `d_i` (`D`) into `out`.
    #[inline(always)]
    pub(crate) fn pivots_into(&self, out: &mut [f64]) {
        for (o, d) in out.iter_mut().zip(&self.d) {
            *o = d.0;
        }
    }

    /// The first `p²` entries of `U`, row-major: `u[i·p + j]` for `j > i` (the unit diagonal
    /// and the zeros below it are not stored there), `p` the dimension.
    #[inline(always)]
    pub(crate) fn unit_triangle(&self, p: usize) -> &[f64] {
        &self.u[..p * p]
    }

    /// `x ← D^-½ U⁻ᵀ x`, i.e. `(x R⁻¹)ᵀ` for a row `x` (forward substitution with the unit
    /// triangular `Uᵀ`, then the pivots' `inv` from [`Self::inverse_sqrt_pivots`]), without
    /// allocating. `size` is the dimension (as for [`Self::inverse_sqrt_pivots`]; the same
    /// operations in the same order for either kind of size).
    #[inline(always)]
    pub(crate) fn right_divide_row(&self, size: impl Size, x: &mut [f64], inv: &[f64]) {
        let p = size.get();
        let x = &mut x[..p];
        let u = &self.u[..p * p];
        for i in 0..p {
            let (done, rest) = x.split_at_mut(i);
            let v = done
                .iter()
                .enumerate()
                .fold(rest[0], |v, (k, xk)| v - u[k * p + i] * xk);
            rest[0] = v;
        }
        for (v, r) in x.iter_mut().zip(&inv[..p]) {
            *v *= r;
        }
    }

    /// `x ← U⁻¹ D^-½ x`, i.e. `R⁻¹ x` (the pivots' `inv`, then back substitution with the unit
    /// triangular `U`), without allocating; `size` as for [`Self::right_divide_row`].
    #[inline(always)]
    pub(crate) fn left_solve(&self, size: impl Size, x: &mut [f64], inv: &[f64]) {
        let p = size.get();
        let x = &mut x[..p];
        let uu = &self.u[..p * p];
        for (v, r) in x.iter_mut().zip(&inv[..p]) {
            *v *= r;
        }
        for i in (0..p).rev() {
            let (head, later) = x.split_at_mut(i + 1);
            let u = &uu[i * p + i + 1..(i + 1) * p];
            head[i] = later.iter().zip(u).fold(head[i], |v, (xk, uk)| v - uk * xk);
        }
    }

    /// `‖R x‖² = Σ_i d_i (U x)_i²`, without allocating; `size` as for
    /// [`Self::right_divide_row`].
    #[inline(always)]
    pub(crate) fn norm_sq_of(&self, size: impl Size, x: &[f64]) -> f64 {
        let p = size.get();
        let (x, u, d) = (&x[..p], &self.u[..p * p], &self.d[..p]);
        (0..p)
            .map(|i| {
                let ux = x[i] + (i + 1..p).map(|k| u[i * p + k] * x[k]).sum::<f64>();
                d[i].0 * ux * ux
            })
            .sum()
    }

    /// `x ← U x` (the unit upper triangular part of `R = D^½ U`), without allocating: with
    /// [`Self::pivot`], `(R x)ᵀ(R y) = Σ_i d_i (U x)_i (U y)_i` needs no square root; `size` as
    /// for [`Self::right_divide_row`].
    #[inline(always)]
    pub(crate) fn unit_upper_times(&self, size: impl Size, x: &mut [f64]) {
        let p = size.get();
        let x = &mut x[..p];
        let uu = &self.u[..p * p];
        for i in 0..p {
            let (head, later) = x.split_at_mut(i + 1);
            let u = &uu[i * p + i + 1..(i + 1) * p];
            head[i] = later.iter().zip(u).fold(head[i], |v, (xk, uk)| v + uk * xk);
        }
    }

    /// The pivot `d_i` (the square of `R`'s diagonal entry `i`).
    pub(crate) fn pivot(&self, i: usize) -> f64 {
        self.d[i].0
    }

    /// The factor `R = D^½ U` (computed).
    pub fn r(&self) -> DMatrix<f64> {
        let p = self.dim();
        DMatrix::from_fn(p, p, |i, j| {
            let s = self.d[i].0.sqrt();
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
            self.d.iter().zip(&self.ubar).map(|(d, u)| d.0.sqrt() * u),
        )
    }

    /// The part of `Σ c_k b_k²` that no linear combination of the rows explains: the (weighted)
    /// residual sum of squares of the least-squares fit.
    pub fn residual_sq(&self) -> f64 {
        self.residual_sq
    }

    /// Adds `r` to the residual sum of squares: another factor's, when its rows are folded
    /// into this one (the residuals of disjoint samples add).
    pub fn add_residual_sq(&mut self, r: f64) {
        self.residual_sq += r;
    }

    /// `RᵀR = UᵀDU`.
    pub fn gram(&self) -> DMatrix<f64> {
        let r = self.r();
        r.transpose() * &r
    }

    /// True when every diagonal entry of `R` is non-zero.
    pub fn is_determined(&self) -> bool {
        self.positive || self.d.iter().all(|d| d.0 > 0.0)
    }

    /// Solves `R x = d` into `x` (`U x = ū`, no divisions); false while not determined.
    pub fn solve_into(&self, x: &mut [f64]) -> bool {
        unrolled_sizes!(self.dim(), N => self.solve_n::<N>(x), p => self.solve_any(p, x))
    }

    #[inline(always)]
    fn solve_n<const N: usize>(&self, x: &mut [f64]) -> bool {
        self.solve_any(N, x)
    }

    /// [`solve_into`](Self::solve_into) for the dimension `N` known at compile time.
    #[inline(always)]
    pub(crate) fn solve_array<const N: usize>(&self) -> Option<[f64; N]> {
        debug_assert_eq!(self.dim(), N);
        let mut x = [0.0; N];
        self.solve_n::<N>(&mut x).then_some(x)
    }

    #[inline(always)]
    fn solve_any(&self, p: usize, x: &mut [f64]) -> bool {
        if !self.is_determined() {
            return false;
        }
        let u: &[f64] = &self.u[..p * p];
        let ubar: &[f64] = &self.ubar[..p];
        let x: &mut [f64] = &mut x[..p];
        for i in (0..p).rev() {
            // The newest unknown last: the next row waits for one multiply-subtract only.
            let mut s = load_unmerged(&ubar[i]);
            for (uij, xj) in u[i * p + i + 1..(i + 1) * p].iter().zip(&x[i + 1..]).rev() {
                s -= load_unmerged(uij) * xj;
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
        unrolled_sizes!(p, N => self.add_row_n::<N>(row_of(a), b, weight), _ => {
            self.scratch.clear();
            self.scratch.extend_from_slice(a);
            self.add_row_any(b, weight);
        })
    }

    /// [`add_row`](Self::add_row) with the row of powers `a = (1, v, v², …, v^(p-1))` (a
    /// polynomial's coefficients observed at `v`), without forming it in memory.
    ///
    /// ```
    /// use seqsmooth::recursive::TriangularFactor;
    /// let (mut f, mut g) = (TriangularFactor::new(3), TriangularFactor::new(3));
    /// for (v, b) in [(-1.0, 2.0), (0.5, 1.0), (2.0, -3.0), (3.0, 0.5)] {
    ///     f.add_row_powers(v, b, 2.0);
    ///     g.add_row(&[1.0, v, v * v], b, 2.0);
    /// }
    /// assert_eq!(f.r(), g.r());
    /// ```
    pub fn add_row_powers(&mut self, v: f64, b: f64, weight: f64) {
        unrolled_sizes!(self.dim(), N => self.add_row_n::<N>(powers(v), b, weight), p => {
            self.scratch.clear();
            let mut pw = 1.0;
            for _ in 0..p {
                self.scratch.push(pw);
                pw *= v;
            }
            self.add_row_any(b, weight);
        })
    }

    #[inline(always)]
    fn add_row_n<const N: usize>(&mut self, a: [f64; N], b: f64, weight: f64) {
        if self.positive && weight >= f64::MIN_POSITIVE {
            self.add_row_reciprocal_n::<N>(a, b, weight);
        } else {
            self.add_row_gentleman_n::<N>(a, b, weight);
            self.refresh_positive();
        }
    }

    /// Gentleman's rotations one pivot after the other (any `D ≥ 0`, any weight `≥ 0`).
    #[inline(always)]
    fn add_row_gentleman_n<const N: usize>(&mut self, a: [f64; N], b: f64, weight: f64) {
        let mut x = a;
        let mut y = b;
        let mut delta = weight;
        let d: &mut [Pivot] = &mut self.d[..N];
        let u: &mut [f64] = &mut self.u[..N * N];
        let ubar: &mut [f64] = &mut self.ubar[..N];
        for i in 0..N {
            let xi = x[i];
            let (cbar, sbar) = gentleman_pivot(&mut delta, xi, &mut d[i].0);
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

    /// The same rotations in the reciprocal form (every `d_i` and the weight normal and
    /// positive; see the [type docs](Self)): the transformed row, the prefix sums `η`, the
    /// reciprocals (independent of each other), then the updates.
    #[inline(always)]
    fn add_row_reciprocal_n<const N: usize>(&mut self, a: [f64; N], b: f64, weight: f64) {
        let d: &mut [Pivot] = &mut self.d[..N];
        let u: &mut [f64] = &mut self.u[..N * N];
        let ubar: &mut [f64] = &mut self.ubar[..N];
        let mut e = [0.0; N];
        for (ei, di) in e.iter_mut().zip(d.iter()) {
            *ei = 1.0 / di.0;
        }
        // The row after each pivot: `after[i][j]` (`j > i`) is entry `j` once pivots `0..=i`
        // are done, `y_after[i]` likewise for `b`; `x[i]` ends as pivot `i`'s own entry.
        let mut x = a;
        let mut after = [[0.0; N]; N];
        let mut y_after = [0.0; N];
        let mut y = b;
        // The pivot index a constant in each step (`each_index!`), so that the steps' loops
        // unroll at every size compiled in (at 9 the compiler left them rolled: twice the
        // instructions of size 8).
        each_index!(N, i => {
            let xi = x[i];
            for j in i + 1..N {
                x[j] -= xi * u[i * N + j];
            }
            after[i][i + 1..].copy_from_slice(&x[i + 1..]);
            y -= xi * ubar[i];
            y_after[i] = y;
        });
        // `η_(i+1) = η_i + x_i²/d_i` from `η_0 = 1/c`, then `δ_(i+1) = 1/η_(i+1)`.
        let mut xe = [0.0; N];
        let mut delta = [0.0; N];
        let mut eta = 1.0 / weight;
        for i in 0..N {
            xe[i] = x[i] * e[i];
            eta += x[i] * xe[i];
            delta[i] = eta;
        }
        for di in delta.iter_mut() {
            *di = 1.0 / *di;
        }
        each_index!(N, i => {
            let delta_i = if i == 0 { weight } else { delta[i - 1] };
            let sbar = xe[i] * delta[i];
            d[i].0 += delta_i * (x[i] * x[i]);
            for j in i + 1..N {
                u[i * N + j] += sbar * after[i][j];
            }
            ubar[i] += sbar * y_after[i];
        });
        self.residual_sq += delta[N - 1] * y * y;
    }

    /// Any size, the row in `scratch[..p]` (overwritten).
    fn add_row_any(&mut self, b: f64, weight: f64) {
        if self.positive && weight >= f64::MIN_POSITIVE {
            self.add_row_reciprocal_any(b, weight);
        } else {
            self.add_row_gentleman_any(b, weight);
            self.refresh_positive();
        }
    }

    fn add_row_gentleman_any(&mut self, b: f64, weight: f64) {
        let p = self.dim();
        let x = &mut self.scratch[..p];
        let mut y = b;
        let mut delta = weight;
        for i in 0..p {
            let xi = x[i];
            let (cbar, sbar) = gentleman_pivot(&mut delta, xi, &mut self.d[i].0);
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

    /// [`Self::add_row_reciprocal_n`] for any size: the first pass keeps only the pivot
    /// entries, the second recomputes the row as it goes.
    fn add_row_reciprocal_any(&mut self, b: f64, weight: f64) {
        let p = self.dim();
        self.scratch.resize(4 * p, 0.0);
        let (a, rest) = self.scratch.split_at_mut(p);
        let (x, rest) = rest.split_at_mut(p);
        let (xe, delta) = rest.split_at_mut(p);
        x.copy_from_slice(a);
        let mut eta = 1.0 / weight;
        for i in 0..p {
            let xi = x[i];
            let row = &self.u[i * p + i + 1..(i + 1) * p];
            for (xj, uij) in x[i + 1..].iter_mut().zip(row) {
                *xj -= xi * uij;
            }
            xe[i] = xi / self.d[i].0;
            eta += xi * xe[i];
            delta[i] = eta;
        }
        for di in delta.iter_mut() {
            *di = 1.0 / *di;
        }
        x.copy_from_slice(a);
        let mut y = b;
        for i in 0..p {
            let xi = x[i];
            let delta_i = if i == 0 { weight } else { delta[i - 1] };
            let sbar = xe[i] * delta[i];
            self.d[i].0 += delta_i * (xi * xi);
            let row = &mut self.u[i * p + i + 1..(i + 1) * p];
            for (xj, uij) in x[i + 1..].iter_mut().zip(row.iter_mut()) {
                *xj -= xi * *uij;
                *uij += sbar * *xj;
            }
            y -= xi * self.ubar[i];
            self.ubar[i] += sbar * y;
        }
        self.residual_sq += delta.last().unwrap_or(&weight) * y * y;
    }

    /// Multiplies the accumulated Gram matrix by `f ≥ 0` (a fading-memory discount): `D ← fD`.
    pub fn discount(&mut self, f: f64) {
        self.d.iter_mut().for_each(|v| v.0 *= f);
        self.residual_sq *= f;
        self.refresh_positive();
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
            self.d[i].0 *= aii * aii;
            self.ubar[i] /= aii;
        }
        self.refresh_positive();
    }

    /// [`change_variables_upper`](Self::change_variables_upper) for the re-expansion of a
    /// polynomial's coefficients about a new centre and unit: the state is `x` with
    /// `f = Σ_k x_k v^k`, and with `v = α v' + β` the new state `x'` has `f = Σ_j x'_j v'^j`, so
    /// `x = A x'` with `A_kj = C(j,k) (-β)^(j-k) / α^j` (`α ≠ 0`) — without forming `A`, in
    /// `O(p³/6)` multiply-adds and no divisions.
    ///
    /// `A = P(-β) diag(α^-j)` with the Pascal matrix `P(h)_kj = C(j,k) h^(j-k)`, which is the
    /// product of the elementary steps `E_k = I + h e_k e_(k+1)ᵀ` of the Taylor shift by
    /// repeated synthetic division ([`shift_scaled`](crate::model::shift_scaled)). `U P` applies
    /// them as column operations `col_(k+1) += h col_k` in the reverse order; then
    /// `U ← diag(A)⁻¹ (U P) diag(α^-j)` is `U_ij ← α^(i-j) (U P)_ij` (`(U P)_ii = 1`),
    /// `D_i ← α^(-2i) D_i` and `ū_i ← α^i ū_i`. With `α` a power of two the scalings are exact.
    pub fn change_variables_polynomial(&mut self, alpha: f64, beta: f64) {
        unrolled_sizes!(self.dim(), N => self.change_variables_polynomial_n::<N>(alpha, beta), p => {
            self.change_variables_polynomial_any(p, alpha, beta)
        })
    }

    #[inline(always)]
    fn change_variables_polynomial_n<const N: usize>(&mut self, alpha: f64, beta: f64) {
        let u: &mut [f64] = &mut self.u[..N * N];
        let h = -beta;
        if h != 0.0 {
            // As in `change_variables_polynomial_any`, the same steps in the same order, the
            // outer index a constant in each copy (`each_index!`) so that the triangle unrolls
            // at every size compiled in.
            each_index!(N.saturating_sub(1), ii => {
                let i = N - 2 - ii;
                for k in i..N - 1 {
                    for r in 0..k {
                        u[r * N + k + 1] += h * u[r * N + k];
                    }
                    u[k * N + k + 1] += h;
                }
            });
        }
        self.scale_polynomial(N, alpha);
    }

    #[inline(always)]
    fn change_variables_polynomial_any(&mut self, p: usize, alpha: f64, beta: f64) {
        let u: &mut [f64] = &mut self.u[..p * p];
        let h = -beta;
        if h != 0.0 {
            // The shift's steps `for i { for k in (i..p-1).rev() { z_k += h z_(k+1) } }` in
            // reverse order, each transposed: `col_(k+1) += h col_k`, where column `k` of `U`
            // is zero below row `k` and 1 at it.
            for i in (0..p.saturating_sub(1)).rev() {
                for k in i..p - 1 {
                    for r in 0..k {
                        u[r * p + k + 1] += h * u[r * p + k];
                    }
                    u[k * p + k + 1] += h;
                }
            }
        }
        self.scale_polynomial(p, alpha);
    }

    /// The scaling of [`Self::change_variables_polynomial`] by `α` (none when `α = 1`).
    #[inline(always)]
    fn scale_polynomial(&mut self, p: usize, alpha: f64) {
        let u: &mut [f64] = &mut self.u[..p * p];
        if alpha != 1.0 {
            // `U_ij ← α^(i-j) U_ij`, `D_i ← α^(-2i) D_i`, `ū_i ← α^i ū_i`.
            let inv = 1.0 / alpha;
            let d: &mut [Pivot] = &mut self.d[..p];
            let ubar: &mut [f64] = &mut self.ubar[..p];
            let mut down = 1.0;
            let mut up = 1.0;
            for i in 0..p {
                let mut s = inv;
                for j in i + 1..p {
                    u[i * p + j] *= s;
                    s *= inv;
                }
                d[i].0 *= down * down;
                ubar[i] *= up;
                down *= inv;
                up *= alpha;
            }
            self.refresh_positive();
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

/// One pivot of Gentleman's rotation for the row entry `x` against the pivot `d`:
/// `d' = d + δx²`, `c̄ = d/d'`, `s̄ = δx/d'`, `δ ← δc̄`; returns `(c̄, s̄)`. A zero pivot (no
/// information yet and a zero entry) leaves everything as it is.
#[inline(always)]
fn gentleman_pivot(delta: &mut f64, x: f64, d: &mut f64) -> (f64, f64) {
    let dx = *delta * x;
    let di = *d;
    let dp = di + dx * x;
    let (cbar, sbar) = if dp > 0.0 {
        (di / dp, dx / dp)
    } else {
        (1.0, 0.0)
    };
    *delta *= cbar;
    *d = dp;
    (cbar, sbar)
}

/// `a` as an array (its length is checked by the caller).
#[inline(always)]
fn row_of<const N: usize>(a: &[f64]) -> [f64; N] {
    let mut x = [0.0; N];
    x.copy_from_slice(&a[..N]);
    x
}

/// `(1, v, v², …, v^(N-1))`, each power the previous one times `v`.
#[inline(always)]
fn powers<const N: usize>(v: f64) -> [f64; N] {
    let mut x = [1.0; N];
    for k in 1..N {
        x[k] = x[k - 1] * v;
    }
    x
}

/// A load of one `f64` that the compiler keeps on its own (never merged with its neighbour into
/// one 16-byte load).
///
/// [`TriangularFactor::solve_into`] typically runs right after a row was folded in, reading
/// what [`TriangularFactor::add_row`] has just stored with stores of the compiler's choosing
/// (some 8, some 16 bytes wide). A load spanning two stores cannot be forwarded from the store
/// buffer and waits until both have been written to the cache: measured as a stall of the
/// whole per-sample pipeline (see BENCHMARKS.md). An
/// 8-byte load is always forwarded from the store containing it; hiding the address from the
/// optimiser (`black_box`) keeps each load on its own.
#[inline(always)]
fn load_unmerged(x: &f64) -> f64 {
    *std::hint::black_box(x)
}

impl TriangularFactor {
    /// The leading `q × q` block of this factor into `out` (dimension `q < p`): the factor of
    /// the same rows restricted to their first `q` entries. In a QR factorisation the first `q`
    /// columns of `R` and the first `q` entries of `Qᵀb` depend only on the first `q` columns of
    /// the design (Morrison (10.2.42)-(10.2.44): each rotation combines whole rows, column by
    /// column), so the leading block of `[R ∣ d]` *is* the factor of the first `q` columns; the
    /// residual sum of squares of that smaller fit is this one's plus what the dropped columns
    /// explained, `Σ_(i ≥ q) d_i ū_i²` (the squares of the dropped entries of `d = D^½ ū`).
    /// `false` (and `out` untouched) unless `out` is smaller.
    ///
    /// ```
    /// use seqsmooth::recursive::TriangularFactor;
    /// // a line (2 columns) and a constant (its first column) through 0, 1, 5
    /// let (mut line, mut constant) = (TriangularFactor::new(2), TriangularFactor::new(1));
    /// for (u, y) in [(0.0, 0.0), (1.0, 1.0), (2.0, 5.0)] {
    ///     line.add_row(&[1.0, u], y, 1.0);
    /// }
    /// let mut lead = TriangularFactor::new(1);
    /// assert!(line.leading_into(&mut lead));
    /// let mut x = [0.0];
    /// assert!(lead.solve_into(&mut x));
    /// assert!((x[0] - 2.0).abs() < 1e-14); // the mean
    /// assert!((lead.residual_sq() - 14.0).abs() < 1e-13); // 4 + 1 + 9
    /// ```
    pub fn leading_into(&self, out: &mut TriangularFactor) -> bool {
        let q = out.dim();
        if q >= self.dim() {
            return false;
        }
        // The sizes compiled in copy in fixed-length moves (no call per row).
        unrolled_sizes!(q, N => self.leading_with(N, out), q => self.leading_with(q, out));
        true
    }

    /// [`Self::leading_into`] for `q = out.dim() < p`.
    #[inline(always)]
    fn leading_with(&self, q: usize, out: &mut TriangularFactor) {
        let p = self.dim();
        let (d, u, b) = (&self.d[..], &self.u[..], &self.ubar[..]);
        let (od, ou, ob) = (&mut out.d[..q], &mut out.u[..q * q], &mut out.ubar[..q]);
        od.copy_from_slice(&d[..q]);
        ob.copy_from_slice(&b[..q]);
        for (i, row) in ou.chunks_exact_mut(q).enumerate() {
            row.copy_from_slice(&u[i * p..i * p + q]);
        }
        let dropped: f64 = d[q..].iter().zip(&b[q..]).map(|(d, u)| d.0 * u * u).sum();
        out.residual_sq = self.residual_sq + dropped;
        out.positive = od.iter().all(|v| v.0 >= f64::MIN_POSITIVE);
    }
}

impl TriangularFactor {
    /// The invariants of a restored factor ([`crate::persist`]): `D`, `U`, `ū` of one
    /// dimension, finite, `D ≥ 0`.
    pub(crate) fn check_saved(&self) -> Result<(), String> {
        let p = self.d.len();
        if self.u.len() != p * p || self.ubar.len() != p {
            return Err(format!("factor's parts disagree on its dimension {p}"));
        }
        let d: Vec<f64> = self.d.iter().map(|x| x.0).collect();
        crate::linalg::invariant::finite(&d, "factor D")?;
        crate::linalg::invariant::finite(&self.u, "factor U")?;
        crate::linalg::invariant::finite(&self.ubar, "factor ū")?;
        if d.iter().any(|&x| x < 0.0) || !self.residual_sq.is_finite() {
            return Err("factor has a negative pivot or residual".into());
        }
        if self.positive && !d.iter().all(|x| x.is_normal()) {
            return Err("factor's pivots are not all positive".into());
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests;
