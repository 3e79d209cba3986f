//! [`InlineVec`]: a vector of `Copy` values kept in place up to `N` of them, on the heap beyond;
//! a copy of a small one allocates nothing. The factors of the polynomial filters of low degree
//! (`m + 1 ≤ 5`) are copied whole where the automatic filter keeps its state to go back to, so
//! their storage is inline.

use std::ops::{Deref, DerefMut};

/// Up to `N` values inline, more on the heap; reads and writes as a slice (crate-internal: its
/// checks are the unit tests below).
#[derive(Debug)]
pub(crate) struct InlineVec<T: Copy, const N: usize> {
    len: usize,
    inline: [T; N],
    /// The values when there are more than `N` (empty otherwise: a copy allocates nothing).
    heap: Vec<T>,
}

impl<T: Copy, const N: usize> InlineVec<T, N> {
    /// `len` copies of `value`.
    pub(crate) fn filled(value: T, len: usize) -> Self {
        let mut v = Self {
            len: 0,
            inline: [value; N],
            heap: Vec::new(),
        };
        v.refill(value, len);
        v
    }

    /// `len` copies of `value`, keeping the storage.
    pub(crate) fn refill(&mut self, value: T, len: usize) {
        self.len = len;
        self.heap.clear();
        if len <= N {
            self.inline[..len].fill(value);
        } else {
            self.heap.resize(len, value);
        }
    }
}

/// A copy; `clone_from` copies only the values in use (the first `len` inline, or the heap's
/// into its buffer): the inline slots beyond `len` are never read.
impl<T: Copy, const N: usize> Clone for InlineVec<T, N> {
    fn clone(&self) -> Self {
        Self {
            len: self.len,
            inline: self.inline,
            heap: self.heap.clone(),
        }
    }

    fn clone_from(&mut self, source: &Self) {
        self.len = source.len;
        if source.len <= N {
            self.inline[..source.len].copy_from_slice(&source.inline[..source.len]);
        }
        self.heap.clone_from(&source.heap);
    }
}

/// Saved as its values (a sequence), whichever the storage ([`crate::persist`]).
impl<T: Copy + serde::Serialize, const N: usize> serde::Serialize for InlineVec<T, N> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(self.iter())
    }
}

impl<'de, T: Copy + Default + serde::Deserialize<'de>, const N: usize> serde::Deserialize<'de>
    for InlineVec<T, N>
{
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let values = Vec::<T>::deserialize(d)?;
        let mut v = Self::filled(T::default(), values.len());
        v.copy_from_slice(&values);
        Ok(v)
    }
}

impl<T: Copy, const N: usize> Deref for InlineVec<T, N> {
    type Target = [T];

    #[inline(always)]
    fn deref(&self) -> &[T] {
        if self.len <= N {
            &self.inline[..self.len]
        } else {
            &self.heap
        }
    }
}

impl<T: Copy, const N: usize> DerefMut for InlineVec<T, N> {
    #[inline(always)]
    fn deref_mut(&mut self) -> &mut [T] {
        if self.len <= N {
            &mut self.inline[..self.len]
        } else {
            &mut self.heap
        }
    }
}

impl<'a, T: Copy, const N: usize> IntoIterator for &'a InlineVec<T, N> {
    type Item = &'a T;
    type IntoIter = std::slice::Iter<'a, T>;

    fn into_iter(self) -> Self::IntoIter {
        self.iter()
    }
}

#[cfg(test)]
mod tests {
    use super::InlineVec;

    #[test]
    fn inline_and_heap_read_and_write_as_slices() {
        let mut small = InlineVec::<f64, 4>::filled(0.0, 3);
        small[2] = 1.0;
        assert_eq!(&small[..], &[0.0, 0.0, 1.0]);
        let copy = small.clone();
        assert_eq!(copy.heap.capacity(), 0); // nothing allocated
        let mut big = InlineVec::<f64, 4>::filled(2.0, 6);
        big[5] = 3.0;
        assert_eq!(&big[..], &[2.0, 2.0, 2.0, 2.0, 2.0, 3.0]);
        big.refill(1.0, 2); // back inline
        assert_eq!(&big[..], &[1.0, 1.0]);
        small.refill(0.5, 5); // onto the heap
        assert_eq!(small.len(), 5);
        assert!(small.iter().all(|&v| v == 0.5));
    }

    #[test]
    fn clone_from_takes_the_values_either_way() {
        let mut to = InlineVec::<f64, 4>::filled(9.0, 4);
        let mut big = InlineVec::<f64, 4>::filled(2.0, 6);
        big[5] = 3.0;
        to.clone_from(&big); // inline → heap
        assert_eq!(&to[..], &big[..]);
        let mut small = InlineVec::<f64, 4>::filled(1.0, 2);
        small[1] = 4.0;
        to.clone_from(&small); // heap → inline: the heap emptied, the first two taken
        assert_eq!(&to[..], &[1.0, 4.0]);
        assert!(to.heap.is_empty());
        to.clone_from(&big);
        let capacity = to.heap.capacity();
        to.clone_from(&big); // heap → heap: its buffer reused
        assert_eq!((&to[..], to.heap.capacity()), (&big[..], capacity));
    }
}
