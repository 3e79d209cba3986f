//! [`SlidingSum`]: the sum of the last `K` values of a stream (or of all of them), the running
//! statistic behind the windowed innovation test and the windowed difference noise estimate.

use std::collections::VecDeque;

/// A sum over the last `window` values pushed, or over all of them with `None`. The windowed
/// sum is updated as `(s − x_old) + x_new` and re-added from scratch every `4·window` pushes, so
/// that its rounding cannot drift, and kept `≥ 0` (the values summed are squares).
#[derive(Debug, serde::Serialize, serde::Deserialize)]
pub(crate) struct SlidingSum {
    window: Option<usize>,
    values: VecDeque<f64>,
    sum: f64,
    count: u64,
    pushes_since_resum: usize,
}

// Field by field, `clone_from` too (the automatic filter's review keeps copies of it).
field_clone!(SlidingSum {
    window,
    values,
    sum,
    count,
    pushes_since_resum
});

impl SlidingSum {
    /// An empty sum over windows of `window ≥ 1` values, or over all values.
    pub(crate) fn new(window: Option<usize>) -> Self {
        Self {
            window,
            values: VecDeque::with_capacity(window.unwrap_or(0)),
            sum: 0.0,
            count: 0,
            pushes_since_resum: 0,
        }
    }

    /// Adds `x` (the oldest value leaves a full window).
    pub(crate) fn push(&mut self, x: f64) {
        self.count += 1;
        match self.window {
            None => self.sum += x,
            Some(w) => {
                if self.values.len() == w {
                    let old = self.values.pop_front().unwrap_or(0.0);
                    self.sum -= old;
                }
                self.values.push_back(x);
                self.sum += x;
                self.pushes_since_resum += 1;
                // Re-add from scratch now and then, so the running sum cannot drift.
                if self.pushes_since_resum >= 4 * w {
                    self.sum = self.values.iter().sum();
                    self.pushes_since_resum = 0;
                }
                self.sum = self.sum.max(0.0);
            }
        }
    }

    /// The sum of the values in the window.
    pub(crate) fn sum(&self) -> f64 {
        self.sum
    }

    /// The number of values in the window (all values pushed, without a window).
    pub(crate) fn len(&self) -> usize {
        match self.window {
            None => self.count as usize,
            Some(_) => self.values.len(),
        }
    }

    /// True when no value is in the window.
    pub(crate) fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Empties the sum.
    pub(crate) fn clear(&mut self) {
        self.values.clear();
        self.sum = 0.0;
        self.count = 0;
        self.pushes_since_resum = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::SlidingSum;

    /// Against direct sums over the last `w` values, across several re-summings.
    #[test]
    fn sliding_sum_equals_the_sum_of_the_window() {
        let xs: Vec<f64> = (0..100).map(|k| ((k * 17 % 11) as f64) * 0.1).collect();
        for w in [1, 3, 8] {
            let mut s = SlidingSum::new(Some(w));
            let mut all = SlidingSum::new(None);
            for (k, &x) in xs.iter().enumerate() {
                s.push(x);
                all.push(x);
                let lo = (k + 1).saturating_sub(w);
                assert!((s.sum() - xs[lo..=k].iter().sum::<f64>()).abs() < 1e-12);
                assert_eq!(s.len(), k + 1 - lo);
                assert_eq!(all.len(), k + 1);
                assert!((all.sum() - xs[..=k].iter().sum::<f64>()).abs() < 1e-12);
            }
            s.clear();
            assert_eq!((s.len(), s.sum()), (0, 0.0));
        }
    }
}
