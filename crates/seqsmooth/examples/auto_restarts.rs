//! The automatic filter's restarts on a CSV file of `t,y` rows (one header line), by cause: a
//! run of rejections taken for a manoeuvre (`AutoOutput::manoeuvre` with `restart`) or the
//! restart's chi-squared test (Morrison §14.8, `MisfitResponse::Restart`), counted on the
//! outputs as they come (a restart the review later takes back is counted there, not in
//! `restarts()`), with the noise σ in use every 2,000 rows. Degree 2, θ = 0.95 per τ = 1, the
//! defaults otherwise (σ estimated unless a third argument gives it): `scripts/auto_speed.sh`'s
//! filter. With `PRINT_RESTARTS` set, each restart's row on standard error (`R row manoeuvre`).
//!
//! Run: `cargo run --release -p seqsmooth --example auto_restarts -- FILE [ROWS] [SIGMA]`
//! (default 2·10⁴ rows; `AUTO_SPEED_INPUT=FILE scripts/auto_speed.sh` writes the speed input).

use seqsmooth::polynomial::automatic::AutomaticFilter;
use seqsmooth::PolynomialFilter;

fn main() {
    let path = std::env::args().nth(1).expect("FILE");
    let n: usize = std::env::args()
        .nth(2)
        .map_or(20_000, |s| s.parse().expect("ROWS"));
    let sigma: Option<f64> = std::env::args().nth(3).map(|s| s.parse().expect("SIGMA"));
    let text = std::fs::read_to_string(path).expect("readable");
    let mut f = AutomaticFilter::new(2, 0.95, 1.0).expect("valid");
    if let Some(s) = sigma {
        f = f.with_noise_sigma(s).expect("valid σ");
    }
    let print = std::env::var_os("PRINT_RESTARTS").is_some();
    let (mut by_run, mut by_test, mut outliers, mut manoeuvres) = (0u64, 0u64, 0u64, 0u64);
    let mut gaps = Vec::new();
    let mut last = 0usize;
    for (i, line) in text.lines().skip(1).take(n).enumerate() {
        let mut cells = line.split(',');
        let mut cell = || -> f64 { cells.next().expect("2 cells").parse().expect("number") };
        let (t, y) = (cell(), cell());
        PolynomialFilter::update(&mut f, t, y).expect("increasing times, finite values");
        let o = f.last_output().expect("an update was made");
        outliers += u64::from(o.outlier);
        manoeuvres += u64::from(o.manoeuvre);
        if o.restart {
            if o.manoeuvre {
                by_run += 1;
            } else {
                by_test += 1;
            }
            gaps.push(i - last);
            last = i;
            if print {
                eprintln!("R {i} {}", o.manoeuvre);
            }
        }
        if i % 2000 == 1999 {
            println!(
                "row {i}: σ {:?}, restarts {}, memory {}, phase {:?}",
                o.noise_sigma,
                f.restarts(),
                f.memory(),
                o.phase
            );
        }
    }
    println!(
        "restarts kept {}; as reported: by a run of rejections {by_run}, by the restart test \
         {by_test}; manoeuvres {manoeuvres}; outliers {outliers}",
        f.restarts()
    );
    gaps.sort_unstable();
    if let (Some(lo), Some(hi)) = (gaps.first(), gaps.last()) {
        println!(
            "rows between restarts: min {lo}, median {}, max {hi}",
            gaps[gaps.len() / 2]
        );
    }
}
