//! Exact recursive least squares with the polynomial model on arbitrary timestamps: the
//! polynomial instance of the square-root information filter of [`crate::recursive`].
//!
//! The state is the coefficient vector `a` of `f(t) = Σ_k a_k u^k` with the centred, scaled
//! time `u = (t - c)/s`. Keeping `c` near the middle of the (effective) memory and `s` near its
//! half-width keeps the rows `(1, u, …, u^m)` in `[-1, 1]`-like ranges; when the memory moves
//! the basis is re-centred by the upper-triangular change of variables
//! `a_old = A a_new`, `A_kj = C(j,k) (-β)^(j-k) / α^j` (`u_old = α u_new + β`), so `R ← R A`
//! stays triangular and no re-factorisation is needed
//! ([`TriangularFactor::change_variables_polynomial`]: Taylor-shift steps on the columns of
//! the factor, `O(m³/6)`, without forming `A`). Re-centring happens `O(log n)` times for
//! expanding memory and about once per quarter memory span for fading memory; the new unit is
//! the old one times a power of two and the centre moves by a multiple of unit/8, so `α`, `β`
//! and the powers of `α` are exact, and `(t - c)/s` is a multiplication by the exact `1/s`.
//!
//! The fading-memory discount `θ^ζ` per sample is [`InformationFilter::fade`] (applied
//! lazily), and the covariance with fading memory is the filter's true (sandwich) covariance,
//! [`InformationFilter::with_true_covariance`]: this engine is the Bayes filter
//! ([`crate::kalman::BayesFilter`]'s recursion) with the polynomial model, its state kept at a
//! centre that moves only now and then instead of at every sample. The factor itself is kept
//! in Gentleman's square-root-free form ([`TriangularFactor`]): no square roots per sample,
//! and once every pivot is positive none of its `2m+3` divisions per sample waits for another.

use crate::discount::{Discount, DiscountMode};
use crate::model::taylor::{unscale_in_range, unscale_stepwise};
use crate::model::{derivative_scale, shift_scaled, shift_scaled_array};
use crate::numeric::sigma::std_dev;
use crate::numeric::unrolled::unrolled_sizes;
use crate::polynomial::options::MAX_DEGREE;
use crate::recursive::InformationFilter;
#[cfg(doc)]
use crate::recursive::TriangularFactor;
use nalgebra::{DMatrix, DVector};

/// The largest state size, `MAX_DEGREE + 1` (stack tables).
const MAX_SIZE: usize = MAX_DEGREE + 1;

/// Pascal's triangle, `PASCAL[k][i] = C(k, i)` for `k, i < MAX_SIZE` (exact: at most
/// `C(24, 12) < 2^53`).
static PASCAL: [[f64; MAX_SIZE]; MAX_SIZE] = pascal();

const fn pascal() -> [[f64; MAX_SIZE]; MAX_SIZE] {
    let mut c = [[0.0; MAX_SIZE]; MAX_SIZE];
    let mut k = 0;
    while k < MAX_SIZE {
        c[k][0] = 1.0;
        let mut i = 1;
        while i <= k {
            c[k][i] = c[k - 1][i - 1] + c[k - 1][i];
            i += 1;
        }
        k += 1;
    }
    c
}

#[derive(Debug, serde::Serialize, serde::Deserialize)]
pub(crate) struct ExactEngine {
    m: usize,
    discount: Option<Discount>,
    info: InformationFilter,
    centre: f64,
    unit: f64,
    /// `1/unit`, exact (the unit is a power of two).
    inv_unit: f64,
    t_first: f64,
    t_last: f64,
    n: u64,
    sigma: Option<f64>,
    /// The last step `Δt` (per time) and `1/√(θ^ζ)`, the fade per sample: constant per
    /// update, per time evaluated only when the step changes.
    step_cached: f64,
    inv_root: f64,
    /// `-ln θ / (2τ)`: `1/√(θ^(Δt/τ)) = exp(Δt · that)` (per time).
    half_rate: f64,
    /// The effective memory span `3/(-ln θ)`, in updates (per update) or times `τ` (per time).
    span_updates: f64,
    span_per_time: f64,
    /// `k!/s^k` for the unit `s` (unscaled derivatives from the coefficients), `k ≤ m` (an
    /// array: a copy of the engine allocates only its factors).
    unscale: [f64; MAX_DEGREE + 1],
    /// Whether every `unscale` entry is a normal double; else the derivatives are unscaled one
    /// factor at a time ([`crate::model::taylor`]'s `unscale_stepwise`).
    unscale_in_range: bool,
    /// The prior's time, when the filter started from one ([`Self::set_prior`]).
    prior: Option<f64>,
}

// Field by field, `clone_from` too (the automatic filter's review keeps copies of it).
field_clone!(ExactEngine {
    m,
    discount,
    info,
    centre,
    unit,
    inv_unit,
    t_first,
    t_last,
    n,
    sigma,
    step_cached,
    inv_root,
    half_rate,
    span_updates,
    span_per_time,
    unscale,
    unscale_in_range,
    prior
});

impl ExactEngine {
    pub fn new(m: usize, discount: Option<Discount>) -> Self {
        Self {
            m,
            discount,
            info: InformationFilter::new(m + 1),
            centre: 0.0,
            unit: 1.0,
            inv_unit: 1.0,
            t_first: f64::NAN,
            t_last: f64::NAN,
            n: 0,
            sigma: None,
            step_cached: f64::NAN,
            inv_root: discount.map_or(1.0, |d| 1.0 / d.theta().sqrt()),
            half_rate: discount.map_or(0.0, |d| -d.theta().ln() / (2.0 * d.tau().unwrap_or(1.0))),
            span_updates: discount.map_or(0.0, |d| 3.0 / -d.theta().ln()),
            span_per_time: discount.map_or(0.0, |d| 3.0 * d.tau().unwrap_or(1.0) / -d.theta().ln()),
            unscale: [0.0; MAX_DEGREE + 1],
            unscale_in_range: true,
            prior: None,
        }
    }

    /// Starts from a prior at `time` given as whitened pseudo-observations of the coefficients
    /// of `Σ a_k (t − time)^k` (`rows`, `values`: [`crate::polynomial::prior::Prior`]'s), the
    /// basis centred there with unit 1; before any sample (the caller checks).
    pub fn set_prior(&mut self, time: f64, rows: &DMatrix<f64>, values: &DVector<f64>) {
        self.centre = time;
        self.unit = 1.0;
        self.set_unscale();
        (self.t_first, self.t_last) = (time, time);
        let mut row = vec![0.0; self.m + 1];
        for (i, &y) in values.iter().enumerate() {
            row.iter_mut()
                .zip(rows.row(i).iter())
                .for_each(|(a, b)| *a = *b);
            self.info.observe(&row, y, 1.0);
        }
        self.prior = Some(time);
    }

    /// The prior's time, if the filter started from one.
    pub fn prior_time(&self) -> Option<f64> {
        self.prior
    }

    /// Whether the rows so far may determine the fit: `m + 1` samples, or a prior.
    #[inline(always)]
    fn enough_rows(&self, size: u64) -> bool {
        self.n >= size || self.prior.is_some()
    }

    pub fn track_covariance(&mut self, sigma: f64) {
        self.sigma = Some(sigma);
        if self.discount.is_some() {
            self.info =
                std::mem::replace(&mut self.info, InformationFilter::new(0)).with_true_covariance();
        }
    }

    /// The noise σ, if tracked.
    pub fn sigma(&self) -> Option<f64> {
        self.sigma
    }

    /// Whether the covariance is tracked (a noise σ was given).
    pub fn tracks_covariance(&self) -> bool {
        self.sigma.is_some()
    }

    pub fn samples(&self) -> u64 {
        self.n
    }

    pub fn last_time(&self) -> f64 {
        self.t_last
    }

    /// Processes one sample; `t` must exceed the previous time (checked by the caller).
    pub fn update(&mut self, t: f64, y: f64) {
        if self.n == 0 && self.prior.is_none() {
            self.t_first = t;
            self.centre = t;
            self.unit = 1.0;
            self.set_unscale();
        } else {
            if let Some(d) = self.discount {
                if d.mode() == DiscountMode::PerTime {
                    let dt = t - self.t_last;
                    if dt != self.step_cached {
                        self.step_cached = dt;
                        self.inv_root = (dt * self.half_rate).exp();
                    }
                }
                self.info.fade(self.inv_root);
            }
            if self.n == 1 && self.prior.is_none() {
                // One row so far, (1, 0, …, 0) at the centre t_first, whatever the unit: the
                // unit is chosen from the first step at no cost, so that the change of
                // variables never has to bridge a factor like 2^±1000 (its powers α^j would
                // overflow) when times are in units far from the step.
                self.unit = (t - self.t_first).log2().round().exp2();
                if !(self.unit.is_normal() && self.unit.recip().is_normal()) {
                    self.unit = 1.0;
                }
                self.set_unscale();
            }
            self.maybe_recentre(t);
        }
        // The row (1, u, u², …, u^m).
        let u = (t - self.centre) * self.inv_unit;
        self.info.observe_powers(u, y, 1.0);
        self.t_last = t;
        self.n += 1;
    }

    /// Re-centres when the basis has drifted from the effective memory `[start, t]`: its
    /// centre off the memory's centre by more than a quarter of the memory, or its unit off the
    /// half-width by more than a factor 4. The test is division-free: the half-width is
    /// `s_num/q` (`q = n` for the per-update discount, whose span is `3(t - t_first)/(n·(-ln θ))`,
    /// else 1) and both sides are multiplied by `q`; the memory's centre is `t` minus its
    /// half-width.
    #[inline]
    fn maybe_recentre(&mut self, t: f64) {
        let elapsed = t - self.t_first;
        let (s_num, q) = match self.discount {
            None => (0.5 * elapsed, 1.0),
            Some(d) => match d.mode() {
                DiscountMode::PerTime => (0.5 * elapsed.min(self.span_per_time), 1.0),
                DiscountMode::PerUpdate => {
                    let n = self.n as f64;
                    (0.5 * elapsed * self.span_updates.min(n), n)
                }
            },
        };
        // NaN or no extent yet: nothing to centre on.
        if s_num.is_nan() || s_num <= 0.0 {
            return;
        }
        let off_centre = (q * (self.centre - t) + s_num).abs() > 0.5 * s_num;
        let unit_q = q * self.unit;
        let off_scale = unit_q > 4.0 * s_num || unit_q < 0.25 * s_num;
        if off_centre || off_scale {
            let target_s = s_num / q;
            let target_c = t - target_s;
            // The new unit is the old one times a power of two and the centre moves by a
            // multiple of unit/8, so `α` and `β` below are exact.
            let alpha = if off_scale {
                (target_s * self.inv_unit).log2().round().exp2()
            } else {
                1.0
            };
            let beta = ((target_c - self.centre) * self.inv_unit * 8.0).round() / 8.0;
            self.recentre(alpha, beta);
        }
    }

    /// `k!/s^k` and `1/s` for the current unit `s`.
    fn set_unscale(&mut self) {
        self.inv_unit = 1.0 / self.unit;
        for (c, d) in self.unscale[..=self.m]
            .iter_mut()
            .zip(derivative_scale(self.unit))
        {
            *c = d;
        }
        self.unscale_in_range = unscale_in_range(self.m, self.unit);
    }

    /// `x_k = a_k k!/s^k` into `out`.
    #[inline(always)]
    fn unscale_into(&self, a: &[f64], out: &mut [f64]) {
        if self.unscale_in_range {
            for ((x, z), c) in out.iter_mut().zip(a).zip(&self.unscale[..=self.m]) {
                *x = z * c;
            }
        } else {
            for (k, (x, z)) in out.iter_mut().zip(a).enumerate() {
                *x = unscale_stepwise(*z, k, self.unit);
            }
        }
    }

    /// Re-centres: `u_old = α u_new + β`, i.e. new centre `c + β·s`, new unit `α·s`.
    fn recentre(&mut self, alpha: f64, beta: f64) {
        self.info.change_variables_polynomial(alpha, beta);
        self.centre += beta * self.unit;
        if alpha != 1.0 {
            self.unit *= alpha;
            self.set_unscale();
        }
    }

    pub fn is_determined(&self) -> bool {
        self.enough_rows(self.m as u64 + 1) && self.info.is_determined()
    }

    /// Writes the unscaled derivatives of the fit at `t` into `out` (`m+1` values) without
    /// allocating: `a = R⁻¹d`, shifted to `u(t)`, `x_k = k! a_k / s^k`. False (and `out`
    /// untouched) while the fit is not determined.
    pub fn derivatives_into(&self, t: f64, out: &mut [f64]) -> bool {
        let h = (t - self.centre) * self.inv_unit;
        // Fixed sizes unroll completely (solve, shift and scaling in one piece).
        unrolled_sizes!(self.m + 1, N => self.derivatives_n::<N>(h, out), _ => self.derivatives_any(h, out))
    }

    #[inline(always)]
    fn derivatives_n<const N: usize>(&self, h: f64, out: &mut [f64]) -> bool {
        if !self.enough_rows(N as u64) {
            return false;
        }
        let Some(mut a) = self.info.factor().solve_array::<N>() else {
            return false;
        };
        shift_scaled_array(&mut a, h);
        // `k!/s^k`: the unit `s` is a power of two, so this equals `z·k!/s^k` computed with
        // the division, bit for bit.
        self.unscale_into(&a, &mut out[..N]);
        true
    }

    fn derivatives_any(&self, h: f64, out: &mut [f64]) -> bool {
        if !self.is_determined() {
            return false;
        }
        let p = self.m + 1;
        let mut buf = [0.0; MAX_DEGREE + 1];
        let a = &mut buf[..p];
        if !self.info.factor().solve_into(a) {
            return false;
        }
        shift_scaled(a, h);
        self.unscale_into(a, out);
        true
    }

    /// The fit's value at `t` and its variance (times the tracked `σ²`), without allocating;
    /// `None` while not determined or without a tracked `σ`. The position is `Σ a_k u^k`, so
    /// its variance is `σ² hᵀ C h` with `h = (1, u, …, u^m)`
    /// ([`InformationFilter::variances_of_rows`] with the one row `h`).
    pub fn position_at(&self, t: f64) -> Option<(f64, f64)> {
        let sigma = self.sigma.filter(|_| self.is_determined())?;
        let mut x = [0.0; MAX_DEGREE + 1];
        if !self.derivatives_into(t, &mut x) {
            return None;
        }
        let u = (t - self.centre) * self.inv_unit;
        let p = self.m + 1;
        let mut h = [0.0; MAX_DEGREE + 1];
        let mut power = 1.0;
        for hk in &mut h[..p] {
            *hk = power;
            power *= u;
        }
        let (mut inv, mut var) = ([0.0; MAX_DEGREE + 1], [0.0]);
        if !self
            .info
            .variances_of_rows(&mut h[..p], &mut inv[..p], &mut var)
        {
            return None;
        }
        Some((x[0], var[0] * (sigma * sigma)))
    }

    /// The derivatives at `t` into `x` and their variances (the squares of
    /// [`Self::std_devs_into`]) into `var`, `m + 1` each, without allocating; false (and the
    /// slices unspecified) while not determined or without a tracked `σ`.
    pub fn variances_at(&self, t: f64, x: &mut [f64], var: &mut [f64]) -> bool {
        if !(self.is_determined() && self.derivatives_into(t, x) && self.std_devs_into(t, var)) {
            return false;
        }
        for v in &mut var[..=self.m] {
            *v *= *v;
        }
        true
    }

    /// The 1σ of the unscaled derivatives at `t` into `out` without allocating: row `i` of
    /// `J = D(s) Φ(v)` (`v` the time in the basis' units) through the information factor
    /// ([`InformationFilter::variances_of_upper_rows`]: `Φ(v)` is upper triangular), times σ.
    /// `false` (and `out` unspecified) without a tracked covariance or while not determined.
    pub fn std_devs_into(&self, t: f64, out: &mut [f64]) -> bool {
        // The sizes compiled in with their loops unrolled, the rest in a frame of their own.
        unrolled_sizes!(self.m + 1, N => self.std_devs_with::<N, false>(N, t, out), p => self.std_devs_any(p, t, out))
    }

    /// The 1σ of a batch's σ rows ([`crate::PolynomialFilter::update_many_sigma_into`]):
    /// [`Self::std_devs_into`], except that on an x86-64 processor with fused multiply-add
    /// (checked at run time) the kernel's multiply-adds at the sizes compiled in (degrees
    /// 0-8) are fused, one rounding each instead of two. The terms and their order are the
    /// same, so the two differ by rounding alone (at most 5.9e-14 relative on 2·10⁴ irregular
    /// samples at degrees 0-8; the unit test holds them to 1e-12, and `tests/batch_sigma.rs`
    /// holds the σ rows to the direct QR solve). Every other 1σ (a single estimate, the
    /// automatic filter's tests) is [`Self::std_devs_into`]'s, bit for bit as before.
    pub fn batch_std_devs_into(&self, t: f64, out: &mut [f64]) -> bool {
        #[cfg(target_arch = "x86_64")]
        if fused_multiply_add() {
            // SAFETY: the processor has AVX2 and FMA (checked just above), the features
            // `std_devs_fused` enables.
            return unsafe { self.std_devs_fused(t, out) };
        }
        self.std_devs_into(t, out)
    }

    /// [`Self::std_devs_into`] with fused multiply-adds at the sizes compiled in.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    fn std_devs_fused(&self, t: f64, out: &mut [f64]) -> bool {
        unrolled_sizes!(self.m + 1, N => self.std_devs_with::<N, true>(N, t, out), p => self.std_devs_any(p, t, out))
    }

    /// [`Self::std_devs_into`] for any size (up to `MAX_DEGREE + 1`), unfused.
    #[inline(never)]
    fn std_devs_any(&self, p: usize, t: f64, out: &mut [f64]) -> bool {
        self.std_devs_with::<MAX_SIZE, false>(p, t, out)
    }

    /// [`Self::std_devs_into`] for the size `p ≤ N` (its tables on the stack), its
    /// multiply-adds fused with `FUSED`.
    #[inline(always)]
    fn std_devs_with<const N: usize, const FUSED: bool>(
        &self,
        p: usize,
        t: f64,
        out: &mut [f64],
    ) -> bool {
        let Some(sigma) = self.sigma.filter(|_| self.enough_rows(self.m as u64 + 1)) else {
            return false;
        };
        let v = (t - self.centre) * self.inv_unit;
        // Φ(v)_ik = C(k, i) v^(k-i), k ≥ i.
        let mut powers = [1.0; N];
        for k in 1..p {
            powers[k] = powers[k - 1] * v;
        }
        let phi = |i: usize, k: usize| PASCAL[k][i] * powers[k - i];
        let out = &mut out[..p];
        if !self.info.variances_of_upper_rows::<N, FUSED>(p, phi, out) {
            return false;
        }
        // The test outside the loop, so that its square roots go in vector operations.
        if self.unscale_in_range {
            for (o, c) in out.iter_mut().zip(&self.unscale[..p]) {
                *o = sigma * std_dev(*o) * c;
            }
        } else {
            for (i, o) in out.iter_mut().enumerate() {
                *o = unscale_stepwise(sigma * std_dev(*o), i, self.unit);
            }
        }
        true
    }

    /// Unscaled derivatives (and covariance, when tracked) of the fit evaluated at `t`.
    pub fn estimate_at(&self, t: f64) -> Option<(Vec<f64>, Option<DMatrix<f64>>)> {
        if !self.is_determined() {
            return None;
        }
        let mut x = vec![0.0; self.m + 1];
        if !self.derivatives_into(t, &mut x) {
            return None;
        }
        let v = (t - self.centre) * self.inv_unit;
        let cov = match self.sigma {
            None => None,
            Some(sigma) if self.unscale_in_range => {
                let p = self.m + 1;
                // Stack tables of p² values for the sizes compiled in, else on the heap.
                unrolled_sizes!(p, N => self.covariance_with(v, sigma, [[0.0; N]; N].as_flattened_mut(), [[0.0; N]; N].as_flattened_mut()), _ => self.covariance_with(v, sigma, &mut vec![0.0; p * p], &mut vec![0.0; p * p]))
            }
            Some(sigma) => {
                let j = crate::model::scaling(self.m, self.unit) * crate::model::phi(self.m, v);
                Some(self.info.covariance_of(&j)? * (sigma * sigma))
            }
        };
        Some((x, cov))
    }

    /// [`Self::estimate_at`]'s derivatives into `x` and its covariance's diagonal into `var`
    /// (`m + 1` each) without allocating: each number by the same operations in the same
    /// order, bit for bit ([`InformationFilter::covariance_diagonal_of_rows`], then
    /// `σ² D(s) … D(s)` entry by entry as [`Self::covariance_with`] scales them). `false` (the
    /// slices unspecified) where `estimate_at` takes another path or has no covariance (not
    /// determined, no tracked `σ`, a unit out of range), and where a number of the diagonal or
    /// of the scaling exceeds `1e60`: below that every entry of the full covariance is finite
    /// (`|C_ij| ≤ √(C_ii C_jj)`, rounding aside), so the diagonal alone answers whether the
    /// estimate is within the double range.
    pub fn estimate_diagonal_into(&self, t: f64, x: &mut [f64], var: &mut [f64]) -> bool {
        const LIMIT: f64 = 1e60;
        let Some(sigma) = self.sigma else {
            return false;
        };
        let s2 = sigma * sigma;
        if !(self.unscale_in_range && self.is_determined() && s2 <= LIMIT) {
            return false;
        }
        if !self.derivatives_into(t, x) {
            return false;
        }
        let v = (t - self.centre) * self.inv_unit;
        let p = self.m + 1;
        let mut diag = [0.0; MAX_SIZE];
        let solved = unrolled_sizes!(p, N => self.diagonal_with(v, [[0.0; N]; N].as_flattened_mut(), &mut diag[..p]), _ => self.diagonal_with(v, &mut vec![0.0; p * p], &mut diag[..p]));
        if !solved {
            return false;
        }
        let d = &self.unscale;
        for (i, (o, c)) in var[..p].iter_mut().zip(&diag[..p]).enumerate() {
            if c.is_nan() || *c > LIMIT || d[i] > LIMIT {
                return false;
            }
            *o = c * s2 * d[i] * d[i];
        }
        true
    }

    /// The diagonal of `Φ(v) C Φ(v)ᵀ` into `diag` ([`Self::covariance_with`]'s, before its
    /// scaling); `rows` is `p²` zeroed scratch.
    #[inline(always)]
    fn diagonal_with(&self, v: f64, rows: &mut [f64], diag: &mut [f64]) -> bool {
        let p = self.m + 1;
        phi_rows(v, p, rows);
        let mut inv = [0.0; MAX_DEGREE + 1];
        self.info
            .covariance_diagonal_of_rows(rows, &mut inv[..p], diag)
    }

    /// The covariance of the unscaled derivatives at `v` (in the basis' units) with one
    /// allocation, its own: `σ² D(s) Φ(v) C Φ(v)ᵀ D(s)`
    /// ([`InformationFilter::covariance_of_rows`]); `rows` and `cov` are `p²` scratch values.
    #[inline(always)]
    fn covariance_with(
        &self,
        v: f64,
        sigma: f64,
        rows: &mut [f64],
        cov: &mut [f64],
    ) -> Option<DMatrix<f64>> {
        let p = self.m + 1;
        phi_rows(v, p, rows);
        let mut inv = [0.0; MAX_DEGREE + 1];
        if !self.info.covariance_of_rows(rows, &mut inv[..p], cov) {
            return None;
        }
        let s2 = sigma * sigma;
        let d = &self.unscale;
        Some(DMatrix::from_fn(p, p, |i, j| {
            cov[i * p + j] * s2 * d[i] * d[j]
        }))
    }
}

/// Whether the processor has AVX2 and fused multiply-add (x86-64; the standard library
/// caches the answer).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn fused_multiply_add() -> bool {
    std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
}

/// The rows of `Φ(v)` into `rows` (`p²` values, row-major): `Φ_ik = C(k, i) v^(k−i)`, `k ≥ i`
/// (zero below the diagonal), Morrison (4.2.5) in the basis' units.
#[inline(always)]
fn phi_rows(v: f64, p: usize, rows: &mut [f64]) {
    let mut powers = [1.0; MAX_DEGREE + 1];
    for k in 1..p {
        powers[k] = powers[k - 1] * v;
    }
    let mut binomial = [0.0; MAX_DEGREE + 1];
    for k in 0..p {
        // Row k of Pascal's triangle from row k-1, in place.
        binomial[k] = 1.0;
        for i in (1..k).rev() {
            binomial[i] += binomial[i - 1];
        }
        for i in 0..=k {
            rows[i * p + k] = binomial[i] * powers[k - i];
        }
    }
}

impl ExactEngine {
    /// The invariants of a restored engine ([`crate::persist`]): degree in range, the
    /// information filter `m + 1` wide.
    pub(crate) fn check_saved(&self, m: usize) -> Result<(), String> {
        if self.m != m || m > MAX_DEGREE {
            return Err(format!(
                "engine's degree {} is not the filter's {m}",
                self.m
            ));
        }
        self.info.check_saved()?;
        if self.info.dim() != m + 1 {
            return Err(format!(
                "engine holds {} states, {} expected",
                self.info.dim(),
                m + 1
            ));
        }
        Ok(())
    }
}

impl ExactEngine {
    /// The degree-`m − 1` engine on the same samples, from this one's leading block, into
    /// `out` (built for degree `m − 1` with the same discount, tracking the covariance exactly
    /// when this one does): the state `a` holds the coefficients of `(1, u, …, u^m)` in the
    /// shared re-centred basis `u = (t − c)/s`, whose centre and unit follow the samples' times
    /// alone (the same for both degrees), so the degree-`m − 1` fit's design is this one's
    /// first `m` columns, and its factors, estimate, true covariance and residual are the
    /// leading block's ([`InformationFilter::leading_into`]). The result equals `out` updated
    /// with the same samples up to rounding: the factor's rows go through the same rotations
    /// except where one of the two uses Gentleman's sequential form and the other its
    /// reciprocal form (the `m + 1`-th sample, whose pivots the smaller factor already has
    /// positive). `false` (and `out` untouched) when they do not match.
    pub(crate) fn leading_into(&self, out: &mut ExactEngine) -> bool {
        if out.m + 1 != self.m
            || out.discount != self.discount
            || out.sigma.is_some() != self.sigma.is_some()
            || !self.info.leading_into(&mut out.info)
        {
            return false;
        }
        if out.n == 0 || out.unit != self.unit {
            out.unit = self.unit;
            out.set_unscale();
        }
        out.centre = self.centre;
        out.t_first = self.t_first;
        out.t_last = self.t_last;
        out.n = self.n;
        out.step_cached = self.step_cached;
        out.inv_root = self.inv_root;
        out.prior = self.prior;
        true
    }
}

impl super::EngineState {
    /// [`ExactEngine::leading_into`] where both are exact engines; `false` otherwise (a gain
    /// engine's recursion keeps no factor to share).
    pub(crate) fn leading_into(&self, out: &mut super::EngineState) -> bool {
        match (self, out) {
            (super::EngineState::Exact(upper), super::EngineState::Exact(lower)) => {
                upper.leading_into(lower)
            }
            _ => false,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The σ kernel with fused multiply-adds ([`ExactEngine::batch_std_devs_into`]) against
    /// the unfused one (`f64::mul_add` is the correctly rounded fused operation on any
    /// processor, so both run here): on 2·10⁴ irregular samples at degrees 0-8, fading memory
    /// per time and per update and expanding memory, every 1σ within 1e-12 relative of the
    /// other — the same terms in the same order, rounded once instead of twice. Both are
    /// held to the direct QR solve in `tests/batch_sigma.rs`.
    #[test]
    fn fused_sigma_kernel_agrees_with_unfused() {
        let mut worst: f64 = 0.0;
        for m in 0..=8 {
            for d in [
                Some(Discount::per_time(0.9, 1.0).unwrap()),
                Some(Discount::per_update(0.95).unwrap()),
                None, // expanding memory
            ] {
                let mut e = ExactEngine::new(m, d);
                e.track_covariance(0.3);
                let (mut t, mut x) = (0.0, 0.37_f64);
                let (mut a, mut b) = ([0.0; MAX_SIZE], [0.0; MAX_SIZE]);
                for n in 0..20_000 {
                    // Steps of 0.05 to 2.05 from a logistic sequence.
                    x = 3.99 * x * (1.0 - x);
                    t += 0.05 + 2.0 * x;
                    e.update(t, (0.3 * t).sin() + 1e-3 * t + 0.1 * (x - 0.5));
                    let p = m + 1;
                    let (fused, plain) = unrolled_sizes!(p, N => (
                        e.std_devs_with::<N, true>(N, t, &mut a),
                        e.std_devs_with::<N, false>(N, t, &mut b)
                    ), _ => unreachable!());
                    assert_eq!(fused, plain, "m {m} sample {n}");
                    if !fused {
                        continue;
                    }
                    for k in 0..p {
                        let rel = (a[k] - b[k]).abs() / b[k];
                        assert!(
                            rel.is_finite() && rel <= 1e-12,
                            "m {m} sample {n} s{k}: {}",
                            rel
                        );
                        worst = worst.max(rel);
                    }
                }
            }
        }
        // Not the same bits everywhere: the test compares two different roundings.
        assert!(worst > 0.0);
        eprintln!("largest relative difference {worst:e}");
    }
}
