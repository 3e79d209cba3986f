//! Villien & Ostertag's Example 3 (§VI-C, eqs. 43-44, Table III): a walker inside four UWB
//! emitters at the corners of a 19 m square, three range differences `h_1j = ‖p − R₁‖ −
//! ‖p − R_j‖` (eq. 43 times `c`, with the bracket put right) every 2 ms, quantised to 2,048
//! values; each 2 s segment fitted by the quadratic track of eq. 44 (`θ = x₀, y₀, v_x, v_y, a_x,
//! a_y`) from the raw samples (ML) and from each stream's 6 polynomial samples of order 5
//! (PAML), against the extended Kalman filter on the true state-space model; the RMS position
//! error over every sample of 200 s runs. The paper prints neither the walker's motion nor the
//! noise: both are chosen here (constants below). Shared by the example `paml_example3` and
//! the test `paml_examples` (included by path).

#![allow(dead_code)]

use nalgebra::{DMatrix, DVector, Matrix2, Matrix4};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::StandardNormal;
use rayon::prelude::*;
use seqsmooth::estimate::curve::{fit_curve, CurveModel};
use seqsmooth::kalman::noise::MatrixNoise;
use seqsmooth::kalman::KalmanFilter;
use seqsmooth::model::linear::LinearDynamics;
use seqsmooth::model::measurement::{Measurement, NoiseCovariance};
use seqsmooth::model::observation::NonlinearObservation;
use seqsmooth::paml::PolynomialSamples;
use seqsmooth::Error;

/// Half the square's side (m): emitters at `(±9.5, ±9.5)`, the square's centre the origin.
pub const HALF: f64 = 9.5;
/// The emitters `R₁..R₄` (counter-clockwise from the lower left).
pub const EMITTERS: [[f64; 2]; 4] = [[-HALF, -HALF], [HALF, -HALF], [HALF, HALF], [-HALF, HALF]];
/// The sampling interval (s), as printed.
pub const STEP: f64 = 0.002;
/// The segment length `T` (s), as printed.
pub const SEGMENT: f64 = 2.0;
/// A run's length (s), as printed.
pub const DURATION: f64 = 200.0;
/// The polynomial samples' order, as printed.
pub const ORDER: usize = 5;
/// The TDOA's 2,048 levels span `±` the square's diagonal (m of range difference).
pub const LSB: f64 = 2.0 * 2.0 * HALF * std::f64::consts::SQRT_2 / 2048.0;
/// The walker (not printed): each axis a damped oscillator about the centre driven by white
/// acceleration noise, `ẍ = −ω² x − 2ζω ẋ + w`, `ω = 0.1 rad/s`, `ζ = 0.7`, and `q` (m²/s³)
/// the noise's spectral density, so that the walker stays within about 4 m (1σ) of the
/// centre at 0.4 m/s (1σ).
pub const OMEGA: f64 = 0.1;
pub const ZETA: f64 = 0.7;
pub const Q: f64 = 0.045;

/// One axis's `A`.
fn axis_a() -> Matrix2<f64> {
    Matrix2::new(0.0, 1.0, -OMEGA * OMEGA, -2.0 * ZETA * OMEGA)
}

/// `Φ` and `Q` of one axis over `STEP` (Van Loan: `exp([[−A, G q Gᵀ], [0, Aᵀ]] Δt)`).
fn axis_step() -> (Matrix2<f64>, Matrix2<f64>) {
    let a = axis_a();
    let mut m = Matrix4::zeros();
    m.fixed_view_mut::<2, 2>(0, 0).copy_from(&(-a * STEP));
    m[(1, 3)] = Q * STEP;
    m.fixed_view_mut::<2, 2>(2, 2)
        .copy_from(&(a.transpose() * STEP));
    let e = m.exp();
    let phi = e.fixed_view::<2, 2>(2, 2).transpose();
    let q = phi * e.fixed_view::<2, 2>(0, 2);
    (phi, (q + q.transpose()) * 0.5)
}

/// The stationary covariance of one axis: `diag(q/(4ζω³), q/(4ζω))`.
fn axis_stationary() -> [f64; 2] {
    [Q / (4.0 * ZETA * OMEGA.powi(3)), Q / (4.0 * ZETA * OMEGA)]
}

/// `h_1j` for `j = 2, 3, 4` at position `p`, and its gradient in `p`.
fn tdoa(p: [f64; 2], pair: usize) -> (f64, [f64; 2]) {
    let (a, b) = (EMITTERS[0], EMITTERS[pair + 1]);
    let d1 = (p[0] - a[0]).hypot(p[1] - a[1]);
    let dj = (p[0] - b[0]).hypot(p[1] - b[1]);
    (
        d1 - dj,
        [
            (p[0] - a[0]) / d1 - (p[0] - b[0]) / dj,
            (p[1] - a[1]) / d1 - (p[1] - b[1]) / dj,
        ],
    )
}

/// Eq. 44 over a segment, the rows `(t, pair)` addressed by their index (the fit's "time").
struct Segment {
    rows: Vec<(f64, usize)>,
}

fn position(th: &[f64], t: f64) -> [f64; 2] {
    [
        th[0] + th[2] * t + 0.5 * th[4] * t * t,
        th[1] + th[3] * t + 0.5 * th[5] * t * t,
    ]
}

impl CurveModel for Segment {
    fn parameters(&self) -> usize {
        6
    }
    fn values(&self, th: &[f64], index: &[f64]) -> Result<Vec<f64>, Error> {
        Ok(index
            .iter()
            .map(|&i| {
                let (t, pair) = self.rows[i as usize];
                tdoa(position(th, t), pair).0
            })
            .collect())
    }
    fn jacobian(&self, th: &[f64], index: &[f64]) -> Option<Result<DMatrix<f64>, Error>> {
        let mut j = DMatrix::zeros(index.len(), 6);
        for (r, &i) in index.iter().enumerate() {
            let (t, pair) = self.rows[i as usize];
            let g = tdoa(position(th, t), pair).1;
            for (c, f) in [1.0, t, 0.5 * t * t].into_iter().enumerate() {
                j[(r, 2 * c)] = g[0] * f;
                j[(r, 2 * c + 1)] = g[1] * f;
            }
        }
        Some(Ok(j))
    }
}

/// A run's sums of squared position errors `[ml, paml, ekf]` and the samples counted.
struct Run {
    squares: [f64; 3],
    samples: usize,
    failed: usize,
}

fn run(seed: u64, index: usize, sigma: f64, duration: f64) -> Run {
    let mut rng = StdRng::seed_from_u64(seed ^ (index as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
    let normal = |rng: &mut StdRng| rng.sample::<f64, _>(StandardNormal);
    let (phi, q) = axis_step();
    let lq = q.cholesky().expect("Q > 0").l();
    let stat = axis_stationary();
    let steps = (duration / STEP).round() as usize;
    // The truth: x, y positions and velocities, from the stationary distribution.
    let mut axes: [nalgebra::Vector2<f64>; 2] = [0, 1].map(|_| {
        nalgebra::Vector2::new(
            stat[0].sqrt() * normal(&mut rng),
            stat[1].sqrt() * normal(&mut rng),
        )
    });
    let mut truth = Vec::with_capacity(steps);
    let mut ys = Vec::with_capacity(steps);
    for _ in 0..steps {
        let p = [axes[0][0], axes[1][0]];
        truth.push(p);
        ys.push([0, 1, 2].map(|pair| {
            let v = tdoa(p, pair).0 + sigma * normal(&mut rng);
            (v / LSB).round() * LSB
        }));
        for a in &mut axes {
            let w = lq * nalgebra::Vector2::new(normal(&mut rng), normal(&mut rng));
            *a = phi * *a + w;
        }
    }
    // The EKF on the true model: state (x, y, ẋ, ẏ), prior the stationary distribution.
    let mut a4 = DMatrix::zeros(4, 4);
    let mut q4 = DMatrix::zeros(4, 4);
    let a = axis_a();
    for ax in 0..2 {
        for (r, c) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
            a4[(2 * r + ax, 2 * c + ax)] = a[(r, c)];
            q4[(2 * r + ax, 2 * c + ax)] = q[(r, c)];
        }
    }
    let observation = NonlinearObservation::new(3, 4, |_t, x: &DVector<f64>| {
        DVector::from_iterator(3, (0..3).map(|j| tdoa([x[0], x[1]], j).0))
    })
    .with_jacobian(|_t, x: &DVector<f64>| {
        let mut h = DMatrix::zeros(3, 4);
        for j in 0..3 {
            let g = tdoa([x[0], x[1]], j).1;
            h[(j, 0)] = g[0];
            h[(j, 1)] = g[1];
        }
        h
    });
    let p0 = DMatrix::from_diagonal(&DVector::from_vec(vec![stat[0], stat[0], stat[1], stat[1]]));
    let mut filter = KalmanFilter::new(
        LinearDynamics::new(a4).expect("A"),
        observation,
        DVector::zeros(4),
        p0,
        0.0,
    )
    .and_then(|f| f.with_process_noise(MatrixNoise::new(q4)?))
    .expect("filter");
    let mut squares = [0.0; 3];
    let per = (SEGMENT / STEP).round() as usize;
    let mut failed = 0;
    let mut start = [0.0; 6];
    let noise = vec![sigma; 3 * per];
    for (s, chunk) in ys.chunks(per).enumerate() {
        let t0 = s as f64 * SEGMENT;
        let times: Vec<f64> = (0..chunk.len()).map(|k| k as f64 * STEP).collect();
        // The EKF, sample by sample.
        for (k, y) in chunk.iter().enumerate() {
            let m = Measurement {
                time: t0 + times[k],
                values: y.iter().map(|&v| Some(v)).collect(),
                noise: NoiseCovariance::Variances(vec![sigma * sigma; 3]),
            };
            filter.update(&m).expect("EKF update");
            let x = filter.state();
            let p = truth[s * per + k];
            squares[2] += (x[0] - p[0]).powi(2) + (x[1] - p[1]).powi(2);
        }
        // ML on the 3 × 1000 raw samples.
        let rows: Vec<(f64, usize)> = (0..3)
            .flat_map(|pair| times.iter().map(move |&t| (t, pair)))
            .collect();
        let index: Vec<f64> = (0..rows.len()).map(|i| i as f64).collect();
        let values: Vec<f64> = (0..3)
            .flat_map(|pair| chunk.iter().map(move |y| y[pair]))
            .collect();
        let raw = fit_curve(
            &Segment { rows },
            &index,
            &values,
            &noise[..index.len()],
            &start,
        );
        // PAML on each stream's 6 polynomial samples.
        let mut rows = vec![];
        let mut values = vec![];
        let mut sigmas = vec![];
        for pair in 0..3 {
            let y: Vec<f64> = chunk.iter().map(|y| y[pair]).collect();
            let ps = PolynomialSamples::from_segment(&times, &y, &vec![sigma; y.len()], ORDER)
                .expect("polynomial samples");
            for ((t, v), var) in ps.times().into_iter().zip(ps.values).zip(ps.variances) {
                rows.push((t, pair));
                values.push(v);
                sigmas.push(var.sqrt());
            }
        }
        let index: Vec<f64> = (0..rows.len()).map(|i| i as f64).collect();
        let paml = fit_curve(&Segment { rows }, &index, &values, &sigmas, &start);
        let (Ok(raw), Ok(paml)) = (raw, paml) else {
            failed += 1;
            continue;
        };
        for (m, fit) in [&raw, &paml].into_iter().enumerate() {
            for (k, &t) in times.iter().enumerate() {
                let e = position(fit.parameters.as_slice(), t);
                let p = truth[s * per + k];
                squares[m] += (e[0] - p[0]).powi(2) + (e[1] - p[1]).powi(2);
            }
        }
        // The next segment starts where this one's ML track ends.
        let th = raw.parameters.as_slice();
        let t = chunk.len() as f64 * STEP;
        start = [
            th[0] + th[2] * t + 0.5 * th[4] * t * t,
            th[1] + th[3] * t + 0.5 * th[5] * t * t,
            th[2] + th[4] * t,
            th[3] + th[5] * t,
            th[4],
            th[5],
        ];
    }
    Run {
        squares,
        samples: steps,
        failed,
    }
}

/// Table III's three RMS errors (m) `[ml, paml, ekf]`, segments that failed, and the report.
pub struct Report {
    pub rms: [f64; 3],
    pub failed: usize,
    pub text: String,
}

/// `runs` runs of `duration` seconds with range-difference noise `sigma` (m), from `seed`.
pub fn table(runs: usize, seed: u64, sigma: f64, duration: f64) -> ([f64; 3], usize) {
    let all: Vec<Run> = (0..runs)
        .into_par_iter()
        .map(|i| run(seed, i, sigma, duration))
        .collect();
    let n: usize = all.iter().map(|r| r.samples).sum();
    let failed = all.iter().map(|r| r.failed).sum();
    let rms = [0, 1, 2].map(|m| (all.iter().map(|r| r.squares[m]).sum::<f64>() / n as f64).sqrt());
    (rms, failed)
}

/// The noise σ of each range difference (m) that the page's table uses (not printed; chosen
/// so that ML's RMS error is about the paper's 8 cm), and the others shown.
pub const SIGMA: f64 = 1.5;
pub const SIGMAS: [f64; 3] = [0.5, SIGMA, 3.0];

pub fn report(runs: usize, seed: u64) -> Report {
    let sig = |v: f64| format!("{:.2}", v * 100.0);
    let mut text = format!(
        "Example 3: {runs} runs of {DURATION} s, seed {seed}; 4 emitters at (±{HALF}, ±{HALF}) m, \
         3 range differences every {} ms quantised to {:.2} cm, segments of {SEGMENT} s, \
         PAML order {ORDER}\n\n",
        STEP * 1e3,
        LSB * 100.0
    );
    text.push_str("| noise σ (m) | ML (cm) | PAML (cm) | EKF (cm) | PAML / ML | EKF / ML | failed segments |\n");
    text.push_str("|---:|---:|---:|---:|---:|---:|---:|\n");
    text.push_str("| paper (Table III) | 8 | 8.1 | 8.2 | 1.0125 | 1.025 | |\n");
    let mut main = ([0.0; 3], 0);
    for s in SIGMAS {
        let (rms, failed) = table(runs, seed, s, DURATION);
        if s == SIGMA {
            main = (rms, failed);
        }
        text.push_str(&format!(
            "| {s} | {} | {} | {} | {:.4} | {:.4} | {failed} |\n",
            sig(rms[0]),
            sig(rms[1]),
            sig(rms[2]),
            rms[1] / rms[0],
            rms[2] / rms[0],
        ));
    }
    Report {
        rms: main.0,
        failed: main.1,
        text,
    }
}
