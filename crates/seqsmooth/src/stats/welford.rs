//! Welford's running mean and variance (Knuth TAOCP vol. 2 §4.2.2, citing Welford 1962; the
//! on-the-fly alternative Reyneke et al. §7.1 name).

use crate::error::Error;

/// Running mean and variance in one pass, numerically stable:
/// `δ = x − μ_{n−1}`, `μ_n = μ_{n−1} + δ/n`, `M_n = M_{n−1} + δ (x − μ_n)`; the sample variance
/// is `M_n/(n−1)`.
///
/// ```
/// use seqsmooth::stats::Welford;
/// let mut w = Welford::new();
/// for x in [1e9 + 4.0, 1e9 + 7.0, 1e9 + 13.0, 1e9 + 16.0] {
///     w.push(x).unwrap();
/// }
/// assert_eq!(w.mean(), Some(1e9 + 10.0));
/// assert_eq!(w.sample_variance(), Some(30.0)); // no cancellation despite the offset
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Welford {
    n: u64,
    mean: f64,
    m2: f64,
}

impl Welford {
    /// An empty accumulator.
    ///
    /// ```
    /// use seqsmooth::stats::Welford;
    /// assert_eq!(Welford::new().count(), 0);
    /// ```
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a finite value (a non-finite one is refused and leaves the state unchanged).
    ///
    /// ```
    /// use seqsmooth::stats::Welford;
    /// let mut w = Welford::new();
    /// w.push(2.0).unwrap();
    /// assert!(w.push(f64::NAN).is_err());
    /// assert_eq!(w.count(), 1);
    /// ```
    pub fn push(&mut self, x: f64) -> Result<(), Error> {
        if !x.is_finite() {
            return Err(Error::NonFinite {
                what: "value",
                value: x,
            });
        }
        self.n += 1;
        let delta = x - self.mean;
        self.mean += delta / self.n as f64;
        self.m2 += delta * (x - self.mean);
        Ok(())
    }

    /// Combines two accumulators (Chan et al.'s parallel update).
    ///
    /// ```
    /// use seqsmooth::stats::Welford;
    /// let (mut a, mut b, mut all) = (Welford::new(), Welford::new(), Welford::new());
    /// for k in 0..10 { let x = (k * k) as f64; a.push(x).unwrap(); all.push(x).unwrap(); }
    /// for k in 10..25 { let x = (k * k) as f64; b.push(x).unwrap(); all.push(x).unwrap(); }
    /// a.merge(&b);
    /// assert!((a.sample_variance().unwrap() - all.sample_variance().unwrap()).abs() < 1e-9);
    /// ```
    pub fn merge(&mut self, other: &Welford) {
        if other.n == 0 {
            return;
        }
        if self.n == 0 {
            *self = *other;
            return;
        }
        let n = self.n + other.n;
        let delta = other.mean - self.mean;
        let mean = self.mean + delta * other.n as f64 / n as f64;
        self.m2 += other.m2 + delta * delta * self.n as f64 * other.n as f64 / n as f64;
        self.mean = mean;
        self.n = n;
    }

    /// Number of values.
    ///
    /// ```
    /// use seqsmooth::stats::Welford;
    /// let mut w = Welford::new();
    /// for x in [1.0, 2.0, 3.0] { w.push(x).unwrap(); }
    /// assert_eq!(w.count(), 3);
    /// ```
    pub fn count(&self) -> u64 {
        self.n
    }

    /// The mean, once a value is in.
    ///
    /// ```
    /// use seqsmooth::stats::Welford;
    /// let mut w = Welford::new();
    /// assert_eq!(w.mean(), None);
    /// for x in [1.0, 2.0, 6.0] { w.push(x).unwrap(); }
    /// assert_eq!(w.mean(), Some(3.0));
    /// ```
    pub fn mean(&self) -> Option<f64> {
        (self.n > 0).then_some(self.mean)
    }

    /// The unbiased sample variance `M_n/(n−1)`, from two values on.
    ///
    /// ```
    /// use seqsmooth::stats::Welford;
    /// let mut w = Welford::new();
    /// w.push(1.0).unwrap();
    /// assert_eq!(w.sample_variance(), None);
    /// w.push(3.0).unwrap();
    /// assert_eq!(w.sample_variance(), Some(2.0));
    /// ```
    pub fn sample_variance(&self) -> Option<f64> {
        (self.n > 1).then(|| self.m2 / (self.n - 1) as f64)
    }

    /// The population variance `M_n/n` (the maximum-likelihood value), once a value is in.
    ///
    /// ```
    /// use seqsmooth::stats::Welford;
    /// let mut w = Welford::new();
    /// for x in [1.0, 3.0] { w.push(x).unwrap(); }
    /// assert_eq!(w.population_variance(), Some(1.0));
    /// ```
    pub fn population_variance(&self) -> Option<f64> {
        (self.n > 0).then(|| self.m2 / self.n as f64)
    }

    /// `√sample_variance`.
    ///
    /// ```
    /// use seqsmooth::stats::Welford;
    /// let mut w = Welford::new();
    /// for x in [1.0, 3.0] { w.push(x).unwrap(); }
    /// assert_eq!(w.sample_std_dev(), Some(2f64.sqrt()));
    /// ```
    pub fn sample_std_dev(&self) -> Option<f64> {
        self.sample_variance().map(f64::sqrt)
    }
}
