//! Online smoothing of a segment (Villien & Ostertag 2009, §V, eqs. 34-37, Table I): the
//! segment's weighted least-squares polynomial of degree `n`, built one sample at a time from
//! work computed offline from the sample times and variances known in advance, then the
//! polynomial samples by virtual sampling (eq. 37).
//!
//! The paper runs recursive least squares, `A_k = A_{k−1} + K_k (y_k − V_kᵀ A_{k−1})` (eq. 35,
//! `4(n+1)` operations a sample with the gains `K_k` of eq. 34 precomputed). In a basis fixed
//! over the segment that recursion is unstable in doubles where the first samples crowd into
//! a small part of the span (the early fits are extrapolations with huge coefficients): started
//! exactly from the first `n+1` samples, in the Legendre basis of the span, it was 4e-4 σ off
//! the least-squares fit at `N = 1000`, `n = 5`, 3e3 σ at `N = 10⁴` and 6e5 σ at `N = 1000`,
//! `n = 8` (ACCURACY.md, examples/accuracy_paml_online.rs). So the
//! smoother accumulates instead, in the basis `b_i` orthonormal for the segment's own measure
//! `Σ_k δ(t − t_k)/σ_k²`: the fit's coefficients are `⟨y, b_i⟩ = Σ_k (b_i(t_k)/σ_k²) y_k`
//! (eqs. 8-9), so each sample costs `n+1` multiplications and `n+1` additions with the
//! precomputed `b_i(t_k)/σ_k²` (Table I's storage halved), the result is the least-squares fit
//! itself whatever the order of magnitudes, and at the end the polynomial samples are
//! `Σ_i ⟨y, b_i⟩ b_i(t_j*)` with variances `1/λ_j`.

use super::samples::PolynomialSamples;
use crate::basis::{GaussRule, Jacobi};
use crate::error::{check_finite, Error, Param};
use std::ops::Deref;

/// The offline part of [`OnlineSmoother`] for one layout of sample times and noise: each
/// sample's `b_i(t_k)/σ_k²`, the segment's Gauss rule and `b_i` at its nodes. Shared by every
/// segment with that layout.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct SmootherGains {
    n: usize,
    /// `b_i(t_k)/σ_k²`, `(n+1)` a sample.
    weights: Vec<f64>,
    rule: GaussRule,
    /// `b_i(t_j*)`, row-major `(n+1) × (n+1)`.
    at_nodes: Vec<f64>,
}

impl SmootherGains {
    /// The layout of samples at `times` (strictly increasing, at least `n+1`) with noise
    /// standard deviations `sigmas`, degree `n` (at most [`MAX_DEGREE`](super::MAX_DEGREE)).
    pub fn new(times: &[f64], sigmas: &[f64], n: usize) -> Result<Self, Error> {
        if sigmas.len() != times.len() {
            return Err(Error::InvalidParameter {
                name: Param::Sigmas,
                value: sigmas.len().to_string(),
                reason: format!("one per time ({} times)", times.len()),
            });
        }
        check_finite("time", times)?;
        if let Some(j) = (1..times.len()).find(|&j| times[j] <= times[j - 1]) {
            return Err(Error::InBatch {
                index: j,
                source: Box::new(Error::TimeNotIncreasing {
                    time: times[j],
                    previous: times[j - 1],
                }),
            });
        }
        Self::layout(times, sigmas, n)
    }

    /// [`new`](Self::new) for times in any order (the order `push` follows).
    pub(super) fn layout(times: &[f64], sigmas: &[f64], n: usize) -> Result<Self, Error> {
        super::check_degree(n)?;
        if let Some((j, &s)) = sigmas
            .iter()
            .enumerate()
            .find(|(_, &s)| !crate::model::measurement::is_usable_sigma(s))
        {
            return Err(Error::InvalidParameter {
                name: Param::Sigmas,
                value: s.to_string(),
                reason: format!("sample {j}: a noise sigma must be above 0 with a normal square"),
            });
        }
        let w: Vec<f64> = sigmas.iter().map(|s| 1.0 / (s * s)).collect();
        let jacobi = Jacobi::discrete(times, &w, n)?;
        let rule = GaussRule::new(&jacobi)?;
        let mut weights = Vec::with_capacity(times.len() * (n + 1));
        for (&t, &w) in times.iter().zip(&w) {
            let b = jacobi.orthonormal_at_offset(t - jacobi.centre);
            weights.extend(b.iter().map(|b| b * w));
        }
        check_finite("weight", &weights)?;
        let at_nodes = rule
            .offsets
            .iter()
            .flat_map(|&o| jacobi.orthonormal_at_offset(o))
            .collect();
        Ok(Self {
            n,
            weights,
            rule,
            at_nodes,
        })
    }

    /// The samples in the layout.
    pub fn len(&self) -> usize {
        self.weights.len() / (self.n + 1)
    }

    /// Never: a layout has at least `n+1` samples.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// A smoother for one segment of this layout, borrowing it.
    pub fn smoother(&self) -> OnlineSmoother<&Self> {
        OnlineSmoother::new(self)
    }
}

/// One segment smoothed online ([`SmootherGains::smoother`]): [`push`](Self::push) each sample
/// in the layout's order.
///
/// ```
/// use seqsmooth::paml::{PolynomialSamples, SmootherGains};
/// let t: Vec<f64> = (0..50).map(|k| k as f64 * 0.1).collect();
/// let y: Vec<f64> = t.iter().map(|t| (2.0 * t).sin()).collect();
/// let gains = SmootherGains::new(&t, &[0.1; 50], 3)?;
/// let mut s = gains.smoother();
/// for &y in &y {
///     s.push(y)?;
/// }
/// let online = s.polynomial_samples()?;
/// let batch = PolynomialSamples::from_segment(&t, &y, &[0.1; 50], 3)?;
/// for (a, b) in online.values.iter().zip(&batch.values) {
///     assert!((a - b).abs() < 1e-12);
/// }
/// # Ok::<(), seqsmooth::Error>(())
/// ```
///
/// It holds its layout by any pointer: borrowed (`&SmootherGains`, as
/// [`SmootherGains::smoother`] gives), or shared (`Arc<SmootherGains>`, for a smoother that
/// outlives the scope of its layout):
///
/// ```
/// use std::sync::Arc;
/// use seqsmooth::paml::{OnlineSmoother, SmootherGains};
/// let gains = Arc::new(SmootherGains::new(&[0.0, 1.0, 2.0], &[1.0; 3], 1)?);
/// let mut s = OnlineSmoother::new(Arc::clone(&gains));
/// s.push_all(&[1.0, 2.0, 3.0])?;
/// assert_eq!(s.taken(), 3);
/// # Ok::<(), seqsmooth::Error>(())
/// ```
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct OnlineSmoother<G: Deref<Target = SmootherGains>> {
    gains: G,
    taken: usize,
    /// `Σ_{k<taken} (b_i(t_k)/σ_k²) y_k`.
    coefficients: Vec<f64>,
}

impl<G: Deref<Target = SmootherGains>> OnlineSmoother<G> {
    /// A smoother for one segment of the layout `gains`, no sample taken.
    pub fn new(gains: G) -> Self {
        let size = gains.n + 1;
        Self {
            gains,
            taken: 0,
            coefficients: vec![0.0; size],
        }
    }

    /// The next sample's value (the layout gives its time and noise):
    /// `c_i ← c_i + (b_i(t_k)/σ_k²) y`, `n+1` multiplications and additions.
    pub fn push(&mut self, y: f64) -> Result<(), Error> {
        let g = &*self.gains;
        let size = g.n + 1;
        if !y.is_finite() {
            return Err(Error::NonFinite {
                what: "value",
                value: y,
            });
        }
        if self.taken >= g.len() {
            return Err(Error::InvalidParameter {
                name: Param::Segment,
                value: (self.taken + 1).to_string(),
                reason: format!("the layout has {} samples", g.len()),
            });
        }
        let w = &g.weights[self.taken * size..(self.taken + 1) * size];
        for (c, w) in self.coefficients.iter_mut().zip(w) {
            *c += w * y;
        }
        self.taken += 1;
        Ok(())
    }

    /// Every value of a segment at once, as [`push`](Self::push) on each (`values.len()` must
    /// be the layout's; nothing is taken on an error).
    pub fn push_all(&mut self, values: &[f64]) -> Result<(), Error> {
        let g = &*self.gains;
        if self.taken + values.len() > g.len() {
            return Err(Error::InvalidParameter {
                name: Param::Segment,
                value: (self.taken + values.len()).to_string(),
                reason: format!("the layout has {} samples", g.len()),
            });
        }
        check_finite("value", values)?;
        let size = g.n + 1;
        let w = &g.weights[self.taken * size..(self.taken + values.len()) * size];
        accumulate(&mut self.coefficients, w, values);
        self.taken += values.len();
        Ok(())
    }

    /// The layout it runs on.
    pub fn gains(&self) -> &G {
        &self.gains
    }

    /// The samples taken.
    pub fn taken(&self) -> usize {
        self.taken
    }

    /// The polynomial samples (eq. 37) once every sample of the layout is in: the smoothing
    /// polynomial `Σ_i c_i b_i` at the Gauss nodes of the layout's measure, with their
    /// variances.
    pub fn polynomial_samples(&self) -> Result<PolynomialSamples, Error> {
        let g = &*self.gains;
        if self.taken < g.len() {
            return Err(Error::TooFewSamples {
                needed: g.len(),
                got: self.taken,
            });
        }
        let size = g.n + 1;
        let values: Vec<f64> = g
            .at_nodes
            .chunks_exact(size)
            .map(|b| b.iter().zip(&self.coefficients).map(|(b, c)| b * c).sum())
            .collect();
        check_finite("polynomial sample", &values)?;
        Ok(PolynomialSamples {
            centre: g.rule.centre,
            offsets: g.rule.offsets.clone(),
            values,
            variances: g.rule.weights.iter().map(|l| 1.0 / l).collect(),
        })
    }
}

/// `c_i += Σ_k w_{k,i} y_k` for `(n+1)`-wide rows `w`, the degrees 0-7 unrolled so that the
/// coefficients stay in registers.
fn accumulate(c: &mut [f64], w: &[f64], y: &[f64]) {
    macro_rules! fixed {
        ($n:literal) => {{
            let mut acc = [0.0; $n];
            acc.copy_from_slice(c);
            for (row, &y) in w.chunks_exact($n).zip(y) {
                for i in 0..$n {
                    acc[i] += row[i] * y;
                }
            }
            c.copy_from_slice(&acc);
        }};
    }
    match c.len() {
        1 => fixed!(1),
        2 => fixed!(2),
        3 => fixed!(3),
        4 => fixed!(4),
        5 => fixed!(5),
        6 => fixed!(6),
        7 => fixed!(7),
        8 => fixed!(8),
        size => {
            for (row, &y) in w.chunks_exact(size).zip(y) {
                for (c, w) in c.iter_mut().zip(row) {
                    *c += w * y;
                }
            }
        }
    }
}

impl SmootherGains {
    /// Restored gains' invariants ([`crate::persist`]): `n + 1` weights a sample, the nodes'
    /// table `(n+1)²`, finite.
    pub(crate) fn check_saved(&self) -> Result<(), String> {
        let k = self.n + 1;
        if !self.weights.len().is_multiple_of(k) || self.at_nodes.len() != k * k {
            return Err("gains are not of their order".into());
        }
        crate::linalg::invariant::finite(&self.weights, "gains")?;
        crate::linalg::invariant::finite(&self.at_nodes, "gains at the nodes")
    }
}

impl<G: Deref<Target = SmootherGains>> OnlineSmoother<G> {
    /// A restored smoother's invariants ([`crate::persist`]): its gains', the samples taken
    /// at most the layout's, the sums of the order.
    pub(crate) fn check_saved(&self) -> Result<(), String> {
        self.gains.check_saved()?;
        if self.taken > self.gains.len() || self.coefficients.len() != self.gains.n + 1 {
            return Err("samples taken or sums do not fit the layout".into());
        }
        crate::linalg::invariant::finite(&self.coefficients, "sums")
    }
}
