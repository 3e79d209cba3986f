//! Orthogonal polynomial bases (Morrison ch. 3, Appendix I; Reyneke et al. §5).
//!
//! - [`DiscreteLegendre`]: `p(x; j, L)`, orthogonal with unit weight on `x = 0..L`; the basis of
//!   the fixed- and expanding-memory filters (Morrison ch. 7, 9).
//! - [`DiscreteLaguerre`]: `p(x; j, θ)`, orthogonal with weight `θ^x` on `x = 0, 1, …`; the basis
//!   of the fading-memory filter (Morrison ch. 13).
//! - [`legendre`]: the classical Legendre polynomials on `[-1, 1]` with derivatives of any order,
//!   the well-conditioned basis of the batch least-squares fits on arbitrary timestamps.

mod discrete_laguerre;
mod discrete_legendre;
pub mod legendre;

pub use discrete_laguerre::DiscreteLaguerre;
pub use discrete_legendre::DiscreteLegendre;
