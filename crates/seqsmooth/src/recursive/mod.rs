//! Recursive estimators built on one information-form (Bayes) recursion.
//!
//! [`InformationFilter`] is the square-root information filter: it holds the upper-triangular
//! factor `R` and vector `d` with `RᵀR = Σ_k w_k h_k h_kᵀ` and `Rᵀd = Σ_k w_k h_k y_k`, so that the
//! estimate solves `R x = d`. New observations are folded in by Givens rotations (the QR
//! factorisation of the stacked weighted observations, never the normal equations), in
//! Gentleman's square-root-free form `R = D^½ U` ([`TriangularFactor`]); a change of
//! state variables `x_old = A x_new` multiplies `R` by `A`; a fading-memory discount scales the
//! accumulated information. The exact expanding- and fading-memory polynomial filters of
//! [`crate::polynomial`] are its polynomial instance; the generalized (Bayes, Kalman, fading
//! Bayes) filters reuse it.

mod information;

pub use information::{InformationFilter, TriangularFactor};
