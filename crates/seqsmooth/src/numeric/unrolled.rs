//! The one dispatch from a run-time state size `p = m + 1` to code compiled for that size:
//! sizes `1 ..= UNROLLED_MAX_SIZE` (degrees `0 ..= 8`, the polynomial filters' common degrees)
//! get a constant `N` and fully unrolled loops; larger sizes take the general path. Every
//! size-specialised kernel (the information filter's factor, the exact engine's read-out, the
//! gain engine's batch kernels and block maps, the expanding-memory block fit, the Taylor
//! shift) goes through [`unrolled_sizes!`].

/// The largest state size `m + 1` with unrolled code.
pub(crate) const UNROLLED_MAX_SIZE: usize = 9;

/// `unrolled_sizes!(p, N => call, q => other)`: `call` with the constant `N` equal to the
/// size `p` for `p` in `1 ..= UNROLLED_MAX_SIZE`, `other` (with the size bound to the pattern
/// `q`) otherwise.
macro_rules! unrolled_sizes {
    ($p:expr, $n:ident => $call:expr, $q:pat => $other:expr) => {
        match $p {
            1 => $crate::numeric::unrolled::unrolled_sizes!(@at 1, $n, $call),
            2 => $crate::numeric::unrolled::unrolled_sizes!(@at 2, $n, $call),
            3 => $crate::numeric::unrolled::unrolled_sizes!(@at 3, $n, $call),
            4 => $crate::numeric::unrolled::unrolled_sizes!(@at 4, $n, $call),
            5 => $crate::numeric::unrolled::unrolled_sizes!(@at 5, $n, $call),
            6 => $crate::numeric::unrolled::unrolled_sizes!(@at 6, $n, $call),
            7 => $crate::numeric::unrolled::unrolled_sizes!(@at 7, $n, $call),
            8 => $crate::numeric::unrolled::unrolled_sizes!(@at 8, $n, $call),
            9 => $crate::numeric::unrolled::unrolled_sizes!(@at 9, $n, $call),
            $q => $other,
        }
    };
    (@at $v:literal, $n:ident, $call:expr) => {{
        const $n: usize = $v;
        $call
    }};
}
pub(crate) use unrolled_sizes;

/// `each_index!(p, k => { … })`: the block for `k = 0, 1, …, p − 1` in turn, `k` a constant
/// in each copy for `k < 9` (the sizes with unrolled kernels,
/// [`crate::numeric::unrolled`]) and a loop variable beyond: loops bounded by `k` inside then
/// have constant trip counts and unroll, which the compiler does not do for a triangle of
/// loops past a few hundred operations.
macro_rules! each_index {
    ($p:expr, $k:ident => $body:block) => {
        $crate::numeric::unrolled::each_index!(@each $p, $k, $body, 0 1 2 3 4 5 6 7 8);
        for $k in 9..$p $body
    };
    (@each $p:expr, $k:ident, $body:block, $($v:literal)*) => {
        $(
            if $v < $p {
                #[allow(non_upper_case_globals)]
                const $k: usize = $v;
                $body
            }
        )*
    };
}
pub(crate) use each_index;

/// A size known at compile time ([`Fixed`]) or only at run time ([`Any`]). A kernel generic
/// over it is one source, compiled once for each fixed size (its loops then have constant
/// trip counts and unroll, closures and all) and once for any size; the caller picks through
/// [`unrolled_sizes!`]: `unrolled_sizes!(n, N => kernel(Fixed::<N>, …), n => kernel(Any(n), …))`.
pub(crate) trait Size: Copy {
    /// The size.
    fn get(self) -> usize;
}

/// The size `N`, a constant.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Fixed<const N: usize>;

impl<const N: usize> Size for Fixed<N> {
    #[inline(always)]
    fn get(self) -> usize {
        N
    }
}

/// A size known only at run time.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Any(pub(crate) usize);

impl Size for Any {
    #[inline(always)]
    fn get(self) -> usize {
        self.0
    }
}

/// The size `N / D`, a constant (the degree's size `m + 1` of a polynomial state of `N`
/// entries on `D` axes), where `N / D` cannot be written as a constant parameter.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Quotient<const N: usize, const D: usize>;

impl<const N: usize, const D: usize> Size for Quotient<N, D> {
    #[inline(always)]
    fn get(self) -> usize {
        N / D
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fixed size is its constant; any size its value.
    #[test]
    fn sizes_report_themselves() {
        let got = unrolled_sizes!(4usize, N => Fixed::<N>.get(), n => Any(n).get());
        assert_eq!((got, Any(11).get()), (4, 11));
        assert_eq!(Quotient::<6, 2>.get(), 3);
    }

    /// Every size in range gets its own constant; the rest the general arm.
    #[test]
    fn dispatch_covers_the_range_once() {
        for p in 0..=UNROLLED_MAX_SIZE + 3 {
            let got = unrolled_sizes!(p, N => Some(N), _ => None);
            let want = (1..=UNROLLED_MAX_SIZE).contains(&p).then_some(p);
            assert_eq!(got, want);
        }
    }
}
