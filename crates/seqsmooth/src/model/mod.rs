//! Process models (Morrison ch. 4): the polynomial model's state conventions, scaling and
//! transition matrices (Reyneke et al. §4), and constant-coefficient linear dynamics.
//!
//! For a degree-`m` process `x(t)` three state vectors appear in the sources:
//!
//! | name | components `k = 0..m` | transition over `h` steps of `τ` |
//! |---|---|---|
//! | unscaled `X` | `x^(k)(t)` (the public API) | `Φ_X(hτ)`, `[Φ_X(ζ)]_ij = ζ^(j-i)/(j-i)!` (4.2.5) |
//! | Morrison's scaled `Z` | `z_k = τ^k x^(k)/k!` | [`phi`]: `[Φ(h)]_ij = C(j,i) h^(j-i)` (4.2.15) |
//! | Reyneke's `Ψ` state | `d_k = τ^k x^(k) = k! z_k` | [`psi`]: `[Ψ(ζ)]_ij = ζ^(j-i)/(j-i)!` (eq. 7) |
//!
//! `X = D(τ) Z` with `D(τ) = diag(k!/τ^k)` ([`scaling`], (4.2.18)). Gains convert as
//! `Γ_Ψ[k] = k! Γ_Φ[k]` (derivative index `k`; Reyneke et al. §4 against Morrison (4.2.14)).
//!
//! - [`transition`]: the matrices `Φ(h)` and `Ψ(ζ)`.
//! - [`taylor`]: `Φ(h) z` as an in-place Taylor shift (plain and compensated) and `D(τ)`.
//! - [`state`]: [`PolynomialState`], the public estimate with its propagation.
//! - [`dynamics`]: the [`dynamics::Dynamics`] trait (the state at any time from any other, with
//!   `Φ(t_b, t_a)`) and [`dynamics::PolynomialDynamics`] (degree `m` on `d` axes, through [`psi`]).
//! - [`linear`]: constant-coefficient linear dynamics `dX/dt = A X`, `Φ(ζ) = e^{ζA}` (§4.6).
//! - [`continuous`]: `dX/dt = A X + w` with white noise of spectral density `Q_c`, discretised
//!   exactly on each step (`e^{Aζ}` and Van Loan's `Q(ζ)`, (15.2.23)); the polynomial, nearly
//!   constant velocity and acceleration, and Singer models.
//! - [`coordinated_turn`]: the coordinated turn in the horizontal plane, known or estimated
//!   turn rate, in closed form with its analytic `Φ` and driving noise `Q(ζ)`.
//! - [`nonlinear`]: `dX/dt = F(X, t)` and `dX/dt = A(t) X` with `Φ` from the variational
//!   equations (§4.7, §8.6), integrated by an embedded Runge–Kutta 8(5,3) pair.
//! - [`observation`]: the [`observation::Observation`] trait `Y = G(X, t) + N`, `M = ∂G/∂X`,
//!   linear and nonlinear (§8.2, §8.6).
//! - [`radar`]: range, azimuth, elevation (and range rate) from a site; polar to Cartesian
//!   with covariance; the nominal state of §8.5.

pub mod continuous;
pub mod coordinated_turn;
pub mod dynamics;
pub mod linear;
pub mod measurement;
pub mod nonlinear;
pub mod observation;
pub mod radar;
pub mod state;
pub mod taylor;
pub mod transition;

pub use state::PolynomialState;
pub(crate) use taylor::{
    derivative_scale, factorial_powers, for_each_shift_step, shift_scaled_array,
};
pub use taylor::{
    derivatives_to_scaled, scaled_to_derivatives, scaling, shift_scaled, shift_scaled_compensated,
};
pub use transition::{phi, psi};
