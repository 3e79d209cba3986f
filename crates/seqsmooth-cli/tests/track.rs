//! End-to-end tests of `seqsmooth track`: every method on the landing trajectory of
//! `tests/data/landing.csv` (bearing convention, a turn and a descent) with seeded noise of
//! known σ, scored against its east/north/up truth; the smoother's last row against the
//! filter's; and the refusals with their line and column.

use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use seqsmooth::track::DEFAULT_LAG;
use std::path::PathBuf;

mod common;
use common::*;

const SIGMA_RANGE: f64 = 10.0;
const SIGMA_ANGLE: f64 = 1e-3;

/// The landing trajectory with N(0, 10 m) on the range and N(0, 1 mrad) on the angles (seed
/// fixed), and its truth (east, north, up) per row.
fn landing() -> (String, Vec<[f64; 3]>) {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/landing.csv");
    let text = std::fs::read_to_string(path).unwrap();
    let mut rng = rand::rngs::StdRng::seed_from_u64(2026);
    let (nr, na) = (
        Normal::new(0.0, SIGMA_RANGE).unwrap(),
        Normal::new(0.0, SIGMA_ANGLE).unwrap(),
    );
    let mut csv = String::from("t,range,azimuth,elevation\n");
    let mut truth = Vec::new();
    for line in text.lines().skip(1) {
        let c: Vec<f64> = line.split(',').map(|v| v.parse().unwrap()).collect();
        // time,east,north,up,azimuth,elevation,range
        csv += &format!(
            "{},{},{},{}\n",
            c[0],
            c[6] + nr.sample(&mut rng),
            c[4] + na.sample(&mut rng),
            c[5] + na.sample(&mut rng)
        );
        truth.push([c[1], c[2], c[3]]);
    }
    (csv, truth)
}

/// `track` on the landing trajectory's noisy rows: the convention and noise of [`landing`].
const LANDING_ARGS: [&str; 7] = [
    "track",
    "--azimuth",
    "bearing",
    "--sigma-range",
    "10",
    "--sigma-angle",
    "1e-3",
];

fn track(input: &str, method: &[&str]) -> Vec<Vec<String>> {
    let args: Vec<&str> = [&LANDING_ARGS[..], &["--method"], method].concat();
    let (header, rows) = table(&ok(&args, input));
    assert_eq!(
        header.join(","),
        "t,x,y,z,vx,vy,vz,sx,sy,sz,svx,svy,svz,nis,flag"
    );
    rows
}

/// Every method, with the settings the help recommends for a manoeuvring target (kalman and
/// smooth --q 10 m²/s³, fading --theta 0.7 --tau 1 (per second), window --window 6), covers the truth
/// within its reported 3σ on at least 97% of the determinable rows on each of east, north
/// and up, turn included; the rows before the first determination are empty (only the first).
#[test]
fn landing_within_three_sigma() {
    let (input, truth) = landing();
    for method in [
        &["kalman", "--q", "10"][..],
        &["smooth", "--q", "10"],
        &["fading", "--theta", "0.7", "--tau", "1"],
        &["window", "--window", "6"],
    ] {
        let rows = track(&input, method);
        assert_eq!(rows.len(), truth.len());
        assert!(
            rows[0][1].is_empty(),
            "{method:?}: one row does not determine the state"
        );
        let mut covered = [0usize; 3];
        let mut determined = 0;
        for (row, want) in rows.iter().zip(&truth) {
            if row[1].is_empty() {
                continue;
            }
            determined += 1;
            for k in 0..3 {
                let (x, s) = (num(&row[1 + k]), num(&row[7 + k]));
                covered[k] += usize::from((x - want[k]).abs() <= 3.0 * s);
            }
        }
        assert_eq!(determined, truth.len() - 1, "{method:?}");
        for (k, axis) in ["east", "north", "up"].iter().enumerate() {
            let rate = covered[k] as f64 / determined as f64;
            println!("{method:?} {axis}: {:.2}%", 100.0 * rate);
            assert!(
                rate >= 0.97,
                "{method:?} {axis}: {:.2}% within 3σ",
                100.0 * rate
            );
        }
    }
}

/// The smoother's last row is the filter's (the backward pass starts there), and its σ are at
/// most the filter's on every row; the NIS column is the forward filter's. Lag 0 is the
/// filter, byte for byte; a longer lag never raises a σ; any lag at least the rows' number is
/// the whole-interval smoother (the same output), said on stderr before the first row when its
/// rows would take over 100 MB.
#[test]
fn smoother_and_filter_agree_where_they_must() {
    let (input, _) = landing();
    let kalman = track(&input, &["kalman", "--q", "10"]);
    let smooth = track(&input, &["smooth", "--q", "10"]);
    assert_eq!(kalman.last(), smooth.last());
    for (k, s) in kalman.iter().zip(&smooth).skip(1) {
        assert_eq!(k[13], s[13], "nis");
        for c in 7..13 {
            assert!(
                num(&s[c]) <= num(&k[c]) * (1.0 + 1e-12),
                "{s:?} against {k:?}"
            );
        }
    }
    assert_eq!(
        track(&input, &["smooth", "--q", "10", "--lag", "0"]),
        kalman
    );
    // With the adaptive driving noise too: the forward filter gated and adapted as kalman's,
    // each row's flag carried to its smoothed row.
    let adaptive = track(&input, &["kalman"]);
    assert_eq!(track(&input, &["smooth", "--lag", "0"]), adaptive);
    for lag in ["7", "200"] {
        let lagged = track(&input, &["smooth", "--lag", lag]);
        assert_eq!(lagged.len(), adaptive.len());
        for (k, s) in adaptive.iter().zip(&lagged) {
            assert_eq!((&k[13], &k[14]), (&s[13], &s[14]), "lag {lag}: nis, flag");
        }
    }
    assert!(
        adaptive.iter().any(|r| !r[14].is_empty()),
        "the landing rows have flagged rows"
    );
    let mut previous = kalman;
    for lag in ["1", "10", "100"] {
        let lagged = track(&input, &["smooth", "--q", "10", "--lag", lag]);
        for (p, s) in previous.iter().zip(&lagged).skip(1) {
            assert_eq!(p[13], s[13], "nis");
            assert_eq!(p[14], s[14], "lag {lag}: the flag is the forward filter's");
            for c in 7..13 {
                assert!(
                    num(&s[c]) <= num(&p[c]) * (1.0 + 1e-12),
                    "lag {lag}: {s:?} against {p:?}"
                );
            }
        }
        previous = lagged;
    }
    let whole = track(&input, &["smooth", "--q", "10", "--lag", "473"]);
    assert_eq!(
        track(&input, &["smooth", "--q", "10", "--lag", "5000"]),
        whole
    );
    let args = [
        &LANDING_ARGS[..],
        &["--method", "smooth", "--q", "10", "--lag", "100000000"],
    ]
    .concat();
    let o = run(&args, &input);
    assert_eq!(o.code, 0, "{}", o.stderr);
    assert!(
        o.stderr
            .contains("--lag 100000000 holds up to 100000001 rows: up to"),
        "{}",
        o.stderr
    );
    assert_eq!(table(&o.stdout).1, whole);
    assert!(run(&args[..args.len() - 2], &input).stderr.is_empty());
    fails(
        &[
            "track",
            "--sigma-range",
            "10",
            "--sigma-angle",
            "1e-3",
            "--lag",
            "5",
        ],
        &input,
        2,
        &["--lag applies only to --method smooth"],
    );
}

/// `track --method smooth` streams: fed 30,000 rows on a pipe left open, it has written the
/// output rows of all but the last few thousand (a batch, the lag, the writer's buffer) before
/// its input ends.
#[test]
fn the_smoother_writes_before_its_input_ends() {
    use std::io::{BufRead, Write};
    let input = long_pass(30_000);
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_seqsmooth"))
        .args(["track", "--sigma-range", "10", "--sigma-angle", "1e-3"])
        .args(["--method", "smooth", "--q", "1"])
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    stdin.write_all(input.as_bytes()).unwrap();
    stdin.flush().unwrap();
    let stdout = child.stdout.take().unwrap();
    let (lines, seen) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        for (k, _) in std::io::BufReader::new(stdout).lines().enumerate() {
            if lines.send(k + 1).is_err() {
                return;
            }
        }
    });
    let want = 20_000;
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(60);
    let mut count = 0;
    while count < want {
        let left = deadline.saturating_duration_since(std::time::Instant::now());
        match seen.recv_timeout(left) {
            Ok(n) => count = n,
            Err(_) => break,
        }
    }
    assert!(
        count >= want,
        "{count} lines written before the input's end"
    );
    drop(stdin);
    assert!(child.wait().unwrap().success());
}

/// Refusals: usage (exit 2) and data (exit 1) errors with their line and column.
#[test]
fn track_refuses_bad_input() {
    let base = ["track", "--sigma-range", "10", "--sigma-angle", "1e-3"];
    let with = |extra: &[&'static str]| -> Vec<&'static str> {
        base.iter().chain(extra).copied().collect()
    };
    let good = "t,range,azimuth,elevation\n0,10000,0.1,0.2\n1,10010,0.11,0.2\n2,10020,0.12,0.2\n";
    fails(
        &["track", "--sigma-angle", "1e-3"],
        good,
        2,
        &["--sigma-range"],
    );
    fails(&with(&["--sigma-range", "0"]), good, 2, &["sigma"]);
    fails(
        &with(&["--method", "kalman", "--window", "5"]),
        good,
        2,
        &["--window"],
    );
    fails(
        &with(&["--max-iterations", "0"]),
        good,
        2,
        &[
            "error: invalid value '0' for '--max-iterations <N>': --max-iterations 0 is invalid: \
           must be from 1 to 1000\n",
        ],
    );
    fails(
        &with(&[
            "--method", "fading", "--theta", "0.9", "--tau", "1", "--q", "1",
        ]),
        good,
        2,
        &["--q applies only"],
    );
    fails(
        &with(&["--method", "kalman", "--theta-per-update", "0.9"]),
        good,
        2,
        &["--theta, --tau and --theta-per-update apply only"],
    );
    // One range and one vocabulary with `filter`: θ in (0, 1) per --tau, or per update.
    fails(
        &with(&["--method", "fading", "--theta", "1.5", "--tau", "1"]),
        good,
        2,
        &["theta 1.5 is out of range"],
    );
    fails(
        &with(&["--method", "fading", "--theta-per-update", "1"]),
        good,
        2,
        &["theta 1 is out of range"],
    );
    fails(
        &with(&["--method", "fading", "--theta", "0.9", "--tau", "0"]),
        good,
        2,
        &["tau"],
    );
    fails(
        &with(&["--method", "fading", "--theta", "0.9"]),
        good,
        2,
        &["--tau"],
    );
    fails(
        &with(&["--method", "fading", "--beta", "0.9"]),
        good,
        2,
        &["--theta 0.9 --tau 1", "--theta-per-update"],
    );
    fails(
        &with(&[]),
        "t,range,azimuth,elevation\n0,10000,0.1,0.2\n1,NaN,0.1,0.2\n",
        1,
        &["line 3", "column 'range'", "not finite"],
    );
    fails(
        &with(&[]),
        "t,range,azimuth,elevation\n0,10000,0.1,0.2\n0,10000,0.1,0.2\n",
        1,
        &["line 3", "not after the previous time"],
    );
    fails(
        &with(&[]),
        "t,range,azimuth,elevation\n0,10000,0.1,2\n1,10000,0.1,0.2\n",
        1,
        &["line 2", "column 'elevation'", "outside"],
    );
    fails(
        &with(&[]),
        "t,range,elevation\n0,10000,0.2\n",
        1,
        &["column 'azimuth'"],
    );
    fails(
        &with(&[]),
        "t,range,azimuth,elevation\n0,10000,0.1,0.2\n",
        1,
        &["too few samples"],
    );
    fails(
        &with(&[]),
        "t,range,azimuth,elevation\n0,10000,,\n1,10000,,\n2,10000,,\n",
        1,
        &["never determine the state"],
    );
}

/// Right or refused on 1,000 seeded random inputs (radar passes anywhere within 20 km with rare
/// empty, huge, zero, negative and out-of-range cells, tiny and huge time steps; random method,
/// settings and convention), run in process: no panic; a success writes only finite numbers;
/// a failure has a message and leaves no output file.
#[test]
fn random_inputs_are_right_or_refused() {
    use clap::Parser;
    use rand::Rng;
    use seqsmooth_cli::args::{Cli, Command};
    let mut rng = rand::rngs::StdRng::seed_from_u64(19);
    let dir = tmp("track-random");
    std::fs::create_dir_all(&dir).unwrap();
    let (input, output) = (dir.join("in.csv"), dir.join("out.csv"));
    let mut succeeded = 0;
    for _ in 0..1000 {
        let mut csv = String::from("t,range,azimuth,elevation\n");
        let mut t: f64 = if rng.gen_bool(0.2) { 1.7e9 } else { 0.0 };
        let x0: Vec<f64> = (0..3).map(|_| rng.gen_range(-2e4..2e4)).collect();
        let v: Vec<f64> = (0..3).map(|_| rng.gen_range(-300.0..300.0)).collect();
        for _ in 0..rng.gen_range(0..60) {
            let p: Vec<f64> = (0..3).map(|i| x0[i] + v[i] * (t % 1e4)).collect();
            let mut cells = [
                t.to_string(),
                ((p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt() + rng.gen_range(-10.0..10.0))
                    .to_string(),
                p[1].atan2(p[0]).to_string(),
                p[2].atan2(p[0].hypot(p[1])).to_string(),
            ];
            for c in cells.iter_mut().skip(1) {
                let odd = ["", "1e300", "1e-300", "0", "-1", "3.14159"];
                if let Some(s) = odd.get(rng.gen_range(0..500)) {
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
        let method = ["window", "kalman", "fading", "smooth"][rng.gen_range(0..4)];
        let mut args: Vec<String> = vec![
            "seqsmooth".into(),
            "track".into(),
            input.display().to_string(),
            format!("--output={}", output.display()),
            format!("--method={method}"),
            "--sigma-range=10".into(),
            "--sigma-angle=1e-3".into(),
            ["--azimuth=from-x", "--azimuth=bearing"][rng.gen_range(0..2)].into(),
        ];
        if method == "smooth" {
            args.push(format!("--lag={}", [0, 1, 5, 200][rng.gen_range(0..4)]));
        }
        match method {
            "window" => args.push(format!("--window={}", rng.gen_range(1..30))),
            "fading" => {
                args.push(format!("--theta={}", rng.gen_range(0.01..1.0)));
                args.push("--tau=1".into());
            }
            _ => args.push(format!(
                "--q={}",
                [0.0, 1.0, 10.0, 1e6][rng.gen_range(0..4)]
            )),
        }
        let Command::Track(a) = Cli::try_parse_from(&args).unwrap().command else {
            unreachable!()
        };
        match seqsmooth_cli::commands::track::run(&a) {
            Ok(()) => {
                succeeded += 1;
                let text = std::fs::read_to_string(&output).unwrap();
                for line in text.lines().skip(1) {
                    for cell in line.split(',').skip(1).filter(|c| !c.is_empty()) {
                        let flag = ["outlier", "misfit"].contains(&cell);
                        assert!(flag || num(cell).is_finite(), "{args:?}: {line}");
                    }
                }
            }
            Err(e) => {
                assert!(!e.to_string().is_empty());
                assert!(!output.exists(), "{args:?}: {e}");
            }
        }
    }
    println!("{succeeded} of 1000 succeeded");
    assert!(succeeded > 200, "{succeeded} successful runs");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The landing trajectory as [`landing`] builds it, with per-row noise: row `k` has range σ
/// `sigmas(k).0` and angle σ `sigmas(k).1` (the noise drawn with them, seed fixed), written in
/// the columns `sr` and `sa` after the measurements. Returns the CSV and the σ of each row.
fn landing_with_sigmas(sigmas: impl Fn(usize) -> (f64, f64)) -> (String, Vec<(f64, f64)>) {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/landing.csv");
    let text = std::fs::read_to_string(path).unwrap();
    let mut rng = rand::rngs::StdRng::seed_from_u64(2027);
    let unit = Normal::new(0.0, 1.0).unwrap();
    let mut csv = String::from("t,range,azimuth,elevation,sr,sa\n");
    let mut used = Vec::new();
    for (k, line) in text.lines().skip(1).enumerate() {
        let c: Vec<f64> = line.split(',').map(|v| v.parse().unwrap()).collect();
        let (sr, sa) = sigmas(k);
        csv += &format!(
            "{},{},{},{},{sr},{sa}\n",
            c[0],
            c[6] + sr * unit.sample(&mut rng),
            c[4] + sa * unit.sample(&mut rng),
            c[5] + sa * unit.sample(&mut rng)
        );
        used.push((sr, sa));
    }
    (csv, used)
}

/// `track` with `args` (no σ flags added) on `input`: the output text.
fn track_text(input: &str, args: &[&str]) -> String {
    let all: Vec<&str> = ["track", "--azimuth", "bearing"]
        .iter()
        .chain(args)
        .copied()
        .collect();
    ok(&all, input)
}

/// The four methods with the settings the help recommends.
const METHODS: [&[&str]; 4] = [
    &["--method", "kalman", "--q", "10"],
    &["--method", "smooth", "--q", "10"],
    &["--method", "fading", "--theta", "0.7", "--tau", "1"],
    &["--method", "window", "--window", "6"],
];

/// Per-row σ columns that hold the flags' values give the flags' output byte for byte, every
/// method: columns alone, columns with flags of other values (a cell wins over the flag), and
/// columns with empty cells where the flags fill in.
#[test]
fn per_row_sigmas_equal_to_the_flags_change_nothing() {
    let (input, _) = landing_with_sigmas(|_| (10.0, 1e-3));
    // Every third row's σ cells emptied: those rows take the flags.
    let holes: String = input
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if i > 0 && i % 3 == 0 {
                let cells: Vec<&str> = l.split(',').collect();
                format!("{},,\n", cells[..4].join(","))
            } else {
                format!("{l}\n")
            }
        })
        .collect();
    let flags = ["--sigma-range", "10", "--sigma-angle", "1e-3"];
    let columns = ["--sigma-range-col", "sr", "--sigma-angle-col", "sa"];
    let other_flags = ["--sigma-range", "99", "--sigma-angle", "0.5"];
    for method in METHODS {
        let want = track_text(&input, &[method, &flags[..]].concat());
        assert_eq!(want.lines().count(), input.lines().count(), "{method:?}");
        for (what, text, args) in [
            ("columns", &input, [method, &columns[..]].concat()),
            (
                "columns over other flags",
                &input,
                [method, &columns[..], &other_flags[..]].concat(),
            ),
            (
                "columns with holes",
                &holes,
                [method, &columns[..], &flags[..]].concat(),
            ),
        ] {
            assert!(track_text(text, &args) == want, "{method:?}: {what}");
        }
    }
}

/// One output row's numbers: the state, its σ and the NIS.
type Row = ([f64; 6], [f64; 6], Option<f64>);

/// The library's start and filter run directly on the rows with their own σ: the fit of the
/// first rows that determines the state (window 60, the radar nominal of degree 2), then
/// `KalmanFilter` with white-noise acceleration `q`: per row `None` before the start, then
/// the state, its σ and the NIS.
fn library_kalman(input: &str, q: f64) -> Vec<Option<Row>> {
    use seqsmooth::estimate::batch::NoiseCovariance;
    use seqsmooth::estimate::gauss_newton::{Epoch, Measurement};
    use seqsmooth::estimate::sliding::{SlidingFit, Start};
    use seqsmooth::kalman::noise::WhiteNoiseDerivative;
    use seqsmooth::kalman::KalmanFilter;
    use seqsmooth::model::dynamics::PolynomialDynamics;
    use seqsmooth::model::radar::{wrap, Radar};
    let radar = Radar::new([0.0; 3], 6).unwrap();
    let dynamics = PolynomialDynamics::new(1, 3);
    let mut start = SlidingFit::new(
        dynamics,
        radar,
        60,
        Epoch::End,
        Start::Radar { radar, degree: 2 },
    )
    .unwrap();
    let mut filter = None;
    let mut out = Vec::new();
    let cells = |x: &nalgebra::DVector<f64>, s: &nalgebra::DMatrix<f64>, nis| {
        let state: [f64; 6] = std::array::from_fn(|k| x[k]);
        let sigma: [f64; 6] = std::array::from_fn(|k| s[(k, k)].sqrt());
        Some((state, sigma, nis))
    };
    for line in input.lines().skip(1) {
        let c: Vec<f64> = line.split(',').map(|v| v.parse().unwrap()).collect();
        let m = Measurement {
            time: c[0],
            values: vec![
                Some(c[1]),
                Some(wrap(std::f64::consts::FRAC_PI_2 - c[2])),
                Some(c[3]),
            ],
            noise: NoiseCovariance::Variances(vec![c[4] * c[4], c[5] * c[5], c[5] * c[5]]),
        };
        match &mut filter {
            None => match start.push(m).unwrap() {
                Some(fit) => {
                    out.push(cells(&fit.state, &fit.covariance, None));
                    filter = Some(
                        KalmanFilter::new(dynamics, radar, fit.state, fit.covariance, fit.epoch)
                            .unwrap()
                            .with_process_noise(WhiteNoiseDerivative::new(1, 3, q).unwrap())
                            .unwrap(),
                    );
                }
                None => out.push(None),
            },
            Some(f) => {
                let nis = f.update(&m).unwrap().map(|i| i.nis);
                out.push(cells(f.state(), f.covariance(), nis));
            }
        }
    }
    out
}

/// Each row's σ reaches the filter: with σ varying row to row (range 3-60 m, angles 0.3-6
/// mrad, the noise drawn with them), every cell of `track --method kalman` is the library's
/// own filter run directly on the rows with their σ (the same doubles: the output's digits
/// round-trip), and not the run with the rows' mean σ.
#[test]
fn per_row_sigmas_reach_the_filter() {
    let sigma = |k: usize| {
        let f = [1.0, 0.3, 2.0, 6.0, 0.6][k % 5];
        (10.0 * f, 1e-3 * f)
    };
    let (input, _) = landing_with_sigmas(sigma);
    let text = track_text(
        &input,
        &[
            "--method",
            "kalman",
            "--q",
            "10",
            "--sigma-range-col",
            "sr",
            "--sigma-angle-col",
            "sa",
        ],
    );
    let (_, rows) = table(&text);
    let want = library_kalman(&input, 10.0);
    assert_eq!(rows.len(), want.len());
    for (k, (row, want)) in rows.iter().zip(&want).enumerate() {
        match want {
            None => assert!(row[1..].iter().all(String::is_empty), "row {k}: {row:?}"),
            Some((x, s, nis)) => {
                for i in 0..6 {
                    assert_eq!(num(&row[1 + i]), x[i], "row {k} state {i}");
                    assert_eq!(num(&row[7 + i]), s[i], "row {k} sigma {i}");
                }
                assert_eq!(row[13].parse::<f64>().ok(), *nis, "row {k} nis");
            }
        }
    }
    // The flags at the mean σ give another track.
    let mean = track_text(
        &input,
        &[
            "--method",
            "kalman",
            "--q",
            "10",
            "--sigma-range",
            "19.8",
            "--sigma-angle",
            "1.98e-3",
        ],
    );
    assert_ne!(mean, text);
}

/// A row with a larger σ weighs less. Row 200's range is given σ 10, 30, 100 and 1000 m in
/// turn (every other row σ 10 m) and pushed 300 m off: the estimate's shift at that row from
/// the same run without the 300 m falls as σ grows (the gain `S Mᵀ (M S Mᵀ + R)⁻¹` falls with
/// `R`); and at σ 1e7 m the row's range carries no weight: the
/// state equals the run where the row's range cell is empty (a missing component), within
/// 1e-6 of its σ, at that row and every later one. The same for the angles (σ 1e3 rad against
/// empty azimuth and elevation cells).
#[test]
fn a_row_with_a_larger_sigma_weighs_less() {
    let (input, _) = landing_with_sigmas(|_| (10.0, 1e-3));
    let lines: Vec<&str> = input.lines().collect();
    let row = 200;
    // The input with row `row`'s cells replaced by `f(cells)`.
    let edit = |f: &dyn Fn(&mut Vec<String>)| -> String {
        let mut out = String::new();
        for (i, l) in lines.iter().enumerate() {
            let mut cells: Vec<String> = l.split(',').map(String::from).collect();
            if i == row + 1 {
                f(&mut cells);
            }
            out += &cells.join(",");
            out.push('\n');
        }
        out
    };
    let args = [
        "--method",
        "kalman",
        "--q",
        "10",
        "--sigma-range-col",
        "sr",
        "--sigma-angle-col",
        "sa",
    ];
    let rows = |input: &str| table(&track_text(input, &args)).1;
    let shift = |a: &[String], b: &[String]| -> f64 {
        (1..4)
            .map(|i| (num(&a[i]) - num(&b[i])).powi(2))
            .sum::<f64>()
            .sqrt()
    };
    let mut previous = f64::INFINITY;
    for sr in ["10", "30", "100", "1000"] {
        let off = rows(&edit(&|c| {
            c[1] = (num(&c[1]) + 300.0).to_string();
            c[4] = sr.into();
        }));
        let clean = rows(&edit(&|c| c[4] = sr.into()));
        let s = shift(&off[row], &clean[row]);
        println!("range sigma {sr}: shift {s:.3} m");
        assert!(s < previous, "sigma {sr}: shift {s} not below {previous}");
        previous = s;
    }
    assert!(previous < 1.0, "{previous}");
    // No weight: a huge σ is an empty cell.
    let same = |a: &[Vec<String>], b: &[Vec<String>], what: &str| {
        for k in row..a.len() {
            for i in 0..6 {
                let (x, y, s) = (num(&a[k][1 + i]), num(&b[k][1 + i]), num(&b[k][7 + i]));
                assert!(
                    (x - y).abs() <= 1e-6 * s,
                    "{what}: row {k}, state {i}: {x} against {y}"
                );
            }
        }
    };
    let huge = rows(&edit(&|c| {
        c[1] = (num(&c[1]) + 300.0).to_string();
        c[4] = "1e7".into();
    }));
    let missing = rows(&edit(&|c| c[1].clear()));
    same(&huge, &missing, "range");
    let huge = rows(&edit(&|c| c[5] = "1e3".into()));
    let missing = rows(&edit(&|c| {
        c[2].clear();
        c[3].clear();
    }));
    same(&huge, &missing, "angles");
}

/// Issue 12 must-show 8: bad input stops with the usual typed message (exit 1, `error: `)
/// naming the line and the column: NaN and non-numbers in every column, times that repeat or
/// go back, missing columns (the header's line), angles out of range, ranges not positive,
/// σ cells not positive, not finite, not numbers or out of range, and an empty σ cell where
/// no flag fills in. Flags that are out of range are command-line errors (exit 2).
#[test]
fn bad_input_names_line_and_column() {
    let flags = ["track", "--sigma-range", "10", "--sigma-angle", "1e-3"];
    let head = "t,range,azimuth,elevation\n0,10000,0.1,0.2\n1,10010,0.11,0.2\n";
    let bad = |row: &str, parts: &[&str]| {
        fails(&flags, &format!("{head}{row}\n"), 1, parts);
    };
    for (row, column, why) in [
        ("NaN,10020,0.12,0.2", "t", "not finite"),
        ("2,NaN,0.12,0.2", "range", "not finite"),
        ("2,10020,nan,0.2", "azimuth", "not finite"),
        ("2,10020,0.12,inf", "elevation", "not finite"),
        ("2,ten,0.12,0.2", "range", "not a number"),
        ("2,10020,0.12,0.2x", "elevation", "not a number"),
        ("1,10020,0.12,0.2", "t", "duplicate time"),
        (
            "0.5,10020,0.12,0.2",
            "t",
            "not after the previous time 1 (line 3)",
        ),
        ("2,10020,0.12,1.6", "elevation", "outside [-pi/2, pi/2]"),
        ("2,10020,0.12,-1.6", "elevation", "outside [-pi/2, pi/2]"),
        ("2,10020,45,0.2", "azimuth", "outside [-2pi, 2pi]"),
        ("2,10020,-7,0.2", "azimuth", "outside [-2pi, 2pi]"),
        ("2,0,0.12,0.2", "range", "not positive"),
        ("2,-5,0.12,0.2", "range", "not positive"),
    ] {
        bad(row, &["line 4", &format!("column '{column}'"), why]);
    }
    // Missing columns: the header's line.
    for (header, column) in [
        ("time,range,azimuth,elevation", "t"),
        ("t,rng,azimuth,elevation", "range"),
        ("t,range,elevation", "azimuth"),
        ("t,range,azimuth", "elevation"),
    ] {
        let cells = header.split(',').count();
        let row = ["0", "10000", "0.1", "0.2"][..cells].join(",");
        fails(
            &flags,
            &format!("{header}\n{row}\n"),
            1,
            &["line 1", &format!("column '{column}' not found")],
        );
    }
    // σ columns.
    let sigma_head = "t,range,azimuth,elevation,sr,sa\n0,10000,0.1,0.2,10,1e-3\n\
                      1,10010,0.11,0.2,10,1e-3\n";
    let columns = [
        "track",
        "--sigma-range-col",
        "sr",
        "--sigma-angle-col",
        "sa",
    ];
    for (row, column, why) in [
        ("2,10020,0.12,0.2,0,1e-3", "sr", "sigma 0 is not positive"),
        ("2,10020,0.12,0.2,-3,1e-3", "sr", "sigma -3 is not positive"),
        (
            "2,10020,0.12,0.2,10,-1e-3",
            "sa",
            "sigma -1e-3 is not positive",
        ),
        ("2,10020,0.12,0.2,NaN,1e-3", "sr", "not finite"),
        ("2,10020,0.12,0.2,10,inf", "sa", "not finite"),
        ("2,10020,0.12,0.2,ten,1e-3", "sr", "not a number"),
        ("2,10020,0.12,0.2,1e200,1e-3", "sr", "out of range"),
        ("2,10020,0.12,0.2,10,1e-160", "sa", "out of range"),
        ("2,10020,0.12,0.2,,1e-3", "sr", "no --sigma-range is given"),
        ("2,10020,0.12,,10,", "sa", "no --sigma-angle is given"),
    ] {
        fails(
            &columns,
            &format!("{sigma_head}{row}\n"),
            1,
            &["line 4", &format!("column '{column}'"), why],
        );
    }
    fails(
        &["track", "--sigma-range-col", "s_r", "--sigma-angle", "1e-3"],
        sigma_head,
        1,
        &["line 1", "column 's_r' not found"],
    );
    // An empty σ cell is fine where the components it weighs are missing.
    let out = ok(
        &columns,
        &format!("{sigma_head}2,,0.12,0.2,,1e-3\n3,10030,,,10,\n"),
    );
    assert_eq!(out.lines().count(), 5);
    // Flags: command-line errors.
    for (args, part) in [
        (&["track", "--sigma-angle", "1e-3"][..], "--sigma-range"),
        (&["track", "--sigma-range", "10"], "--sigma-angle"),
        (
            &["track", "--sigma-range", "0", "--sigma-angle", "1e-3"],
            "sigma",
        ),
        (
            &["track", "--sigma-range", "10", "--sigma-angle", "-1"],
            "sigma",
        ),
        (
            &["track", "--sigma-range", "nan", "--sigma-angle", "1e-3"],
            "sigma",
        ),
    ] {
        fails(args, head, 2, &[part]);
    }
}

/// A failure after many rows have been written leaves no output file, and an existing one as
/// it was (kalman, fading and window stream their rows into a temporary file renamed only at
/// the end); on standard output the rows before the error are written.
#[test]
fn a_late_error_leaves_no_output() {
    let (input, _) = landing();
    let bad = format!("{input}1e9,NaN,0.1,0.2\n");
    let dir = tmp("track-late-error");
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("out.csv");
    for method in METHODS {
        let _ = std::fs::remove_file(&out);
        let o = format!("--output={}", out.display());
        let args: Vec<&str> = [
            &["track", "--azimuth", "bearing", "--sigma-range", "10"][..],
            &["--sigma-angle", "1e-3", &o],
            method,
        ]
        .concat();
        fails(&args, &bad, 1, &["line 476", "column 'range'"]);
        assert!(!out.exists(), "{method:?}");
        std::fs::write(&out, "before\n").unwrap();
        fails(&args, &bad, 1, &["line 476"]);
        assert_eq!(std::fs::read_to_string(&out).unwrap(), "before\n");
        let left: Vec<_> = std::fs::read_dir(&dir).unwrap().collect();
        assert_eq!(left.len(), 1, "{method:?}: temporary files left: {left:?}");
    }
    let o = run(&[&LANDING_ARGS[..], &["--q", "10"]].concat(), &bad);
    assert_eq!(o.code, 1);
    assert_eq!(
        o.stdout.lines().count(),
        475,
        "the header and the 474 good rows"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A straight pass of `rows` rows (from (20, −15, 3) km at (−40, 25, −1) m/s, steps of
/// 0.1 s, noise σ 10 m and 1 mrad, seed fixed), azimuth from +x.
fn long_pass(rows: usize) -> String {
    let mut rng = rand::rngs::StdRng::seed_from_u64(7);
    let (nr, na) = (
        Normal::new(0.0, SIGMA_RANGE).unwrap(),
        Normal::new(0.0, SIGMA_ANGLE).unwrap(),
    );
    let mut csv = String::from("t,range,azimuth,elevation\n");
    for k in 0..rows {
        let t = k as f64 * 0.1;
        let (x, y, z) = (2e4 - 40.0 * t, -1.5e4 + 25.0 * t, 3e3 - t);
        csv += &format!(
            "{t},{},{},{}\n",
            (x * x + y * y + z * z).sqrt() + nr.sample(&mut rng),
            y.atan2(x) + na.sample(&mut rng),
            z.atan2(x.hypot(y)) + na.sample(&mut rng)
        );
    }
    csv
}

/// The rows are read, tracked and written in batches of thousands on three threads; on an
/// input of 10,000 rows the filters' output rows for the first 2,500, 4,096, 4,097 and 6,000
/// rows are the first rows of the whole input's output, byte for byte (a filter's estimate
/// depends only on the rows so far, so no batch boundary may show), and the same from a file
/// as from standard input. An error on row 9,000 stops every streaming method with its line,
/// leaves no output file, and gives standard output the header and the 8,999 rows before it.
#[test]
fn long_inputs_stream_across_batches() {
    let input = long_pass(10_000);
    let lines: Vec<&str> = input.lines().collect();
    let prefix = |n: usize| lines[..=n].join("\n") + "\n";
    let dir = tmp("track-long");
    std::fs::create_dir_all(&dir).unwrap();
    let (file, out) = (dir.join("in.csv"), dir.join("out.csv"));
    std::fs::write(&file, &input).unwrap();
    let base = ["track", "--sigma-range", "10", "--sigma-angle", "1e-3"];
    for method in [
        &["--method", "kalman", "--q", "1"][..],
        &["--method", "fading", "--theta", "0.9", "--tau", "1"],
    ] {
        let args: Vec<&str> = [&base[..], method].concat();
        let whole = ok(&args, &input);
        assert_eq!(whole.lines().count(), 10_001);
        for n in [2500, 4096, 4097, 6000] {
            let part = ok(&args, &prefix(n));
            assert!(whole.starts_with(&part), "{method:?}: the first {n} rows");
        }
        let o = format!("--output={}", out.display());
        let from_file: Vec<&str> = [&args[..], &[file.to_str().unwrap(), &o]].concat();
        ok(&from_file, "");
        assert!(
            std::fs::read_to_string(&out).unwrap() == whole,
            "{method:?}"
        );
    }
    // The smoother: row k's output is the same once row k + lag is in, whatever comes after.
    for lag in ["0", "37", "200"] {
        let args: Vec<&str> =
            [&base[..], &["--method", "smooth", "--q", "1", "--lag", lag]].concat();
        let whole = ok(&args, &input);
        assert_eq!(whole.lines().count(), 10_001);
        let lag: usize = lag.parse().unwrap();
        for n in [2500, 4096, 4097, 6000] {
            let part = ok(&args, &prefix(n));
            let final_rows = |text: &str| -> String {
                text.lines()
                    .take(1 + n - lag)
                    .collect::<Vec<_>>()
                    .join("\n")
            };
            assert_eq!(
                final_rows(&part),
                final_rows(&whole),
                "lag {lag}: the first {n} rows"
            );
        }
    }
    let mut bad = lines.clone();
    bad[9000] = "899.9,NaN,0.1,0.1";
    let bad = bad.join("\n") + "\n";
    for method in [
        &["--method", "kalman", "--q", "1"][..],
        &["--method", "fading", "--theta", "0.9", "--tau", "1"],
        &["--method", "smooth", "--q", "1"],
    ] {
        let args: Vec<&str> = [&base[..], method].concat();
        let o = run(&args, &bad);
        assert_eq!(o.code, 1, "{method:?}: {}", o.stderr);
        assert!(
            o.stderr.contains("line 9001, column 'range'"),
            "{}",
            o.stderr
        );
        // The smoother writes the rows it gave: all but its last `lag`.
        let lag = if method[1] == "smooth" {
            DEFAULT_LAG
        } else {
            0
        };
        assert_eq!(o.stdout.lines().count(), 9000 - lag, "{method:?}");
        let _ = std::fs::remove_file(&out);
        let to_file = format!("--output={}", out.display());
        fails(&[&args[..], &[&to_file]].concat(), &bad, 1, &["line 9001"]);
        assert!(!out.exists(), "{method:?}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The writer's errors: an output file that cannot be created, and one that cannot be written
/// (`/dev/full`), stop the command with a message naming the file (exit 1).
#[test]
fn output_errors_are_reported() {
    let input = long_pass(3000);
    let base = ["track", "--sigma-range", "10", "--sigma-angle", "1e-3"];
    let missing = tmp("track-no-such-dir").join("sub").join("out.csv");
    let o = format!("--output={}", missing.display());
    fails(
        &[&base[..], &[&o]].concat(),
        &input,
        1,
        &["cannot create output file"],
    );
    if std::path::Path::new("/dev/full").exists() {
        fails(
            &[&base[..], &["--output=/dev/full"]].concat(),
            &input,
            1,
            &["cannot write to '/dev/full'"],
        );
    }
}

/// Every method at its defaults (no --q, --beta, --theta or --window) runs on the landing
/// trajectory with noise; every flag cell is empty, `outlier` or `misfit`; the unflagged rows
/// cover the truth within 3σ on at least 95 % of each axis (one run: the Monte Carlo of
/// `seqsmooth/tests/track_coverage.rs` holds 97 % over 200 runs) and fewer than a third of
/// the rows are flagged.
#[test]
fn defaults_run_on_landing_and_name_their_flags() {
    let (input, truth) = landing();
    for method in ["kalman", "fading", "smooth", "window"] {
        let rows = track(&input, &[method]);
        assert_eq!(rows.len(), truth.len());
        let (mut flagged, mut unflagged, mut covered) = (0, 0, [0usize; 3]);
        for (row, want) in rows.iter().zip(&truth) {
            if row[1].is_empty() {
                assert!(row[14].is_empty());
                continue;
            }
            match row[14].as_str() {
                "" => {
                    unflagged += 1;
                    for k in 0..3 {
                        let (x, s) = (num(&row[1 + k]), num(&row[7 + k]));
                        covered[k] += usize::from((x - want[k]).abs() <= 3.0 * s);
                    }
                }
                "outlier" | "misfit" => flagged += 1,
                other => panic!("{method}: flag {other:?}"),
            }
        }
        let share = flagged as f64 / (flagged + unflagged) as f64;
        println!(
            "{method}: {:.1}% flagged, covered {covered:?} of {unflagged}",
            100.0 * share
        );
        assert!(share < 1.0 / 3.0, "{method}: {:.1}% flagged", 100.0 * share);
        for (k, axis) in ["east", "north", "up"].iter().enumerate() {
            let rate = covered[k] as f64 / unflagged as f64;
            assert!(rate >= 0.95, "{method} {axis}: {:.2}%", 100.0 * rate);
        }
    }
}

/// A range 30σ off is named: every method flags its row `outlier` and leaves it out (the next
/// row is not flagged `outlier`).
#[test]
fn a_flagged_row_is_named() {
    let (input, _) = landing();
    let mut lines: Vec<String> = input.lines().map(str::to_string).collect();
    let k = 300;
    let mut cells: Vec<String> = lines[k + 1].split(',').map(str::to_string).collect();
    cells[1] = (num(&cells[1]) + 300.0).to_string();
    lines[k + 1] = cells.join(",");
    let bad = lines.join("\n") + "\n";
    for method in ["kalman", "fading", "smooth", "window"] {
        let rows = track(&bad, &[method]);
        assert_eq!(rows[k][14], "outlier", "{method}");
        assert_ne!(rows[k + 1][14], "outlier", "{method}");
    }
}

/// A window that does not converge names what to change with this command's options.
#[test]
fn a_window_that_does_not_converge_says_what_to_change() {
    let (input, _) = landing();
    let window = [
        "--method",
        "window",
        "--window",
        "60",
        "--max-iterations",
        "1",
    ];
    fails(
        &[&LANDING_ARGS[..], &window].concat(),
        &input,
        1,
        &["did not converge", "--max-iterations N", "--window W"],
    );
}

/// `fit --model radar` at its defaults runs on the landing trajectory and writes its flag
/// column: `misfit` or empty.
#[test]
fn fit_radar_defaults_run_on_landing_with_a_flag_column() {
    let (input, _) = landing();
    let args = "fit --model radar --sigma-range 10 --sigma-angle 1e-3";
    let out = ok(&args.split(' ').collect::<Vec<_>>(), &input);
    let (header, rows) = table(&out);
    assert_eq!(header.last().unwrap(), "flag");
    let flagged = rows
        .iter()
        .filter(|r| match r.last().unwrap().as_str() {
            "misfit" => true,
            "" => false,
            other => panic!("flag {other:?}"),
        })
        .count();
    println!(
        "fit --model radar: {flagged} of {} rows flagged",
        rows.len()
    );
    assert!(flagged > 0 && flagged < rows.len() / 2);
}

/// `--model`: constant velocity is the default, byte for byte; every built-in model runs on the
/// landing trajectory with the kalman and smooth methods at their defaults, each row reporting
/// position and velocity, the NIS per degree of freedom near 1 (printed: docs/tracking.md).
#[test]
fn every_model_runs_on_landing() {
    let (input, truth) = landing();
    let default = ok(&LANDING_ARGS, &input);
    let cv = ok(
        &[&LANDING_ARGS[..], &["--model", "constant-velocity"]].concat(),
        &input,
    );
    assert_eq!(default, cv);
    for model in [
        "constant-velocity",
        "constant-acceleration",
        "singer",
        "coordinated-turn",
    ] {
        for method in ["kalman", "smooth"] {
            let rows = track(&input, &[method, "--model", model]);
            assert_eq!(rows.len(), truth.len());
            let (mut nis, mut count, mut squared) = (0.0, 0usize, 0.0);
            for (row, want) in rows.iter().zip(&truth) {
                if row[1].is_empty() {
                    continue;
                }
                squared += (0..3)
                    .map(|k| (num(&row[1 + k]) - want[k]).powi(2))
                    .sum::<f64>();
                count += 1;
                if !row[13].is_empty() {
                    nis += num(&row[13]);
                }
            }
            // Every row has its three components: the NIS per degree of freedom.
            let per_dof = nis / (3 * count) as f64;
            let rms = (squared / count as f64).sqrt();
            println!("landing {method} --model {model}: NIS/dof {per_dof:.2}, RMS {rms:.1} m");
            assert!(count >= truth.len() - 2, "{model}: {count} rows");
            assert!((0.5..2.0).contains(&per_dof), "{model}: {per_dof}");
        }
    }
}

/// A model or model parameter a method cannot use is refused, naming the flag.
#[test]
fn models_a_method_cannot_use_are_refused() {
    let base = ["track", "--sigma-range", "10", "--sigma-angle", "1e-3"];
    let with = |extra: &[&'static str]| -> Vec<&'static str> {
        base.iter().chain(extra).copied().collect()
    };
    let good = "t,range,azimuth,elevation\n0,10000,0.1,0.2\n1,10010,0.11,0.2\n2,10020,0.12,0.2\n";
    fails(
        &with(&["--model", "spiral"]),
        good,
        2,
        &["--model 'spiral' is invalid: must be one of constant-velocity, constant-acceleration, singer, coordinated-turn"],
    );
    fails(
        &with(&["--method", "window", "--model", "coordinated-turn"]),
        good,
        2,
        &["--model coordinated-turn is invalid: the window method fits the constant-velocity model only"],
    );
    fails(
        &with(&["--model", "singer", "--q", "1"]),
        good,
        2,
        &["--q 1 is invalid: does not apply to the singer model"],
    );
    fails(
        &with(&[
            "--method",
            "fading",
            "--model",
            "singer",
            "--manoeuvre-variance",
            "4",
        ]),
        good,
        2,
        &["--manoeuvre-variance 4 is invalid: does not apply to the fading method"],
    );
    fails(
        &with(&["--turn-rate-noise", "1e-4"]),
        good,
        2,
        &["--turn-rate-noise 0.0001 is invalid: is not a parameter of the constant-velocity model"],
    );
    fails(
        &with(&["--model", "coordinated-turn", "--manoeuvre-alpha", "0.1"]),
        good,
        2,
        &["--manoeuvre-alpha 0.1 is invalid: is not a parameter of the coordinated-turn model"],
    );
    fails(
        &with(&["--model", "singer", "--manoeuvre-alpha", "0"]),
        good,
        2,
        &["--manoeuvre-alpha 0 is invalid"],
    );
    fails(
        &with(&["--model", "coordinated-turn", "--turn-rate-noise", "-1"]),
        good,
        2,
        &["--turn-rate-noise -1 is invalid"],
    );
}
