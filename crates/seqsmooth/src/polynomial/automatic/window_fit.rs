//! The review's window fit ([`WindowFit`]): a least-squares polynomial through the samples of
//! a review window, by the normal equations in the Legendre basis of the centred, scaled time.
//!
//! Morrison's fixed-memory filter (ch. 7) is a least-squares polynomial over a window, written
//! in the polynomials orthogonal over it (the discrete Legendre polynomials), in which the
//! normal equations are diagonal for equally spaced samples. On the review's irregular times
//! the window is centred and scaled to `u ∈ [−1, 1]` and the fit is written in the continuous
//! Legendre polynomials `P_k(u)` (the discrete ones' limit). The normal equations square the
//! condition of the rows (Morrison §6.5: never in the powers `u^k`, whose rows' condition grows
//! as `~10^(0.6 m)`); in the Legendre basis the rows' condition is of order `√(2m + 1)` on
//! evenly spread samples, so `G = Σ_j P(u_j) P(u_j)ᵀ` stays near diagonal (condition of order
//! `2m + 1`: a few bits lost, where the review's decisions compare numbers known to a few
//! per cent). `G = Uᵀ D U` (unit upper `U`) is then solved directly: `p(p + 1)/2` products a
//! sample instead of a QR factor's row rotation (`p` divisions and about `p²` products a row),
//! the review's most frequent step (one fit of `2L` samples a decision). A window whose times
//! bunch so that `G` is near singular ([`DETERMINED`]) leaves the decision to the gate. The
//! fit is the same least-squares polynomial as a QR factor's; its numbers differ in the last
//! bits (tested against nalgebra's QR below).

use crate::numeric::unrolled::unrolled_sizes;
use crate::polynomial::options::MAX_DEGREE;

/// The most coefficients of a [`WindowFit`]: degree `MAX_DEGREE + 2`.
pub(super) const MAX_FIT: usize = MAX_DEGREE + 3;

/// A pivot `d_i` of `G = Uᵀ D U` at most this fraction of `G_ii` leaves the fit undetermined:
/// the `i`-th Legendre polynomial is then, to about `10⁻⁵` of its norm over the window, a
/// combination of the lower ones (samples bunched at a few times), and the fit says nothing the
/// gate does not.
const DETERMINED: f64 = 1e-10;

/// The Legendre recurrence `P_{k+1}(u) = A_k u P_k(u) − C_k P_{k−1}(u)`, `A_k = (2k + 1)/(k + 1)`,
/// `C_k = k/(k + 1)` (Abramowitz & Stegun 22.7.10).
static RECURRENCE: [(f64, f64); MAX_FIT] = recurrence();

const fn recurrence() -> [(f64, f64); MAX_FIT] {
    let mut r = [(0.0, 0.0); MAX_FIT];
    let mut k = 0;
    while k < MAX_FIT {
        r[k] = (
            (2 * k + 1) as f64 / (k + 1) as f64,
            k as f64 / (k + 1) as f64,
        );
        k += 1;
    }
    r
}

/// `h = (P_0(u), …, P_{p−1}(u))`, `p = h.len()`.
#[inline(always)]
fn legendre_row(u: f64, h: &mut [f64]) {
    let p = h.len();
    if p == 0 {
        return;
    }
    h[0] = 1.0;
    if p > 1 {
        h[1] = u;
    }
    for k in 1..p.saturating_sub(1) {
        let (a, c) = RECURRENCE[k];
        h[k + 1] = a * u * h[k] - c * h[k - 1];
    }
}

/// A least-squares polynomial `p(t) = Σ_k a_k P_k(u)`, `u = (t − c)/h` centred and scaled on
/// the window (so `|u| ≤ 1`), through the samples of a review window (module docs). Refitted in
/// place ([`WindowFit::fit`]): the review keeps two and allocates nothing per sample.
///
/// ```text
/// fit(ts, ys, d)          G = Σ P(u_j) P(u_j)ᵀ = Uᵀ D U,  Uᵀ D U a = Σ P(u_j) y_j
/// value_and_vrf_at(t)     (P(u)ᵀ a,  P(u)ᵀ G⁻¹ P(u))
/// residual_sq()           Σ (y_j − p(t_j))²
/// ```
#[derive(Clone, Debug)]
pub(super) struct WindowFit {
    /// The coefficients `a_k` of `P_k(u)`.
    coefficients: [f64; MAX_FIT],
    /// `U`, unit upper triangular, row-major with stride `p` (`u[i·p + j]`, `j > i`).
    unit: [f64; MAX_FIT * MAX_FIT],
    /// `1/d_i`.
    inv_d: [f64; MAX_FIT],
    centre: f64,
    inv_half: f64,
    degree: usize,
    determined: bool,
    /// `Σ (y_j − p(t_j))²` over the samples fitted.
    residual_sq: f64,
    /// The samples' rows `(P_0(u_j), …, P_d(u_j))` (stride `d + 1`) and residuals
    /// `y_j − p(t_j)` of the latest fit, for [`WindowFit::worst_residual`] (grown to the
    /// largest window once, then reused).
    rows: Vec<f64>,
    residuals: Vec<f64>,
}

impl Default for WindowFit {
    fn default() -> Self {
        Self {
            coefficients: [0.0; MAX_FIT],
            unit: [0.0; MAX_FIT * MAX_FIT],
            inv_d: [0.0; MAX_FIT],
            centre: 0.0,
            inv_half: 1.0,
            degree: 0,
            determined: false,
            residual_sq: 0.0,
            rows: Vec::new(),
            residuals: Vec::new(),
        }
    }
}

impl WindowFit {
    /// Fits degree `d` through `(ts, ys)` (at least `d + 1` distinct times), replacing the fit
    /// held; false when it is not determined. The size `d + 1` compiled in
    /// ([`unrolled_sizes!`]).
    pub(super) fn fit(&mut self, ts: &[f64], ys: &[f64], degree: usize) -> bool {
        let p = degree + 1;
        unrolled_sizes!(p, N => self.fit_with::<N>(N, ts, ys), p => self.fit_with::<MAX_FIT>(p, ts, ys))
    }

    /// The fit of `p ≤ N` coefficients, its scratch arrays of `N` (`N = p` compiled in, or
    /// [`MAX_FIT`]: no more zeroed per fit than the size needs).
    #[inline(always)]
    fn fit_with<const N: usize>(&mut self, p: usize, ts: &[f64], ys: &[f64]) -> bool {
        let (lo, hi) = ts
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &t| {
                (a.min(t), b.max(t))
            });
        let half = 0.5 * (hi - lo);
        self.centre = 0.5 * (lo + hi);
        self.inv_half = if half > 0.0 { 1.0 / half } else { 1.0 };
        self.degree = p - 1;
        self.coefficients[..p].fill(0.0);
        self.residual_sq = 0.0;
        // The values less their mean (added back to `a_0`, `P_0 ≡ 1`: the same fit), so the
        // normal equations' rounding scales with the values' spread over the window, not with
        // their offset (a range of 10⁵ m known to 1 m).
        let mean = if ts.is_empty() {
            0.0
        } else {
            ys.iter().sum::<f64>() / ys.len() as f64
        };
        // The normal equations' upper triangle and right-hand side.
        let mut g = [[0.0; N]; N];
        let mut b = [0.0; N];
        let n = ts.len().min(ys.len());
        self.rows.resize(n * p, 0.0);
        self.residuals.resize(n, 0.0);
        for ((&t, &y), row) in ts.iter().zip(ys).zip(self.rows.chunks_exact_mut(p)) {
            let h = row;
            legendre_row((t - self.centre) * self.inv_half, h);
            let y = y - mean;
            for i in 0..p {
                b[i] += h[i] * y;
                for k in i..p {
                    g[i][k] += h[i] * h[k];
                }
            }
        }
        // G = Uᵀ D U, row by row.
        let (unit, inv_d) = (&mut self.unit, &mut self.inv_d);
        let mut d = [0.0; N];
        let mut ok = true;
        for i in 0..p {
            let mut di = g[i][i];
            for k in 0..i {
                let uki = unit[k * p + i];
                di -= uki * uki * d[k];
            }
            // NaN fails too.
            ok &= di > DETERMINED * g[i][i];
            d[i] = di;
            inv_d[i] = 1.0 / di;
            for j in i + 1..p {
                let mut s = g[i][j];
                for k in 0..i {
                    s -= unit[k * p + i] * unit[k * p + j] * d[k];
                }
                unit[i * p + j] = s * inv_d[i];
            }
        }
        self.determined = ok;
        if !ok {
            return false;
        }
        // Uᵀ z = b, then U a = D⁻¹ z.
        let a = &mut self.coefficients;
        for i in 0..p {
            let mut z = b[i];
            for k in 0..i {
                z -= unit[k * p + i] * b[k];
            }
            b[i] = z;
        }
        for i in (0..p).rev() {
            let mut x = b[i] * inv_d[i];
            for j in i + 1..p {
                x -= unit[i * p + j] * a[j];
            }
            a[i] = x;
        }
        a[0] += mean;
        // The residuals, from the rows kept (the same numbers as `value_and_row` gives).
        let mut rss = 0.0;
        let a = &self.coefficients[..p];
        let rows = self.rows.chunks_exact(p);
        for ((&y, h), e) in ys.iter().zip(rows).zip(self.residuals.iter_mut()) {
            *e = y - a.iter().zip(h.iter()).map(|(a, h)| a * h).sum::<f64>();
            rss += *e * *e;
        }
        self.residual_sq = rss;
        true
    }

    /// `p(t)` and its variance for unit noise `h(t)ᵀ G⁻¹ h(t)`; `None` while not determined.
    /// The size `d + 1` compiled in ([`unrolled_sizes!`]).
    pub(super) fn value_and_vrf_at(&self, t: f64) -> Option<(f64, f64)> {
        let p = self.degree + 1;
        unrolled_sizes!(p, N => self.value_and_vrf_with::<N>(N, t), p => self.value_and_vrf_with::<MAX_FIT>(p, t))
    }

    #[inline(always)]
    fn value_and_vrf_with<const N: usize>(&self, p: usize, t: f64) -> Option<(f64, f64)> {
        let mut h = [0.0; N];
        let value = self.value_and_row(t, &mut h[..p]);
        Some((value, self.vrf_of::<N>(&h[..p])?))
    }

    /// `p(t)`, with the row `h(t) = (P_0(u), …, P_d(u))` into `h` (`p` values).
    #[inline(always)]
    fn value_and_row(&self, t: f64, h: &mut [f64]) -> f64 {
        legendre_row((t - self.centre) * self.inv_half, h);
        let a = &self.coefficients[..h.len()];
        a.iter().zip(h.iter()).map(|(a, h)| a * h).sum()
    }

    /// `hᵀ G⁻¹ h = Σ_i g_i²/d_i` with `Uᵀ g = h`; `None` while not determined.
    #[inline(always)]
    fn vrf_of<const N: usize>(&self, h: &[f64]) -> Option<f64> {
        if !self.determined {
            return None;
        }
        let p = h.len();
        Some(quadratic_form::<N>(
            &self.unit[..p * p],
            &self.inv_d[..p],
            h,
        ))
    }

    /// The largest squared studentised residual `e_j²/(σ²(1 − h_j))` (`s2 = σ²`, `h_j` the
    /// fit's VRF at `t_j`, as [`value_and_vrf_at`](Self::value_and_vrf_at) gives it) over the
    /// samples of the latest fit (their rows and residuals kept by [`fit`](Self::fit)), and its
    /// index (the first of equals); `None` while not determined or when one is not a number.
    /// The fit's size compiled in ([`unrolled_sizes!`]).
    pub(super) fn worst_residual(&self, s2: f64) -> Option<(f64, usize)> {
        let p = self.degree + 1;
        unrolled_sizes!(p, N => self.worst_residual_with::<N>(N, s2), p => self.worst_residual_with::<MAX_FIT>(p, s2))
    }

    #[inline(always)]
    fn worst_residual_with<const N: usize>(&self, p: usize, s2: f64) -> Option<(f64, usize)> {
        if !self.determined {
            return None;
        }
        let (u, inv_d) = (&self.unit[..p * p], &self.inv_d[..p]);
        let mut worst = (f64::NEG_INFINITY, 0);
        let rows = self.rows.chunks_exact(p);
        for (j, (h, &e)) in rows.zip(&self.residuals).enumerate() {
            let q = quadratic_form::<N>(u, inv_d, h);
            let r2 = e * e / (s2 * (1.0 - q).max(f64::EPSILON));
            if r2.is_nan() {
                return None;
            }
            if r2 > worst.0 {
                worst = (r2, j);
            }
        }
        Some(worst)
    }

    /// `Σ (y_j − p(t_j))²` over the samples of the latest fit.
    pub(super) fn residual_sq(&self) -> f64 {
        self.residual_sq
    }
}

/// `hᵀ G⁻¹ h = Σ_i g_i²/d_i` with `Uᵀ g = h`, for the unit triangle `u` (row-major, `p × p`,
/// `p = h.len() ≤ N`) and the pivots' reciprocals `inv_d` of `G = Uᵀ D U`.
#[inline(always)]
fn quadratic_form<const N: usize>(u: &[f64], inv_d: &[f64], h: &[f64]) -> f64 {
    let p = h.len();
    let mut g = [0.0; N];
    let mut q = 0.0;
    for i in 0..p {
        let mut gi = h[i];
        for k in 0..i {
            gi -= u[k * p + i] * g[k];
        }
        g[i] = gi;
        q += gi * gi * inv_d[i];
    }
    q
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, DVector};
    use rand::rngs::StdRng;
    use rand::{Rng, SeedableRng};

    /// The oracle: the least-squares fit in the powers of `t − t₀` by nalgebra's QR, its value,
    /// the VRF `h (AᵀA)⁻¹ hᵀ` by solving `R` twice, and the residual sum of squares.
    fn qr_fit(ts: &[f64], ys: &[f64], d: usize, t: f64) -> (f64, f64, f64) {
        let t0 = ts[ts.len() / 2];
        let row = |t: f64| (0..=d).map(move |k| (t - t0).powi(k as i32));
        let a = DMatrix::from_fn(ts.len(), d + 1, |i, k| row(ts[i]).nth(k).unwrap());
        let qr = a.clone().qr();
        let r = qr.r();
        let qty = qr.q().transpose() * DVector::from_column_slice(ys);
        let x = r.solve_upper_triangular(&qty).unwrap();
        let h = DVector::from_iterator(d + 1, row(t));
        let g = r.transpose().solve_lower_triangular(&h).unwrap();
        let rss = (&a * &x - DVector::from_column_slice(ys)).norm_squared();
        (h.dot(&x), g.norm_squared(), rss)
    }

    #[test]
    fn equals_a_qr_least_squares_fit() {
        let mut r = StdRng::seed_from_u64(30);
        for case in 0..400 {
            let d = case % 6;
            let n = d + 2 + r.gen_range(0..12);
            let mut t: f64 = r.gen_range(-1e4..1e4);
            let (mut ts, mut ys) = (Vec::new(), Vec::new());
            for _ in 0..n {
                t += r.gen_range(0.3..1.7);
                ts.push(t);
                ys.push(5e3 + 40.0 * t.sin() + r.gen_range(-10.0..10.0));
            }
            let mut f = WindowFit::default();
            assert!(f.fit(&ts, &ys, d), "case {case}");
            let at = ts[n / 2] + 0.3;
            let (v, vrf) = f.value_and_vrf_at(at).unwrap();
            let (v0, vrf0, rss0) = qr_fit(&ts, &ys, d, at);
            assert!((v - v0).abs() <= 1e-9 * v0.abs(), "case {case}: {v} {v0}");
            assert!(
                (vrf - vrf0).abs() <= 1e-9 * vrf0,
                "case {case}: {vrf} {vrf0}"
            );
            let rss = f.residual_sq();
            assert!(
                (rss - rss0).abs() <= 1e-6 * rss0.max(1e-6),
                "case {case}: {rss} {rss0}"
            );
            // The studentised residuals: the largest one's index and value by the oracle.
            let (w, j) = f.worst_residual(4.0).unwrap();
            let (vj, hj, _) = qr_fit(&ts, &ys, d, ts[j]);
            let want = (ys[j] - vj).powi(2) / (4.0 * (1.0 - hj).max(f64::EPSILON));
            assert!(
                (w - want).abs() <= 1e-6 * want.max(1e-9),
                "case {case}: {w} {want}"
            );
        }
    }

    /// The oracle at any degree: the same Legendre rows solved by nalgebra's QR (no normal
    /// equations), its value at `t`.
    fn qr_legendre(ts: &[f64], ys: &[f64], d: usize, t: f64) -> f64 {
        let (lo, hi) = (ts[0], ts[ts.len() - 1]);
        let (c, h) = (0.5 * (lo + hi), 0.5 * (hi - lo));
        let row = |t: f64| {
            let mut r = vec![0.0; d + 1];
            legendre_row((t - c) / h, &mut r);
            r
        };
        let a = DMatrix::from_fn(ts.len(), d + 1, |i, k| row(ts[i])[k]);
        let qr = a.qr();
        let qty = qr.q().transpose() * DVector::from_column_slice(ys);
        let x = qr.r().solve_upper_triangular(&qty).unwrap();
        DVector::from_vec(row(t)).dot(&x)
    }

    /// Degrees to `MAX_DEGREE + 2` (the review's widest fit), windows of `d + 2` to `2d + 10`
    /// irregular samples, values offset by 10⁶ with noise of 10⁻²: every determined fit's
    /// value within a hundredth of the noise of the QR oracle's (the review compares numbers
    /// known to a few per cent), and most windows determined.
    #[test]
    fn high_degrees_and_large_offsets_against_qr() {
        let mut r = StdRng::seed_from_u64(31);
        let (mut fits, mut determined) = (0, 0);
        for d in 0..=MAX_DEGREE + 2 {
            for _ in 0..12 {
                let n = d + 2 + r.gen_range(0..d + 9);
                let mut t: f64 = r.gen_range(-1e5..1e5);
                let (mut ts, mut ys) = (Vec::new(), Vec::new());
                for _ in 0..n {
                    t += r.gen_range(0.5..1.5);
                    ts.push(t);
                    ys.push(1e6 + 3.0 * (0.2 * t).sin() + r.gen_range(-1e-2..1e-2));
                }
                let mut f = WindowFit::default();
                fits += 1;
                if !f.fit(&ts, &ys, d) {
                    continue;
                }
                determined += 1;
                let at = ts[n / 3] + 0.25;
                let (v, vrf) = f.value_and_vrf_at(at).unwrap();
                let v0 = qr_legendre(&ts, &ys, d, at);
                assert!((v - v0).abs() <= 1e-4, "degree {d}, {n} samples: {v} {v0}");
                assert!(vrf.is_finite() && vrf > 0.0, "degree {d}: vrf {vrf}");
            }
        }
        assert!(
            determined * 10 >= fits * 9,
            "{determined} of {fits} determined"
        );
    }

    #[test]
    fn too_few_or_bunched_times_are_not_determined() {
        let mut f = WindowFit::default();
        assert!(!f.fit(&[1.0, 2.0], &[0.0, 1.0], 2));
        assert!(f.value_and_vrf_at(1.5).is_none());
        assert!(f.worst_residual(1.0).is_none());
        assert!(f.fit(&[1.0, 2.0, 3.0], &[0.0, 1.0, 4.0], 2));
        let (v, _) = f.value_and_vrf_at(4.0).unwrap();
        assert!((v - 9.0).abs() < 1e-12);
    }
}
