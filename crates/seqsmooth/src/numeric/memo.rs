//! A process-wide memo for constants that depend only on a small key (a degree, a discount)
//! and cost exact rational arithmetic to derive — the expanding-memory gain numerators
//! (Morrison Table 9.1), the fading-memory gains at `θ` (Table 13.1), the switch constants
//! (Table 13.4), the sliding fixed-memory engine's shift matrix. Every filter built with the
//! same key shares one copy, so that a bank of filters, or the automatic filter restarting its
//! memory, pays for them once.
//!
//! The value is computed outside the lock (two threads asking for a new key at once may both
//! compute it; the first stored wins). The memo holds at most [`CAPACITY`] keys and is emptied
//! when full, so that a caller sweeping many discounts cannot grow it without bound.

use std::collections::HashMap;
use std::hash::Hash;
use std::sync::{Arc, Mutex, OnceLock};

/// The most keys a memo holds before it is emptied.
pub(crate) const CAPACITY: usize = 256;

pub(crate) struct Memo<K, V> {
    map: OnceLock<Mutex<HashMap<K, Arc<V>>>>,
}

impl<K: Eq + Hash + Copy, V> Memo<K, V> {
    pub(crate) const fn new() -> Self {
        Self {
            map: OnceLock::new(),
        }
    }

    /// The value for `key`, computed by `make` the first time it is asked for.
    pub(crate) fn get(&self, key: K, make: impl FnOnce() -> V) -> Arc<V> {
        let map = self.map.get_or_init(|| Mutex::new(HashMap::new()));
        // A panic while the lock is held cannot leave the map half-updated (insert is the
        // only mutation), so a poisoned lock is still safe to use.
        let lock = || map.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        if let Some(v) = lock().get(&key) {
            return Arc::clone(v);
        }
        let value = Arc::new(make());
        let mut map = lock();
        if map.len() >= CAPACITY {
            map.clear();
        }
        Arc::clone(map.entry(key).or_insert(value))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicUsize, Ordering};

    #[test]
    fn computes_once_per_key_and_stays_bounded() {
        static MEMO: Memo<usize, usize> = Memo::new();
        static CALLS: AtomicUsize = AtomicUsize::new(0);
        let make = |k: usize| {
            move || {
                CALLS.fetch_add(1, Ordering::Relaxed);
                k * k
            }
        };
        assert_eq!(*MEMO.get(3, make(3)), 9);
        assert_eq!(*MEMO.get(3, make(3)), 9);
        assert_eq!(CALLS.load(Ordering::Relaxed), 1);
        for k in 0..3 * CAPACITY {
            assert_eq!(*MEMO.get(k, make(k)), k * k);
        }
        let len = MEMO.map.get().unwrap().lock().unwrap().len();
        assert!((1..=CAPACITY).contains(&len), "{len}");
    }
}
