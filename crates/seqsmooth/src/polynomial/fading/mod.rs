//! Fading memory (Morrison ch. 13; Reyneke et al. §6.5-6.6): the polynomial minimising
//! `Σ_k θ^((t_n-t_k)/τ) (y_k - p(t_k))²`.
//!
//! | concept | where | source |
//! |---|---|---|
//! | the filter | [`FadingMemory`] | Morrison §13.4-13.5 |
//! | gains `h_k(θ)` | [`gains`] | Morrison Table 13.1, (13.5.28)-(13.5.30); Reyneke §6.6 |
//! | variance reduction | [`vrf`] | Morrison (13.6.4), Tables 13.2-13.3 |
//! | the expanding-to-fading switch | [`switch`] | Morrison §13.8, (13.8.8); Reyneke Table 1 |

mod filter;
pub mod gains;
pub mod switch;
pub mod vrf;

pub use filter::FadingMemory;
pub use switch::SwitchRule;
