//! End-to-end tests of `seqsmooth filter --id-col`: many series in one input.
//!
//! The oracle is the command itself on one series at a time: every filter is causal, so a
//! series' rows in the multi-series output must equal, cell for cell, the output of running
//! that series alone (padded with extra rows at the end, so that a series shorter than the
//! degree needs is accepted alone too; the padding cannot change the earlier rows, except the
//! automatic filter's outlier decisions, made from later samples: it runs unpadded), with the
//! id cell in front, re-interleaved in the input's order. The series are interleaved
//! irregularly, on different time grids, with different lengths, with ids that reappear after
//! long gaps, and the input is cut into small chunks (the hidden `--chunk-rows`) so that series
//! and chunk boundaries cross in every way.

use std::collections::HashMap;

mod common;
use common::run;

/// Runs and asserts success.
fn ok(args: &[&str], stdin: &str) -> String {
    let o = run(args, stdin);
    assert_eq!(o.code, 0, "seqsmooth {args:?} failed: {}", o.stderr);
    assert_eq!(o.stderr, "", "seqsmooth {args:?} wrote to stderr");
    o.stdout
}

/// xorshift64*: deterministic test data.
struct Rng(u64);

impl Rng {
    fn uniform(&mut self) -> f64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        (x.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// One series: its id as written in the CSV (quoted where needed), its id as a value, and
/// its rows.
struct Series {
    cell: String,
    rows: Vec<(f64, f64)>,
}

/// `id` as a CSV cell.
fn csv_cell(id: &str) -> String {
    if id.contains([',', '"', '\n']) {
        format!("\"{}\"", id.replace('"', "\"\""))
    } else {
        id.to_string()
    }
}

/// The test series: regular and irregular grids, a grid that turns irregular (the fixed
/// filter's engine switch), a series that pauses for a long stretch, one that starts late,
/// and one too short for the degree. Ids with a comma, a quote and a space.
fn series() -> Vec<Series> {
    let mut rng = Rng(0x1234_5678_9ABC_DEF1);
    let mut make = |id: &str, n: usize, step: &mut dyn FnMut(usize, &mut Rng) -> f64| {
        let mut t = 0.0;
        let mut rows = Vec::with_capacity(n);
        for k in 0..n {
            t += step(k, &mut rng);
            let noise = rng.uniform() - 0.5;
            // An outlier now and then, for the automatic filter's gate.
            let jump = if k % 97 == 60 { 25.0 } else { 0.0 };
            let y = 3.0 + 0.5 * t - 0.01 * t * t + (0.3 * t).sin() + 0.2 * noise + jump;
            rows.push((t, y));
        }
        Series {
            cell: csv_cell(id),
            rows,
        }
    };
    vec![
        make("a", 400, &mut |_, _| 0.5),
        make("b", 260, &mut |_, r| 0.3 + 0.4 * r.uniform()),
        make("s,1", 300, &mut |k, r| {
            if k < 120 {
                1.0
            } else {
                0.8 + 0.4 * r.uniform()
            }
        }),
        // A long pause: no row between t = 20 and t = 150.
        make("q\"x y", 90, &mut |k, _| if k == 40 { 130.0 } else { 0.5 }),
        // Starts late: its first row is at t = 120.
        make("late", 150, &mut |k, _| if k == 0 { 120.0 } else { 0.25 }),
        make("short", 2, &mut |_, _| 7.0),
    ]
}

/// The rows of all series interleaved by time plus a random delay (so neither the times nor
/// the series alternate regularly), as `(series index, row index)`.
fn interleave(all: &[Series]) -> Vec<(usize, usize)> {
    let mut rng = Rng(0xDEAD_BEEF_CAFE_F00D);
    let mut keyed: Vec<(f64, usize, usize)> = Vec::new();
    for (s, series) in all.iter().enumerate() {
        for (k, &(t, _)) in series.rows.iter().enumerate() {
            // Delays grow within a series only as much as its times do, so its rows stay in
            // order: key = t + delay with a small delay.
            keyed.push((t + 0.2 * rng.uniform(), s, k));
        }
    }
    keyed.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
    // A stable order within each series: re-number its rows in order of appearance.
    let mut next = vec![0; all.len()];
    keyed
        .into_iter()
        .map(|(_, s, _)| {
            let k = next[s];
            next[s] += 1;
            (s, k)
        })
        .collect()
}

/// The multi-series input: columns `t,id,y,note` (the id column in the middle and an ignored
/// column after), rows in `order`.
fn multi_input(all: &[Series], order: &[(usize, usize)]) -> String {
    let mut text = String::from("t,id,y,note\n");
    for &(s, k) in order {
        let (t, y) = all[s].rows[k];
        text += &format!("{t},{},{y},n{k}\n", all[s].cell);
    }
    text
}

/// One series alone (`t,y`), padded with `pad` more rows after its last.
fn single_input(series: &Series, pad: usize) -> String {
    let mut text = String::from("t,y\n");
    for &(t, y) in &series.rows {
        text += &format!("{t},{y}\n");
    }
    let (mut t, y) = *series.rows.last().unwrap();
    for _ in 0..pad {
        t += 1.0;
        text += &format!("{t},{y}\n");
    }
    text
}

/// The expected multi-series output: each series alone, its first rows (those of the
/// series itself) with the id cell in front, re-interleaved in `order`.
fn expected(all: &[Series], order: &[(usize, usize)], args: &[&str]) -> String {
    // The automatic filter's outlier column is decided by the samples after (its review), so
    // its series run alone padded only to the degree's m + 1 rows the command asks for (too
    // few for a noise estimate, whose decisions are the gate's).
    let auto = args.contains(&"auto");
    let degree: usize = args[args.iter().position(|&a| a == "--degree").unwrap() + 1]
        .parse()
        .unwrap();
    let alone: Vec<Vec<String>> = all
        .iter()
        .map(|s| {
            let pad = if auto {
                (degree + 1).saturating_sub(s.rows.len())
            } else {
                30
            };
            let out = ok(args, &single_input(s, pad));
            out.lines().map(str::to_string).collect()
        })
        .collect();
    let mut text = format!("id,{}\n", alone[0][0]);
    for &(s, k) in order {
        text += &format!("{},{}\n", all[s].cell, alone[s][k + 1]);
    }
    text
}

/// The filter settings under test: every kind, both engines, with and without σ and a lead.
/// τ is given: the default τ comes from the first rows of the whole input (tested apart).
const CONFIGS: &[&[&str]] = &[
    &["--kind", "expanding", "--degree", "2", "--engine", "gain"],
    &["--kind", "expanding", "--degree", "1", "--sigma", "0.2"],
    &[
        "--kind", "fading", "--degree", "2", "--theta", "0.9", "--tau", "0.5", "--engine", "gain",
        "--sigma", "0.1",
    ],
    &[
        "--kind", "fading", "--degree", "1", "--theta", "0.8", "--tau", "0.7", "--lead", "0.5",
    ],
    &["--kind", "fixed", "--degree", "2", "--window", "7"],
    &[
        "--kind", "fixed", "--degree", "1", "--window", "5", "--sigma", "0.3", "--lead", "-1",
    ],
    &[
        "--kind", "auto", "--degree", "2", "--theta", "0.9", "--tau", "0.5",
    ],
    &[
        "--kind", "auto", "--degree", "1", "--theta", "0.85", "--tau", "0.5", "--sigma", "0.1",
        "--engine", "gain",
    ],
];

fn filter_args<'a>(config: &[&'a str], extra: &[&'a str]) -> Vec<&'a str> {
    let mut v = vec!["filter"];
    v.extend_from_slice(config);
    v.extend_from_slice(extra);
    v
}

/// Every kind: the multi-series output is each series alone, re-interleaved, whatever the
/// chunk size.
#[test]
fn multi_series_equals_each_series_alone() {
    let all = series();
    let order = interleave(&all);
    // The interleaving really is irregular: some series follow themselves, ids come back
    // after long gaps.
    let longest_gap = {
        let mut last = HashMap::new();
        let mut gap = 0;
        for (i, &(s, _)) in order.iter().enumerate() {
            if let Some(j) = last.insert(s, i) {
                gap = gap.max(i - j);
            }
        }
        gap
    };
    assert!(longest_gap > 300, "{longest_gap}");
    assert!(order.windows(2).any(|w| w[0].0 == w[1].0));
    let input = multi_input(&all, &order);
    for config in CONFIGS {
        let want = expected(&all, &order, &filter_args(config, &[]));
        for chunk in ["1", "3", "64", "65536"] {
            let args = filter_args(config, &["--id-col", "id", "--chunk-rows", chunk]);
            let got = ok(&args, &input);
            if got != want {
                let (g, w): (Vec<_>, Vec<_>) = (got.lines().collect(), want.lines().collect());
                let first = g.iter().zip(&w).position(|(a, b)| a != b);
                panic!(
                    "{args:?}: {} rows vs {} expected; first difference at line {:?}: {:?} vs \
                     {:?}",
                    g.len(),
                    w.len(),
                    first.map(|i| i + 1),
                    first.map(|i| g[i]),
                    first.map(|i| w[i])
                );
            }
        }
    }
}

/// A single series comes out the same whatever the chunk size, and with `--id-col` naming a
/// column with one id the output is the same with the id column in front.
#[test]
fn chunk_size_does_not_change_single_series() {
    let all = series();
    let input = single_input(&all[2], 0);
    let with_id: String = input
        .lines()
        .enumerate()
        .map(|(i, l)| format!("{l},{}\n", if i == 0 { "id" } else { "only" }))
        .collect();
    for config in CONFIGS {
        let want = ok(&filter_args(config, &[]), &input);
        for chunk in ["1", "2", "101", "102", "1000"] {
            let got = ok(&filter_args(config, &["--chunk-rows", chunk]), &input);
            assert_eq!(got, want, "{config:?} --chunk-rows {chunk}");
        }
        let got = ok(
            &filter_args(config, &["--id-col", "id", "--chunk-rows", "5"]),
            &with_id,
        );
        let want_id: String = want
            .lines()
            .enumerate()
            .map(|(i, l)| format!("{},{l}\n", if i == 0 { "id" } else { "only" }))
            .collect();
        assert_eq!(got, want_id, "{config:?}");
    }
}

/// The default τ with `--id-col` is the median of the first 100 time steps within the series:
/// with every series on the same step, it is that step, whatever the chunk size; many series
/// in turn need more than 101 rows for those steps.
#[test]
fn default_tau_is_median_step_within_series() {
    let mut text = String::from("id,t,y\n");
    let mut alone: HashMap<&str, String> = HashMap::new();
    for k in 0..200 {
        for (id, offset) in [("u", 0.0), ("v", 0.1), ("w", 0.35)] {
            let t = offset + 0.25 * k as f64;
            let y = (t * 0.7).cos() + 0.01 * ((k * 13 % 7) as f64);
            text += &format!("{id},{t},{y}\n");
            alone
                .entry(id)
                .or_insert_with(|| "t,y\n".to_string())
                .push_str(&format!("{t},{y}\n"));
        }
    }
    for (kind, chunk) in [("fading", "7"), ("auto", "65536")] {
        let base = ["filter", "--kind", kind, "--degree", "2", "--theta", "0.9"];
        let got = ok(
            &[&base[..], &["--id-col", "id", "--chunk-rows", chunk]].concat(),
            &text,
        );
        let mut rows: HashMap<&str, std::vec::IntoIter<String>> = HashMap::new();
        for id in ["u", "v", "w"] {
            let out = ok(&[&base[..], &["--tau", "0.25"]].concat(), &alone[id]);
            let lines: Vec<String> = out.lines().skip(1).map(str::to_string).collect();
            rows.insert(id, lines.into_iter());
        }
        for line in got.lines().skip(1) {
            let (id, rest) = line.split_once(',').unwrap();
            assert_eq!(rest, rows.get_mut(id).unwrap().next().unwrap(), "{kind}");
        }
    }
    // 500 series in turn: the first 100 steps are all 2 (rows 501 to 600), so τ = 2; the
    // steps of the rows after (0.5) do not count. Degree 0: each estimate is the mean of the
    // series' values so far weighted by θ^(age/τ), θ = 0.5.
    let series = 500;
    let mut text = String::from("id,t,y\n");
    let mut history: Vec<Vec<(f64, f64)>> = vec![Vec::new(); series];
    let mut t = vec![0.0; series];
    for k in 0..3 * series {
        let s = k % series;
        let y = ((k * 7919) % 101) as f64;
        if k >= series {
            t[s] += if k < 2 * series { 2.0 } else { 0.5 };
        }
        text += &format!("s{s},{},{y}\n", t[s]);
        history[s].push((t[s], y));
    }
    let want: Vec<f64> = history
        .iter()
        .map(|h| {
            let now = h.last().unwrap().0;
            let w: Vec<f64> = h
                .iter()
                .map(|&(t, _)| 0.5f64.powf((now - t) / 2.0))
                .collect();
            h.iter().zip(&w).map(|(&(_, y), w)| w * y).sum::<f64>() / w.iter().sum::<f64>()
        })
        .collect();
    let args = [
        "filter", "--kind", "fading", "--degree", "0", "--theta", "0.5", "--id-col", "id",
    ];
    let got = ok(&[&args[..], &["--chunk-rows", "1"]].concat(), &text);
    assert_eq!(got, ok(&args, &text));
    let mut last = HashMap::new();
    for line in got.lines().skip(1) {
        let cells: Vec<&str> = line.split(',').collect();
        last.insert(cells[0].to_string(), cells[3].parse::<f64>().unwrap());
    }
    for (s, w) in want.iter().enumerate() {
        let g = last[&format!("s{s}")];
        assert!((g - w).abs() <= 1e-9 * (1.0 + w.abs()), "s{s}: {g} vs {w}");
    }
    // No series with two rows among the first 65536: no median step; τ must be given.
    let mut text = String::from("id,t,y\n");
    for k in 0..70_000 {
        text += &format!("s{k},0,1\n");
    }
    let o = run(
        &[
            "filter", "--kind", "fading", "--degree", "0", "--theta", "0.9", "--id-col", "id",
        ],
        &text,
    );
    assert_eq!(o.code, 1, "{}", o.stderr);
    assert!(
        o.stderr
            .contains("no series has two rows among the first 65536 rows")
            && o.stderr.contains("give --tau"),
        "{}",
        o.stderr
    );
    assert_eq!(o.stdout, "");
}

/// Replaces data row `k` (0-based) of `input` with `line`.
fn replace_row(input: &str, k: usize, line: &str) -> String {
    let mut lines: Vec<&str> = input.lines().collect();
    lines[k + 1] = line;
    lines.join("\n") + "\n"
}

/// Errors name the file line and column (and the series for a time that goes backwards).
/// An error after the first 101 rows stops the command after every row before it, of all
/// series, has been written (the good output's first rows); one among the first 101 rows
/// before any output.
#[test]
fn errors_name_line_and_column_and_keep_rows_before() {
    let all = series();
    let order = interleave(&all);
    let input = multi_input(&all, &order);
    let args = [
        "filter",
        "--kind",
        "fading",
        "--degree",
        "2",
        "--theta",
        "0.9",
        "--tau",
        "0.5",
        "--id-col",
        "id",
        "--chunk-rows",
        "16",
    ];
    let good = ok(&args, &input);
    let good_lines: Vec<&str> = good.lines().collect();
    // Data row k is on file line k + 2.
    let prefix = |k: usize| -> String {
        good_lines[..k + 1]
            .iter()
            .map(|l| format!("{l}\n"))
            .collect()
    };

    // A time going backwards within series "b" (others' times may go back freely).
    let k = order
        .iter()
        .enumerate()
        .filter(|(_, &(s, j))| s == 1 && j > 0)
        .map(|(i, _)| i)
        .find(|&i| i > 500)
        .unwrap();
    let (s, j) = order[k];
    let prev_row = order.iter().position(|&x| x == (s, j - 1)).unwrap();
    let (t_prev, _) = all[s].rows[j - 1];
    let bad_t = t_prev - 0.01;
    let bad = replace_row(&input, k, &format!("{bad_t},b,1,x"));
    let o = run(&args, &bad);
    assert_eq!(o.code, 1, "{}", o.stderr);
    let want = format!(
        "line {}: time {bad_t} is not after the previous time {t_prev} (line {}) of series 'b'",
        k + 2,
        prev_row + 2
    );
    assert!(o.stderr.contains(&want), "{} lacks {want}", o.stderr);
    assert_eq!(o.stdout, prefix(k));

    // A NaN value, a bad number and a ragged row late in the stream.
    for (cell, message) in [
        (
            "NaN",
            format!("line {}, column 'y': value NaN is not finite", k + 2),
        ),
        (
            "1.2.3",
            format!("line {}, column 'y': '1.2.3' is not a number", k + 2),
        ),
    ] {
        let (t, _) = all[s].rows[j];
        let bad = replace_row(&input, k, &format!("{t},b,{cell},x"));
        let o = run(&args, &bad);
        assert_eq!(o.code, 1, "{}", o.stderr);
        assert!(o.stderr.contains(&message), "{} lacks {message}", o.stderr);
        assert_eq!(o.stdout, prefix(k));
    }
    let bad = replace_row(&input, k, "1,b,2");
    let o = run(&args, &bad);
    assert_eq!(o.code, 1, "{}", o.stderr);
    assert!(
        o.stderr.contains(&format!("line {}: malformed CSV", k + 2)),
        "{}",
        o.stderr
    );
    assert_eq!(o.stdout, prefix(k));

    // Among the first 101 rows: no output at all.
    let bad = replace_row(&input, 50, "x,a,1,x");
    let o = run(&args, &bad);
    assert_eq!(o.code, 1, "{}", o.stderr);
    assert!(
        o.stderr
            .contains("line 52, column 't': 'x' is not a number"),
        "{}",
        o.stderr
    );
    assert_eq!(o.stdout, "");
}

/// The id column is checked like the others.
#[test]
fn id_column_errors() {
    let o = run(
        &[
            "filter",
            "--kind",
            "expanding",
            "--degree",
            "0",
            "--id-col",
            "series",
        ],
        "t,y\n0,1\n",
    );
    assert_eq!(o.code, 1, "{}", o.stderr);
    assert!(o
        .stderr
        .contains("column 'series' not found in the header; columns are: t, y"));
    let o = run(
        &[
            "filter",
            "--kind",
            "expanding",
            "--degree",
            "0",
            "--id-col",
            "y",
        ],
        "t,y\n0,1\n",
    );
    assert_eq!(o.code, 2, "{}", o.stderr);
    assert!(o
        .stderr
        .contains("--id-col y is the time or the value column"));
}

/// When standard error is not a terminal the progress display stays silent: nothing is
/// written to it on an input of many chunks, with or without `--no-progress`.
#[test]
fn progress_is_silent_when_stderr_is_not_a_terminal() {
    let mut text = String::from("t,y\n");
    for k in 0..5000 {
        text += &format!("{k},{}\n", (k as f64 * 0.01).sin());
    }
    let args = [
        "filter",
        "--kind",
        "fading",
        "--degree",
        "2",
        "--theta",
        "0.9",
        "--chunk-rows",
        "100",
    ];
    for extra in [&[][..], &["--no-progress"][..]] {
        let o = run(&[&args[..], extra].concat(), &text);
        assert_eq!(o.code, 0);
        assert_eq!(o.stderr, "", "{extra:?}");
        assert_eq!(o.stdout.lines().count(), 5001);
    }
    // The same from a file (the bar would show bytes of the file's size).
    let path = std::env::temp_dir().join(format!("seqsmooth-progress-{}.csv", std::process::id()));
    std::fs::write(&path, &text).unwrap();
    let o = run(&[&args[..], &[path.to_str().unwrap()]].concat(), "");
    std::fs::remove_file(&path).unwrap();
    assert_eq!(o.code, 0);
    assert_eq!(o.stderr, "");
    assert_eq!(o.stdout.lines().count(), 5001);
}

/// The automatic filter's `outlier` column holds the final decision of each sample (a run of
/// rejections the filter applies after all, a step, decided by the review), however the
/// series are interleaved and the input cut into chunks. The oracle is the library's
/// `final_outliers` over each series alone.
#[test]
fn auto_outlier_column_is_the_final_decision() {
    use seqsmooth::polynomial::automatic::{final_outliers, AutomaticFilter};
    // Two series on the same grid: an outlier, then a step (three rejections, the first two
    // reinstated), at different rows.
    let value = |s: usize, n: usize| match (s, n) {
        (0, 20) | (1, 33) => 5.0,
        (0, 40..) | (1, 57..) => 9.0,
        _ => 0.0,
    };
    let rows = 80;
    let mut want_flags = Vec::new();
    for s in 0..2 {
        let mut f = AutomaticFilter::new(0, 0.9, 1.0)
            .unwrap()
            .with_noise_sigma(0.1)
            .unwrap();
        let outs: Vec<_> = (0..rows)
            .map(|n| f.update(n as f64, value(s, n)).unwrap())
            .collect();
        let tail = f.finish();
        let flags = final_outliers(&outs, &tail);
        // The step's first two rejections are reinstated when the third comes (a run), and
        // their final decision is the review's by interpolation (not the gate's, which
        // rejected them).
        assert!(
            outs.iter().any(|o| o.reinstated == 2),
            "series {s}: the step's first two rejections are reinstated"
        );
        assert!(
            flags.iter().any(|&r| r),
            "series {s}: the outlier is rejected"
        );
        want_flags.push(flags);
    }
    let mut input = String::from("id,t,y\n");
    for n in 0..rows {
        for s in 0..2 {
            input += &format!("s{s},{n},{}\n", value(s, n));
        }
    }
    let args = |chunk: &'static str| {
        [
            "filter",
            "-",
            "--kind",
            "auto",
            "--degree",
            "0",
            "--theta",
            "0.9",
            "--tau",
            "1",
            "--sigma",
            "0.1",
            "--id-col",
            "id",
            "--no-progress",
            "--chunk-rows",
            chunk,
        ]
    };
    for chunk in ["1", "2", "3", "64"] {
        let out = ok(&args(chunk), &input);
        let mut lines = out.lines();
        let header: Vec<&str> = lines.next().unwrap().split(',').collect();
        let col = header.iter().position(|&c| c == "outlier").unwrap();
        let mut got = vec![Vec::new(), Vec::new()];
        for line in lines {
            let cells: Vec<&str> = line.split(',').collect();
            let s = (cells[0] == "s1") as usize;
            got[s].push(cells[col] == "1");
        }
        assert_eq!(got, want_flags, "--chunk-rows {chunk}");
    }
}

/// An id that is not UTF-8 text is refused with its line and column (it would be written back
/// in every row of its series); the rows before it are kept on standard output.
#[test]
fn id_that_is_not_utf8_is_refused() {
    let path = common::tmp("not-utf8-id.csv");
    let mut input = b"id,t,y\n".to_vec();
    for n in 0..150 {
        input.extend_from_slice(format!("a,{n},1\n").as_bytes());
    }
    input.extend_from_slice(b"\xff\xfe,150,2\n");
    std::fs::write(&path, &input).unwrap();
    let file = path.to_str().unwrap();
    let o = run(
        &[
            "filter",
            file,
            "--kind",
            "expanding",
            "--degree",
            "0",
            "--id-col",
            "id",
        ],
        "",
    );
    assert_eq!(o.code, 1, "{}", o.stderr);
    assert!(
        o.stderr.contains("line 152, column 1: the id") && o.stderr.contains("not valid UTF-8"),
        "{}",
        o.stderr
    );
    assert_eq!(
        o.stdout.lines().count(),
        151,
        "the header and the 150 rows before"
    );
    std::fs::remove_file(&path).unwrap();
}
