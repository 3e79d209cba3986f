//! The window's samples: a ring buffer of the newest `capacity` values, oldest first.

/// The newest `capacity` values pushed, in arrival order.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub(super) struct Ring<T> {
    buf: Vec<T>,
    head: usize,
    capacity: usize,
}

impl<T: Copy> Ring<T> {
    /// An empty ring holding at most `capacity ≥ 1` values (memory is reserved as it fills).
    pub(super) fn new(capacity: usize) -> Self {
        Self {
            buf: Vec::with_capacity(capacity.min(1 << 16)),
            head: 0,
            capacity,
        }
    }

    /// Appends `v`; returns the value it displaces once the ring is full.
    pub(super) fn push(&mut self, v: T) -> Option<T> {
        if self.buf.len() < self.capacity {
            self.buf.push(v);
            return None;
        }
        let old = std::mem::replace(&mut self.buf[self.head], v);
        self.head += 1;
        if self.head == self.capacity {
            self.head = 0;
        }
        Some(old)
    }

    pub(super) fn is_full(&self) -> bool {
        self.buf.len() == self.capacity
    }

    /// The values, oldest first.
    pub(super) fn iter(&self) -> impl Iterator<Item = &T> {
        let (newer, older) = self.buf.split_at(self.head);
        older.iter().chain(newer)
    }

    /// The `i`-th value, oldest first (`i` below the number held).
    pub(super) fn get(&self, i: usize) -> T {
        // While filling, `head` is 0; once full, the oldest is at `head`.
        let k = self.head + i;
        self.buf[if k >= self.capacity {
            k - self.capacity
        } else {
            k
        }]
    }
}

impl<T> Ring<T> {
    /// A restored ring's invariants ([`crate::persist`]): `capacity` as given, at most that
    /// many values, the head inside them.
    pub(super) fn check_saved(&self, capacity: usize) -> bool {
        self.capacity == capacity
            && self.buf.len() <= capacity
            && (self.head == 0 || self.head < self.buf.len())
    }
}
