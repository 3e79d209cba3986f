//! Which filter gives the output ([`Phase`]); the expanding → fading-memory switch of the final
//! degree (Morrison §13.8, (13.8.8)) is the adaptive memory's ([`super::memory`]).

/// Which filter produced an output.
///
/// ```
/// use seqsmooth::polynomial::automatic::{AutomaticFilter, Phase};
/// let mut f = AutomaticFilter::new(1, 0.8, 1.0).unwrap().with_noise_sigma(1.0).unwrap();
/// let phases: Vec<Phase> = (0..30).map(|n| f.update(n as f64, 2.0 * n as f64).unwrap().phase).collect();
/// assert_eq!(phases[0], Phase::Settling);            // degree 0 first
/// assert_eq!(phases[29], Phase::Fading);             // switched at ⌊3.2/0.2⌋ = 16
/// assert_eq!(f.switched_at(), Some(16));
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Phase {
    /// A lower degree of the quick-settling ladder (expanding memory).
    Settling,
    /// The final degree, expanding memory (before the switch).
    Expanding,
    /// The final degree, fading memory (the configured `θ` after the switch, or a shorter
    /// memory `θ^(4^j)`, see [`AutomaticFilter::memory`](super::AutomaticFilter::memory)).
    Fading,
}
