//! `seqsmooth::stats::chi_squared`: quantiles against printed tables and closed forms, the
//! Gaussian gate helpers, bad input, and Morrison (1969) TV5.6 consistency test.

mod common;

use seqsmooth::stats::{
    chi_squared_cdf, chi_squared_quantile, chi_squared_sf, normal_quantile, two_sided_tail,
    two_sided_threshold, ChiSquaredTest,
};
use seqsmooth::Error;

#[test]
fn chi_squared_quantiles_match_tables_and_closed_forms() {
    // (dof, p, quantile) from standard tables.
    let table = [
        (1.0, 0.95, 3.841458820694124),
        (1.0, 0.99, 6.634896601021214),
        (2.0, 0.95, 5.991464547107979),
        (5.0, 0.05, 1.145476226061769),
        (10.0, 0.99, 23.209251158954356),
    ];
    for (dof, p, q) in table {
        let x = chi_squared_quantile(dof, p).unwrap();
        assert!(
            (x - q).abs() <= 1e-10 * q,
            "quantile({dof}, {p}) = {x}, table {q}"
        );
    }
    // 2 dof is exponential: q = −2 ln(1 − p).
    for p in [1e-6f64, 0.01, 0.5, 0.99, 0.9999, 1.0 - 1e-9] {
        let q = -2.0 * (-p).ln_1p();
        let x = chi_squared_quantile(2.0, p).unwrap();
        assert!((x - q).abs() <= 1e-11 * q, "p {p}: {x} vs {q}");
    }
    // 3 dof near 0: P(χ²_3 ≤ x) ≈ x^(3/2)/(2^(3/2) Γ(5/2)) (1 − 3x/10).
    let x = chi_squared_quantile(3.0, 1e-6).unwrap();
    let approx =
        x.powf(1.5) / (2f64.powf(1.5) * 0.75 * std::f64::consts::PI.sqrt()) * (1.0 - 0.3 * x);
    assert!((approx - 1e-6).abs() < 1e-12);
}

#[test]
fn chi_squared_helpers_reject_bad_input() {
    assert!(matches!(
        chi_squared_quantile(0.0, 0.5),
        Err(Error::InvalidParameter { .. })
    ));
    assert!(chi_squared_quantile(f64::NAN, 0.5).is_err());
    assert!(chi_squared_quantile(3.0, 0.0).is_err());
    assert!(chi_squared_quantile(3.0, 1.0).is_err());
    assert!(chi_squared_quantile(3.0, f64::NAN).is_err());
    assert!(chi_squared_cdf(-1.0, 1.0).is_err());
    assert!(matches!(
        chi_squared_cdf(2.0, f64::NAN),
        Err(Error::NonFinite { .. })
    ));
    assert_eq!(chi_squared_cdf(2.0, -3.0).unwrap(), 0.0);
    assert_eq!(chi_squared_sf(2.0, -3.0).unwrap(), 1.0);
    assert_eq!(chi_squared_sf(2.0, f64::INFINITY).unwrap(), 0.0);
    assert!(normal_quantile(1.0).is_err());
    assert!(two_sided_tail(-1.0).is_err());
    assert!(two_sided_threshold(0.0).is_err());
    assert!(ChiSquaredTest::new(3.0, 1.5).is_err());
}

#[test]
fn gaussian_gate_helpers_are_inverse() {
    for alpha in [0.5, 0.1, 0.0027, 1e-4, 1e-9] {
        let k = two_sided_threshold(alpha).unwrap();
        let back = two_sided_tail(k).unwrap();
        assert!(
            (back - alpha).abs() <= 1e-9 * alpha,
            "{alpha}: k {k}, back {back}"
        );
        // P(|Z| > k) = P(χ²_1 > k²)
        let chi = chi_squared_sf(1.0, k * k).unwrap();
        assert!((chi - alpha).abs() <= 1e-9 * alpha);
    }
    assert!((normal_quantile(0.5).unwrap()).abs() < 1e-15);
    assert!((normal_quantile(0.15865525393145707).unwrap() + 1.0).abs() < 1e-9);
}

#[test]
fn morrison_tv5_6_chi_squared_consistency_test() {
    // R = [[1,-1],[-1,1.01]], R⁻¹ = [[101,100],[100,100]], N = (1/2, 1/2): χ² = 100.25.
    let (a, b) = (0.5f64, 0.5f64);
    let chi2 = 101.0 * a * a + 200.0 * a * b + 100.0 * b * b;
    assert!((chi2 - 100.25).abs() < 1e-12);
    let test = ChiSquaredTest::new(2.0, 0.05).unwrap();
    assert!(test.rejects(chi2));
    assert!(chi_squared_cdf(2.0, chi2).unwrap() > 0.99999);
    assert!(test.p_value(chi2).unwrap() < 1e-20);
}
