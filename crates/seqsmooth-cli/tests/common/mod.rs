//! Running the `seqsmooth` binary from the integration tests.
#![allow(dead_code)]

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// The outcome of one run of the binary.
pub struct Out {
    pub code: i32,
    pub stdout: String,
    pub stderr: String,
}

/// Runs `seqsmooth args…` in `dir` (or the current directory) with `stdin` as standard input.
pub fn run_at(dir: Option<&Path>, args: &[&str], stdin: &str) -> Out {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_seqsmooth"));
    cmd.args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    if let Some(d) = dir {
        cmd.current_dir(d);
    }
    let mut child = cmd.spawn().expect("spawn seqsmooth");
    let mut input = child.stdin.take().unwrap();
    let data = stdin.as_bytes().to_vec();
    // Write from a thread: the child may exit (on an error) before reading everything.
    let writer = std::thread::spawn(move || {
        let _ = input.write_all(&data);
    });
    let out = child.wait_with_output().expect("wait for seqsmooth");
    writer.join().unwrap();
    Out {
        code: out.status.code().expect("exit code"),
        stdout: String::from_utf8(out.stdout).unwrap(),
        stderr: String::from_utf8(out.stderr).unwrap(),
    }
}

/// Runs `seqsmooth args…` with `stdin` as standard input.
pub fn run(args: &[&str], stdin: &str) -> Out {
    run_at(None, args, stdin)
}

/// Runs and asserts success.
pub fn ok(args: &[&str], stdin: &str) -> String {
    let o = run(args, stdin);
    assert_eq!(o.code, 0, "seqsmooth {args:?} failed: {}", o.stderr);
    o.stdout
}

/// Runs and asserts failure with `code` and every `parts` in stderr.
pub fn fails(args: &[&str], stdin: &str, code: i32, parts: &[&str]) {
    let o = run(args, stdin);
    assert_eq!(o.code, code, "seqsmooth {args:?}: stderr {}", o.stderr);
    assert!(
        o.stderr.starts_with("error: "),
        "message must start with 'error: ': {}",
        o.stderr
    );
    for p in parts {
        assert!(o.stderr.contains(p), "stderr lacks {p:?}: {}", o.stderr);
    }
    assert!(!o.stderr.contains("panicked"), "{}", o.stderr);
}

/// Splits CSV output (no quoting occurs in it) into the header and rows of cells.
pub fn table(text: &str) -> (Vec<String>, Vec<Vec<String>>) {
    let mut lines = text.lines();
    let header = lines
        .next()
        .expect("header")
        .split(',')
        .map(String::from)
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    (header, rows)
}

pub fn num(cell: &str) -> f64 {
    cell.parse()
        .unwrap_or_else(|_| panic!("{cell:?} is not a number"))
}

pub fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + b.abs())
}

pub fn tmp(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name)
}

/// The double nearest to the exact number `text` (e.g. `0.9` or `9/10`).
pub fn exact_f64(text: &str) -> f64 {
    seqsmooth::scalar::ratio_to_f64(&seqsmooth::scalar::parse_rational(text).unwrap())
}

/// Morrison's running example (test vector T9-02): samples 1, 3, 2, 5, 4 at n = 0..4.
pub const T9_02: &str = "t,y\n0,1\n1,3\n2,2\n3,5\n4,4\n";

/// Morrison test vector T7-08: Y = (y_n, …, y_{n-4}) = (5, 3, 4, 2, 1), newest first, so
/// the CSV (oldest first) is y = 1, 2, 4, 3, 5 at t = 0..4.
pub const T7_08: &str = "t,y\n0,1\n1,2\n2,4\n3,3\n4,5\n";

/// xorshift64*: deterministic test data.
pub struct Rng(pub u64);

impl Rng {
    /// Uniform on `[0, 1)`.
    pub fn uniform(&mut self) -> f64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        (x.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform on `0..n`.
    pub fn below(&mut self, n: usize) -> usize {
        (self.uniform() * n as f64) as usize % n
    }
}
