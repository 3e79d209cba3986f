//! `field_clone!`: `impl Clone` field by field, `clone_from` too, for the state the automatic
//! filter's review keeps and takes again ([`crate::polynomial::automatic`]): a copy taken into
//! an existing value reuses its buffers (`Vec::clone_from`, `VecDeque::clone_from`, the nested
//! types' own `clone_from`) instead of allocating new ones and dropping the old.

/// `impl Clone` for a struct of the named fields (every one: the destructuring fails to
/// compile otherwise), with `clone_from` field by field, so that a copy taken again into an
/// existing value reuses its buffers (`Vec::clone_from`) instead of allocating new ones.
macro_rules! field_clone {
    ($t:ident { $($f:ident),* $(,)? }) => {
        impl Clone for $t {
            fn clone(&self) -> Self {
                let Self { $($f),* } = self;
                Self { $($f: $f.clone()),* }
            }
            fn clone_from(&mut self, source: &Self) {
                let Self { $($f),* } = source;
                $(self.$f.clone_from($f);)*
            }
        }
    };
}
