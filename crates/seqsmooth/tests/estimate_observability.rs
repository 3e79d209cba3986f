//! `estimate::observability`: Theorem 8.1's rank test on Morrison §8.9's Examples 1-4 and
//! Ex. 8.23-8.25, and the theorem itself: the stacked `T = [M Φ(0); M Φ(−1); …]` of
//! `estimate::batch` has the same rank once the window is long enough.

use nalgebra::{DMatrix, DVector};
use seqsmooth::estimate::batch::{minimum_variance, NoiseCovariance};
use seqsmooth::estimate::observability::observability;
use seqsmooth::model::linear::LinearDynamics;
use seqsmooth::Error;

fn dynamics(n: usize, a: &[f64]) -> LinearDynamics {
    LinearDynamics::new(DMatrix::from_row_slice(n, n, a)).unwrap()
}

fn rows(n: usize, m: &[f64]) -> DMatrix<f64> {
    DMatrix::from_row_slice(m.len() / n, n, m)
}

/// The rank `estimate::batch` finds for `T` stacked over `L + 1` samples one unit apart.
fn batch_rank(d: &LinearDynamics, m: &DMatrix<f64>, l: usize) -> usize {
    let n = d.dimension();
    let p = m.nrows();
    let mut t = DMatrix::zeros(p * (l + 1), n);
    for k in 0..=l {
        let block = m * d.transition(-(k as f64)).unwrap();
        t.rows_mut(k * p, p).copy_from(&block);
    }
    let y = DVector::from_element(t.nrows(), 1.0);
    match minimum_variance(&t, &y, &NoiseCovariance::Identity) {
        Ok(_) => n,
        Err(Error::Unobservable { rank, .. }) => rank,
        Err(e) => panic!("{e}"),
    }
}

#[test]
fn morrison_8_9_examples_and_exercises() {
    let shift3 = [0., 1., 0., 0., 0., 1., 0., 0., 0.];
    let w = 0.7;
    let cases: Vec<(&str, LinearDynamics, DMatrix<f64>, usize)> = vec![
        // Example 1: M = (1, 0, 0), G = I (8.9.12)-(8.9.15).
        ("Example 1", dynamics(3, &shift3), rows(3, &[1., 0., 0.]), 3),
        // Example 2: M = (0, 1, 0), rank 2 (8.9.16)-(8.9.17).
        ("Example 2", dynamics(3, &shift3), rows(3, &[0., 1., 0.]), 2),
        // Example 4: x'' = −ω² x, observing x or ẋ suffices (8.9.21)-(8.9.22).
        (
            "Example 4, x",
            dynamics(2, &[0., 1., -w * w, 0.]),
            rows(2, &[1., 0.]),
            2,
        ),
        (
            "Example 4, ẋ",
            dynamics(2, &[0., 1., -w * w, 0.]),
            rows(2, &[0., 1.]),
            2,
        ),
        // Ex. 8.23: Φ = [[1, ζ, 0], [0, 1, 0], [0, 0, 1]].
        (
            "Ex. 8.23 (1,0,1)",
            dynamics(3, &[0., 1., 0., 0., 0., 0., 0., 0., 0.]),
            rows(3, &[1., 0., 1.]),
            2,
        ),
        (
            "Ex. 8.23 two rows",
            dynamics(3, &[0., 1., 0., 0., 0., 0., 0., 0., 0.]),
            rows(3, &[1., 0., 1., 1., 0., 0.]),
            3,
        ),
        // Ex. 8.24: Φ = [[1 − ζ, ζ], [−ζ, 1 + ζ]], one eigenvector (1, 1): M (1, 1)ᵀ ≠ 0 needed.
        (
            "Ex. 8.24 (1,0)",
            dynamics(2, &[-1., 1., -1., 1.]),
            rows(2, &[1., 0.]),
            2,
        ),
        (
            "Ex. 8.24 (1,-1)",
            dynamics(2, &[-1., 1., -1., 1.]),
            rows(2, &[1., -1.]),
            1,
        ),
        // Ex. 8.25: Φ = [[1, ζ, 0], [0, 1, 0], [0, ζ, 1]].
        (
            "Ex. 8.25 (1,0,-1)",
            dynamics(3, &[0., 1., 0., 0., 0., 0., 0., 1., 0.]),
            rows(3, &[1., 0., -1.]),
            1,
        ),
        (
            "Ex. 8.25 (1,0,1)",
            dynamics(3, &[0., 1., 0., 0., 0., 0., 0., 1., 0.]),
            rows(3, &[1., 0., 1.]),
            2,
        ),
        (
            "Ex. 8.25 two rows",
            dynamics(3, &[0., 1., 0., 0., 0., 0., 0., 1., 0.]),
            rows(3, &[1., 0., -1., 1., 0., 1.]),
            3,
        ),
    ];
    for (name, d, m, rank) in cases {
        let o = observability(&d, &m).unwrap();
        assert_eq!(o.rank, rank, "{name}");
        assert_eq!(o.is_observable(), rank == d.dimension(), "{name}");
        assert_eq!(o.check().is_ok(), o.is_observable(), "{name}");
        // Theorem 8.1: the same rank from enough samples.
        assert_eq!(
            batch_rank(&d, &m, 3 * d.dimension()),
            rank,
            "{name}: T's rank"
        );
    }
    // Example 1 with too short a window: rank 2 at L = 1, 3 from L = 2 (8.9.15).
    let (d, m) = (dynamics(3, &shift3), rows(3, &[1., 0., 0.]));
    assert_eq!(batch_rank(&d, &m, 1), 2);
    assert_eq!(batch_rank(&d, &m, 2), 3);
}

#[test]
fn polynomial_models_of_high_degree() {
    // Observed in position, every degree is observable; in any derivative j > 0 alone, the
    // rank is n − j (the lower derivatives are never seen).
    for m in [4, 8, 12] {
        let n = m + 1;
        let a = DMatrix::from_fn(n, n, |i, j| if j == i + 1 { 1.0 } else { 0.0 });
        let d = LinearDynamics::new(a).unwrap();
        for j in [0, 1, 3] {
            let row = DMatrix::from_fn(1, n, |_, k| if k == j { 1.0 } else { 0.0 });
            assert_eq!(
                observability(&d, &row).unwrap().rank,
                n - j,
                "degree {m}, derivative {j}"
            );
        }
    }
}

#[test]
fn bad_observation_matrices_are_refused() {
    let d = dynamics(2, &[0., 1., 0., 0.]);
    let e = observability(&d, &rows(3, &[1., 0., 0.])).unwrap_err();
    assert!(e.to_string().contains("1x3"), "{e}");
    let e = observability(&d, &rows(2, &[1., f64::NAN])).unwrap_err();
    assert!(e.to_string().contains("entry [0, 1] = NaN"), "{e}");
    let huge = LinearDynamics::new(DMatrix::from_row_slice(
        3,
        3,
        &[1e200, 0., 0., 0., 1e200, 0., 0., 0., 1.],
    ))
    .unwrap();
    let e = observability(&huge, &rows(3, &[1., 1., 1.])).unwrap_err();
    assert!(e.to_string().contains("double range"), "{e}");
}
