//! End-to-end tests of `seqsmooth fit`: the polynomial model against `seqsmooth filter --kind
//! fixed` (the same least-squares fit by another engine, Morrison ch. 7 against §8.6), the radar
//! model against the library's `SlidingFit` run directly (bit for bit) and against the truth it
//! was simulated from, the epoch column, missing components, and every refusal with its line
//! and column.

use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal};
use seqsmooth::estimate::batch::NoiseCovariance;
use seqsmooth::estimate::gauss_newton::{Epoch, Measurement};
use seqsmooth::estimate::sliding::{SlidingFit, Start};
use seqsmooth::model::dynamics::PolynomialDynamics;
use seqsmooth::model::radar::Radar;

mod common;
use common::*;

/// A scalar series on irregular times from `t0`: a slow sine plus noise.
fn scalar_series(n: usize, t0: f64, seed: u64) -> String {
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let mut text = String::from("t,y\n");
    let mut t = t0;
    for _ in 0..n {
        let y = 5.0 * (0.1 * (t - t0)).sin() + rng.gen_range(-0.3..0.3);
        text += &format!("{t},{y}\n");
        t += rng.gen_range(0.3..1.7);
    }
    text
}

/// The polynomial model is the fixed-memory filter's least-squares fit: every d and s cell
/// within 1e-9 (relative to max(1, |value|)) of `filter --kind fixed --sigma` on the rows
/// where both have an estimate, degrees 0-8, windows from M+1 to 40, irregular times from 0
/// and from a Unix-epoch time.
#[test]
fn polynomial_model_equals_filter_fixed() {
    let mut worst: f64 = 0.0;
    for (degree, window, t0) in [
        (0, 1, 0.0),
        (1, 5, 0.0),
        (2, 15, 0.0),
        (3, 40, 1.7e9),
        (5, 12, 0.0),
        (8, 30, 0.0),
        (8, 9, 100.0),
    ] {
        let input = scalar_series(90, t0, degree as u64 + 7);
        let (d, w, s) = (degree.to_string(), window.to_string(), "0.3");
        let fit = ok(
            &[
                "fit",
                "--model",
                "polynomial",
                "--degree",
                &d,
                "--window",
                &w,
                "--sigma",
                s,
            ],
            &input,
        );
        let filter = ok(
            &[
                "filter", "--kind", "fixed", "--degree", &d, "--window", &w, "--sigma", s,
            ],
            &input,
        );
        let (fh, fr) = table(&fit);
        let (_, gr) = table(&filter);
        let mut want: Vec<String> = vec!["t".into(), "y".into()];
        want.extend((0..=degree).map(|k| format!("d{k}")));
        want.extend((0..=degree).map(|k| format!("s{k}")));
        want.extend(["iterations".into(), "chi2".into()]);
        assert_eq!(fh, want);
        assert_eq!(fr.len(), gr.len());
        let mut compared = 0;
        for (i, (a, b)) in fr.iter().zip(&gr).enumerate() {
            assert_eq!(a[..2], b[..2], "row {i}: t and y echoed");
            // fit estimates from row M on (the window growing), filter from row W-1 on.
            assert_eq!(a[2].is_empty(), i < degree, "row {i}");
            if b[2].is_empty() {
                continue;
            }
            compared += 1;
            for k in 2..2 + 2 * (degree + 1) {
                let (x, y) = (num(&a[k]), num(&b[k]));
                let e = (x - y).abs() / y.abs().max(1.0);
                worst = worst.max(e);
                assert!(
                    e <= 1e-9,
                    "degree {degree} window {window} row {i} {}: {x} against {y}",
                    fh[k]
                );
            }
        }
        assert_eq!(compared, 90 - window + 1);
    }
    println!("worst relative difference: {worst:e}");
}

/// `seqsmooth fit --model radar` with the noise of [`radar_pass`] (10 m, 1 mrad).
const RADAR: [&str; 7] = [
    "fit",
    "--model",
    "radar",
    "--sigma-range",
    "10",
    "--sigma-angle",
    "1e-3",
];

/// A constant-velocity target seen from `site`, irregular times, 10 m and 1 mrad noise; every
/// fifth row lacks its elevation. Returns the CSV and the true states.
fn radar_pass(n: usize, site: [f64; 3], seed: u64) -> (String, Vec<(f64, [f64; 6])>) {
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let (nr, na) = (
        Normal::new(0.0, 10.0).unwrap(),
        Normal::new(0.0, 1e-3).unwrap(),
    );
    let (x0, v) = ([9_000.0, -4_000.0, 2_000.0], [-80.0, 160.0, -3.0]);
    let mut text = String::from("t,range,azimuth,elevation,note\n");
    let mut truth = Vec::new();
    let mut t: f64 = 10.0;
    for k in 0..n {
        let p: Vec<f64> = (0..3).map(|i| x0[i] + v[i] * t - site[i]).collect();
        let range = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt() + nr.sample(&mut rng);
        let azimuth = p[1].atan2(p[0]) + na.sample(&mut rng);
        let elevation = p[2].atan2(p[0].hypot(p[1])) + na.sample(&mut rng);
        let elevation = if k % 5 == 4 {
            String::new()
        } else {
            elevation.to_string()
        };
        text += &format!("{t},{range},{azimuth},{elevation},x\n");
        let s = [
            x0[0] + v[0] * t,
            x0[1] + v[1] * t,
            x0[2] + v[2] * t,
            v[0],
            v[1],
            v[2],
        ];
        truth.push((t, s));
        t += rng.gen_range(0.5..1.5);
    }
    (text, truth)
}

/// The library's sliding fit of the same rows (the CLI's reference).
fn library_radar(text: &str, site: [f64; 3], window: usize, epoch: Epoch) -> Vec<Option<Vec<f64>>> {
    let radar = Radar::new(site, 6).unwrap();
    let mut fit = SlidingFit::new(
        PolynomialDynamics::new(1, 3),
        radar,
        window,
        epoch,
        Start::Radar { radar, degree: 2 },
    )
    .unwrap()
    .with_misfit_scale();
    text.lines()
        .skip(1)
        .map(|line| {
            let c: Vec<&str> = line.split(',').collect();
            let value = |s: &str| (!s.is_empty()).then(|| s.parse::<f64>().unwrap());
            let m = Measurement {
                time: c[0].parse().unwrap(),
                values: vec![value(c[1]), value(c[2]), value(c[3])],
                noise: NoiseCovariance::Variances(vec![100.0, 1e-6, 1e-6]),
            };
            fit.push(m).unwrap().map(|c| {
                let mut v: Vec<f64> = c.state.iter().copied().collect();
                v.extend((0..6).map(|k| c.covariance[(k, k)].sqrt()));
                v.push(c.iterations.len() as f64);
                v.push(c.chi_squared);
                v.push(c.epoch);
                v
            })
        })
        .collect()
}

/// The radar model writes the library's numbers bit for bit (state, σ, iterations, χ², and the
/// epoch column for --epoch centre), empty cells on the first row only (two rows determine a
/// constant-velocity state), and estimates whose errors are within 5σ of the truth.
#[test]
fn radar_model_equals_library_and_covers_the_truth() {
    let site = [500.0, -200.0, 30.0];
    let (input, truth) = radar_pass(150, site, 1);
    for (epoch_arg, epoch) in [("end", Epoch::End), ("centre", Epoch::Centre)] {
        let out = ok(
            &[
                "fit",
                "--model",
                "radar",
                "--site",
                "500,-200,30",
                "--sigma-range",
                "10",
                "--sigma-angle",
                "1e-3",
                "--window",
                "40",
                "--epoch",
                epoch_arg,
            ],
            &input,
        );
        let (header, rows) = table(&out);
        let mut want = "t,x,y,z,vx,vy,vz,sx,sy,sz,svx,svy,svz,iterations,chi2".to_string();
        if epoch_arg != "end" {
            want += ",epoch";
        }
        want += ",flag";
        assert_eq!(header.join(","), want);
        let reference = library_radar(&input, site, 40, epoch);
        assert_eq!(rows.len(), reference.len());
        for (i, (row, r)) in rows.iter().zip(&reference).enumerate() {
            assert_eq!(row.len(), header.len());
            match r {
                None => {
                    assert_eq!(i, 0, "only the first row is undetermined");
                    assert!(row[1..].iter().all(String::is_empty));
                }
                Some(r) => {
                    let last = row.len() - 1;
                    assert!(["", "misfit"].contains(&row[last].as_str()), "row {i}");
                    let cells: Vec<f64> = row[1..last].iter().map(|c| num(c)).collect();
                    let n = if epoch_arg == "end" { 14 } else { 15 };
                    assert_eq!(cells[..], r[..n], "row {i}");
                    assert!(r[12] <= 10.0, "row {i}: {} iterations", r[12]);
                }
            }
        }
        // Against the truth (once the window holds 10 rows): each component within 5σ.
        for (i, row) in rows.iter().enumerate().skip(10) {
            let cells: Vec<f64> = row[1..13].iter().map(|c| num(c)).collect();
            let t = if epoch_arg == "end" {
                truth[i].0
            } else {
                num(&row[15])
            };
            let s = truth[i].1;
            let at = |k: usize| {
                if k < 3 {
                    s[k] + s[k + 3] * (t - truth[i].0)
                } else {
                    s[k]
                }
            };
            for k in 0..6 {
                assert!(
                    (cells[k] - at(k)).abs() <= 5.0 * cells[k + 6],
                    "{epoch_arg} row {i} state {k}: {} against {} (sigma {})",
                    cells[k],
                    at(k),
                    cells[k + 6]
                );
            }
        }
    }
}

/// Refusals: usage errors (exit 2) and data errors (exit 1) with the line and column or the
/// window's lines; nothing written to an existing output file.
#[test]
fn fit_refuses_bad_input() {
    let radar = RADAR;
    fn with<'a>(radar: &[&'a str], extra: &[&'a str]) -> Vec<&'a str> {
        radar.iter().chain(extra).copied().collect()
    }
    let (good, _) = radar_pass(30, [0.0; 3], 2);
    // Usage.
    fails(&["fit", "--model", "radar"], &good, 2, &["--sigma-range"]);
    fails(
        &with(&radar, &["--sigma", "1"]),
        &good,
        2,
        &["--sigma applies only"],
    );
    fails(
        &with(&radar, &["--degree", "3"]),
        &good,
        2,
        &["degree 3", "radar"],
    );
    fails(
        &with(&radar, &["--site", "1,2"]),
        &good,
        2,
        &["site", "X,Y,Z"],
    );
    fails(
        &with(&radar, &["--site", "1,nan,2"]),
        &good,
        2,
        &[
            "error: invalid value '1,nan,2' for '--site <X,Y,Z>': --site NaN is invalid: a radar \
           site's coordinates must be finite\n",
        ],
    );
    fails(
        &with(&radar, &["--site", "1,x,2"]),
        &good,
        2,
        &["error: invalid value '1,x,2' for '--site <X,Y,Z>': site Y 'x' is not a number\n"],
    );
    fails(
        &with(&radar, &["--epoch", "later"]),
        &good,
        2,
        &["epoch 'later'"],
    );
    fails(&with(&radar, &["--window", "0"]), &good, 2, &["window"]);
    fails(
        &["fit", "--model", "polynomial", "--sigma", "1"],
        "t,y\n0,1\n",
        2,
        &["--degree"],
    );
    fails(
        &["fit", "--model", "polynomial", "--degree", "2"],
        "t,y\n0,1\n",
        2,
        &["--sigma S"],
    );
    fails(
        &[
            "fit",
            "--model",
            "polynomial",
            "--degree",
            "3",
            "--sigma",
            "1",
            "--window",
            "3",
        ],
        "t,y\n0,1\n",
        2,
        &["error: --window 3 is invalid: too small for degree 3: a degree-3 fit needs a window of \
           at least 4 rows\n"],
    );
    // Data: cells, with line and column.
    let line7 = good.lines().nth(6).unwrap().to_string();
    let c: Vec<&str> = line7.split(',').collect();
    let nan_range = format!("{},NaN,{},{},x", c[0], c[2], c[3]);
    let swap = |row: &str| -> String {
        let mut l: Vec<String> = good.lines().map(String::from).collect();
        l[6] = row.to_string();
        l.join("\n") + "\n"
    };
    fails(
        &with(&radar, &[]),
        &swap(&nan_range),
        1,
        &["line 7", "column 'range'", "not finite"],
    );
    fails(
        &with(&radar, &[]),
        &swap(&format!("{},-5,{},{},x", c[0], c[2], c[3])),
        1,
        &["line 7", "column 'range'", "range -5 is not positive"],
    );
    fails(
        &with(&radar, &[]),
        &swap(&format!("{},{},{},2.5,x", c[0], c[1], c[2])),
        1,
        &["line 7", "column 'elevation'", "outside [-pi/2, pi/2]"],
    );
    fails(
        &with(&radar, &[]),
        &swap(&format!(",{},{},{},x", c[1], c[2], c[3])),
        1,
        &["line 7", "column 't'", "empty"],
    );
    fails(
        &with(&radar, &[]),
        &swap(&format!("0,{},{},{},x", c[1], c[2], c[3])),
        1,
        &["line 7", "not after the previous time"],
    );
    fails(
        &with(&radar, &[]),
        "t,range,azimuth\n0,1,2\n",
        1,
        &["column 'elevation'"],
    );
    // Too few rows, and rows that never determine the state.
    fails(
        &with(&radar, &[]),
        "t,range,azimuth,elevation\n0,1000,0,0\n",
        1,
        &["too few samples", "1 data row"],
    );
    fails(&with(&radar, &[]), "", 1, &["too few samples", "empty"]);
    let range_only: String = std::iter::once("t,range,azimuth,elevation".to_string())
        .chain((0..8).map(|k| format!("{k},{},,", 1000.0 + k as f64)))
        .collect::<Vec<_>>()
        .join("\n");
    fails(
        &with(&radar, &["--window", "20"]),
        &range_only,
        1,
        &["never determine the state"],
    );
    // A full window that does not determine the state: its lines.
    fails(
        &with(&radar, &["--window", "4"]),
        &range_only,
        1,
        &[
            "lines 2-5",
            "window of 4 rows does not determine the state",
            "4 given, at least 6",
        ],
    );
    fails(
        &with(&radar, &["--window", "8"]),
        &range_only,
        1,
        &[
            "lines 2-9",
            "window of 8 rows does not determine the state",
            "two rows with range",
        ],
    );
    // Not converged within --max-iterations: the window's lines (its first line is the
    // input's first data row while the window fills).
    fails(
        &with(&radar, &["--max-iterations", "1"]),
        &good,
        1,
        &[
            "lines 2-",
            "(the window)",
            "did not converge in 1 iterations",
        ],
    );
    // An existing output file is left as it was.
    let path = tmp("fit-refused.csv");
    std::fs::write(&path, "keep\n").unwrap();
    let p = path.to_str().unwrap();
    fails(&with(&radar, &["-o", p]), &swap(&nan_range), 1, &["line 7"]);
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "keep\n");
    let o = run(&with(&radar, &["-o", p]), &good);
    assert_eq!(o.code, 0, "{}", o.stderr);
    assert!(std::fs::read_to_string(&path)
        .unwrap()
        .starts_with("t,x,y,z"));
    let _ = std::fs::remove_file(&path);
}

/// Right or refused on 1,500 seeded random inputs (radar passes anywhere within 20 km, and
/// scalar series, with rare empty, huge, tiny, zero, negative and out-of-range cells, tiny and
/// huge time steps, Unix-epoch times; random degree, window, epoch and iteration limit), run in
/// process: no panic; a success writes only finite numbers; a failure has a message and leaves
/// no output file.
#[test]
fn random_inputs_are_right_or_refused() {
    use clap::Parser;
    use seqsmooth_cli::args::{Cli, Command};
    let mut rng = rand::rngs::StdRng::seed_from_u64(17);
    let dir = tmp("fit-random");
    std::fs::create_dir_all(&dir).unwrap();
    let (input, output) = (dir.join("in.csv"), dir.join("out.csv"));
    let mut succeeded = 0;
    for _ in 0..1500 {
        let radar = rng.gen_bool(0.8);
        let mut csv = String::from(if radar {
            "t,range,azimuth,elevation\n"
        } else {
            "t,y\n"
        });
        let mut t: f64 = if rng.gen_bool(0.2) { 1.7e9 } else { 0.0 };
        let x0: Vec<f64> = (0..3).map(|_| rng.gen_range(-2e4..2e4)).collect();
        let v: Vec<f64> = (0..3).map(|_| rng.gen_range(-300.0..300.0)).collect();
        for _ in 0..rng.gen_range(0..80) {
            let p: Vec<f64> = (0..3).map(|i| x0[i] + v[i] * (t % 1e4)).collect();
            let range =
                (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt() + rng.gen_range(-10.0..10.0);
            let mut cells = vec![
                t.to_string(),
                range.to_string(),
                p[1].atan2(p[0]).to_string(),
                p[2].atan2(p[0].hypot(p[1])).to_string(),
            ];
            if !radar {
                cells.truncate(2);
            }
            for c in cells.iter_mut().skip(1) {
                let odd = ["", "1e300", "1e-300", "0", "-1", "3.14159"];
                if let Some(s) = odd.get(rng.gen_range(0..600)) {
                    *c = s.to_string();
                }
            }
            csv += &cells.join(",");
            csv.push('\n');
            t += match rng.gen_range(0..300) {
                0 => 1e-9,
                1 => 1e6,
                _ => rng.gen_range(0.1..2.0),
            };
        }
        std::fs::write(&input, &csv).unwrap();
        let _ = std::fs::remove_file(&output);
        let mut args: Vec<String> = vec![
            "seqsmooth".into(),
            "fit".into(),
            input.display().to_string(),
            format!("--output={}", output.display()),
            format!("--window={}", rng.gen_range(1..70)),
            ["--epoch=end", "--epoch=centre", "--epoch=100"][rng.gen_range(0..3)].into(),
        ];
        if radar {
            args.extend([
                "--model=radar".into(),
                "--sigma-range=10".into(),
                "--sigma-angle=1e-3".into(),
                format!("--degree={}", rng.gen_range(1..3)),
            ]);
        } else {
            args.extend([
                "--model=polynomial".into(),
                "--sigma=0.5".into(),
                format!("--degree={}", rng.gen_range(0..10)),
            ]);
        }
        if rng.gen_bool(0.3) {
            args.push(format!("--max-iterations={}", rng.gen_range(1..5)));
        }
        let Command::Fit(a) = Cli::try_parse_from(&args).unwrap().command else {
            unreachable!()
        };
        match seqsmooth_cli::commands::fit::run(&a) {
            Ok(()) => {
                succeeded += 1;
                let text = std::fs::read_to_string(&output).unwrap();
                for line in text.lines().skip(1) {
                    for cell in line.split(',').skip(1).filter(|c| !c.is_empty()) {
                        assert!(
                            cell == "misfit" || num(cell).is_finite(),
                            "{args:?}: {line}"
                        );
                    }
                }
            }
            Err(e) => {
                assert!(!e.to_string().is_empty());
                assert!(!output.exists(), "{args:?}: {e}");
            }
        }
    }
    assert!(succeeded > 300, "{succeeded} successful runs");
    let _ = std::fs::remove_dir_all(&dir);
}

/// An epoch ~1e200 from the times made nalgebra's SVD panic on NaN singular values, and a
/// window of 2^63 - 1 rows the row buffer's allocation: now a refusal naming the window, and
/// the fit of all rows so far.
#[test]
fn far_epochs_and_huge_windows_do_not_panic() {
    let poly = [
        "fit",
        "--model",
        "polynomial",
        "--degree",
        "1",
        "--sigma",
        "1",
    ];
    let input = "t,y\n0,0\n1,1\n2,2.5\n3,3\n";
    for epoch in ["1e200", "-1e250", "1e300"] {
        let args: Vec<&str> = poly.iter().copied().chain(["--epoch", epoch]).collect();
        fails(&args, input, 1, &["(the window)", "not finite"]);
    }
    let huge = i64::MAX.to_string();
    let args: Vec<&str> = poly.iter().copied().chain(["--window", &huge]).collect();
    let all = ok(&args, input);
    let window = ok(
        &poly
            .iter()
            .copied()
            .chain(["--window", "4"])
            .collect::<Vec<_>>(),
        input,
    );
    assert_eq!(all, window);
}

/// `fit --model radar` reads its rows as `track` does (one reader, the library's rule for a
/// radar row): `--azimuth bearing` equals the angle from +x turned by the library
/// (`from_bearing`), per-row σ columns equal the flags they repeat, and an azimuth beyond
/// `[-2π, 2π]` is refused with its line and column.
#[test]
fn radar_rows_read_as_track_reads_them() {
    let (input, _) = radar_pass(60, [0.0; 3], 3);
    let radar = RADAR;
    let plain = ok(&radar, &input);
    // Bearings b = π/2 − azimuth; the command turns them back with the library's rule.
    let mut bearing = String::from("t,range,azimuth,elevation,note\n");
    let mut turned = bearing.clone();
    for line in input.lines().skip(1) {
        let c: Vec<&str> = line.split(',').collect();
        let b = std::f64::consts::FRAC_PI_2 - c[2].parse::<f64>().unwrap();
        bearing += &format!("{},{},{b},{},{}\n", c[0], c[1], c[3], c[4]);
        let a = seqsmooth::model::radar::from_bearing(b);
        turned += &format!("{},{},{a},{},{}\n", c[0], c[1], c[3], c[4]);
    }
    let mut args = radar.to_vec();
    args.extend(["--azimuth", "bearing"]);
    let from_bearing = ok(&args, &bearing);
    assert_eq!(from_bearing, ok(&radar, &turned));
    assert_ne!(from_bearing, ok(&radar, &bearing), "the bearing is turned");
    // Per-row σ columns (empty cells take the flag) equal the flags.
    let mut with_sigmas = String::from("t,range,azimuth,elevation,note,sr,sa\n");
    for (k, line) in input.lines().skip(1).enumerate() {
        let sr = if k % 3 == 0 { "" } else { "10" };
        with_sigmas += &format!("{line},{sr},1e-3\n");
    }
    let cols = [
        "fit",
        "--model",
        "radar",
        "--sigma-range",
        "10",
        "--sigma-range-col",
        "sr",
        "--sigma-angle-col",
        "sa",
    ];
    assert_eq!(ok(&cols, &with_sigmas), plain);
    // Without a σ for the angles: the message names both ways to give one.
    fails(
        &["fit", "--model", "radar", "--sigma-range", "10"],
        &input,
        2,
        &["--sigma-angle S", "--sigma-angle-col NAME"],
    );
    // The azimuth's range, checked as track checks it.
    let mut lines: Vec<String> = input.lines().map(String::from).collect();
    let c: Vec<String> = lines[6].split(',').map(String::from).collect();
    lines[6] = format!("{},{},7,{},x", c[0], c[1], c[3]);
    fails(
        &radar,
        &(lines.join("\n") + "\n"),
        1,
        &[
            "line 7",
            "column 'azimuth'",
            "azimuth 7 is outside [-2pi, 2pi]",
        ],
    );
}
