//! Expanding memory (Morrison ch. 9; Reyneke et al. §6.3-6.4): the least-squares polynomial
//! through every sample so far.
//!
//! | concept | where | source |
//! |---|---|---|
//! | the filter | [`ExpandingMemory`] | Morrison §9.3-9.6 |
//! | gains `h_k(n)` | [`gains`] | Morrison Table 9.1, (9.4.28)-(9.4.30); Reyneke §6.4 |
//! | variance reduction | [`vrf`] | Morrison (9.7.2)-(9.7.4), Table 9.2 |
//! | continuous time | [`continuous`] | Luenberger (1967): `a_i' = (b_i/T^i) ε(T)`, `b = H⁻¹·1` |

pub mod continuous;
mod filter;
pub mod gains;
pub mod vrf;

pub use filter::ExpandingMemory;
