//! The linearisation of the Gauss–Newton fit (Morrison (8.6.28)-(8.6.35); the prior's rows
//! (11.4.33)): each measurement's whitened rows `M_k Φ(t_k, t_c)` and residuals at a nominal
//! state, into buffers made once per fit ([`System`], [`Scratch`]), so that an iteration
//! allocates nothing.

use super::{Measurement, NoiseCovariance, Prior};
use crate::error::{Error, Param};
use crate::linalg::dense::all_finite;
use crate::model::dynamics::Dynamics;
use crate::model::observation::Observation;
use crate::model::radar::Radar;
use crate::model::transition::psi_term;
use crate::numeric::unrolled::{unrolled_sizes, Any, Fixed, Size};
use nalgebra::{Cholesky, DMatrix, DVector, Dyn};

/// One measurement: its time, where its present components start in [`Prepared`]'s lists
/// and how many there are, and how they are whitened (`R_k = L Lᵀ` on those rows).
#[derive(Clone, Debug)]
pub(super) struct Rows {
    pub(super) time: f64,
    start: usize,
    pub(super) count: usize,
    whiten: Whiten,
}

/// A measurement's whitening: each row times its scale `1/σ` (the lists' `scale`), or by the
/// Cholesky factor of its `R` (the lists' scale then 1, unused).
#[derive(Clone, Debug)]
enum Whiten {
    Scale,
    Factor(Cholesky<f64, Dyn>),
}

/// Every measurement's [`Rows`], and their present components, values and scales one after
/// another in three lists: four allocations for a fit, not three a measurement.
pub(super) struct Prepared {
    pub(super) rows: Vec<Rows>,
    present: Vec<usize>,
    values: Vec<f64>,
    scale: Vec<f64>,
}

/// One measurement's present components, their measured values and their scales.
#[derive(Clone, Copy)]
struct Entries<'a> {
    present: &'a [usize],
    values: &'a [f64],
    scale: &'a [f64],
}

impl Prepared {
    #[inline]
    fn entries(&self, row: &Rows) -> Entries<'_> {
        let range = row.start..row.start + row.count;
        Entries {
            present: &self.present[range.clone()],
            values: &self.values[range.clone()],
            scale: &self.scale[range],
        }
    }
}

/// The whitened linear system at one nominal state: `T` (`rows × n`), `δY` and `e(X̄)`.
pub(super) struct System {
    pub(super) t: DMatrix<f64>,
    pub(super) r: DVector<f64>,
    pub(super) chi_squared: f64,
}

impl System {
    pub(super) fn new(rows: usize, n: usize) -> Self {
        Self {
            t: DMatrix::zeros(rows, n),
            r: DVector::zeros(rows),
            chi_squared: 0.0,
        }
    }
}

/// The linearisation's own buffers (`n` states, `p` components).
pub(super) struct Scratch {
    carried: DMatrix<f64>,
    m: DMatrix<f64>,
    step: DMatrix<f64>,
    next: DVector<f64>,
    value: DVector<f64>,
    jacobian: DMatrix<f64>,
    state: DVector<f64>,
    phi: DMatrix<f64>,
    residual: DVector<f64>,
}

impl Scratch {
    pub(super) fn new(n: usize, p: usize) -> Self {
        Self {
            carried: DMatrix::zeros(n, n),
            m: DMatrix::zeros(p, n),
            step: DMatrix::zeros(n, n),
            next: DVector::zeros(n),
            value: DVector::zeros(p),
            jacobian: DMatrix::zeros(p, n),
            state: DVector::zeros(n),
            phi: DMatrix::zeros(n, n),
            residual: DVector::zeros(n),
        }
    }
}

/// What a linearisation reads: the models, the measurements' rows and their layout, the epoch
/// and the prior.
pub(super) struct Model<'a, D, O> {
    pub(super) dynamics: &'a D,
    pub(super) observation: &'a O,
    pub(super) rows: &'a Prepared,
    pub(super) layout: &'a Layout,
    pub(super) t_c: f64,
    pub(super) prior: Option<&'a PriorRows>,
}

/// Checks every measurement and builds its whitening of the present components.
pub(super) fn prepare<O: Observation>(
    observation: &O,
    measurements: &[Measurement],
) -> Result<Prepared, Error> {
    let p = observation.components();
    let entries = measurements.len() * p;
    let mut out = Prepared {
        rows: Vec::with_capacity(measurements.len()),
        present: Vec::with_capacity(entries),
        values: Vec::with_capacity(entries),
        scale: Vec::with_capacity(entries),
    };
    for (index, m) in measurements.iter().enumerate() {
        let row = out.push(p, m).map_err(|source| Error::InBatch {
            index,
            source: Box::new(source),
        })?;
        out.rows.push(row);
    }
    Ok(out)
}

impl Prepared {
    /// One measurement's present components and values onto the lists, as
    /// [`Measurement::present`] finds them (its errors where it refuses the measurement), and
    /// their whitening.
    fn push(&mut self, p: usize, m: &Measurement) -> Result<Rows, Error> {
        let start = self.present.len();
        let usable = m.time.is_finite()
            && m.values.len() == p
            && m.values.iter().all(|v| v.is_none_or(f64::is_finite));
        if usable {
            for (k, v) in m.values.iter().enumerate() {
                if let Some(v) = *v {
                    self.present.push(k);
                    self.values.push(v);
                }
            }
        } else {
            let (present, values) = m.present(p)?;
            self.present.extend(present);
            self.values.extend(values);
        }
        let whiten = whiten(p, m, &self.present[start..], &mut self.scale)?;
        Ok(Rows {
            time: m.time,
            start,
            count: self.present.len() - start,
            whiten,
        })
    }
}

/// The whitening of a measurement's `present` components, their scales onto `scale` (1
/// where `R` is full).
fn whiten(
    p: usize,
    m: &Measurement,
    present: &[usize],
    scale: &mut Vec<f64>,
) -> Result<Whiten, Error> {
    let bad = |value: String, reason: &str| Error::InvalidParameter {
        name: Param::MeasurementNoise,
        value,
        reason: reason.into(),
    };
    Ok(match &m.noise {
        NoiseCovariance::Identity => {
            scale.extend(present.iter().map(|_| 1.0));
            Whiten::Scale
        }
        NoiseCovariance::Variances(v) => {
            if v.len() != p {
                return Err(bad(
                    format!("{} variances", v.len()),
                    &format!("need {p}, one per component"),
                ));
            }
            for &k in present {
                if !(v[k].is_finite() && v[k] > 0.0) {
                    return Err(bad(
                        format!("variance {}", v[k]),
                        "must be positive and finite",
                    ));
                }
                scale.push(1.0 / v[k].sqrt());
            }
            Whiten::Scale
        }
        NoiseCovariance::Full(r) => {
            if r.shape() != (p, p) {
                return Err(bad(
                    format!("{}x{}", r.nrows(), r.ncols()),
                    &format!("must be {p}x{p}"),
                ));
            }
            if r.iter().any(|v| !v.is_finite())
                || (r - r.transpose()).abs().max() > 1e-12 * r.abs().max()
            {
                return Err(bad(format!("{r:?}"), "must be finite and symmetric"));
            }
            let sub = DMatrix::from_fn(present.len(), present.len(), |i, j| {
                r[(present[i], present[j])]
            });
            scale.extend(present.iter().map(|_| 1.0));
            match Cholesky::new(sub) {
                Some(c) => Whiten::Factor(c),
                None if present.is_empty() => Whiten::Scale,
                None => return Err(bad(format!("{r:?}"), "must be positive definite")),
            }
        }
    })
}

/// The prior's whitening `S_p = L Lᵀ` and state.
pub(super) struct PriorRows {
    state: DVector<f64>,
    factor: Cholesky<f64, Dyn>,
    /// `L⁻¹`, the prior's rows of `T` (the same at every linearisation).
    block: DMatrix<f64>,
}

pub(super) fn prepare_prior(p: &Prior, n: usize) -> Result<PriorRows, Error> {
    let bad = |value: String, reason: &str| Error::InvalidParameter {
        name: Param::Prior,
        value,
        reason: reason.into(),
    };
    if p.state.len() != n || p.covariance.shape() != (n, n) {
        return Err(bad(
            format!(
                "state of length {}, covariance {}x{}",
                p.state.len(),
                p.covariance.nrows(),
                p.covariance.ncols()
            ),
            &format!("the model has {n} states"),
        ));
    }
    if let Some(&value) = p
        .state
        .iter()
        .chain(p.covariance.iter())
        .find(|v| !v.is_finite())
    {
        return Err(Error::NonFinite {
            what: "prior entry",
            value,
        });
    }
    let c = &p.covariance;
    if (c - c.transpose()).abs().max() > 1e-12 * c.abs().max() {
        return Err(bad(format!("{c:?}"), "the covariance must be symmetric"));
    }
    let factor = Cholesky::new(c.clone())
        .ok_or_else(|| bad(format!("{c:?}"), "the covariance must be positive definite"))?;
    let mut block = DMatrix::identity(n, n);
    let _ = factor.l_dirty().solve_lower_triangular_mut(&mut block);
    Ok(PriorRows {
        state: p.state.clone(),
        factor,
        block,
    })
}

/// The order the trajectory is carried in, fixed by the times and the epoch: each
/// measurement's first row of `T`, the measurements at or after `t_c` by increasing time, those
/// before it by decreasing time, and the rows in all.
pub(super) struct Layout {
    offsets: Vec<usize>,
    after: Vec<usize>,
    before: Vec<usize>,
    pub(super) total: usize,
    /// `Φ(t_k, t_c)` of each row, once per fit, for dynamics whose `Φ` does not depend on the
    /// state ([`Dynamics::is_linear`]), column-major `n × n` one after another; empty where
    /// every row is the radar's, written without them ([`radar_rows`]), each then computed
    /// only for a row that the radar's rows leave to the general path.
    transitions: Option<Vec<f64>>,
}

impl Layout {
    pub(super) fn new(rows: &[Rows], t_c: f64, prior_states: usize) -> Self {
        let mut offsets = Vec::with_capacity(rows.len());
        let mut at = 0;
        for row in rows {
            offsets.push(at);
            at += row.count;
        }
        let mut order: Vec<usize> = (0..rows.len()).collect();
        order.sort_by(|&a, &b| rows[a].time.total_cmp(&rows[b].time));
        let split = order.partition_point(|&k| rows[k].time < t_c);
        let after = order.split_off(split);
        order.reverse();
        Self {
            offsets,
            after,
            before: order,
            total: at + prior_states,
            transitions: None,
        }
    }

    /// With each row's `Φ(t_k, t_c)`, carried from `t_c` directly (any state will do); none
    /// stored for the radar's model with every row whitened by scales (`radar`), whose rows
    /// [`radar_rows`] writes from `Φ`'s two terms (a row it leaves to the general path computes
    /// its own then, the same numbers; the first linearisation is at `x`, where a `Φ x` that
    /// is not finite gives the error it gives here).
    pub(super) fn with_transitions<D: Dynamics>(
        mut self,
        dynamics: &D,
        rows: &[Rows],
        (t_c, x): (f64, &DVector<f64>),
        radar: bool,
    ) -> Result<Self, Error> {
        if radar && rows.iter().all(|r| matches!(r.whiten, Whiten::Scale)) {
            self.transitions = Some(Vec::new());
            return Ok(self);
        }
        let n = x.len();
        let (mut state, mut phi) = (DVector::zeros(n), DMatrix::zeros(n, n));
        let mut all = Vec::with_capacity(rows.len() * n * n);
        for row in rows {
            dynamics.propagate_into(x, t_c, row.time, &mut state, &mut phi)?;
            all.extend_from_slice(phi.as_slice());
        }
        self.transitions = Some(all);
        Ok(self)
    }
}

/// `out = a b` for the small `Φ` and `M Φ` products: nalgebra's product of dynamically sized
/// matrices goes through a general blocked multiplication whose set-up costs more than a 6 × 6
/// product (it was 30 % of a radar fit's instructions), so the inner size `n` (the state
/// dimension) goes through the crate's one unrolled-size dispatch. Each column of `out` is a
/// sum of `a`'s columns, `l` ascending, skipping the entries of `b` that are zero: `Φ` of the
/// polynomial model is `Ψ ⊗ I`, mostly zeros (27 of 36 for constant velocity on 3 axes). The
/// sums are those of the dot products `Σ_l a_il b_lj` term for term; a skipped `a_il · 0` could
/// change only the sign of a zero.
fn product_into(a: &DMatrix<f64>, b: &DMatrix<f64>, out: &mut DMatrix<f64>) {
    let (rows, inner) = a.shape();
    debug_assert_eq!(
        (b.nrows(), out.nrows(), out.ncols()),
        (inner, rows, b.ncols())
    );
    product_slices(rows, inner, a.as_slice(), b.as_slice(), out.as_mut_slice());
}

/// The column-major product of `a` (`rows × inner`) and `b` (`inner × out.len()/rows`).
fn product_slices(rows: usize, inner: usize, a: &[f64], b: &[f64], out: &mut [f64]) {
    unrolled_sizes!(inner, N => product_n(Fixed::<N>, rows, a, b, out),
        n => product_n(Any(n), rows, a, b, out));
}

/// [`product_into`] for an inner size `inner` (a constant in the sizes the dispatch unrolls).
#[inline(always)]
fn product_n<S: Size>(inner: S, rows: usize, a: &[f64], b: &[f64], out: &mut [f64]) {
    let inner = inner.get();
    for (o, b) in out.chunks_exact_mut(rows).zip(b.chunks_exact(inner)) {
        o.fill(-0.0);
        for (l, &w) in b.iter().enumerate() {
            if w != 0.0 {
                for (o, a) in o.iter_mut().zip(&a[l * rows..(l + 1) * rows]) {
                    *o += a * w;
                }
            }
        }
    }
}

/// Writes one observation's present rows, `M Φ` and the residuals, whitened, at `at`: each
/// row times its scale `1/σ` as it is copied (the products of a copy scaled afterwards), or
/// copied and then solved by the Cholesky factor of `R`.
#[allow(clippy::too_many_arguments)]
fn write_rows<O: Observation>(
    observation: &O,
    row: &Rows,
    entries: Entries<'_>,
    at: usize,
    m: &DMatrix<f64>,
    value: &DVector<f64>,
    t: &mut DMatrix<f64>,
    r: &mut DVector<f64>,
) {
    let (count, n) = (row.count, m.ncols());
    let Entries {
        present,
        values,
        scale,
    } = entries;
    match &row.whiten {
        Whiten::Scale => {
            let (total, p) = (t.nrows(), m.nrows());
            let (t, m) = (t.as_mut_slice(), m.as_slice());
            for (i, (&c, &s)) in present.iter().zip(scale).enumerate() {
                for j in 0..n {
                    t[at + i + j * total] = m[c + j * p] * s;
                }
                r[at + i] = observation.residual(c, values[i], value[c]) * s;
            }
        }
        Whiten::Factor(factor) => {
            for (i, &c) in present.iter().enumerate() {
                t.row_mut(at + i).copy_from(&m.row(c));
                r[at + i] = observation.residual(c, values[i], value[c]);
            }
            let _ = factor
                .l_dirty()
                .solve_lower_triangular_mut(&mut t.view_mut((at, 0), (count, n)));
            let _ = factor
                .l_dirty()
                .solve_lower_triangular_mut(&mut r.rows_mut(at, count));
        }
    }
}

/// The radar, when the model is constant velocity on three axes seen by one radar measuring
/// range, azimuth and elevation: [`radar_rows`] writes its rows.
pub(super) fn radar_cv<'a, D: Dynamics, O: Observation>(
    dynamics: &D,
    observation: &'a O,
) -> Option<&'a Radar> {
    let dynamics = dynamics.polynomial()?;
    let radar = observation.as_radar()?;
    (dynamics.degree() == 1 && dynamics.axes() == 3 && !radar.has_range_rate()).then_some(radar)
}

impl<D: Dynamics, O: Observation> Model<'_, D, O> {
    /// `T` and `δY` whitened, and `e(X̄)`, at the nominal `x` (state at `t_c`) into `out`:
    /// with each row's `Φ(t_k, t_c)` computed once ([`Layout::with_transitions`]), or carried
    /// outwards from `t_c` through the sorted times,
    /// `Φ(t_k, t_c) = Φ(t_k, t_{k∓1}) Φ(t_{k∓1}, t_c)`.
    pub(super) fn linearise(
        &self,
        x: &DVector<f64>,
        out: &mut System,
        scratch: &mut Scratch,
    ) -> Result<(), Error> {
        let (observation, layout) = (self.observation, self.layout);
        let n = x.len();
        let Scratch {
            carried,
            m,
            step,
            next,
            value,
            jacobian,
            state,
            phi,
            residual,
        } = scratch;
        let (t, r) = (&mut out.t, &mut out.r);
        if let Some(transitions) = &layout.transitions {
            let radar = radar_cv(self.dynamics, observation);
            for (k, row) in self.rows.rows.iter().enumerate() {
                if row.count == 0 {
                    continue;
                }
                let entries = self.rows.entries(row);
                if let (Some(radar), Whiten::Scale) = (radar, &row.whiten) {
                    let at = layout.offsets[k];
                    if radar_rows(radar, row.time, entries, self.t_c, x, at, t, r) {
                        continue;
                    }
                }
                let phi = match transitions.get(k * n * n..(k + 1) * n * n) {
                    Some(stored) => stored,
                    None => {
                        self.dynamics
                            .propagate_into(x, self.t_c, row.time, next, phi)?;
                        phi.as_slice()
                    }
                };
                product_slices(n, n, phi, x.as_slice(), next.as_mut_slice());
                observation.predict_into(next, row.time, value, jacobian)?;
                product_slices(m.nrows(), n, jacobian.as_slice(), phi, m.as_mut_slice());
                let at = layout.offsets[k];
                write_rows(observation, row, entries, at, m, value, t, r);
            }
        }
        let sides = match layout.transitions {
            Some(_) => [&[][..], &[][..]],
            None => [&layout.after[..], &layout.before[..]],
        };
        for side in sides {
            state.copy_from(x);
            phi.fill_with_identity();
            let mut time = self.t_c;
            for &k in side {
                let row = &self.rows.rows[k];
                if row.time != time {
                    self.dynamics
                        .propagate_into(state, time, row.time, next, step)?;
                    product_into(step, phi, carried);
                    std::mem::swap(phi, carried);
                    std::mem::swap(state, next);
                    time = row.time;
                }
                if row.count == 0 {
                    continue;
                }
                observation.predict_into(state, row.time, value, jacobian)?;
                product_into(jacobian, phi, m);
                let (entries, at) = (self.rows.entries(row), layout.offsets[k]);
                write_rows(observation, row, entries, at, m, value, t, r);
            }
        }
        if let Some(p) = self.prior {
            let at = layout.total - n;
            for (o, (a, b)) in residual.iter_mut().zip(p.state.iter().zip(x)) {
                *o = a - b;
            }
            let _ = p.factor.l_dirty().solve_lower_triangular_mut(residual);
            t.view_mut((at, 0), (n, n)).copy_from(&p.block);
            r.rows_mut(at, n).copy_from(residual);
        }
        let chi_squared = r.norm_squared();
        out.chi_squared = chi_squared;
        if !(chi_squared.is_finite() && all_finite(t.as_slice())) {
            return Err(Error::NonFinite {
                what: "linearised observation system",
                value: chi_squared,
            });
        }
        Ok(())
    }
}

/// The rows of one measurement for constant velocity on three axes seen by `radar` (states
/// `(x, y, z, vx, vy, vz)`), written out with `Φ(t_k, t_c) = Ψ(ζ) ⊗ I₃`, `ζ = t_k − t_c`:
/// `X(t_k)`'s position `x_a + ζ v_a`, `M Φ = [J, ζ J]` (`J` the radar's Jacobian on the
/// position, [`Radar::look`]), each row times its scale `1/σ`. The numbers of the general
/// path (`Φ`'s terms by `psi_term`, the products of `product_into` less its products with a
/// zero of `Φ` or `J`, which could change only the sign of a zero); `false`, writing nothing
/// the general path would not, where a number is not finite or the target is at the site (the
/// general path then decides).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn radar_rows(
    radar: &Radar,
    time: f64,
    entries: Entries<'_>,
    t_c: f64,
    x: &DVector<f64>,
    at: usize,
    t: &mut DMatrix<f64>,
    r: &mut DVector<f64>,
) -> bool {
    let zeta = time - t_c;
    let (t0, t1) = (psi_term(0, &zeta), psi_term(1, &zeta));
    let Ok(x) = <&[f64; 6]>::try_from(x.as_slice()) else {
        return false;
    };
    let next: [f64; 6] = std::array::from_fn(|i| {
        if i < 3 {
            t0 * x[i] + t1 * x[i + 3]
        } else {
            t0 * x[i]
        }
    });
    if !all_finite(&next) {
        return false;
    }
    let Some(look) = radar.look([next[0], next[1], next[2]]) else {
        return false;
    };
    let (g, j) = (look.value, look.jacobian);
    if !(all_finite(&g) && j.iter().all(|row| all_finite(row))) {
        return false;
    }
    let total = t.nrows();
    let Entries {
        present,
        values,
        scale,
    } = entries;
    let count = present.len().min(3);
    // The rows into a block by columns of `T`, then each column's part copied at once.
    let mut block = [[0.0; 3]; 6];
    let mut residuals = [0.0; 3];
    for (i, (&c, &s)) in present.iter().zip(scale).take(count).enumerate() {
        for l in 0..3 {
            block[l][i] = j[c][l] * t0 * s;
            block[l + 3][i] = j[c][l] * t1 * s;
        }
        residuals[i] = radar.residual(c, values[i], g[c]) * s;
    }
    for (column, values) in t.as_mut_slice().chunks_exact_mut(total).zip(&block) {
        column[at..at + count].copy_from_slice(&values[..count]);
    }
    r.as_mut_slice()[at..at + count].copy_from_slice(&residuals[..count]);
    true
}
