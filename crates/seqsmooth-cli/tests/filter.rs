//! End-to-end tests of `seqsmooth filter` of every kind: published test vectors (Morrison 1969; Reyneke et al.
//! 2012) and the library.

use seqsmooth::polynomial::automatic::{final_outliers, AutomaticFilter};
use seqsmooth::polynomial::expanding::vrf::expanding_vrf;
use seqsmooth::polynomial::fixed::covariance_unscaled;
use seqsmooth::polynomial::form::EstimateForm;
use seqsmooth::{
    Engine, ExpandingMemory, FadingMemory, FixedEngine, FixedMemory, PolynomialFilter,
};

mod common;
use common::*;

/// Morrison T9-02: the degree-1 expanding-memory estimate after samples 0..4 is
/// Z*_{4,4} = (23/5, 4/5); the first row (one sample, degree 1) has no estimate yet. Both
/// engines.
#[test]
fn filter_expanding_degree1_matches_t9_02() {
    for engine in ["exact", "gain"] {
        let out = ok(
            &[
                "filter",
                "--kind",
                "expanding",
                "--degree",
                "1",
                "--engine",
                engine,
            ],
            T9_02,
        );
        let (header, rows) = table(&out);
        assert_eq!(header, ["t", "y", "d0", "d1"]);
        assert_eq!(rows.len(), 5);
        assert_eq!(out.lines().nth(1), Some("0,1,,"), "{engine}");
        assert_eq!(rows[4][..2], ["4", "4"]);
        assert!(
            close(num(&rows[4][2]), 4.6, 1e-12),
            "{engine}: {:?}",
            rows[4]
        );
        assert!(
            close(num(&rows[4][3]), 0.8, 1e-12),
            "{engine}: {:?}",
            rows[4]
        );
    }
}

/// Morrison T9-02: the 1-step prediction Z*_{5,4} = (27/5, 4/5) with `--lead 1`; a negative
/// lead retrodicts (`--lead -10` at t = 4: 4.6 - 8 = -3.4). Both engines.
#[test]
fn filter_lead_predicts_and_retrodicts() {
    for engine in ["exact", "gain"] {
        let args = [
            "filter",
            "--kind",
            "expanding",
            "--degree",
            "1",
            "--engine",
            engine,
        ];
        let out = ok(&[&args[..], &["--lead", "1"]].concat(), T9_02);
        let (_, rows) = table(&out);
        assert!(
            close(num(&rows[4][2]), 5.4, 1e-12),
            "{engine}: {:?}",
            rows[4]
        );
        assert!(
            close(num(&rows[4][3]), 0.8, 1e-12),
            "{engine}: {:?}",
            rows[4]
        );
        let out = ok(&[&args[..], &["--lead", "-10"]].concat(), T9_02);
        let (_, rows) = table(&out);
        assert!(
            close(num(&rows[4][2]), -3.4, 1e-12),
            "{engine}: {:?}",
            rows[4]
        );
        assert_eq!(rows[4][..2], ["4", "4"]);
    }
}

/// `--sigma S` adds s0..sM: for Morrison's example at n = 4 (τ = 1, so scaled = unscaled)
/// s_k = S·sqrt(VRF_kk) with the expanding-memory VRF of Table 9.2 (`expanding_vrf(1, 4)`).
#[test]
fn filter_sigma_columns_match_vrf() {
    let sigma = 0.5;
    let vrf = expanding_vrf::<f64>(1, 4, EstimateForm::Current).unwrap();
    for engine in ["exact", "gain"] {
        let out = ok(
            &[
                "filter",
                "--kind",
                "expanding",
                "--degree",
                "1",
                "--engine",
                engine,
                "--sigma",
                "0.5",
            ],
            T9_02,
        );
        let (header, rows) = table(&out);
        assert_eq!(header, ["t", "y", "d0", "d1", "s0", "s1"]);
        assert_eq!(out.lines().nth(1), Some("0,1,,,,"));
        assert!(
            close(num(&rows[4][4]), sigma * vrf[(0, 0)].sqrt(), 1e-12),
            "{engine}"
        );
        assert!(
            close(num(&rows[4][5]), sigma * vrf[(1, 1)].sqrt(), 1e-12),
            "{engine}"
        );
    }
}

/// A fading-memory filter is exact on a polynomial (Morrison ch. 13): y = 2 + 0.5 t for 300
/// evenly spaced rows gives x = 151.5, x' = 0.5 at t = 299, on both engines.
#[test]
fn filter_fading_exact_on_long_polynomial() {
    let mut input = String::from("t,y\n");
    for k in 0..300 {
        input += &format!("{k},{}\n", 2.0 + 0.5 * k as f64);
    }
    for engine in ["exact", "gain"] {
        let out = ok(
            &[
                "filter", "--kind", "fading", "--degree", "1", "--theta", "0.9", "--engine", engine,
            ],
            &input,
        );
        let (_, rows) = table(&out);
        assert_eq!(rows.len(), 300);
        let last = &rows[299];
        assert!(close(num(&last[2]), 151.5, 1e-12), "{engine}: {last:?}");
        assert!(close(num(&last[3]), 0.5, 1e-10), "{engine}: {last:?}");
    }
}

/// The exact engine is least squares on any timestamps, so a quadratic on irregular times is
/// reproduced exactly, derivatives included (value 1 + t + t²: x' = 1 + 2t, x'' = 2).
#[test]
fn filter_exact_engine_on_irregular_quadratic() {
    let mut input = String::from("t,y\n");
    let mut t = 0.0;
    for k in 0..200 {
        t += 0.05 + 0.1 * ((k * 7 % 5) as f64);
        input += &format!("{t},{}\n", 1.0 + t + t * t);
    }
    let out = ok(
        &[
            "filter", "--kind", "fading", "--degree", "2", "--theta", "9/10",
        ],
        &input,
    );
    let (_, rows) = table(&out);
    let last = &rows[199];
    let t = num(&last[0]);
    assert!(close(num(&last[2]), 1.0 + t + t * t, 1e-9), "{last:?}");
    assert!(close(num(&last[3]), 1.0 + 2.0 * t, 1e-9), "{last:?}");
    assert!(close(num(&last[4]), 2.0, 1e-7), "{last:?}");
}

/// Every number written parses back to the identical f64 the library computed (round-trip
/// output), including values far from 1 that need an exponent (1e-300 must not print 300
/// digits).
#[test]
fn filter_output_round_trips_library_values() {
    let mut input = String::from("t,y\n");
    let mut samples = Vec::new();
    for k in 0..60 {
        let t = 1e-3 * k as f64 + 1e-4 * ((k * 3 % 7) as f64);
        let y = 1e-300 * (1.0 + 0.1 * ((k * 5 % 11) as f64)) + 3e-301 * t;
        samples.push((t, y));
        input += &format!("{t:e},{y:e}\n");
    }
    for engine in [Engine::Exact, Engine::Gain] {
        let name = if engine == Engine::Exact {
            "exact"
        } else {
            "gain"
        };
        let out = ok(
            &[
                "filter", "--kind", "fading", "--degree", "2", "--theta", "0.8", "--tau", "1e-3",
                "--sigma", "1e-150", "--lead", "2e-3", "--engine", name,
            ],
            &input,
        );
        let mut f = FadingMemory::new(2, 0.8, 1e-3, engine)
            .unwrap()
            .with_noise_sigma(1e-150)
            .unwrap();
        let (header, rows) = table(&out);
        assert_eq!(header.last().map(String::as_str), Some("lead"));
        for (row, &(t, y)) in rows.iter().zip(&samples) {
            f.update(t, y).unwrap();
            assert_eq!(num(&row[0]).to_bits(), t.to_bits());
            assert_eq!(num(&row[1]).to_bits(), y.to_bits());
            // The trailing lead column records --lead.
            let (row, lead) = row.split_at(row.len() - 1);
            assert_eq!(lead, ["0.002"]);
            match f.estimate_at(t + 2e-3) {
                None => assert!(row[2..].iter().all(String::is_empty), "{row:?}"),
                Some(s) => {
                    let sd = s.std_devs().unwrap();
                    let want = s.derivatives.iter().chain(&sd);
                    for (cell, w) in row[2..].iter().zip(want) {
                        assert_eq!(num(cell).to_bits(), w.to_bits(), "{cell} vs {w:e}");
                        assert!(cell.len() <= 24, "{cell} is not the shortest form");
                    }
                }
            }
        }
    }
}

/// `--time-col`/`--value-col` pick the columns by name; other columns are ignored; the output
/// header stays `t,y,d…` and the t and y cells echo the input cells as written.
#[test]
fn filter_custom_columns_with_extra_columns() {
    let input = "id,time,note,pos\na,0.0,x,1\nb,1.0,y,3\nc,2.0,z,2\nd,3.0,w,5\ne,4.0,v,4.00\n";
    let out = ok(
        &[
            "filter",
            "--kind",
            "expanding",
            "--degree",
            "1",
            "--time-col",
            "time",
            "--value-col",
            "pos",
        ],
        input,
    );
    let (header, rows) = table(&out);
    assert_eq!(header, ["t", "y", "d0", "d1"]);
    assert_eq!(rows[4][..2], ["4.0", "4.00"]);
    assert!(close(num(&rows[4][2]), 4.6, 1e-12));
}

/// INPUT `-`, INPUT omitted and a file name read the same data; `-o` writes the same CSV.
#[test]
fn filter_reads_stdin_and_files_and_writes_output_file() {
    let args = ["filter", "--kind", "expanding", "--degree", "1"];
    let from_stdin = ok(&[&args[..], &["-"]].concat(), T9_02);
    assert_eq!(ok(&args, T9_02), from_stdin);
    let input = tmp("t9_02.csv");
    std::fs::write(&input, T9_02).unwrap();
    let input = input.to_str().unwrap();
    assert_eq!(ok(&[&args[..], &[input]].concat(), ""), from_stdin);
    let output = tmp("t9_02_out.csv");
    let output = output.to_str().unwrap();
    assert_eq!(ok(&[&args[..], &[input, "-o", output]].concat(), ""), "");
    assert_eq!(std::fs::read_to_string(output).unwrap(), from_stdin);
}

/// Without `--tau`, τ is the median time step of the first rows, so θ is the discount per
/// typical sample: a series with steps mostly 0.5 gives the same output as `--tau 0.5`.
#[test]
fn filter_default_tau_is_median_step() {
    let mut input = String::from("t,y\n");
    let mut t = 0.0;
    for k in 0..40 {
        t += if k % 4 == 3 { 0.9 } else { 0.5 };
        input += &format!("{t},{}\n", (k * 13 % 7) as f64);
    }
    let args = [
        "filter", "--kind", "fading", "--degree", "1", "--theta", "0.8",
    ];
    let default = ok(&args, &input);
    assert_eq!(
        ok(&[&args[..], &["--tau", "0.5"]].concat(), &input),
        default
    );
    assert_ne!(ok(&[&args[..], &["--tau", "1"]].concat(), &input), default);
}

/// The library's answer for the same run equals the command's (gain engine, fading memory,
/// irregular then even times; exact engine, expanding memory): the binary is a thin layer. Without 1σ
/// columns or a lead it feeds each series' rows of a chunk through `update_many_into`, so that
/// is the reference, equal to the end (every row); the per-sample `update` + `estimate` path
/// agrees up to the batch kernels' rounding.
#[test]
fn filter_agrees_with_library() {
    let mut input = String::from("t,y\n");
    let (mut ts, mut ys) = (Vec::new(), Vec::new());
    // Irregular, then evenly spaced from row 60 on (long enough for the fading gain engine's
    // typical step to settle, so its steady batch kernel runs).
    for k in 0..1200 {
        let t = k as f64
            + if k < 60 {
                0.3 * ((k * 7 % 3) as f64)
            } else {
                0.3
            };
        let y = (k as f64 * 0.37).sin() * 10.0;
        input += &format!("{t},{y}\n");
        ts.push(t);
        ys.push(y);
    }
    type Make = fn() -> Box<dyn PolynomialFilter>;
    let filters: [(&[&str], Make); 2] = [
        (
            &[
                "filter", "--kind", "fading", "--degree", "2", "--theta", "0.95", "--tau", "1",
                "--engine", "gain",
            ],
            || Box::new(FadingMemory::new(2, 0.95, 1.0, Engine::Gain).unwrap()),
        ),
        (&["filter", "--kind", "expanding", "--degree", "2"], || {
            Box::new(ExpandingMemory::new(2, Engine::Exact).unwrap())
        }),
    ];
    for (args, make) in filters {
        let (mut f, mut one) = (make(), make());
        let mut est = vec![0.0; ts.len() * 3];
        f.update_many_into(&ts, &ys, &mut est).unwrap();
        let (_, rows) = table(&ok(args, &input));
        for (k, row) in rows.iter().enumerate() {
            one.update(ts[k], ys[k]).unwrap();
            for (d, cell) in row[2..].iter().enumerate() {
                let want = est[3 * k + d];
                if want.is_nan() {
                    assert_eq!(cell, "", "{args:?} row {k}");
                    continue;
                }
                assert_eq!(num(cell), want, "{args:?} row {k}");
                let single = one.estimate().unwrap().derivatives[d];
                assert!(
                    close(want, single, 1e-11),
                    "{args:?} row {k}: {want} vs {single}"
                );
            }
        }
    }
}

// filter --kind fixed

/// Morrison T7-08, L = 4 (`--window 5`): m = 1, h = 0 gives Z* = (24/5, 9/10); h = 1 (`--lead 1`)
/// the prediction (57/10, 9/10); h = -2 the centre (3, 9/10); m = 2, h = 0 gives
/// (163/35, 43/70, -1/14) scaled, so x'' = 2!·(-1/14) = -1/7 (τ = 1). Only the last row has an
/// estimate: the four before it have empty d cells and say so in the window column.
#[test]
fn filter_fixed_t7_08() {
    let cases: [(&str, &str, &[&str]); 4] = [
        ("1", "0", &["24/5", "9/10"]),
        ("1", "1", &["57/10", "9/10"]),
        ("1", "-2", &["3", "9/10"]),
        ("2", "0", &["163/35", "43/70", "-1/7"]),
    ];
    for (degree, lead, want) in cases {
        let args = [
            "filter", "--kind", "fixed", "--degree", degree, "--window", "5", "--lead", lead,
        ];
        let out = ok(&args, T7_08);
        let (header, rows) = table(&out);
        let mut want_header = vec!["t".to_string(), "y".to_string()];
        want_header.extend((0..want.len()).map(|k| format!("d{k}")));
        want_header.push("window".into());
        if lead != "0" {
            want_header.push("lead".into());
        }
        assert_eq!(header, want_header);
        assert_eq!(rows.len(), 5);
        for (k, row) in rows[..4].iter().enumerate() {
            assert!(
                row[2..2 + want.len()].iter().all(String::is_empty),
                "{row:?}"
            );
            assert_eq!(row[2 + want.len()], (k + 1).to_string(), "{row:?}");
        }
        let last = &rows[4];
        assert_eq!(last[..2], ["4", "5"]);
        for (cell, w) in last[2..].iter().zip(want) {
            assert!(
                close(num(cell), exact_f64(w), 1e-14),
                "degree {degree}, lead {lead}: {cell} vs {w}"
            );
        }
        assert_eq!(last[2 + want.len()], "5");
    }
}

/// Rows before the window fills: empty d and s cells, the window column counting the rows so
/// far (1, 2, …, W-1), then W on every row with an estimate — also for a window longer than
/// the 101 rows `filter` otherwise reads ahead (W = 150). `--sigma S` adds s0..sM before the
/// window column: S·sqrt of the diagonal of Morrison's (7.5.27) covariance `D W(0) W(0)ᵀ D`
/// (m = 1, L = 149, τ = 0.5). The values equal the library's FixedMemory bit for bit.
#[test]
fn filter_fixed_rows_before_window_fills() {
    let mut input = String::from("t,y\n");
    let mut samples = Vec::new();
    for k in 0..300 {
        let t = 0.5 * k as f64;
        let y = 3.0 - 0.25 * t + ((k * 17 % 13) as f64 - 6.0) * 0.1;
        samples.push((t, y));
        input += &format!("{t},{y}\n");
    }
    let out = ok(
        &[
            "filter", "--kind", "fixed", "--degree", "1", "--window", "150", "--sigma", "0.3",
        ],
        &input,
    );
    let (header, rows) = table(&out);
    assert_eq!(header, ["t", "y", "d0", "d1", "s0", "s1", "window"]);
    assert_eq!(rows.len(), 300);
    let mut f = FixedMemory::new(1, 150, FixedEngine::Sliding)
        .unwrap()
        .with_noise_sigma(0.3)
        .unwrap();
    let cov = covariance_unscaled(1, 149, 0.0, 0.5).unwrap();
    for (k, (row, &(t, y))) in rows.iter().zip(&samples).enumerate() {
        f.update(t, y).unwrap();
        if k < 149 {
            assert!(row[2..6].iter().all(String::is_empty), "{row:?}");
            assert_eq!(row[6], (k + 1).to_string());
            continue;
        }
        assert_eq!(row[6], "150");
        let s = f.estimate().unwrap();
        let sd = s.std_devs().unwrap();
        for (cell, w) in row[2..6].iter().zip(s.derivatives.iter().chain(&sd)) {
            assert_eq!(num(cell).to_bits(), w.to_bits(), "row {k}: {cell} vs {w:e}");
        }
        assert!(close(num(&row[4]), 0.3 * cov[(0, 0)].sqrt(), 1e-12));
        assert!(close(num(&row[5]), 0.3 * cov[(1, 1)].sqrt(), 1e-12));
    }
    // A window longer than the input is refused before any output.
    let o = run(
        &[
            "filter", "--kind", "fixed", "--degree", "1", "--window", "301",
        ],
        &input,
    );
    assert_eq!(o.code, 1, "{}", o.stderr);
    assert_eq!(o.stdout, "");
    assert!(o
        .stderr
        .contains("too few samples: the input has 300 data rows, window 301 needs at least 301"));
}

/// Irregular times: the fixed-memory filter is least squares over the window at the actual
/// times, so a quadratic (1 + t + t²) is reproduced with its derivatives (x' = 1 + 2t, x'' = 2),
/// and the output is the library's irregular engine's bit for bit. A series that turns
/// irregular half-way (the sliding engine hands over at the first uneven step) agrees with the
/// irregular engine throughout.
#[test]
fn filter_fixed_irregular_times() {
    let mut input = String::from("t,y\n");
    let mut samples = Vec::new();
    let mut t = 0.0;
    for k in 0..120 {
        t += 0.05 + 0.1 * ((k * 7 % 5) as f64);
        let y = 1.0 + t + t * t;
        samples.push((t, y));
        input += &format!("{t},{y}\n");
    }
    let out = ok(
        &[
            "filter", "--kind", "fixed", "--degree", "2", "--window", "9", "--sigma", "0.1",
            "--lead", "0.25",
        ],
        &input,
    );
    let (header, rows) = table(&out);
    assert_eq!(
        header,
        ["t", "y", "d0", "d1", "d2", "s0", "s1", "s2", "window", "lead"]
    );
    let mut f = FixedMemory::new(2, 9, FixedEngine::Irregular)
        .unwrap()
        .with_noise_sigma(0.1)
        .unwrap();
    for (k, (row, &(t, y))) in rows.iter().zip(&samples).enumerate() {
        f.update(t, y).unwrap();
        match f.estimate_at(t + 0.25) {
            None => {
                assert!(k < 8);
                assert!(row[2..8].iter().all(String::is_empty), "{row:?}");
            }
            Some(s) => {
                let sd = s.std_devs().unwrap();
                for (cell, w) in row[2..8].iter().zip(s.derivatives.iter().chain(&sd)) {
                    assert_eq!(num(cell).to_bits(), w.to_bits(), "row {k}: {cell} vs {w:e}");
                }
                let h = t + 0.25;
                assert!(close(num(&row[2]), 1.0 + h + h * h, 1e-9), "{row:?}");
                assert!(close(num(&row[3]), 1.0 + 2.0 * h, 1e-9), "{row:?}");
                assert!(close(num(&row[4]), 2.0, 1e-7), "{row:?}");
            }
        }
        assert_eq!(row[8], (k + 1).min(9).to_string());
    }

    // Even for 50 rows, then irregular.
    let mut input = String::from("t,y\n");
    let mut f = FixedMemory::new(2, 9, FixedEngine::Irregular).unwrap();
    let mut want = Vec::new();
    let mut t = 0.0;
    for k in 0..100 {
        t += if k < 50 {
            0.5
        } else {
            0.3 + 0.1 * ((k * 3 % 4) as f64)
        };
        let y = (0.3 * t).sin() * 4.0;
        input += &format!("{t},{y}\n");
        f.update(t, y).unwrap();
        want.push(f.estimate());
    }
    let (_, rows) = table(&ok(
        &[
            "filter", "--kind", "fixed", "--degree", "2", "--window", "9",
        ],
        &input,
    ));
    for (row, w) in rows.iter().zip(&want) {
        match w {
            None => assert!(row[2..5].iter().all(String::is_empty), "{row:?}"),
            Some(s) => {
                for (cell, w) in row[2..5].iter().zip(&s.derivatives) {
                    assert!(close(num(cell), *w, 1e-9), "{row:?} vs {w}");
                }
            }
        }
    }
}

// filter --kind auto

/// A line y = 2 + 0.5 t with bounded noise (uniform, σ = 0.2) and an outlier of 20σ at row
/// 120, through `--kind auto --degree 1 --theta 0.9` (τ = the median step, 1).
fn auto_input(outlier_at: Option<usize>) -> (String, Vec<(f64, f64)>) {
    let mut state = 0x2545_F491_4F6C_DD1D_u64;
    let mut input = String::from("t,y\n");
    let mut samples = Vec::new();
    for k in 0..200 {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        let u = (state >> 11) as f64 / (1u64 << 53) as f64; // [0, 1)
        let noise = 0.2 * 3f64.sqrt() * (2.0 * u - 1.0); // uniform, σ = 0.2, |noise| < 1.74σ
        let t = k as f64;
        let y = 2.0 + 0.5 * t + noise + if Some(k) == outlier_at { 4.0 } else { 0.0 };
        samples.push((t, y));
        input += &format!("{t},{y}\n");
    }
    (input, samples)
}

/// `--kind auto`: the columns t,y,d0,d1,s0,s1,noise,outlier,misfit,bias; the 20σ outlier is flagged
/// on its row only (the row's estimate is the prediction across it, not pulled towards the
/// outlier), the noise column is positive once estimated and near σ = 0.2; every cell equals
/// the library's AutomaticFilter (the binary is a thin layer).
#[test]
fn filter_auto_flags_outlier() {
    let (input, samples) = auto_input(Some(120));
    let out = ok(
        &[
            "filter", "--kind", "auto", "--degree", "1", "--theta", "0.9",
        ],
        &input,
    );
    let (header, rows) = table(&out);
    assert_eq!(
        header,
        ["t", "y", "d0", "d1", "s0", "s1", "noise", "outlier", "misfit", "bias"]
    );
    assert_eq!(rows.len(), 200);
    let flagged: Vec<usize> = (0..200).filter(|&k| rows[k][7] == "1").collect();
    assert_eq!(flagged, [120]);
    assert!(rows.iter().all(|r| r[7] == "0" || r[7] == "1"));
    assert!(rows.iter().all(|r| r[8] == "0" || r[8] == "1"));
    let noise = num(&rows[120][6]);
    assert!(noise > 0.0 && (noise - 0.2).abs() < 0.05, "{:?}", rows[120]);
    assert!((num(&rows[120][2]) - 62.0).abs() < 0.3, "{:?}", rows[120]);
    assert!(rows[199][4..7].iter().all(|c| num(c) > 0.0));

    let mut f = AutomaticFilter::new(1, 0.9, 1.0).unwrap();
    for (row, &(t, y)) in rows.iter().zip(&samples) {
        let o = f.update(t, y).unwrap();
        let d = o.derivatives().unwrap_or(&[]);
        let sd = o.std_devs().unwrap_or_default();
        for k in 0..2 {
            match d.get(k) {
                Some(w) => assert_eq!(num(&row[2 + k]).to_bits(), w.to_bits(), "{row:?}"),
                None => assert_eq!(row[2 + k], "", "{row:?}"),
            }
            match sd.get(k) {
                Some(w) => assert_eq!(num(&row[4 + k]).to_bits(), w.to_bits(), "{row:?}"),
                None => assert_eq!(row[4 + k], "", "{row:?}"),
            }
        }
        match o.noise_sigma {
            Some(w) => assert_eq!(num(&row[6]).to_bits(), w.to_bits(), "{row:?}"),
            None => assert_eq!(row[6], "", "{row:?}"),
        }
        assert_eq!(row[7], if o.outlier { "1" } else { "0" });
        assert_eq!(row[8], if o.misfit { "1" } else { "0" });
        match &o.bias {
            Some(b) => assert_eq!(num(&row[9]).to_bits(), b[0].to_bits(), "{row:?}"),
            None => assert_eq!(row[9], "", "{row:?}"),
        }
    }
}

/// `--kind auto --sigma S`: the noise column is S on every row and s0..sM come from it; a
/// manoeuvre (the slope turns from 0.5 to -1.5 at t = 150) raises the misfit flag, as the
/// library's filter does row for row.
#[test]
fn filter_auto_given_sigma_and_misfit() {
    let (input, _) = auto_input(None);
    let mut bent = String::from("t,y\n");
    let mut samples = Vec::new();
    for line in input.lines().skip(1) {
        let (t, y) = line.split_once(',').unwrap();
        let (t, mut y): (f64, f64) = (t.parse().unwrap(), y.parse().unwrap());
        if t > 150.0 {
            y -= 2.0 * (t - 150.0);
        }
        samples.push((t, y));
        bent += &format!("{t},{y}\n");
    }
    let out = ok(
        &[
            "filter", "--kind", "auto", "--degree", "1", "--theta", "0.9", "--sigma", "0.2",
        ],
        &bent,
    );
    let (_, rows) = table(&out);
    assert!(
        rows.iter().all(|r| r[6] == "0.2"),
        "noise column is the given sigma"
    );
    let mut f = AutomaticFilter::new(1, 0.9, 1.0)
        .unwrap()
        .with_noise_sigma(0.2)
        .unwrap();
    // The outlier column is the final decision: the manoeuvre's first rejections are applied
    // after all.
    let (outs, flags) = library_run(&mut f, &samples);
    assert!(outs.iter().zip(&flags).any(|(o, &r)| o.outlier && !r));
    for ((row, o), rejected) in rows.iter().zip(&outs).zip(flags) {
        assert_eq!(row[7], if rejected { "1" } else { "0" }, "{row:?}");
        assert_eq!(row[8], if o.misfit { "1" } else { "0" }, "{row:?}");
    }
    assert!(
        rows[..150].iter().all(|r| r[8] == "0"),
        "no misfit on the line"
    );
    assert!(
        rows[150..].iter().any(|r| r[8] == "1"),
        "misfit after the manoeuvre"
    );
}

/// The library's automatic filter over `samples`, finished: its outputs and final outlier
/// decisions (what `seqsmooth filter --kind auto` writes in its `outlier` column).
fn library_run(
    f: &mut AutomaticFilter,
    samples: &[(f64, f64)],
) -> (Vec<seqsmooth::polynomial::automatic::AutoOutput>, Vec<bool>) {
    let outs: Vec<_> = samples
        .iter()
        .map(|&(t, y)| f.update(t, y).unwrap())
        .collect();
    let tail = f.finish();
    let flags = final_outliers(&outs, &tail);
    (outs, flags)
}

/// `--review-window N`: the automatic filter's outlier column is its review's final decision
/// (or, with 0, the gate's), as the library's filter gives it for the same N; the option is
/// checked and refused for the other kinds.
#[test]
fn filter_auto_review_window() {
    let (input, samples) = auto_input(Some(120));
    for (window, arg) in [(None, None), (Some(0), Some("0")), (Some(9), Some("9"))] {
        let mut args = vec![
            "filter", "--kind", "auto", "--degree", "1", "--theta", "0.9",
        ];
        if let Some(a) = arg {
            args.extend(["--review-window", a]);
        }
        let (_, rows) = table(&ok(&args, &input));
        let mut f = AutomaticFilter::new(1, 0.9, 1.0).unwrap();
        if let Some(w) = window {
            f = f.with_review_window(w).unwrap();
        }
        let (_, flags) = library_run(&mut f, &samples);
        assert!(flags[120], "{window:?}: the 20σ outlier");
        for (row, rejected) in rows.iter().zip(flags) {
            assert_eq!(
                row[7],
                if rejected { "1" } else { "0" },
                "{window:?} {row:?}"
            );
        }
    }
    fails(
        &[
            "filter",
            "--kind",
            "auto",
            "--degree",
            "2",
            "--theta",
            "0.9",
            "--review-window",
            "2",
        ],
        &input,
        2,
        &["--review-window 2", "from 3 to 31"],
    );
    fails(
        &[
            "filter",
            "--kind",
            "fading",
            "--degree",
            "1",
            "--theta",
            "0.9",
            "--review-window",
            "3",
        ],
        &input,
        2,
        &["--review-window", "--kind auto"],
    );
}
