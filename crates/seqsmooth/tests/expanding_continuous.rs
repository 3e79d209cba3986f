//! `polynomial::expanding::continuous` (Luenberger 1967): `b = H⁻¹·1` against its closed form
//! in exact rationals (`n ≤ 12`), the printed expression's misprint, the Taylor-form gains as
//! the limit of Morrison's expanding-memory gains (Table 9.1, `n^(k+1) h_k(n) → g_k`), and the
//! discretised estimator against a direct least-squares fit of the signal over `[0, T]`
//! (Gauss–Legendre quadrature, QR), converging as `h⁴`.

use nalgebra::{DMatrix, DVector};
use num_traits::ToPrimitive;
use seqsmooth::basis::legendre::taylor_table;
use seqsmooth::basis::Jacobi;
use seqsmooth::polynomial::expanding::continuous::{
    hilbert_gains, luenberger_gains, luenberger_gains_as_printed, taylor_gains,
    ContinuousExpandingMemory,
};
use seqsmooth::polynomial::expanding::gains::expanding_gains;
use seqsmooth::polynomial::form::GainForm;
use seqsmooth::scalar::Rational;
use seqsmooth::Error;

#[test]
fn b_is_the_inverse_hilbert_row_sum_and_its_closed_form() {
    for n in 1..=12 {
        let exact: Vec<Rational> = hilbert_gains(n);
        let closed: Vec<Rational> = luenberger_gains(n);
        assert_eq!(exact, closed, "n = {n}");
        assert!(exact.iter().all(|b| b.is_integer()), "n = {n}");
        let sum: Rational = exact.iter().sum();
        assert_eq!(sum, Rational::from_integer((n * n).into()), "n = {n}");
        let printed: Vec<Rational> = luenberger_gains_as_printed(n);
        assert_eq!(printed == exact, n <= 2, "n = {n}: the printed expression");
    }
    // his vectors for n = 1..8 as integers
    let want: [&[i64]; 8] = [
        &[1],
        &[-2, 6],
        &[3, -24, 30],
        &[-4, 60, -180, 140],
        &[5, -120, 630, -1120, 630],
        &[-6, 210, -1680, 5040, -6300, 2772],
        &[7, -336, 3780, -16800, 34650, -33264, 12012],
        &[-8, 504, -7560, 46200, -138600, 216216, -168168, 51480],
    ];
    for (n, w) in want.iter().enumerate() {
        let b: Vec<f64> = luenberger_gains(n + 1);
        assert_eq!(b, w.iter().map(|&v| v as f64).collect::<Vec<_>>());
    }
    // the closed form stays exact in f64 to n = 21 (max |b_j| below 2^53)
    let b21: Vec<Rational> = luenberger_gains(21);
    let f21: Vec<f64> = luenberger_gains(21);
    for (r, f) in b21.iter().zip(&f21) {
        assert_eq!(Rational::from_float(*f).unwrap(), *r);
    }
}

/// `g_k = lim n^(k+1) h_k(n)` for Morrison's expanding-memory gains (Table 9.1), `m ≤ 5`:
/// at `n = 10⁶` the ratio is within `1e-4` of 1; and `g_0 = (m+1)²`.
#[test]
fn taylor_gains_are_the_limit_of_the_discrete_gains() {
    for m in 0..=5 {
        let g: Vec<f64> = taylor_gains(m);
        assert_eq!(g[0], ((m + 1) * (m + 1)) as f64);
        let n: u64 = 1_000_000;
        let h: Vec<Rational> = expanding_gains(m, n, GainForm::Current);
        for (k, (hk, gk)) in h.iter().zip(&g).enumerate() {
            let scaled = (hk * Rational::from_integer(n.into()).pow(k as i32 + 1))
                .to_f64()
                .unwrap();
            assert!(
                (scaled / gk - 1.0).abs() < 1e-4,
                "m {m} k {k}: {scaled} {gk}"
            );
        }
    }
    assert_eq!(taylor_gains::<f64>(3), vec![16.0, 120.0, 240.0, 140.0]);
    assert_eq!(
        taylor_gains::<f64>(5),
        vec![36.0, 630.0, 3360.0, 7560.0, 7560.0, 2772.0]
    );
}

/// The least-squares polynomial of degree `m` of `x` over `[start, start + t]`, its
/// derivatives at `start + t`: a direct QR solve on 40 Gauss–Legendre nodes in the Legendre
/// basis (exact for the polynomial part; `x` smooth).
fn direct_fit(x: &dyn Fn(f64) -> f64, m: usize, start: f64, t: f64) -> Vec<f64> {
    let h = t / 2.0;
    let g = Jacobi::legendre(39, -1.0, 1.0).unwrap().gauss().unwrap();
    let rows = g.offsets.len();
    let a = DMatrix::from_fn(rows, m + 1, |r, j| {
        g.weights[r].sqrt() * seqsmooth::basis::legendre::values(m, g.offsets[r])[j]
    });
    let y = DVector::from_fn(rows, |r, _| {
        g.weights[r].sqrt() * x(start + h + h * g.offsets[r])
    });
    let (q, r) = a.qr().unpack();
    let coef = r.solve_upper_triangular(&(q.transpose() * y)).unwrap();
    let table = taylor_table(m, m, 1.0); // P_j^(k)(1)/k!
    let mut factorial = 1.0;
    (0..=m)
        .map(|k| {
            if k > 0 {
                factorial *= k as f64;
            }
            (0..=m).map(|j| coef[j] * table[(k, j)]).sum::<f64>() * factorial / h.powi(k as i32)
        })
        .collect()
}

#[test]
fn the_estimator_converges_to_the_least_squares_fit_as_h_to_the_fourth() {
    let signals: [(&str, &dyn Fn(f64) -> f64); 2] = [
        ("exp", &|t: f64| t.exp()),
        ("sin", &|t: f64| (2.0 * t).sin() + 0.3 * t),
    ];
    for (name, x) in signals {
        for m in [1, 2, 4] {
            let (t0, t1) = (0.5, 3.0);
            let want = direct_fit(x, m, 0.0, t1);
            let scale = want.iter().fold(1.0f64, |s, v| s.max(v.abs()));
            let mut errors = Vec::new();
            for steps in [100, 200, 400, 800] {
                let mut f =
                    ContinuousExpandingMemory::new(m, 0.0, t0, &direct_fit(x, m, 0.0, t0)).unwrap();
                f.advance(x, t1 - t0, steps).unwrap();
                assert!((f.elapsed() - t1).abs() < 1e-15);
                let err = f
                    .derivatives()
                    .iter()
                    .zip(&want)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f64::max)
                    / scale;
                errors.push(err);
            }
            // fourth order: each halving of h divides the error by ≈ 16, until rounding
            for pair in errors.windows(2) {
                let ratio = pair[0] / pair[1];
                assert!(
                    (11.0..=22.0).contains(&ratio) || pair[1] < 1e-12,
                    "{name} m {m}: {errors:?}"
                );
            }
            assert!(errors[3] < 1e-8, "{name} m {m}: {errors:?}");
        }
    }
}

/// The same signal observed from a Unix-epoch start gives the same fit (to rounding).
#[test]
fn the_estimator_does_not_depend_on_the_start_time() {
    let x = |t: f64| (t - 1.7e9).exp();
    let y = |t: f64| t.exp();
    let start = direct_fit(&y, 2, 0.0, 0.5);
    let mut a = ContinuousExpandingMemory::new(2, 1.7e9, 0.5, &start).unwrap();
    let mut b = ContinuousExpandingMemory::new(2, 0.0, 0.5, &start).unwrap();
    a.advance(x, 2.0, 200).unwrap();
    b.advance(y, 2.0, 200).unwrap();
    // x(t) at t = 1.7e9 + s rounds s to 2.4e-7: the signal itself differs by that much
    for (p, q) in a.derivatives().iter().zip(b.derivatives()) {
        assert!((p - q).abs() <= 1e-5 * q.abs().max(1.0), "{p} {q}");
    }
}

#[test]
fn bad_starts_and_signals_are_refused() {
    assert!(ContinuousExpandingMemory::new(1, 0.0, 0.0, &[1.0, 0.0]).is_err());
    assert!(ContinuousExpandingMemory::new(1, 0.0, 1.0, &[1.0]).is_err());
    assert!(matches!(
        ContinuousExpandingMemory::new(21, 0.0, 1.0, &[0.0; 22]),
        Err(Error::DegreeOutOfRange {
            degree: 21,
            max: 20
        })
    ));
    assert!(ContinuousExpandingMemory::new(1, f64::NAN, 1.0, &[1.0, 0.0]).is_err());
    let mut f = ContinuousExpandingMemory::new(1, 0.0, 1.0, &[1.0, 0.0]).unwrap();
    let e = f
        .advance(|t| if t > 1.5 { f64::NAN } else { 1.0 }, 1.0, 10)
        .unwrap_err();
    assert!(matches!(e, Error::NonFinite { .. }), "{e}");
    assert_eq!((f.elapsed(), f.derivatives()), (1.0, vec![1.0, 0.0]));
    assert!(f.advance(|_| 1.0, 0.0, 10).is_err());
    assert!(f.advance(|_| 1.0, 1.0, 0).is_err());
}
