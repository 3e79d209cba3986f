//! A Kalman bank: one linear model, many series, each with its own times (any spacing) and
//! its own missing components — the Kalman filter of Morrison ch. 12 (prediction
//! (12.2.15)-(12.2.16) with driving noise (15.4.10)-(15.4.11), update (12.2.17)-(12.2.19) with
//! Joseph's covariance (12.3.7)) run on every series independently, and the
//! Rauch–Tung–Striebel fixed-interval and fixed-lag smoothers over it.
//!
//! - [`KalmanBank`]: the model (any linear [`Dynamics`] — the polynomial model of any degree
//!   and axes, a continuous model `dX/dt = A X` discretised for each step's own length,
//!   [`ContinuousModel`](crate::model::continuous::ContinuousModel) — with optional driving
//!   noise [`ProcessNoise`], a constant observation matrix `M` and noise `R`) and the prior
//!   every series starts from, at its own first time.
//! - [`Panel`]: the series in structure-of-arrays form, one array per quantity: the times of
//!   every row, the `p` values of every row (NaN where a component is missing), and the
//!   offsets of each series' rows (in time order within a series).
//! - [`KalmanBank::filter`], [`KalmanBank::smooth`] (RTS), [`KalmanBank::smooth_fixed_lag`]:
//!   per row the estimate, its σ (`√diag S`) and the update's NIS (`νᵀ V⁻¹ ν`, χ² with as
//!   many degrees of freedom as components present when the model holds, §14.8), in
//!   [`BankRows`]; the series run in parallel (rayon), each by the same code whatever the
//!   split, so any batching of the series gives the same numbers bit for bit.
//! - [`BankStream`]: the streaming filter, a step of every series at a time; its memory is
//!   the series' states and covariances (`n + n²` numbers and a time each), not the steps.
//!
//! Every series runs the library's own Kalman arithmetic: for `n ≤ 9` states and `p ≤ 3`
//! components a fixed-size path (the series' estimate, prediction and scratch in arrays on
//! the stack, the sizes compile-time constants, the arithmetic of the filter's `carry` and
//! `correct_kernel` operation for operation), which the filter and the RTS smoother run on
//! four series at once (structure of arrays across the series, each its own step lengths and
//! missing rows: `lanes`; the same operations, so a series' numbers do not depend on its
//! neighbours), beyond it the kernels of
//! [`KalmanFilter`](super::KalmanFilter) on their work buffers; `Φ` and `Q` computed once per
//! step length for a time-invariant model; and the library's own backward steps (the
//! whole-interval step of [`super::smoother`]'s `smooth_flat` for the RTS smoother,
//! [`super::fixed_lag`]'s for the fixed-lag one), so it equals one `KalmanFilter` (and one
//! `Smoother`, one `FixedLagSmoother`) per series to rounding: tested to `10⁻¹²` relative in
//! `tests/kalman_bank.rs`, on both sides of the fixed sizes.

use super::correct::noise_entries;
use super::noise::{check_covariance, check_estimate, check_noise_dimension, ProcessNoise};
use crate::error::{Error, Param};
use crate::model::dynamics::Dynamics;
use crate::model::measurement::NoiseCovariance;
use crate::model::observation::{LinearObservation, Observation};
use crate::numeric::sigma::std_dev;
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use std::sync::Arc;

mod backward;
mod fixed;
mod kernel;
mod labels;
#[cfg(target_arch = "x86_64")]
mod lanes;
mod series;
mod smooth;
mod stream;

pub use labels::Grouping;
pub use stream::BankStream;

use crate::numeric::unrolled::unrolled_sizes;
use fixed::{FixedSeries, MAX_COMPONENTS};
#[cfg(target_arch = "x86_64")]
use lanes::{Lanes, LANES};
use series::{Forward, SeriesFilter};
use smooth::Kept;

/// A pass over a series: the filter, the RTS smoother, the fixed-lag smoother of a lag.
#[derive(Clone, Copy, Debug)]
enum Pass {
    Filter,
    Rts,
    Lag(usize),
}

impl Pass {
    /// The pass over series `s` of `panel` into `out` with the filter `f`.
    fn series<F: Forward>(
        self,
        f: &mut F,
        kept: &mut Kept,
        panel: &Panel<'_>,
        s: usize,
        out: RowsMut<'_>,
    ) -> Result<(), Error> {
        match self {
            Pass::Filter => f.filter_series(panel, s, out),
            Pass::Rts => smooth::rts_series(f, kept, panel, s, out),
            Pass::Lag(lag) => smooth::fixed_lag_series(f, panel, s, lag, out),
        }
    }
}

/// Series per rayon task (each series is independent; the split changes no number).
pub const SERIES_PER_TASK: usize = 64;

/// The series of a bank, structure of arrays: series `s` is rows `offsets[s]..offsets[s + 1]`
/// of `times` and of `values` (`p` values a row, row-major, NaN for a missing component),
/// its times not decreasing.
#[derive(Clone, Copy, Debug)]
pub struct Panel<'a> {
    /// `S + 1` offsets, from 0 to the rows, not decreasing.
    pub offsets: &'a [usize],
    /// One time a row.
    pub times: &'a [f64],
    /// `p` values a row.
    pub values: &'a [f64],
}

impl Panel<'_> {
    /// The number of series.
    pub fn series(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    /// The number of rows.
    pub fn rows(&self) -> usize {
        self.times.len()
    }

    /// Refuses offsets that do not cut `times` into series, or values not `p` a row.
    fn check(&self, p: usize) -> Result<(), Error> {
        let rows = self.times.len();
        let bad = |name, value: String, reason: String| Error::InvalidParameter {
            name,
            value,
            reason,
        };
        if self.offsets.first() != Some(&0)
            || self.offsets.last() != Some(&rows)
            || self.offsets.windows(2).any(|w| w[0] > w[1])
        {
            return Err(bad(
                Param::Channels,
                format!("offsets of {} series over {rows} rows", self.series()),
                "must run from 0 to the number of rows, not decreasing".into(),
            ));
        }
        if self.values.len() != rows * p {
            return Err(bad(
                Param::RowsLength,
                format!("{} values for {rows} rows", self.values.len()),
                format!("must be {p} a row"),
            ));
        }
        Ok(())
    }
}

/// Per row of a [`Panel`], in its order: the estimate, its σ and the update's NIS.
///
/// The NIS is held as one number a row (8 bytes: 10⁷ rows' NIS are 80 MB, not the 160 MB of
/// an `Option<f64>` a row), read as an `Option` by [`BankRows::nis`] and [`BankRows::row`]
/// (`None` where every component of the row was missing); [`BankRows::into_columns`] hands
/// the columns over as they are, NaN for `None`, the form of an array front end.
#[derive(Clone, Debug, Default)]
pub struct BankRows {
    /// The state dimension `n`.
    pub states: usize,
    /// `n` a row: `X` (filtered `X_{k|k}`, or smoothed).
    pub state: Vec<f64>,
    /// `n` a row: `√diag S` of the same estimate.
    pub sigma: Vec<f64>,
    /// One a row: the forward update's NIS, NaN where none (every NIS the bank gives is finite).
    nis: Vec<f64>,
}

impl PartialEq for BankRows {
    /// The same rows: every number equal, the NIS present in the same rows (any two absent
    /// ones equal).
    fn eq(&self, other: &Self) -> bool {
        self.states == other.states
            && self.state == other.state
            && self.sigma == other.sigma
            && self.nis.len() == other.nis.len()
            && self
                .nis
                .iter()
                .zip(&other.nis)
                .all(|(a, b)| a == b || a.is_nan() && b.is_nan())
    }
}

impl BankRows {
    fn zeros(rows: usize, n: usize) -> Self {
        Self {
            states: n,
            state: vec![0.0; rows * n],
            sigma: vec![0.0; rows * n],
            nis: vec![f64::NAN; rows],
        }
    }

    /// The number of rows.
    pub fn rows(&self) -> usize {
        self.nis.len()
    }

    /// Row `r`'s NIS, `None` where every component was missing (the prediction).
    pub fn nis(&self, r: usize) -> Option<f64> {
        let v = self.nis[r];
        (!v.is_nan()).then_some(v)
    }

    /// Row `r`'s `(state, σ, NIS)`.
    pub fn row(&self, r: usize) -> (&[f64], &[f64], Option<f64>) {
        let n = self.states;
        (
            &self.state[r * n..(r + 1) * n],
            &self.sigma[r * n..(r + 1) * n],
            self.nis(r),
        )
    }

    /// The rows of `other` after these (the same state dimension, or these empty: they take
    /// `other`'s): the rows of a panel run in batches put back together.
    pub fn append(&mut self, other: BankRows) {
        if self.nis.is_empty() {
            self.states = other.states;
        }
        assert_eq!(self.states, other.states, "the same state dimension");
        self.state.extend(other.state);
        self.sigma.extend(other.sigma);
        self.nis.extend(other.nis);
    }

    /// The columns `(state, σ, NIS)`, `n`, `n` and one a row, the NIS NaN where
    /// [`BankRows::nis`] is `None`: nothing copied.
    pub fn into_columns(self) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        (self.state, self.sigma, self.nis)
    }
}

/// The rows of one series in [`BankRows`], as mutable slices.
pub(super) struct RowsMut<'a> {
    pub(super) state: &'a mut [f64],
    pub(super) sigma: &'a mut [f64],
    pub(super) nis: &'a mut [f64],
}

impl RowsMut<'_> {
    /// Row `r` from the estimate `(x, s)` and its NIS.
    #[inline]
    pub(super) fn set(&mut self, r: usize, x: &[f64], s: &[f64], nis: Option<f64>) {
        let n = x.len();
        self.state[r * n..(r + 1) * n].copy_from_slice(x);
        for (i, o) in self.sigma[r * n..(r + 1) * n].iter_mut().enumerate() {
            *o = std_dev(s[i + i * n]);
        }
        self.put_nis(r, nis);
    }

    /// Row `r`'s NIS, NaN for `None` ([`BankRows`]' form).
    #[inline]
    pub(super) fn put_nis(&mut self, r: usize, nis: Option<f64>) {
        self.nis[r] = nis.unwrap_or(f64::NAN);
    }
}

/// `len` zeros, their pages not yet touched (a large zeroed allocation is fresh pages of the
/// system's), advised as [`huge_pages`]: faulted in by the tasks that write them.
fn zeroed(len: usize) -> Vec<f64> {
    let mut v = vec![0.0; len];
    huge_pages(&mut v);
    v
}

/// Advises the kernel to back the whole 2 MiB pages of `v`'s allocation with huge pages
/// (Linux `madvise(MADV_HUGEPAGE)`, for transparent huge pages in `madvise` mode), before the
/// first touch of its pages: a large new output is then faulted in 2 MiB at a time rather
/// than 4 KiB (the bank's outputs are 40 bytes a row and more, hundreds of MB for 10⁷ rows,
/// where the 4 KiB faults cost as much CPU time as the filter). Advice only: no content or
/// number changes, a refusal is ignored; nothing elsewhere.
fn huge_pages<T>(v: &mut Vec<T>) {
    #[cfg(target_os = "linux")]
    {
        const HUGE: usize = 2 << 20;
        let start = v.as_mut_ptr() as usize;
        let end = start + v.capacity() * std::mem::size_of::<T>();
        let (a, b) = (start.next_multiple_of(HUGE), end / HUGE * HUGE);
        if a < b {
            // SAFETY: `a..b` is whole pages inside `v`'s own allocation; the advice changes
            // how the kernel backs them (contents kept), not the mapping or any byte.
            unsafe {
                libc::madvise(a as *mut libc::c_void, b - a, libc::MADV_HUGEPAGE);
            }
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = v;
}

/// A Kalman bank: one linear model and prior for many series.
///
/// ```
/// use nalgebra::{DMatrix, DVector};
/// use seqsmooth::kalman::bank::{KalmanBank, Panel};
/// use seqsmooth::kalman::noise::WhiteNoiseDerivative;
/// use seqsmooth::model::dynamics::PolynomialDynamics;
/// use seqsmooth::model::observation::LinearObservation;
/// // Constant velocity, position observed (σ = 1), two series with their own times.
/// let bank = KalmanBank::new(PolynomialDynamics::new(1, 1), LinearObservation::value_of(2),
///     DMatrix::identity(1, 1), DVector::zeros(2), DMatrix::identity(2, 2) * 100.0).unwrap()
///     .with_process_noise(WhiteNoiseDerivative::new(1, 1, 0.01).unwrap()).unwrap();
/// let times = [0.0, 1.0, 2.5, 0.0, 3.0];
/// let values = [0.0, 1.1, f64::NAN, 5.0, 4.0];
/// let rows = bank.filter(&Panel { offsets: &[0, 3, 5], times: &times, values: &values }).unwrap();
/// assert_eq!(rows.nis(2), None); // missing: the prediction
/// assert!((rows.state[2 * 2] - (rows.state[2] + 1.5 * rows.state[3])).abs() < 1e-12);
/// ```
#[derive(Clone, Debug)]
pub struct KalmanBank<D: Dynamics> {
    dynamics: D,
    observation: LinearObservation,
    r: DMatrix<f64>,
    noise: Option<Arc<dyn ProcessNoise>>,
    state: DVector<f64>,
    covariance: DMatrix<f64>,
}

impl<D: Dynamics + Sync> KalmanBank<D> {
    /// The bank of `dynamics` (linear, [`Dynamics::is_linear`]) observed by `observation`
    /// with noise covariance `r` (`p × p`, symmetric, positive semidefinite), every series
    /// starting from `state`, `covariance` at its first time (the first row is then an update
    /// without a prediction, as a [`KalmanFilter`](super::KalmanFilter) made at that time).
    pub fn new(
        dynamics: D,
        observation: LinearObservation,
        r: DMatrix<f64>,
        state: DVector<f64>,
        covariance: DMatrix<f64>,
    ) -> Result<Self, Error> {
        let n = dynamics.dimension();
        if !dynamics.is_linear() {
            return Err(Error::InvalidParameter {
                name: Param::Dynamics,
                value: "nonlinear".into(),
                reason: "a Kalman bank takes a linear model".into(),
            });
        }
        if observation.state_dimension() != n {
            return Err(Error::InvalidParameter {
                name: Param::ObservationModel,
                value: format!("for {} states", observation.state_dimension()),
                reason: format!("the dynamics have {n} states"),
            });
        }
        check_covariance(&r, observation.components(), Param::MeasurementNoise)?;
        check_estimate(&state, &covariance, n)?;
        Ok(Self {
            dynamics,
            observation,
            r,
            noise: None,
            state,
            covariance,
        })
    }

    /// With driving noise `Q` (ch. 15) of the model's dimension.
    pub fn with_process_noise<P: ProcessNoise + 'static>(
        mut self,
        noise: P,
    ) -> Result<Self, Error> {
        check_noise_dimension(&noise, self.dynamics.dimension())?;
        self.noise = Some(Arc::new(noise));
        Ok(self)
    }

    /// The state dimension `n`.
    pub fn states(&self) -> usize {
        self.dynamics.dimension()
    }

    /// The observed components `p`.
    pub fn components(&self) -> usize {
        self.observation.components()
    }

    /// The measurement noise as the filter takes it.
    fn noise_covariance(&self) -> NoiseCovariance {
        NoiseCovariance::Full(self.r.clone())
    }

    /// `R`'s entries, checked.
    fn r_entries(&self) -> Vec<f64> {
        let p = self.components();
        let noise = self.noise_covariance();
        let entry = noise_entries(p, &noise).expect("R is p × p");
        (0..p * p).map(|i| entry(i % p, i / p)).collect()
    }

    /// The filter over every series of `panel`: per row `X_{k|k}`, its σ and the NIS. An error
    /// names the first failing series ([`Error::InChannel`]) and its row within the series
    /// ([`Error::InBatch`]).
    pub fn filter(&self, panel: &Panel<'_>) -> Result<BankRows, Error> {
        self.run(panel, Pass::Filter)
    }

    /// The Rauch–Tung–Striebel smoother over every series (see [`super::smoother`]): per row
    /// `X_{k|N}`, its σ and the forward update's NIS; memory per series is its rows'.
    pub fn smooth(&self, panel: &Panel<'_>) -> Result<BankRows, Error> {
        self.run(panel, Pass::Rts)
    }

    /// The fixed-lag smoother (see [`super::fixed_lag`]) over every series: per row
    /// `X_{k|k+L}` (the last `L` rows of a series from all of its rows), its σ and the NIS;
    /// memory per series is `L + 1` rows' estimates and backward steps, not its length.
    pub fn smooth_fixed_lag(&self, panel: &Panel<'_>, lag: usize) -> Result<BankRows, Error> {
        self.run(panel, Pass::Lag(lag))
    }

    /// [`KalmanBank::filter`] into `out`, its buffers reused (grown or shrunk to the panel's
    /// rows): no page of a large output faulted in again. On an error `out` holds no rows.
    pub fn filter_into(&self, panel: &Panel<'_>, out: &mut BankRows) -> Result<(), Error> {
        self.run_into(panel, Pass::Filter, out)
    }

    /// [`KalmanBank::smooth`] into `out`, its buffers reused as [`KalmanBank::filter_into`]'s.
    pub fn smooth_into(&self, panel: &Panel<'_>, out: &mut BankRows) -> Result<(), Error> {
        self.run_into(panel, Pass::Rts, out)
    }

    /// Runs `pass` on every series of `panel` in parallel, each into its own rows.
    fn run(&self, panel: &Panel<'_>, pass: Pass) -> Result<BankRows, Error> {
        let mut out = BankRows::default();
        self.run_into(panel, pass, &mut out)?;
        Ok(out)
    }

    /// [`Self::run`] into `out`'s buffers.
    fn run_into(&self, panel: &Panel<'_>, pass: Pass, out: &mut BankRows) -> Result<(), Error> {
        let (n, p) = (self.states(), self.components());
        if let Err(e) = panel.check(p) {
            *out = BankRows::default();
            return Err(e);
        }
        // Buffers of the right length kept as they are (every entry is written); others made
        // anew (zeroed pages, faulted in by the tasks that write them).
        let rows = panel.rows();
        out.states = n;
        if out.state.len() != rows * n || out.sigma.len() != rows * n {
            out.state = zeroed(rows * n);
            out.sigma = zeroed(rows * n);
        }
        if out.nis.len() != rows {
            out.nis = zeroed(rows);
        }
        let r = self.r_entries();
        // The output cut into each task's contiguous rows.
        let count = panel.series();
        let mut tasks = Vec::with_capacity(count.div_ceil(SERIES_PER_TASK));
        let (mut state, mut sigma, mut nis) =
            (&mut out.state[..], &mut out.sigma[..], &mut out.nis[..]);
        for first in (0..count).step_by(SERIES_PER_TASK) {
            let last = (first + SERIES_PER_TASK).min(count);
            let rows = panel.offsets[last] - panel.offsets[first];
            let (a, rest_a) = std::mem::take(&mut state).split_at_mut(rows * n);
            let (b, rest_b) = std::mem::take(&mut sigma).split_at_mut(rows * n);
            let (c, rest_c) = std::mem::take(&mut nis).split_at_mut(rows);
            (state, sigma, nis) = (rest_a, rest_b, rest_c);
            tasks.push((
                first..last,
                RowsMut {
                    state: a,
                    sigma: b,
                    nis: c,
                },
            ));
        }
        let failures: Vec<(usize, Error)> = tasks
            .into_par_iter()
            .filter_map(|(range, rows)| {
                #[cfg(target_arch = "x86_64")]
                if !matches!(pass, Pass::Lag(_))
                    && (1..=MAX_COMPONENTS).contains(&p)
                    && (1..=9).contains(&n)
                    && lanes::available()
                {
                    return unrolled_sizes!(n, N => self.lanes::<N>(&r, pass, panel, range, rows),
                        _ => unreachable!("n ≤ 9"));
                }
                if p <= MAX_COMPONENTS {
                    unrolled_sizes!(n, N => self.task(&mut FixedSeries::<D, N>::new(self, &r), pass, panel, range, rows),
                        _ => self.task(&mut SeriesFilter::new(self, &r), pass, panel, range, rows))
                } else {
                    self.task(&mut SeriesFilter::new(self, &r), pass, panel, range, rows)
                }
            })
            .collect();
        match failures.into_iter().min_by_key(|(s, _)| *s) {
            Some((channel, source)) => {
                *out = BankRows::default();
                Err(Error::InChannel {
                    channel,
                    source: Box::new(source),
                    also_failed: Vec::new(),
                })
            }
            None => Ok(()),
        }
    }

    #[cfg(target_arch = "x86_64")]
    /// The filter or the RTS smoother over the series `range` of `panel` into their `rows`,
    /// [`LANES`] series at a time ([`Lanes`], `N ≤ 9` states, 1 to [`MAX_COMPONENTS`]
    /// components): the first failing series and its error.
    fn lanes<const N: usize>(
        &self,
        r: &[f64],
        pass: Pass,
        panel: &Panel<'_>,
        range: std::ops::Range<usize>,
        rows: RowsMut<'_>,
    ) -> Option<(usize, Error)> {
        match self.components() {
            1 => self.lanes_of::<N, 1>(r, pass, panel, range, rows),
            2 => self.lanes_of::<N, 2>(r, pass, panel, range, rows),
            _ => self.lanes_of::<N, 3>(r, pass, panel, range, rows),
        }
    }

    /// [`Self::lanes`] with `K` components.
    #[cfg(target_arch = "x86_64")]
    fn lanes_of<const N: usize, const K: usize>(
        &self,
        r: &[f64],
        pass: Pass,
        panel: &Panel<'_>,
        range: std::ops::Range<usize>,
        mut rows: RowsMut<'_>,
    ) -> Option<(usize, Error)> {
        let base = panel.offsets[range.start];
        let mut lanes = Lanes::<D, N, K, LANES>::new(self, r);
        match pass {
            Pass::Filter => lanes.filter(panel, range, &mut rows, base),
            _ => {
                let mut kept = Kept::default();
                let mut alone = |one: &mut FixedSeries<'_, D, N>, s, out: RowsMut<'_>| {
                    smooth::rts_series(one, &mut kept, panel, s, out)
                };
                lanes.smooth(panel, range, &mut rows, base, &mut Vec::new(), &mut alone)
            }
        }
    }

    /// `pass` over the series `range` of `panel` with the filter `f`, into their `rows`: the
    /// first failing series and its error.
    fn task<F: Forward>(
        &self,
        f: &mut F,
        pass: Pass,
        panel: &Panel<'_>,
        range: std::ops::Range<usize>,
        rows: RowsMut<'_>,
    ) -> Option<(usize, Error)> {
        let n = self.states();
        let mut kept = Kept::default();
        let base = panel.offsets[range.start];
        for s in range {
            let (a, b) = (panel.offsets[s] - base, panel.offsets[s + 1] - base);
            let out = RowsMut {
                state: &mut rows.state[a * n..b * n],
                sigma: &mut rows.sigma[a * n..b * n],
                nis: &mut rows.nis[a..b],
            };
            if let Err(e) = pass.series(f, &mut kept, panel, s, out) {
                return Some((s, e));
            }
        }
        None
    }
}
