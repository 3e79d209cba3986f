//! The seqsmooth side of the peer comparison (`scripts/peers.sh`): runs the library's filters on
//! the data the script generated, times them, and writes their per-sample estimates for the
//! script's agreement check against filterpy and scipy.
//!
//! Run by the script; by hand: `cargo run --release -p seqsmooth --example peers -- DIR REPS`.
//!
//! `DIR/runs.txt` lists one run per line, whitespace-separated:
//! `name data filter degree [key=value ...]`, with
//!
//! - `data`: the data set, read from `DIR/<data>.t.f64` and `DIR/<data>.y.f64` (raw
//!   little-endian doubles, times and values);
//! - `filter`: `fading-gain` / `fading-exact` (keys `theta`, `tau`, optional `mode=update` for
//!   [`DiscountMode::PerUpdate`]), `expanding-gain` / `expanding-exact`, `fixed-sliding`
//!   (key `window`: the streaming [`FixedMemory`] evaluated at the centre of each window, i.e.
//!   at the time of the sample `(window-1)/2` before the newest), `smooth` (key `window`: the
//!   whole-series [`smooth_into`]).
//!
//! For each run it writes `DIR/<name>.est.f64`: `samples × (degree+1)` doubles, row-major, the
//! estimate `[x, x', …]` after each sample (NaN while undetermined; for `fixed-sliding` row
//! `n` holds the centred estimate for sample `n`, NaN where no window is centred on it),
//! `DIR/<name>.last.f64`: the estimate after the timed update-only call (`degree+1` doubles;
//! empty for the fixed-memory runs), and
//! prints one CSV line to stdout:
//! `name,samples,seconds_update,seconds_update_estimate,switched_at`: the best of `REPS` timed
//! repetitions of the update loop alone and of the loop that also reads each sample's estimate
//! (I/O and filter construction excluded), and the fading-memory gain engine's switch sample.
//!
//! A `gauss-newton` run writes instead `DIR/<name>.data.f64` (`windows × 60 × 4`: `t, ρ, ψ, θ`),
//! `DIR/<name>.nominal.f64` (`windows × 6`: the bootstrap nominal, where the peer starts too),
//! `DIR/<name>.est.f64` (`windows × 6`: the converged state) and `DIR/<name>.sigma.f64`
//! (`windows × 6`: the square roots of its covariance's diagonal), and prints
//! `name,windows,seconds_fit,seconds_bootstrap_and_fit,,seconds_bootstrap`: the best of `REPS`
//! runs over all the windows of the fit from the (precomputed) nominal, of the bootstrap and
//! the fit, and of the bootstrap alone (the measurements built outside the timing).
//!
//! A `kalman-q` run (`name data kalman-q degree q=Q r=R`) is the Kalman filter
//! ([`KalmanFilter`]) on the polynomial model of that degree on one axis with white-noise
//! driving noise of spectral density `Q` on the highest derivative
//! ([`WhiteNoiseDerivative`]), the first value observed with variance `R`, started at sample
//! `degree` from the prior in `DIR/<name>.prior.f64` (the state, then the covariance row by
//! row, as the script computed it for filterpy) and predicted and updated with every later
//! sample. It writes `.est.f64` and `.last.f64` as above and prints
//! `name,updates,seconds_update,seconds_update_estimate,,seconds_full_innovation`: the best of
//! `REPS` runs of the loop of [`KalmanFilter::update_stats`] (NIS and log-likelihood, no
//! allocation), of that loop also copying each state out, and of the loop of
//! [`KalmanFilter::update`] (each update's full [`seqsmooth::kalman::Innovation`]).
//!
//! An `ekf` run (`name radar ekf 1 tracks=W`) is the extended Kalman filter on the first `W`
//! radar tracks of `benches/common/kalman.rs` (the criterion bench's): it writes
//! `DIR/<name>.data.f64` (`W × 59 × 4`: `t, ρ, ψ, θ` of each update), `DIR/<name>.prior.f64`
//! (`W × 43`: the prior's time, state and covariance row by row), `DIR/<name>.est.f64` and
//! `DIR/<name>.sigma.f64` (`W × 59 × 6`: the state and the square roots of its covariance's
//! diagonal after each update), and prints the timings as a `kalman-q` run does, over all the
//! tracks (each track's filter copied before the timing).
//!
//! Each timed loop is one small function per filter family ([`feed`], [`feed_and_read`],
//! [`feed_fixed_and_read`]), so a batch update API can replace the per-sample loop in one place.

use nalgebra::{DMatrix, DVector};
use seqsmooth::kalman::noise::WhiteNoiseDerivative;
use seqsmooth::kalman::KalmanFilter;
use seqsmooth::model::dynamics::{Dynamics, PolynomialDynamics};
use seqsmooth::model::measurement::Measurement;
use seqsmooth::model::measurement::NoiseCovariance;
use seqsmooth::model::observation::{LinearObservation, Observation};
use seqsmooth::polynomial::fixed::smooth_into;
use seqsmooth::{
    DiscountMode, Engine, ExpandingMemory, FadingMemory, FixedEngine, FixedMemory, PolynomialFilter,
};
use std::collections::BTreeMap;
use std::error::Error;
use std::hint::black_box;
use std::path::Path;
use std::time::Instant;

type Res<T> = Result<T, Box<dyn Error>>;

#[path = "../benches/common/radar.rs"]
mod radar;

#[path = "../benches/common/kalman.rs"]
mod kalman_tracks;

/// One line of `runs.txt`.
struct Run {
    name: String,
    data: String,
    filter: String,
    degree: usize,
    keys: BTreeMap<String, String>,
}

impl Run {
    fn parse(line: &str, lineno: usize) -> Res<Self> {
        let f: Vec<&str> = line.split_whitespace().collect();
        if f.len() < 4 {
            return Err(format!("runs.txt line {lineno}: need name data filter degree").into());
        }
        let degree = f[3]
            .parse()
            .map_err(|e| format!("runs.txt line {lineno}: degree '{}': {e}", f[3]))?;
        let mut keys = BTreeMap::new();
        for kv in &f[4..] {
            let (k, v) = kv
                .split_once('=')
                .ok_or_else(|| format!("runs.txt line {lineno}: '{kv}' is not key=value"))?;
            keys.insert(k.to_string(), v.to_string());
        }
        Ok(Self {
            name: f[0].into(),
            data: f[1].into(),
            filter: f[2].into(),
            degree,
            keys,
        })
    }

    fn key<T: std::str::FromStr>(&self, k: &str) -> Res<T>
    where
        T::Err: std::fmt::Display,
    {
        let v = self
            .keys
            .get(k)
            .ok_or_else(|| format!("run {}: missing {k}=", self.name))?;
        v.parse()
            .map_err(|e| format!("run {}: {k}={v}: {e}", self.name).into())
    }

    fn fading(&self, engine: Engine) -> Res<FadingMemory> {
        let f = FadingMemory::new(self.degree, self.key("theta")?, self.key("tau")?, engine)?;
        Ok(match self.keys.get("mode").map(String::as_str) {
            None | Some("time") => f,
            Some("update") => f.with_discount_mode(DiscountMode::PerUpdate)?,
            Some(other) => return Err(format!("run {}: mode={other}", self.name).into()),
        })
    }
}

fn read_f64s(path: &Path) -> Res<Vec<f64>> {
    let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    if bytes.len() % 8 != 0 {
        return Err(format!(
            "{}: length {} is not a multiple of 8",
            path.display(),
            bytes.len()
        )
        .into());
    }
    Ok(bytes
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes")))
        .collect())
}

fn write_f64s(path: &Path, v: &[f64]) -> Res<()> {
    let bytes: Vec<u8> = v.iter().flat_map(|x| x.to_le_bytes()).collect();
    std::fs::write(path, bytes).map_err(|e| format!("{}: {e}", path.display()).into())
}

/// The timed loop without reading estimates: one batch call
/// ([`PolynomialFilter::update_many`]: the input checked in one pass, then the engine's tight
/// loop).
fn feed<F: PolynomialFilter>(f: &mut F, t: &[f64], y: &[f64]) -> Res<()> {
    f.update_many(t, y)?;
    Ok(())
}

/// The timed loop that also reads every sample's current estimate into `out`
/// (`samples × (m+1)`; NaN while undetermined): one
/// [`PolynomialFilter::update_many_into`] call.
fn feed_and_read<F: PolynomialFilter>(f: &mut F, t: &[f64], y: &[f64], out: &mut [f64]) -> Res<()> {
    f.update_many_into(t, y, out)?;
    Ok(())
}

/// The streaming fixed-memory loop reading the centred estimate: after sample `n` the window
/// holds samples `n-L..=n`; its fit evaluated at `t[n-L/2]` goes to row `n-L/2`.
fn feed_fixed_and_read(f: &mut FixedMemory, t: &[f64], y: &[f64], out: &mut [f64]) -> Res<()> {
    let width = f.degree() + 1;
    let half = (f.window() - 1) / 2;
    out.fill(f64::NAN);
    for (n, (&ti, &yi)) in t.iter().zip(y).enumerate() {
        f.update(ti, yi)?;
        if n + 1 >= f.window() {
            let c = n - half;
            if let Some(s) = f.estimate_at(t[c]) {
                out[c * width..(c + 1) * width].copy_from_slice(&s.derivatives);
            }
        }
    }
    Ok(())
}

/// Best wall-clock seconds of `reps` calls of `body` (each given a fresh setup).
fn best_of<S>(
    reps: usize,
    mut setup: impl FnMut() -> Res<S>,
    mut body: impl FnMut(&mut S) -> Res<()>,
) -> Res<f64> {
    let mut best = f64::INFINITY;
    for _ in 0..reps {
        let mut s = setup()?;
        let start = Instant::now();
        body(&mut s)?;
        best = best.min(start.elapsed().as_secs_f64());
        black_box(&s);
    }
    Ok(best)
}

/// What [`time_filter`] returns: seconds of the update loop and of the update + estimate
/// loop, the per-sample estimates, the final estimate after the update-only loop, and the
/// switch sample.
type Timed = (f64, f64, Vec<f64>, Vec<f64>, Option<u64>);

/// Times a filter that implements [`PolynomialFilter`]: both loops, then untimed runs for the
/// estimates (every sample's through `update_many_into`, and the last one after the
/// update-only call, so that the script checks what the update-only timing computed).
fn time_filter<F: PolynomialFilter>(
    reps: usize,
    make: impl Fn() -> Res<F>,
    t: &[f64],
    y: &[f64],
    switched: impl Fn(&F) -> Option<u64>,
) -> Res<Timed> {
    let width = make()?.degree() + 1;
    let mut out = vec![0.0; t.len() * width];
    let plain = best_of(reps, &make, |f| feed(f, t, y))?;
    let read = best_of(reps, &make, |f| feed_and_read(f, t, y, &mut out))?;
    let mut f = make()?;
    feed(&mut f, t, y)?;
    let last = f
        .estimate()
        .map_or_else(|| vec![f64::NAN; width], |s| s.derivatives);
    let mut f = make()?;
    feed_and_read(&mut f, t, y, &mut out)?;
    Ok((plain, read, out, last, switched(&f)))
}

/// The `gauss-newton` run: times the fits of the first `windows` simulated radar passes and
/// writes the data, the nominal states, the estimates and their σ for the script.
fn gauss_newton(dir: &Path, name: &str, windows: usize, reps: usize) -> Res<()> {
    let (dynamics, radar) = radar::models();
    let passes = radar::windows(radar::SEED, windows);
    let rows: Vec<_> = passes.iter().map(|w| w.measurements()).collect();
    let nominals = passes
        .iter()
        .map(|w| w.nominal(&radar))
        .collect::<Result<Vec<_>, _>>()?;
    let fit_all = |_: &mut ()| -> Res<()> {
        for (r, x0) in rows.iter().zip(&nominals) {
            black_box(radar::fit(&dynamics, &radar, black_box(r), x0)?);
        }
        Ok(())
    };
    let bootstrap_and_fit = |_: &mut ()| -> Res<()> {
        for (w, r) in passes.iter().zip(&rows) {
            let x0 = w.nominal(&radar)?;
            black_box(radar::fit(&dynamics, &radar, black_box(r), &x0)?);
        }
        Ok(())
    };
    let bootstrap = |_: &mut ()| -> Res<()> {
        for w in &passes {
            black_box(black_box(w).nominal(&radar)?);
        }
        Ok(())
    };
    let secs_fit = best_of(reps, || Ok(()), fit_all)?;
    let secs_both = best_of(reps, || Ok(()), bootstrap_and_fit)?;
    let secs_boot = best_of(reps, || Ok(()), bootstrap)?;
    let mut data = Vec::new();
    let (mut est, mut sigma, mut nominal) = (Vec::new(), Vec::new(), Vec::new());
    for ((w, r), x0) in passes.iter().zip(&rows).zip(&nominals) {
        for (t, m) in w.times.iter().zip(&w.measured) {
            data.extend([*t, m[0], m[1], m[2]]);
        }
        let fit = radar::fit(&dynamics, &radar, r, x0)?;
        est.extend(fit.state.iter());
        sigma.extend(fit.covariance.diagonal().iter().map(|v| v.sqrt()));
        nominal.extend(x0.iter());
    }
    write_f64s(&dir.join(format!("{name}.data.f64")), &data)?;
    write_f64s(&dir.join(format!("{name}.nominal.f64")), &nominal)?;
    write_f64s(&dir.join(format!("{name}.est.f64")), &est)?;
    write_f64s(&dir.join(format!("{name}.sigma.f64")), &sigma)?;
    println!("{name},{windows},{secs_fit:e},{secs_both:e},,{secs_boot:e}");
    Ok(())
}

/// Filters, each with the measurements it updates with.
type Tracks<'a, D, O> = [(KalmanFilter<D, O>, &'a [Measurement])];

/// Best seconds of `reps` runs of `step(filter, measurement, index)` over every measurement of
/// every track (`index` counting the updates in order), the filters copied before each run.
fn time_tracks<D, O>(
    reps: usize,
    tracks: &Tracks<D, O>,
    mut step: impl FnMut(&mut KalmanFilter<D, O>, &Measurement, usize) -> Res<()>,
) -> Res<f64>
where
    D: Dynamics + Clone,
    O: Observation + Clone,
{
    let setup = || Ok(tracks.iter().map(|(f, _)| f.clone()).collect::<Vec<_>>());
    best_of(reps, setup, |fs| {
        let mut index = 0;
        for (f, (_, rows)) in fs.iter_mut().zip(tracks) {
            for m in rows.iter() {
                step(f, black_box(m), index)?;
                index += 1;
            }
        }
        Ok(())
    })
}

/// The three timed loops of a Kalman filter over `tracks`: [`KalmanFilter::update_stats`], the
/// same copying each state into `out` (`updates × n`, in order), and [`KalmanFilter::update`];
/// seconds.
fn time_kalman<D, O>(reps: usize, tracks: &Tracks<D, O>, out: &mut [f64]) -> Res<(f64, f64, f64)>
where
    D: Dynamics + Clone,
    O: Observation + Clone,
{
    let n = tracks[0].0.state().len();
    let quiet = time_tracks(reps, tracks, |f, m, _| {
        black_box(f.update_stats(m)?);
        Ok(())
    })?;
    let read = time_tracks(reps, tracks, |f, m, i| {
        black_box(f.update_stats(m)?);
        out[i * n..(i + 1) * n].copy_from_slice(f.state().as_slice());
        Ok(())
    })?;
    let full = time_tracks(reps, tracks, |f, m, _| {
        black_box(f.update(m)?);
        Ok(())
    })?;
    Ok((quiet, read, full))
}

/// The `kalman-q` run (see the module docs).
fn kalman_q(dir: &Path, run: &Run, t: &[f64], y: &[f64], reps: usize) -> Res<()> {
    let (m, w) = (run.degree, run.degree + 1);
    let (q, r): (f64, f64) = (run.key("q")?, run.key("r")?);
    let prior = read_f64s(&dir.join(format!("{}.prior.f64", run.name)))?;
    if prior.len() != w + w * w || t.len() <= w {
        return Err(format!("run {}: prior or data of the wrong size", run.name).into());
    }
    let filter = KalmanFilter::new(
        PolynomialDynamics::new(m, 1),
        LinearObservation::value_of(w),
        DVector::from_column_slice(&prior[..w]),
        DMatrix::from_row_slice(w, w, &prior[w..]),
        t[m],
    )?
    .with_process_noise(WhiteNoiseDerivative::new(m, 1, q)?)?;
    let rows: Vec<Measurement> = (w..t.len())
        .map(|i| Measurement {
            time: t[i],
            values: vec![Some(y[i])],
            noise: NoiseCovariance::Variances(vec![r]),
        })
        .collect();
    let mut out = vec![f64::NAN; t.len() * w];
    out[m * w..w * w].copy_from_slice(&prior[..w]);
    let tracks = [(filter, &rows[..])];
    let (quiet, read, full) = time_kalman(reps, &tracks, &mut out[w * w..])?;
    let mut f = tracks[0].0.clone();
    for m in &rows {
        f.update_stats(m)?;
    }
    write_f64s(&dir.join(format!("{}.est.f64", run.name)), &out)?;
    write_f64s(
        &dir.join(format!("{}.last.f64", run.name)),
        f.state().as_slice(),
    )?;
    println!("{},{},{quiet:e},{read:e},,{full:e}", run.name, rows.len());
    Ok(())
}

/// The `ekf` run (see the module docs).
fn ekf(dir: &Path, name: &str, count: usize, reps: usize) -> Res<()> {
    let tracks = kalman_tracks::tracks(radar::SEED, count);
    let filters: Vec<_> = tracks
        .iter()
        .map(|t| (t.filter(), &t.measurements[..]))
        .collect();
    let updates: usize = tracks.iter().map(|t| t.measurements.len()).sum();
    let mut est = vec![0.0; updates * 6];
    let (quiet, read, full) = time_kalman(reps, &filters, &mut est)?;
    let (mut data, mut prior, mut sigma) = (Vec::new(), Vec::new(), Vec::new());
    for (track, (filter, rows)) in tracks.iter().zip(&filters) {
        prior.push(track.time);
        prior.extend(track.state.iter());
        prior.extend(track.covariance.transpose().iter());
        let mut f = filter.clone();
        for m in rows.iter() {
            data.push(m.time);
            data.extend(m.values.iter().map(|v| v.unwrap_or(f64::NAN)));
            f.update_stats(m)?;
            sigma.extend(f.covariance().diagonal().iter().map(|v| v.sqrt()));
        }
    }
    write_f64s(&dir.join(format!("{name}.data.f64")), &data)?;
    write_f64s(&dir.join(format!("{name}.prior.f64")), &prior)?;
    write_f64s(&dir.join(format!("{name}.est.f64")), &est)?;
    write_f64s(&dir.join(format!("{name}.sigma.f64")), &sigma)?;
    println!("{name},{updates},{quiet:e},{read:e},,{full:e}");
    Ok(())
}

fn main() -> Res<()> {
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 3 {
        return Err("usage: peers DIR REPS".into());
    }
    let dir = Path::new(&args[1]);
    let reps: usize = args[2]
        .parse()
        .map_err(|e| format!("REPS '{}': {e}", args[2]))?;
    let spec = std::fs::read_to_string(dir.join("runs.txt"))
        .map_err(|e| format!("{}: {e}", dir.join("runs.txt").display()))?;
    let mut data: BTreeMap<String, (Vec<f64>, Vec<f64>)> = BTreeMap::new();
    println!("name,samples,seconds_update,seconds_update_estimate,switched_at");
    for (i, line) in spec.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let run = Run::parse(line, i + 1)?;
        if run.filter == "gauss-newton" {
            gauss_newton(dir, &run.name, run.key("windows")?, reps)?;
            continue;
        }
        if run.filter == "ekf" {
            ekf(dir, &run.name, run.key("tracks")?, reps)?;
            continue;
        }
        if !data.contains_key(&run.data) {
            let t = read_f64s(&dir.join(format!("{}.t.f64", run.data)))?;
            let y = read_f64s(&dir.join(format!("{}.y.f64", run.data)))?;
            if t.len() != y.len() {
                return Err(
                    format!("data {}: {} times, {} values", run.data, t.len(), y.len()).into(),
                );
            }
            data.insert(run.data.clone(), (t, y));
        }
        let (t, y) = &data[&run.data];
        if run.filter == "kalman-q" {
            kalman_q(dir, &run, t, y, reps)?;
            continue;
        }
        let m = run.degree;
        let (plain, read, out, last, switched) = match run.filter.as_str() {
            "fading-gain" => {
                time_filter(reps, || run.fading(Engine::Gain), t, y, |f| f.switched_at())?
            }
            "fading-exact" => time_filter(reps, || run.fading(Engine::Exact), t, y, |_| None)?,
            "expanding-gain" => time_filter(
                reps,
                || Ok(ExpandingMemory::new(m, Engine::Gain)?),
                t,
                y,
                |_| None,
            )?,
            "expanding-exact" => time_filter(
                reps,
                || Ok(ExpandingMemory::new(m, Engine::Exact)?),
                t,
                y,
                |_| None,
            )?,
            "fixed-sliding" => {
                let window: usize = run.key("window")?;
                let make = || Ok(FixedMemory::new(m, window, FixedEngine::Sliding)?);
                let mut out = vec![0.0; t.len() * (m + 1)];
                let plain = best_of(reps, make, |f| feed(f, t, y))?;
                let read = best_of(reps, make, |f| feed_fixed_and_read(f, t, y, &mut out))?;
                feed_fixed_and_read(&mut make()?, t, y, &mut out)?;
                (plain, read, out, Vec::new(), None)
            }
            "smooth" => {
                let window: usize = run.key("window")?;
                let mut out = vec![0.0; t.len() * (m + 1)];
                let secs = best_of(
                    reps,
                    || Ok(()),
                    |_| Ok(smooth_into(t, y, m, window, &mut out)?),
                )?;
                (secs, secs, out, Vec::new(), None)
            }
            other => return Err(format!("run {}: unknown filter '{other}'", run.name).into()),
        };
        write_f64s(&dir.join(format!("{}.est.f64", run.name)), &out)?;
        write_f64s(&dir.join(format!("{}.last.f64", run.name)), &last)?;
        println!(
            "{},{},{:e},{:e},{}",
            run.name,
            t.len(),
            plain,
            read,
            switched.map(|s| s.to_string()).unwrap_or_default()
        );
    }
    Ok(())
}
