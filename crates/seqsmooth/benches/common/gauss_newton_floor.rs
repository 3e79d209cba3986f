//! The floor of the radar Gauss–Newton fit (`benches/gauss_newton.rs`, `examples/gauss_newton_floor_pace.rs`):
//! the library's algorithm (`GaussNewton::fit` with `Epoch::End` on `PolynomialDynamics::new(1, 3)`
//! seen by `Radar::new([0.0; 3], 6)`, Morrison §8.6-8.7) written by hand for that model on
//! buffers sized once per fit, without checks (no finiteness tests, no missing components, no
//! rank test or condition number): at each linearisation the 60 predictions and rows
//! `T_k = [J, ζ_k J]` (`M Φ(t_k, t_c)` of constant velocity, `ζ_k = t_k − t_c`) and residuals
//! `δY_k`, whitened by `1/σ`, (8.6.35); the Householder QR of `T` with `Qᵀ δY`, `δX` by back
//! substitution (8.6.36)-(8.6.37); the correction `|(Qᵀ δY)_head|` in its own σ against the
//! tolerance; the step accepted when the next linearisation's `e(X)` has not risen (halved
//! otherwise, (8.7.1)); at the end `S = R⁻¹ R⁻ᵀ` (8.6.38). Returns the state, its covariance
//! and the number of linearisations, which the pace example compares with the library's
//! before timing (a floor that did less would not agree).

// The loops index by row and column on purpose: the algorithm's formulas, entry by entry.
#![allow(clippy::needless_range_loop)]

use seqsmooth::model::radar::wrap;

/// States.
const N: usize = 6;

/// The fit's work buffers, sized for `rows` whitened rows (3 a measurement), column-major.
pub struct FloorWork {
    rows: usize,
    t: Vec<f64>,
    y: Vec<f64>,
    t_next: Vec<f64>,
    y_next: Vec<f64>,
}

impl FloorWork {
    /// Buffers for `samples` measurements.
    pub fn new(samples: usize) -> Self {
        let rows = 3 * samples;
        Self {
            rows,
            t: vec![0.0; rows * N],
            y: vec![0.0; rows],
            t_next: vec![0.0; rows * N],
            y_next: vec![0.0; rows],
        }
    }
}

/// The whitened rows and residuals at `x` (the state at `t_c`) into `t`, `y`; `e(x)`.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn linearise(
    times: &[f64],
    measured: &[[f64; 3]],
    weight: [f64; 3],
    t_c: f64,
    x: &[f64; N],
    rows: usize,
    t: &mut [f64],
    y: &mut [f64],
) -> f64 {
    let mut chi_squared = 0.0;
    for (k, (&time, z)) in times.iter().zip(measured).enumerate() {
        let zeta = time - t_c;
        let p = [x[0] + zeta * x[3], x[1] + zeta * x[4], x[2] + zeta * x[5]];
        let h2 = p[0] * p[0] + p[1] * p[1];
        let rho2 = h2 + p[2] * p[2];
        let (h, rho) = (h2.sqrt(), rho2.sqrt());
        let g = [rho, (p[1] + 0.0).atan2(p[0]), p[2].atan2(h)];
        let j = [
            [p[0] / rho, p[1] / rho, p[2] / rho],
            [-p[1] / h2, p[0] / h2, 0.0],
            [
                -p[0] * p[2] / (rho2 * h),
                -p[1] * p[2] / (rho2 * h),
                h / rho2,
            ],
        ];
        let nu = [z[0] - g[0], wrap(z[1] - g[1]), z[2] - g[2]];
        for c in 0..3 {
            let row = 3 * k + c;
            let w = weight[c];
            for l in 0..3 {
                let v = j[c][l] * w;
                t[row + l * rows] = v;
                t[row + (l + 3) * rows] = zeta * v;
            }
            let r = nu[c] * w;
            y[row] = r;
            chi_squared += r * r;
        }
    }
    chi_squared
}

/// Householder QR of `t` (`rows × N`, column-major) in place, `y ← Qᵀ y`; `R`'s diagonal
/// (the rest of `R` is `t`'s upper triangle).
#[inline(always)]
fn householder(rows: usize, t: &mut [f64], y: &mut [f64]) -> [f64; N] {
    let mut diagonal = [0.0; N];
    for j in 0..N {
        let (head, tail) = t.split_at_mut((j + 1) * rows);
        let v = &mut head[j * rows + j..];
        let norm2: f64 = v.iter().map(|a| a * a).sum();
        let norm = norm2.sqrt();
        let alpha = if v[0] > 0.0 { -norm } else { norm };
        let v0 = v[0] - alpha;
        let vtv = norm2 - v[0] * v[0] + v0 * v0;
        v[0] = v0;
        diagonal[j] = alpha;
        if vtv == 0.0 {
            continue;
        }
        let beta = 2.0 / vtv;
        let apply = |column: &mut [f64]| {
            let s: f64 = v.iter().zip(column.iter()).map(|(a, b)| a * b).sum::<f64>() * beta;
            for (c, a) in column.iter_mut().zip(v.iter()) {
                *c -= s * a;
            }
        };
        for c in 0..N - j - 1 {
            apply(&mut tail[c * rows + j..(c + 1) * rows]);
        }
        apply(&mut y[j..]);
    }
    diagonal
}

/// `R⁻¹ b` by back substitution (`R` from [`householder`]).
#[inline(always)]
fn back_substitute(rows: usize, t: &[f64], diagonal: &[f64; N], b: &[f64; N]) -> [f64; N] {
    let mut x = [0.0; N];
    for i in (0..N).rev() {
        let mut acc = b[i];
        for c in i + 1..N {
            acc -= t[i + c * rows] * x[c];
        }
        x[i] = acc / diagonal[i];
    }
    x
}

/// The fit from `nominal` at the last time, correction tolerance `tolerance` (of its own σ),
/// at most `max_iterations` linearisations and `max_halvings` halvings of a step; the
/// measurements' σ `sigma` (range, azimuth, elevation). `None` if it does not converge.
#[allow(clippy::too_many_arguments)]
pub fn radar_fit(
    work: &mut FloorWork,
    times: &[f64],
    measured: &[[f64; 3]],
    sigma: [f64; 3],
    nominal: [f64; N],
    tolerance: f64,
    max_iterations: usize,
    max_halvings: usize,
) -> Option<([f64; N], [[f64; N]; N], usize)> {
    let rows = work.rows;
    let t_c = times.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let weight = sigma.map(|s| 1.0 / s);
    let mut x = nominal;
    let mut chi_squared = linearise(
        times,
        measured,
        weight,
        t_c,
        &x,
        rows,
        &mut work.t,
        &mut work.y,
    );
    for iteration in 1..=max_iterations {
        let diagonal = householder(rows, &mut work.t, &mut work.y);
        let head: [f64; N] = std::array::from_fn(|i| work.y[i]);
        let dx = back_substitute(rows, &work.t, &diagonal, &head);
        let correction = head.iter().map(|v| v * v).sum::<f64>().sqrt();
        if correction <= tolerance {
            for i in 0..N {
                x[i] += dx[i];
            }
            // S = R⁻¹ R⁻ᵀ: the columns of R⁻¹ by back substitution of the unit vectors.
            let mut inverse = [[0.0; N]; N];
            for c in 0..N {
                let e: [f64; N] = std::array::from_fn(|i| f64::from(u8::from(i == c)));
                let column = back_substitute(rows, &work.t, &diagonal, &e);
                for i in 0..N {
                    inverse[i][c] = column[i];
                }
            }
            let covariance = std::array::from_fn(|i| {
                std::array::from_fn(|j| (0..N).map(|l| inverse[i][l] * inverse[j][l]).sum())
            });
            return Some((x, covariance, iteration));
        }
        let slack = 1e-10 * chi_squared.max(1.0);
        let mut step = 1.0;
        let mut accepted = false;
        for _ in 0..=max_halvings {
            let candidate: [f64; N] = std::array::from_fn(|i| x[i] + dx[i] * step);
            let next = linearise(
                times,
                measured,
                weight,
                t_c,
                &candidate,
                rows,
                &mut work.t_next,
                &mut work.y_next,
            );
            if next <= chi_squared + slack {
                x = candidate;
                chi_squared = next;
                std::mem::swap(&mut work.t, &mut work.t_next);
                std::mem::swap(&mut work.y, &mut work.y_next);
                accepted = true;
                break;
            }
            step *= 0.5;
        }
        if !accepted {
            return None;
        }
    }
    None
}
