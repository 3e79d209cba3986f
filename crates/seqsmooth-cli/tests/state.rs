//! End-to-end tests of `seqsmooth filter --state FILE`: a stream cut into pieces, each run from
//! the state the previous run saved, gives the unbroken run's rows byte for byte.
//!
//! The oracle is the command's own unbroken run over the whole input: the concatenated data
//! rows of the pieces (each piece's header dropped) must be the same bytes, for every filter
//! kind (with and without `--sigma`, a lead, one series or many interleaved series with ids,
//! the automatic filter with outliers whose decisions cross the cuts). The cuts are at random
//! rows, ten pieces, a piece possibly empty or a single row; where the run decides the default
//! τ (fading memory and the automatic filter without `--tau`) the first piece holds the 101
//! rows that decide it, elsewhere one cut falls within them (the first piece holding the rows
//! the command needs to start without a state: the window, or degree + 1).

mod common;
use common::{fails, run, tmp, Rng};
use std::path::Path;

/// `n` rows of `series` interleaved series (ids `s0`, `s1`, … when more than one): a cubic with
/// noise, steps of 1 mostly (so that the default τ of any first piece is 1), some of 0.5 and
/// 2, and an outlier in about one row in 40.
fn data(n: usize, series: usize, seed: u64) -> (String, Vec<String>) {
    let mut rng = Rng(seed);
    let mut t = vec![0.0f64; series];
    let mut rows = Vec::with_capacity(n);
    for _ in 0..n {
        let s = rng.below(series);
        let u = rng.uniform();
        t[s] += if u < 0.8 {
            1.0
        } else if u < 0.9 {
            0.5
        } else {
            2.0
        };
        let x = t[s] * 0.01;
        let mut y = 3.0 + s as f64 + 2.0 * x - x * x + 0.5 * x * x * x + (rng.uniform() - 0.5);
        if rng.uniform() < 0.025 {
            y += 40.0;
        }
        rows.push(if series > 1 {
            format!("s{s},{},{y}", t[s])
        } else {
            format!("{},{y}", t[s])
        });
    }
    let header = if series > 1 { "id,t,y" } else { "t,y" };
    (header.to_string(), rows)
}

/// The rows of the first piece: the default τ's.
const FIRST: usize = 101;

/// The data rows of a run's CSV output (its header dropped).
fn body(out: &str) -> &str {
    &out[out.find('\n').map_or(out.len(), |i| i + 1)..]
}

/// Runs `filter args` on `input` and returns its standard output.
fn filter(args: &[&str], input: &str) -> String {
    let o = run(args, input);
    assert_eq!(o.code, 0, "seqsmooth {args:?}: {}", o.stderr);
    o.stdout
}

/// The unbroken run and the run cut into 10 pieces at random rows, each with `--state`
/// (the last with `--final`), give the same rows.
fn pieces_match(args: &[&str], series: usize, n: usize, seed: u64) {
    let (header, rows) = data(n, series, seed);
    let mut rng = Rng(seed ^ 0x9e37_79b9);
    let id = ["--id-col", "id"];
    let mut base: Vec<&str> = vec!["filter"];
    base.extend_from_slice(args);
    if series > 1 {
        base.extend_from_slice(&id);
    }
    let whole = format!("{header}\n{}\n", rows.join("\n"));
    let unbroken = filter(&base, &whole);
    // Where the run decides the default τ, the first piece decides it from its first rows
    // (101, as the unbroken run): it holds them. Otherwise (`--tau`, or a kind without τ) a cut
    // falls within them, after the rows the command needs to start without a state (the
    // window, or degree + 1: it refuses fewer). The other cuts fall anywhere, an empty piece
    // included.
    let decides_tau =
        ["fading", "auto"].iter().any(|k| args.contains(k)) && !args.contains(&"--tau");
    let value = |flag: &str| {
        let i = args.iter().position(|a| *a == flag)?;
        args[i + 1].parse::<usize>().ok()
    };
    let start = value("--window").unwrap_or_else(|| value("--degree").unwrap_or(1) + 1);
    let first = if decides_tau { FIRST } else { start };
    let mut cuts: Vec<usize> = (0..8).map(|_| rng.below(n)).collect();
    cuts.push(if decides_tau {
        FIRST + rng.below(n - FIRST)
    } else {
        start + rng.below(FIRST - start)
    });
    cuts.extend([0, n]);
    cuts.sort_unstable();
    cuts.iter_mut().skip(1).for_each(|c| *c = (*c).max(first));
    let name = format!("state-{seed}-{}.bin", args.join("_").replace('/', ""));
    let state = tmp(&name);
    let _ = std::fs::remove_file(&state);
    let path = state.to_str().unwrap();
    let mut joined = String::new();
    for (k, w) in cuts.windows(2).enumerate() {
        let piece = format!("{header}\n{}", rows[w[0]..w[1]].join("\n"));
        let piece = if w[1] > w[0] { piece + "\n" } else { piece };
        let mut a = base.clone();
        a.extend_from_slice(&["--state", path]);
        if k == cuts.len() - 2 {
            a.push("--final");
        }
        let out = filter(&a, &piece);
        assert_eq!(out.lines().next(), unbroken.lines().next(), "{a:?}: header");
        joined.push_str(body(&out));
    }
    let (want, got) = (body(&unbroken), joined.as_str());
    if want != got {
        let bad = want.lines().zip(got.lines()).position(|(a, b)| a != b);
        panic!(
            "{args:?}, {series} series, cuts {cuts:?}: row {bad:?} differs ({} vs {} rows)",
            want.lines().count(),
            got.lines().count()
        );
    }
    std::fs::remove_file(&state).unwrap();
}

/// Every kind, one series and many, with and without σ, a lead and `--tau`.
#[test]
fn ten_pieces_give_the_unbroken_rows_for_every_kind() {
    let kinds: &[&[&str]] = &[
        &["--kind", "expanding", "--degree", "2"],
        &[
            "--kind",
            "expanding",
            "--degree",
            "1",
            "--sigma",
            "0.3",
            "--engine",
            "gain",
        ],
        &["--kind", "fading", "--degree", "2", "--theta", "0.9"],
        &[
            "--kind", "fading", "--degree", "1", "--theta", "0.8", "--sigma", "0.5", "--lead", "2",
        ],
        &["--kind", "fixed", "--degree", "2", "--window", "15"],
        &[
            "--kind", "fixed", "--degree", "1", "--window", "6", "--sigma", "0.5",
        ],
        &[
            "--kind", "fading", "--degree", "2", "--theta", "0.9", "--tau", "1.5",
        ],
        &["--kind", "auto", "--degree", "2", "--theta", "0.9"],
        &[
            "--kind", "auto", "--degree", "2", "--theta", "0.9", "--tau", "1",
        ],
        &[
            "--kind", "auto", "--degree", "1", "--theta", "0.95", "--sigma", "0.3",
        ],
    ];
    for (k, args) in kinds.iter().enumerate() {
        for (series, n) in [(1, 600), (7, 3000)] {
            for seed in 1..=3 {
                pieces_match(args, series, n, 100 * k as u64 + 10 * series as u64 + seed);
            }
        }
    }
}

/// Writes the state of a run of `args` on `input` at `path`.
fn saved(path: &Path, args: &[&str], input: &str) {
    let _ = std::fs::remove_file(path);
    let mut a = vec!["filter", "--state", path.to_str().unwrap()];
    a.extend_from_slice(args);
    filter(&a, input);
}

/// A state made with other options is refused naming the option; a damaged or foreign file is
/// refused naming the file; a failed run leaves the state as it was.
#[test]
fn other_options_and_damaged_states_are_refused() {
    let (header, rows) = data(300, 1, 7);
    let input = format!("{header}\n{}\n", rows[..200].join("\n"));
    let rest = format!("{header}\n{}\n", rows[200..].join("\n"));
    let path = tmp("state-refused.bin");
    let p = path.to_str().unwrap();
    let args = ["--kind", "fading", "--degree", "2", "--theta", "0.9"];
    saved(&path, &args, &input);
    let before = std::fs::read(&path).unwrap();
    let f = "filter";
    let other = [
        (
            vec![f, "--kind", "fading", "--degree", "2", "--theta", "0.8"],
            "--theta",
        ),
        (
            vec![f, "--kind", "fading", "--degree", "1", "--theta", "0.9"],
            "--degree",
        ),
        (
            vec![
                f, "--kind", "fading", "--degree", "2", "--theta", "0.9", "--tau", "2",
            ],
            "--tau",
        ),
        (vec![f, "--kind", "expanding", "--degree", "2"], "kind"),
        (
            vec![
                f, "--kind", "fading", "--degree", "2", "--theta", "0.9", "--lead", "1",
            ],
            "--lead",
        ),
        (
            vec![
                f, "--kind", "fading", "--degree", "2", "--theta", "0.9", "--sigma", "1",
            ],
            "--sigma",
        ),
    ];
    for (mut a, word) in other {
        a.extend_from_slice(&["--state", p]);
        fails(&a, &rest, 2, &[word, p, "saved state was made with"]);
    }
    // A row the filter refuses (time going back): the state is not written.
    let back = format!("{header}\n{}\n1.5,2\n", rows[200..210].join("\n"));
    let mut a = vec![f, "--state", p];
    a.extend_from_slice(&args);
    let o = run(&a, &back);
    assert_eq!(o.code, 1, "{}", o.stderr);
    assert_eq!(
        std::fs::read(&path).unwrap(),
        before,
        "a failed run changed the state"
    );
    // One byte changed, the file cut short, another file: refused naming the file.
    for damage in [0usize, 1, 2] {
        let mut bytes = before.clone();
        match damage {
            0 => *bytes.last_mut().unwrap() ^= 1,
            1 => bytes.truncate(bytes.len() / 2),
            _ => bytes = b"t,y\n1,2\n".to_vec(),
        }
        std::fs::write(&path, &bytes).unwrap();
        fails(&a, &rest, 1, &["state file", p]);
        assert_eq!(
            std::fs::read(&path).unwrap(),
            bytes,
            "a refused state was overwritten"
        );
    }
    std::fs::remove_file(&path).unwrap();
}
