//! The filter specification (`polynomial::spec`) and the row runner (`polynomial::rows`)
//! against the filters built and run directly: every kind built by a spec gives the bits of
//! the filter made by its own constructor, and every row the runner writes is the direct
//! filter's estimate (batch kernels, `try_estimate_at`, the automatic filter's output), with
//! the one rule for undetermined and refused rows.

use seqsmooth::polynomial::automatic::AutomaticFilter;
use seqsmooth::polynomial::rows::{decisions, degree_in_use, RowLayout, UPDATE_CELLS};
use seqsmooth::polynomial::spec::{AnyFilter, FilterKind, FilterSpec};
use seqsmooth::polynomial::tau::default_tau;
use seqsmooth::{Engine, Error, ExpandingMemory, FadingMemory, FixedEngine, FixedMemory};
use seqsmooth::{PolynomialFilter, PolynomialState};

/// Irregular times (steps 0.6 … 1.4) and a curved signal with a deterministic wobble and two
/// outliers (for the automatic filter's gate).
fn data(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut t = Vec::with_capacity(n);
    let mut now = 0.0;
    for k in 0..n {
        now += 0.6 + 0.8 * (((k * 7919) % 101) as f64 / 100.0);
        t.push(now);
    }
    let y = t
        .iter()
        .enumerate()
        .map(|(k, &t)| {
            let spike = if k == 40 || k == 71 { 25.0 } else { 0.0 };
            3.0 + 0.5 * t - 0.01 * t * t + 0.3 * ((k * 37 % 17) as f64 / 17.0 - 0.5) + spike
        })
        .collect();
    (t, y)
}

fn spec(kind: FilterKind, sigma: Option<f64>) -> FilterSpec {
    FilterSpec {
        theta: Some(0.9),
        tau: Some(1.1),
        window: Some(7),
        sigma,
        ..FilterSpec::new(kind, 2)
    }
}

/// The filter of `spec` made by its own constructor.
fn direct(spec: &FilterSpec) -> Box<dyn PolynomialFilter> {
    let (m, sigma) = (spec.degree, spec.sigma);
    let (theta, tau) = (spec.theta.unwrap(), spec.tau.unwrap());
    match spec.kind {
        FilterKind::Expanding => {
            let f = ExpandingMemory::new(m, spec.engine).unwrap();
            Box::new(
                sigma
                    .map_or(Ok(f.clone()), |s| f.with_noise_sigma(s))
                    .unwrap(),
            )
        }
        FilterKind::Fading => {
            let f = FadingMemory::new(m, theta, tau, spec.engine).unwrap();
            Box::new(
                sigma
                    .map_or(Ok(f.clone()), |s| f.with_noise_sigma(s))
                    .unwrap(),
            )
        }
        FilterKind::Fixed => {
            let f = FixedMemory::new(m, spec.window.unwrap(), spec.fixed_engine).unwrap();
            Box::new(
                sigma
                    .map_or(Ok(f.clone()), |s| f.with_noise_sigma(s))
                    .unwrap(),
            )
        }
        FilterKind::Automatic => Box::new(automatic(spec)),
    }
}

fn automatic(spec: &FilterSpec) -> AutomaticFilter {
    let f = AutomaticFilter::new(spec.degree, spec.theta.unwrap(), spec.tau.unwrap())
        .unwrap()
        .with_engine(spec.engine)
        .unwrap();
    spec.sigma
        .map_or(Ok(f.clone()), |s| f.with_noise_sigma(s))
        .unwrap()
}

const KINDS: [FilterKind; 4] = [
    FilterKind::Expanding,
    FilterKind::Fading,
    FilterKind::Fixed,
    FilterKind::Automatic,
];

fn bits(s: &Option<PolynomialState>) -> Option<(Vec<u64>, Option<Vec<u64>>)> {
    s.as_ref().map(|s| {
        let d = s.derivatives.iter().map(|v| v.to_bits()).collect();
        let c = s
            .covariance
            .as_ref()
            .map(|c| c.iter().map(|v| v.to_bits()).collect());
        (d, c)
    })
}

/// Every kind and engine the spec builds is its constructor's filter: the same estimates, bit
/// for bit, after every sample, now and carried ahead.
#[test]
fn a_spec_builds_the_filter_its_constructor_makes() {
    let (t, y) = data(120);
    for kind in KINDS {
        for engine in [Engine::Exact, Engine::Gain] {
            for sigma in [None, Some(0.2)] {
                let spec = FilterSpec {
                    engine,
                    ..spec(kind, sigma)
                };
                let (mut a, mut b) = (spec.build().unwrap(), direct(&spec));
                assert_eq!(a.kind(), kind);
                for (&t, &y) in t.iter().zip(&y) {
                    a.update(t, y).unwrap();
                    b.update(t, y).unwrap();
                    assert_eq!(a.samples(), b.samples());
                    assert_eq!(a.is_determined(), b.is_determined());
                    assert_eq!(bits(&a.estimate()), bits(&b.estimate()));
                    for at in [t, t + 0.7] {
                        assert_eq!(
                            bits(&a.estimate_at(at)),
                            bits(&b.estimate_at(at)),
                            "{spec:?}"
                        );
                    }
                }
            }
        }
    }
    // Fixed memory on each of its engines.
    let (t, y) = (Vec::from_iter((0..40).map(f64::from)), data(40).1);
    for fixed_engine in [
        FixedEngine::Sliding,
        FixedEngine::Direct,
        FixedEngine::Irregular,
    ] {
        let spec = FilterSpec {
            fixed_engine,
            ..spec(FilterKind::Fixed, Some(0.2))
        };
        let (mut a, mut b) = (spec.build().unwrap(), direct(&spec));
        a.update_many(&t, &y).unwrap();
        b.update_many(&t, &y).unwrap();
        assert_eq!(bits(&a.estimate()), bits(&b.estimate()));
    }
}

/// The settings a kind needs and lacks are refused by name; the filters' own checks stand.
#[test]
fn a_spec_refuses_what_its_kind_lacks() {
    let name = |e: Error| match e {
        Error::InvalidParameter { name, .. } => name.name(),
        other => panic!("{other}"),
    };
    let fading = FilterSpec::new(FilterKind::Fading, 1);
    assert_eq!(name(fading.build().unwrap_err()), "theta");
    let no_tau = FilterSpec {
        theta: Some(0.9),
        ..FilterSpec::new(FilterKind::Automatic, 1)
    };
    assert_eq!(name(no_tau.build().unwrap_err()), "tau");
    assert_eq!(
        name(FilterSpec::new(FilterKind::Fixed, 1).build().unwrap_err()),
        "window"
    );
    let theta = FilterSpec {
        theta: Some(1.0),
        ..no_tau.clone()
    };
    let theta = theta.with_default_tau(&[0.0, 1.0], &[0, 0], true).unwrap();
    assert!(matches!(theta.build(), Err(Error::ThetaOutOfRange { .. })));
    let small = FilterSpec {
        window: Some(2),
        ..FilterSpec::new(FilterKind::Fixed, 2)
    };
    assert!(small.build().is_err());
    // Expanding and fixed memory take no tau: the default rule leaves them as they are.
    let (t, _) = data(30);
    let series = vec![0; t.len()];
    let expanding = FilterSpec::new(FilterKind::Expanding, 1);
    let resolved = expanding
        .clone()
        .with_default_tau(&t, &series, true)
        .unwrap();
    assert_eq!(resolved, expanding);
    // A fading memory without tau takes the library's default, a given one stays.
    let spec = no_tau.with_default_tau(&t, &series, true).unwrap();
    assert_eq!(spec.tau, Some(default_tau(&t, &series, true).unwrap()));
    let given = FilterSpec {
        tau: Some(3.0),
        ..spec
    };
    assert_eq!(
        given.clone().with_default_tau(&t, &series, true).unwrap(),
        given
    );
}

/// The rows a filter writes, computed from the filter run directly: the batch kernels for the
/// expanding and fading memories without lead; otherwise each sample's estimate at `t + lead`
/// (`try_estimate_at`, too few samples an empty row) with its 1σ, and the kind's cells.
fn expected_rows(spec: &FilterSpec, t: &[f64], y: &[f64], layout: RowLayout) -> Vec<f64> {
    let w = spec.degree + 1;
    let sd = w << usize::from(layout.sigma);
    let trailing = match (spec.kind, layout.trailing) {
        (FilterKind::Fixed, true) => 1,
        (FilterKind::Automatic, true) => 4 + UPDATE_CELLS,
        _ => 0,
    };
    let stride = sd + trailing;
    let mut out = vec![f64::NAN; t.len() * stride];
    let batch = matches!(spec.kind, FilterKind::Expanding | FilterKind::Fading);
    if batch && layout.lead == 0.0 {
        let mut f = direct(spec);
        match layout.sigma {
            false => f.update_many_into(t, y, &mut out).unwrap(),
            true => f.update_many_sigma_into(t, y, &mut out).unwrap(),
        }
        return out;
    }
    let write = |row: &mut [f64], s: &PolynomialState| {
        row[..s.derivatives.len()].copy_from_slice(&s.derivatives);
        if layout.sigma {
            let sigma = s.std_devs().unwrap();
            row[w..w + sigma.len()].copy_from_slice(&sigma);
        }
    };
    if spec.kind == FilterKind::Automatic {
        let mut f = automatic(spec);
        for (i, row) in out.chunks_exact_mut(stride).enumerate() {
            let o = f.update(t[i], y[i]).unwrap();
            if layout.trailing {
                row[sd] = o.noise_sigma.unwrap_or(f64::NAN);
                row[sd + 1] = f64::from(u8::from(o.outlier));
                row[sd + 2] = f64::from(u8::from(o.misfit));
                row[sd + 3] = o.bias.as_ref().map_or(f64::NAN, |b| b[0]);
                let bits = o
                    .decided
                    .iter()
                    .rev()
                    .fold(0u64, |b, &r| b << 1 | u64::from(r));
                row[sd + 4] = o.decided.len() as f64;
                row[sd + 5] = (bits & 0xffff_ffff) as f64;
                row[sd + 6] = (bits >> 32) as f64;
                row[sd + 7] = o.degree as f64;
            }
            let estimate = match layout.lead {
                0.0 => o.estimate.clone(),
                lead => f.estimate_at(t[i] + lead),
            };
            if let Some(s) = estimate {
                write(row, &s);
            }
        }
        return out;
    }
    let mut f = direct(spec);
    for (i, row) in out.chunks_exact_mut(stride).enumerate() {
        f.update(t[i], y[i]).unwrap();
        if trailing == 1 {
            row[sd] = (f.samples() as f64).min(spec.window.unwrap() as f64);
        }
        match f.try_estimate_at(t[i] + layout.lead) {
            Ok(s) => write(row, &s),
            Err(Error::TooFewSamples { .. }) => {}
            Err(e) => panic!("{e}"),
        }
    }
    out
}

fn same_bits(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

/// Every kind's rows, with and without σ, lead and the kind's cells, are the direct filter's,
/// bit for bit, in one batch or in uneven pieces; the row count carries across the pieces.
#[test]
fn the_runner_writes_the_direct_filters_rows() {
    let (t, y) = data(150);
    for kind in KINDS {
        for sigma in [None, Some(0.2)] {
            for lead in [0.0, 0.7, -1.3] {
                for trailing in [false, true] {
                    let spec = spec(kind, sigma);
                    let layout = RowLayout {
                        sigma: spec.writes_sigma(),
                        lead,
                        trailing,
                    };
                    let want = expected_rows(&spec, &t, &y, layout);
                    let mut f = spec.build().unwrap();
                    let stride = f.stride(layout);
                    let mut got = vec![0.0; t.len() * stride];
                    f.run_rows(&t, &y, &mut got, layout).unwrap();
                    assert!(same_bits(&got, &want), "{spec:?} {layout:?}");
                    assert!(got.iter().all(|v| !v.is_infinite()));
                    let mut f = spec.build().unwrap();
                    let mut pieces = vec![0.0; t.len() * stride];
                    for (a, b) in [(0, 1), (1, 2), (2, 3), (3, 50), (50, 150)] {
                        let out = &mut pieces[a * stride..b * stride];
                        f.run_rows(&t[a..b], &y[a..b], out, layout).unwrap();
                    }
                    assert!(same_bits(&pieces, &want), "{spec:?} {layout:?} in pieces");
                }
            }
        }
    }
}

/// The automatic filter's decision cells give back the final decisions its updates made.
#[test]
fn the_update_cells_hold_the_final_outlier_decisions_and_the_degree() {
    let (t, y) = data(150);
    let spec = FilterSpec {
        sigma: None,
        ..spec(FilterKind::Automatic, None)
    };
    let layout = RowLayout {
        sigma: true,
        lead: 0.0,
        trailing: true,
    };
    let mut f = spec.build().unwrap();
    let stride = f.stride(layout);
    let mut rows = vec![0.0; t.len() * stride];
    f.run_rows(&t, &y, &mut rows, layout).unwrap();
    let mut decided: Vec<bool> = rows
        .chunks_exact(stride)
        .flat_map(|r| decisions(&r[stride - UPDATE_CELLS..]))
        .collect();
    let degrees: Vec<usize> = rows
        .chunks_exact(stride)
        .map(|r| degree_in_use(&r[stride - UPDATE_CELLS..]))
        .collect();
    decided.extend(f.automatic_mut().unwrap().finish());
    let mut g = automatic(&spec);
    let (mut want, mut want_degrees) = (Vec::new(), Vec::new());
    for (&t, &y) in t.iter().zip(&y) {
        let o = g.update(t, y).unwrap();
        want.extend(o.decided.iter());
        want_degrees.push(o.degree);
    }
    want.extend(g.finish());
    assert_eq!(decided, want);
    // The degree in use at each update, as it settles.
    assert_eq!(degrees, want_degrees);
    assert!(degrees[0] < degrees[degrees.len() - 1], "{degrees:?}");
    assert_eq!(decided.len(), t.len());
    assert!(decided[40] && decided[71], "the two spikes are rejected");
}

/// The rule: empty cells before the fit is determined; once it is, a row without an estimate
/// is refused (`NotDetermined`), and so is a number beyond the double range
/// (`EstimateOutOfRange` naming its column), each with its row's index, the rows before it
/// written — also when the batch is cut in pieces.
#[test]
fn undetermined_and_refused_rows() {
    let t = [0.0, 1.0, 2.0, 3.0, 4.0];
    let y = [1.0, 2.0, 3.0, 5.0, 5.0];
    let layout = RowLayout::default();
    let refusal = |spec: &FilterSpec, t: &[f64], layout: RowLayout| {
        let mut f = spec.build().unwrap();
        let mut out = vec![0.0; t.len() * f.stride(layout)];
        match f.run_rows(t, &y[..t.len()], &mut out, layout) {
            Err(Error::InBatch { index, source }) => (index, *source, out),
            other => panic!("{other:?}"),
        }
    };
    // A discount that underflows: θ^(1/1e-300) = 0 leaves the fit undetermined from the
    // third sample (degree 2) on.
    let fading = FilterSpec {
        tau: Some(1e-300),
        ..spec(FilterKind::Fading, None)
    };
    let (index, e, out) = refusal(&fading, &t, layout);
    assert_eq!(index, 2);
    assert!(matches!(e, Error::NotDetermined { samples: 3, .. }), "{e}");
    assert!(
        out.iter().all(|v| v.is_nan()),
        "the first two rows: empty, not refused"
    );
    // In pieces, the count of rows carries: the refusal is the second piece's row 0.
    let mut f = fading.build().unwrap();
    let mut out = vec![0.0; 6];
    f.run_rows(&t[..2], &y[..2], &mut out, layout).unwrap();
    let e = f
        .run_rows(&t[2..4], &y[2..4], &mut out, layout)
        .unwrap_err();
    assert!(matches!(e, Error::InBatch { index: 0, .. }), "{e}");
    // A lead beyond the double range.
    let lead = RowLayout {
        lead: 1e308,
        ..layout
    };
    let unit = FilterSpec {
        tau: Some(1.0),
        ..spec(FilterKind::Fading, None)
    };
    let (index, e, _) = refusal(&unit, &t, lead);
    assert_eq!(index, 2);
    assert!(matches!(e, Error::EstimateOutOfRange { .. }), "{e}");
    // Times in units far too small for the curvature: d2 ~ 1e400.
    let tiny = [0.0, 1e-200, 2e-200, 3e-200, 4e-200];
    let fixed = FilterSpec {
        window: Some(3),
        ..spec(FilterKind::Fixed, None)
    };
    let (index, e, out) = refusal(&fixed, &tiny, layout);
    assert_eq!(
        index, 3,
        "rows 0-2 are a line (d2 = 0): the first curved window ends at 3"
    );
    assert!(
        matches!(e, Error::EstimateOutOfRange { ref what } if what == "d2"),
        "{e}"
    );
    assert!(out[..6].iter().all(|v| v.is_nan()) && out[6..9].iter().all(|v| v.is_finite()));
    // An earlier refused row comes before a later refused sample.
    let mut f = fading.build().unwrap();
    let mut out = vec![0.0; 15];
    let e = f.run_rows(&t, &[1.0, 2.0, 3.0, f64::NAN, 5.0], &mut out, layout);
    assert!(matches!(e, Err(Error::InBatch { index: 2, .. })), "{e:?}");
    // σ asked of a filter without noise σ.
    let mut f = spec(FilterKind::Fixed, None).build().unwrap();
    let sigma = RowLayout {
        sigma: true,
        ..layout
    };
    let mut out = vec![0.0; 9 * 6];
    let e = f
        .run_rows(&data(9).0, &data(9).1, &mut out, sigma)
        .unwrap_err();
    assert!(matches!(e, Error::InBatch { index: 6, .. }), "{e}");
}

/// The σ kernel's rows (expanding and fading memory, no lead) are checked by the same rule as
/// every other row, once, while the kernel writes them: a fit that the discount leaves
/// undetermined (the exact engine's weighted fit) is refused with its row's index, the rows
/// before it empty; a determined run's every cell is a number, with either engine, across the
/// runner's blocks.
#[test]
fn sigma_kernel_rows_follow_the_rule() {
    let t: Vec<f64> = (0..5000).map(f64::from).collect();
    let y: Vec<f64> = t.iter().map(|t| 1.0 + 0.5 * t).collect();
    let sigma = RowLayout {
        sigma: true,
        ..RowLayout::default()
    };
    // θ^(1/1e-300) = 0: the exact engine's fit undetermined from the third sample (degree 2).
    let fading = FilterSpec {
        tau: Some(1e-300),
        ..spec(FilterKind::Fading, Some(0.1))
    };
    let mut f = fading.build().unwrap();
    let mut out = vec![0.0; 3 * f.stride(sigma)];
    match f.run_rows(&t[..3], &y[..3], &mut out, sigma) {
        Err(Error::InBatch { index: 2, source }) => {
            assert!(
                matches!(*source, Error::NotDetermined { samples: 3, .. }),
                "{source}"
            );
        }
        other => panic!("{other:?}"),
    }
    assert!(out[..12].iter().all(|v| v.is_nan()));
    for engine in [Engine::Exact, Engine::Gain] {
        let ok = FilterSpec {
            engine,
            ..spec(FilterKind::Fading, Some(0.1))
        };
        let mut f = ok.build().unwrap();
        let mut out = vec![0.0; t.len() * f.stride(sigma)];
        f.run_rows(&t, &y, &mut out, sigma).unwrap();
        assert!(out[..12].iter().all(|v| v.is_nan()));
        assert!(out[12..].iter().all(|v| v.is_finite()), "{engine:?}");
    }
}

/// Samples the filter refuses are its own errors, with their index and the rows before them
/// written; a mismatched output is refused before any sample is taken.
#[test]
fn refused_samples_and_lengths() {
    let (t, mut y) = data(20);
    y[12] = f64::INFINITY;
    for kind in KINDS {
        for lead in [0.0, 1.0] {
            let layout = RowLayout {
                sigma: true,
                lead,
                trailing: true,
            };
            let mut f: AnyFilter = spec(kind, Some(0.2)).build().unwrap();
            let stride = f.stride(layout);
            let mut out = vec![0.0; t.len() * stride];
            let e = f.run_rows(&t, &y, &mut out, layout).unwrap_err();
            assert!(
                matches!(e, Error::InBatch { index: 12, .. }),
                "{kind:?}: {e}"
            );
            let taken = if kind == FilterKind::Automatic {
                f.samples()
            } else {
                12
            };
            assert_eq!(f.samples(), taken, "{kind:?}");
            let want = expected_rows(&spec(kind, Some(0.2)), &t[..12], &y[..12], layout);
            assert!(same_bits(&out[..12 * stride], &want), "{kind:?}");
            let mut short = vec![0.0; stride];
            assert!(f.run_rows(&t[13..], &y[13..], &mut short, layout).is_err());
            assert_eq!(f.samples(), taken);
        }
    }
}

/// A batch longer than the runner's block of rows: the same rows as the filters run directly,
/// and a refused sample beyond the first block named by its index in the whole batch.
#[test]
fn long_batches_run_in_blocks_as_one() {
    let n = 12_000;
    let (t, mut y) = data(n);
    for kind in KINDS {
        let spec = spec(kind, Some(0.2));
        let layout = RowLayout {
            sigma: true,
            lead: 0.0,
            trailing: true,
        };
        let want = expected_rows(&spec, &t, &y, layout);
        let mut f = spec.build().unwrap();
        let stride = f.stride(layout);
        let mut got = vec![0.0; n * stride];
        f.run_rows(&t, &y, &mut got, layout).unwrap();
        assert!(same_bits(&got, &want), "{kind:?}");
        let bad = 9_001;
        let keep = y[bad];
        y[bad] = f64::NAN;
        let mut f = spec.build().unwrap();
        let e = f.run_rows(&t, &y, &mut got, layout).unwrap_err();
        assert!(
            matches!(e, Error::InBatch { index, .. } if index == bad),
            "{kind:?}: {e}"
        );
        assert!(
            same_bits(&got[..bad * stride], &want[..bad * stride]),
            "{kind:?}"
        );
        y[bad] = keep;
    }
}
