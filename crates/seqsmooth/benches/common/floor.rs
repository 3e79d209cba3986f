//! Hand-written fixed-size loops of the library's Kalman recursions, the floors that
//! `benches/kalman.rs` times beside the library in the same run: the same algorithm as
//! `KalmanFilter::update_stats` (prediction `Φ S Φᵀ + Q`, (12.2.15)-(12.2.16), (15.4.11); the
//! gain from the innovation covariance `V = M S Mᵀ + R` by its `L D Lᵀ` factors; NIS and
//! `ln det V`; Joseph's covariance (12.3.7) applied from each side, `O(n² k)`), on stack arrays
//! with the model's sizes and structure written out, and no checks (no finiteness tests, no
//! missing components, no errors). Each returns the final state and covariance and the sum of
//! the log-likelihoods, which the bench compares with the library's before timing (a floor
//! that did less would not agree).

// The loops index by row and column on purpose: the recursion's formulas, entry by entry.
#![allow(clippy::needless_range_loop)]

use nalgebra::{DMatrix, DVector};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::StandardNormal;
use seqsmooth::kalman::noise::WhiteNoiseDerivative;
use seqsmooth::kalman::KalmanFilter;
use seqsmooth::model::dynamics::PolynomialDynamics;
use seqsmooth::model::measurement::{Measurement, NoiseCovariance};
use seqsmooth::model::observation::LinearObservation;
use seqsmooth::model::radar::wrap;
use std::f64::consts::TAU;

/// The 3-state filter's driving-noise spectral density (jerk), value²/time⁵.
pub const Q3: f64 = 1.0;
/// σ of the 3-state filter's measurements.
pub const SIGMA3: f64 = 0.5;

/// The 3-state case the floor is timed on (`benches/kalman.rs`, `examples/kalman_floor_pace.rs`):
/// `KalmanFilter` on `PolynomialDynamics::new(2, 1)` observed by `LinearObservation::value_of(3)`
/// with driving noise `WhiteNoiseDerivative::new(2, 1, Q3)`, from a vague prior (state 0,
/// variances 10⁴) at 0, and `count` measurements at irregular steps `0.001·U(0.5, 1.5)` of a
/// slow sine plus N(0, SIGMA3²).
pub fn polynomial_case(
    count: usize,
) -> (
    KalmanFilter<PolynomialDynamics, LinearObservation>,
    Vec<Measurement>,
) {
    let mut rng = StdRng::seed_from_u64(20_260_417);
    let mut t = 0.0;
    let rows = (0..count)
        .map(|_| {
            t += 1e-3 * rng.gen_range(0.5..1.5);
            let e: f64 = rng.sample(StandardNormal);
            let y = 10.0 * (t * TAU / 25.0).sin() + 0.5 * t + SIGMA3 * e;
            Measurement {
                time: t,
                values: vec![Some(y)],
                noise: NoiseCovariance::Variances(vec![SIGMA3 * SIGMA3]),
            }
        })
        .collect();
    let filter = KalmanFilter::new(
        PolynomialDynamics::new(2, 1),
        LinearObservation::value_of(3),
        DVector::zeros(3),
        DMatrix::from_diagonal(&DVector::from_vec(vec![1e4, 1e4, 1e4])),
        0.0,
    )
    .unwrap()
    .with_process_noise(WhiteNoiseDerivative::new(2, 1, Q3).unwrap())
    .unwrap();
    (filter, rows)
}

/// The 3-state polynomial filter (constant acceleration on one axis, `Φ = Ψ(ζ)`, white jerk of
/// spectral density `q`, `Q(ζ)` of (15.2.23) in closed form), the position observed with
/// variance `r`: from `x`, `s` at `t0` over the samples `(ts[i], ys[i])`.
pub fn kalman3(
    mut x: [f64; 3],
    mut s: [[f64; 3]; 3],
    t0: f64,
    q: f64,
    r: f64,
    ts: &[f64],
    ys: &[f64],
) -> ([f64; 3], [[f64; 3]; 3], f64) {
    let mut t_prev = t0;
    let mut total = 0.0;
    let ln_tau = TAU.ln();
    for (&t, &y) in ts.iter().zip(ys) {
        let z = t - t_prev;
        t_prev = t;
        let (z2, z3) = (z * z, z * z * z);
        let (z4, z5) = (z3 * z, z3 * z2);
        let h = 0.5 * z2;
        // X = Φ x; A = Φ S (rows of Φ: [1, ζ, ζ²/2], [0, 1, ζ], [0, 0, 1]).
        let xp = [x[0] + z * x[1] + h * x[2], x[1] + z * x[2], x[2]];
        let mut a = [[0.0; 3]; 3];
        for j in 0..3 {
            a[0][j] = s[0][j] + z * s[1][j] + h * s[2][j];
            a[1][j] = s[1][j] + z * s[2][j];
            a[2][j] = s[2][j];
        }
        // P = A Φᵀ + Q (upper triangle, mirrored).
        let qm = [
            [q * z5 / 20.0, q * z4 / 8.0, q * z3 / 6.0],
            [0.0, q * z3 / 3.0, q * z2 / 2.0],
            [0.0, 0.0, q * z],
        ];
        let mut p = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in i..3 {
                let v = match j {
                    0 => a[i][0] + z * a[i][1] + h * a[i][2],
                    1 => a[i][1] + z * a[i][2],
                    _ => a[i][2],
                } + qm[i][j];
                p[i][j] = v;
                p[j][i] = v;
            }
        }
        // One component: U = P Mᵀ = P's first column, V = U₀ + r, H = U / V.
        let v = p[0][0] + r;
        let nu = y - xp[0];
        let nis = nu * nu / v;
        total += -0.5 * (nis + v.ln() + ln_tau);
        let gain = [p[0][0] / v, p[1][0] / v, p[2][0] / v];
        for i in 0..3 {
            x[i] = xp[i] + gain[i] * nu;
        }
        // Joseph: X = P − H (M P), then X − (X Mᵀ) Hᵀ + H r Hᵀ.
        let mut xm = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                xm[i][j] = p[i][j] - gain[i] * p[0][j];
            }
        }
        for i in 0..3 {
            for j in i..3 {
                let lower = xm[i][j] - xm[i][0] * gain[j] + gain[i] * r * gain[j];
                let upper = xm[j][i] - xm[j][0] * gain[i] + gain[j] * r * gain[i];
                let v = 0.5 * (lower + upper);
                s[i][j] = v;
                s[j][i] = v;
            }
        }
    }
    (x, s, total)
}

/// The 6-state radar extended filter (constant velocity on three axes, state
/// `(x, y, z, vx, vy, vz)`, white acceleration of spectral density `q`; range, azimuth and
/// elevation from a radar at the origin, variances `r`): from `x`, `s` at `t0` over the
/// measurements `(ts[i], zs[i])`. `Φ S Φᵀ` by the constant-velocity blocks, `M` on the
/// position columns only (its Jacobian `J`, 3 × 3), `V = L D Lᵀ` (3 × 3).
pub fn ekf6(
    x: [f64; 6],
    s: [[f64; 6]; 6],
    t0: f64,
    q: f64,
    r: [f64; 3],
    ts: &[f64],
    zs: &[[f64; 3]],
) -> ([f64; 6], [[f64; 6]; 6], f64) {
    ekf6_over(x, s, t0, q, ts.iter().zip(zs).map(|(&t, z)| (t, *z, r)))
}

/// [`ekf6`] reading what the library reads, the `Measurement` rows (each one's time, its
/// three values and the variances of its `R`, from their own allocations), instead of flat
/// arrays made beforehand: the same loop on the library's input (`examples/kalman_floor_pace.rs`;
/// the criterion bench does not time it).
#[allow(dead_code)]
pub fn ekf6_rows(
    x: [f64; 6],
    s: [[f64; 6]; 6],
    t0: f64,
    q: f64,
    rows: &[Measurement],
) -> ([f64; 6], [[f64; 6]; 6], f64) {
    let read = |m: &Measurement| {
        let z = [0, 1, 2].map(|c| m.values[c].expect("every component present"));
        let r = match &m.noise {
            NoiseCovariance::Variances(v) => [v[0], v[1], v[2]],
            NoiseCovariance::Identity => [1.0; 3],
            NoiseCovariance::Full(_) => panic!("a diagonal R"),
        };
        (m.time, z, r)
    };
    ekf6_over(x, s, t0, q, rows.iter().map(read))
}

/// The loop of [`ekf6`] over `(time, values, variances)`.
#[inline(always)]
fn ekf6_over(
    mut x: [f64; 6],
    mut s: [[f64; 6]; 6],
    t0: f64,
    q: f64,
    rows: impl Iterator<Item = (f64, [f64; 3], [f64; 3])>,
) -> ([f64; 6], [[f64; 6]; 6], f64) {
    let mut t_prev = t0;
    let mut total = 0.0;
    let ln_tau = TAU.ln();
    for (t, zm, r) in rows {
        let z = t - t_prev;
        t_prev = t;
        let mut xp = x;
        for a in 0..3 {
            xp[a] += z * x[a + 3];
        }
        // Blocks of S: [[A, B], [Bᵀ, C]]; Φ S Φᵀ = [[A + ζ(B + Bᵀ) + ζ² C, B + ζ C], [·, C]].
        let mut p = [[0.0; 6]; 6];
        for i in 0..3 {
            for j in 0..3 {
                let (b, bt, c) = (s[i][j + 3], s[i + 3][j], s[i + 3][j + 3]);
                p[i][j] = s[i][j] + z * (b + bt) + z * z * c;
                p[i][j + 3] = b + z * c;
                p[i + 3][j] = bt + z * c;
                p[i + 3][j + 3] = c;
            }
        }
        let (q3, q2, q1) = (q * z * z * z / 3.0, q * z * z / 2.0, q * z);
        for a in 0..3 {
            p[a][a] += q3;
            p[a][a + 3] += q2;
            p[a + 3][a] += q2;
            p[a + 3][a + 3] += q1;
        }
        // The radar's prediction and Jacobian on the position.
        let (px, py, pz) = (xp[0], xp[1], xp[2]);
        let h2 = px * px + py * py;
        let rho2 = h2 + pz * pz;
        let (hh, rho) = (h2.sqrt(), rho2.sqrt());
        let g = [rho, (py + 0.0).atan2(px), pz.atan2(hh)];
        let jm = [
            [px / rho, py / rho, pz / rho],
            [-py / h2, px / h2, 0.0],
            [-px * pz / (rho2 * hh), -py * pz / (rho2 * hh), hh / rho2],
        ];
        // U = P Mᵀ (6 × 3) = P[:, 0..3] Jᵀ; V = J U[0..3] + R.
        let mut u = [[0.0; 3]; 6];
        for i in 0..6 {
            for c in 0..3 {
                u[i][c] = p[i][0] * jm[c][0] + p[i][1] * jm[c][1] + p[i][2] * jm[c][2];
            }
        }
        let mut v = [[0.0; 3]; 3];
        for a in 0..3 {
            for b in 0..3 {
                v[a][b] = jm[a][0] * u[0][b] + jm[a][1] * u[1][b] + jm[a][2] * u[2][b];
            }
            v[a][a] += r[a];
        }
        for a in 0..3 {
            for b in a + 1..3 {
                let m = 0.5 * (v[a][b] + v[b][a]);
                v[a][b] = m;
                v[b][a] = m;
            }
        }
        // V = L D Lᵀ.
        let d0 = v[0][0];
        let l10 = v[1][0] / d0;
        let l20 = v[2][0] / d0;
        let d1 = v[1][1] - l10 * l10 * d0;
        let l21 = (v[2][1] - l20 * l10 * d0) / d1;
        let d2 = v[2][2] - l20 * l20 * d0 - l21 * l21 * d1;
        let nu = [zm[0] - g[0], wrap(zm[1] - g[1]), zm[2] - g[2]];
        let y0 = nu[0];
        let y1 = nu[1] - l10 * y0;
        let y2 = nu[2] - l20 * y0 - l21 * y1;
        let nis = y0 * y0 / d0 + y1 * y1 / d1 + y2 * y2 / d2;
        total += -0.5 * (nis + (d0 * d1 * d2).ln() + 3.0 * ln_tau);
        // H = U L⁻ᵀ D⁻¹ L⁻¹, row by row.
        let mut gain = [[0.0; 3]; 6];
        for i in 0..6 {
            let g0 = u[i][0];
            let g1 = u[i][1] - l10 * g0;
            let g2 = u[i][2] - l20 * g0 - l21 * g1;
            let (w0, w1, w2) = (g0 / d0, g1 / d1, g2 / d2);
            let h2v = w2;
            let h1v = w1 - l21 * h2v;
            let h0v = w0 - l10 * h1v - l20 * h2v;
            gain[i] = [h0v, h1v, h2v];
        }
        for i in 0..6 {
            x[i] = xp[i] + gain[i][0] * nu[0] + gain[i][1] * nu[1] + gain[i][2] * nu[2];
        }
        // Joseph: X = P − H Uᵀ, Y = X Mᵀ = X[:, 0..3] Jᵀ, X − Y Hᵀ + H R Hᵀ.
        let mut xm = [[0.0; 6]; 6];
        for i in 0..6 {
            for j in 0..6 {
                xm[i][j] =
                    p[i][j] - (gain[i][0] * u[j][0] + gain[i][1] * u[j][1] + gain[i][2] * u[j][2]);
            }
        }
        let mut y = [[0.0; 3]; 6];
        for i in 0..6 {
            for c in 0..3 {
                y[i][c] = xm[i][0] * jm[c][0] + xm[i][1] * jm[c][1] + xm[i][2] * jm[c][2];
            }
        }
        for i in 0..6 {
            for j in 0..6 {
                let mut acc = xm[i][j];
                for c in 0..3 {
                    acc += gain[i][c] * (r[c] * gain[j][c]) - y[i][c] * gain[j][c];
                }
                s[i][j] = acc;
            }
        }
        for i in 0..6 {
            for j in i + 1..6 {
                let m = 0.5 * (s[i][j] + s[j][i]);
                s[i][j] = m;
                s[j][i] = m;
            }
        }
    }
    (x, s, total)
}
