//! Recursive estimators built on one information-form (Bayes) recursion.
//!
//! [`InformationFilter`] is the square-root information filter: it holds the upper-triangular
//! factor `R` and vector `d` with `RᵀR = Σ_k w_k h_k h_kᵀ` and `Rᵀd = Σ_k w_k h_k y_k`, so that the
//! estimate solves `R x = d`. New observations are folded in by Givens rotations (the QR
//! factorisation of the stacked weighted observations, never the normal equations), in
//! Gentleman's square-root-free form `R = D^½ U` ([`TriangularFactor`]); a change of
//! state variables `x_old = A x_new` (a transition) multiplies `R` by `A`; a fading-memory
//! discount scales the accumulated information, and the estimate's true covariance under
//! fading is kept as a second factor. One recursion, two users: the exact expanding- and
//! fading-memory polynomial filters of [`crate::polynomial`] run it with the polynomial model
//! (state at a centre moved now and then), and [`crate::kalman::BayesFilter`] (Morrison ch.
//! 10, fading ch. 14) runs it with any linear model (state carried to each observation).

mod factor;
mod information;

pub use factor::TriangularFactor;
pub use information::InformationFilter;
