//! Orthogonal polynomial bases (Morrison ch. 3, Appendix I; Reyneke et al. §5).
//!
//! - [`DiscreteLegendre`]: `p(x; j, L)`, orthogonal with unit weight on `x = 0..L`; the basis of
//!   the fixed- and expanding-memory filters (Morrison ch. 7, 9).
//! - [`DiscreteLaguerre`]: `p(x; j, θ)`, orthogonal with weight `θ^x` on `x = 0, 1, …`; the basis
//!   of the fading-memory filter (Morrison ch. 13).
//! - [`legendre`]: the classical Legendre polynomials on `[-1, 1]` with derivatives of any order,
//!   the well-conditioned basis of the batch least-squares fits on arbitrary timestamps.
//! - [`Jacobi`]: the polynomials orthonormal for any positive measure — a weight function on an
//!   interval or weighted sample times — by their three-term recurrence (Villien & Ostertag
//!   2009, eqs. 5-9); [`GaussRule`]: its Gauss nodes and Christoffel numbers by Golub–Welsch
//!   (their Lemmas 1 and 3, eqs. 21, 26), the sampling instants of polynomial samples.

mod discrete_laguerre;
mod discrete_legendre;
mod gauss;
mod jacobi;
pub mod legendre;

pub use discrete_laguerre::DiscreteLaguerre;
pub use discrete_legendre::DiscreteLegendre;
pub use gauss::GaussRule;
pub use jacobi::{check_jacobi_degree, Jacobi, Weight, MAX_JACOBI_DEGREE};
