//! The steady state of the fading-memory filter (Morrison §14.7) for a constant-coefficient
//! model observed at a constant interval with constant `M` and `R`:
//!
//! `Z = β Φ⁻ᵀ Z Φ⁻¹ + G`, `G = Mᵀ R⁻¹ M` (14.7.9), (14.7.56),
//!
//! the limit of the information `Z_n = P_{n,n}⁻¹` for `0 < β < 1` whatever the start (Lemma
//! 14.5; `β` is the discount over one interval, `θ` for a count-based filter). It is solved here
//! as the linear system `(I − β Φ⁻ᵀ ⊗ Φ⁻ᵀ) vec Z = vec G` (the Sylvester form (14.7.61)) by LU
//! with partial pivoting, `O(n⁶)`: for the small states of tracking models. Its conditioning
//! grows with the polynomial degree (ACCURACY.md: the covariance to 2.6e-12 at degree 4,
//! 1.2e-9 at degree 6). The eigenvalues of
//! `β Φ⁻ᵀ ⊗ Φ⁻ᵀ` are `β/(λ_i λ_j)`, of modulus `β < 1` when those of `Φ` lie on the unit circle
//! (polynomial and Fourier models, the case of §14.7), so the system is then nonsingular and
//! the recursion converges to its solution. `Z` is nonsingular exactly when `M V ≠ 0` for every eigenvector
//! `V` of `Φ` (Lemma 14.6); then `P = Z⁻¹`, the gain `H = P Mᵀ R⁻¹` (14.4.29) and the true
//! covariance `S = P Z(β²) P` ((14.3.19) in the limit), `Z(β²)` the same equation at `β²`.

use crate::error::{Error, Param};
use nalgebra::{Cholesky, DMatrix};

/// The fading filter's limit.
#[derive(Clone, Debug, PartialEq)]
pub struct SteadyState {
    /// `Z_∞(β)`, the limit of the information `P_{n,n}⁻¹`.
    pub information: DMatrix<f64>,
    /// `P_∞ = Z_∞⁻¹` (not the covariance for `β < 1`).
    pub weight: DMatrix<f64>,
    /// The gain `H = P Mᵀ R⁻¹`.
    pub gain: DMatrix<f64>,
    /// The true covariance of the estimate, `S = P Z_∞(β²) P`.
    pub covariance: DMatrix<f64>,
}

/// The steady state for the one-interval transition `phi` (`n × n`, nonsingular), observation
/// `m` (`p × n`), noise `r` (`p × p`, positive definite) and discount `0 < β < 1` per interval.
///
/// ```
/// use nalgebra::DMatrix;
/// use seqsmooth::kalman::steady::steady_state;
/// // Degree 0 at θ = 0.5 (Table 13.1 and (13.6.x)): H = 1 − θ, S = (1 − θ)/(1 + θ).
/// let one = DMatrix::identity(1, 1);
/// let s = steady_state(&one, &one, &one, 0.5).unwrap();
/// assert!((s.gain[(0, 0)] - 0.5).abs() < 1e-15 && (s.covariance[(0, 0)] - 1.0 / 3.0).abs() < 1e-15);
/// ```
pub fn steady_state(
    phi: &DMatrix<f64>,
    m: &DMatrix<f64>,
    r: &DMatrix<f64>,
    beta: f64,
) -> Result<SteadyState, Error> {
    let n = phi.nrows();
    let bad = |name: Param, value: String, reason: &str| Error::InvalidParameter {
        name,
        value,
        reason: reason.into(),
    };
    if !(beta > 0.0 && beta < 1.0) {
        return Err(bad(
            Param::Beta,
            beta.to_string(),
            "the steady state needs 0 < β < 1 (at β = 1 the covariance goes to 0)",
        ));
    }
    if n == 0 || phi.ncols() != n || m.ncols() != n || r.shape() != (m.nrows(), m.nrows()) {
        return Err(bad(
            Param::Shapes,
            format!(
                "Φ {}x{}, M {}x{}, R {}x{}",
                phi.nrows(),
                phi.ncols(),
                m.nrows(),
                m.ncols(),
                r.nrows(),
                r.ncols()
            ),
            "Φ must be n x n, M p x n and R p x p",
        ));
    }
    if let Some(&value) = phi
        .iter()
        .chain(m.iter())
        .chain(r.iter())
        .find(|v| !v.is_finite())
    {
        return Err(Error::NonFinite {
            what: "Φ, M or R entry",
            value,
        });
    }
    let r_chol = Cholesky::new(r.clone()).ok_or_else(|| {
        bad(
            Param::R,
            format!("{r:?}"),
            "must be symmetric positive definite",
        )
    })?;
    let phi_inv = phi
        .clone()
        .try_inverse()
        .ok_or_else(|| bad(Param::Phi, format!("{phi:?}"), "must be nonsingular"))?;
    let g = m.transpose() * r_chol.solve(m);
    let z = information(&phi_inv, &g, beta)?;
    let z2 = information(&phi_inv, &g, beta * beta)?;
    let weight = match Cholesky::new(z.clone()) {
        Some(c) => c.inverse(),
        None => {
            let sv = crate::linalg::singular_values(&z)?;
            return Err(Error::Unobservable {
                rank: sv
                    .iter()
                    .filter(|&&v| v > 1e-12 * z.amax().max(f64::MIN_POSITIVE))
                    .count(),
                states: n,
                smallest_singular_value: sv.min(),
                largest_singular_value: sv.max(),
            });
        }
    };
    let weight = (&weight + weight.transpose()) * 0.5;
    let gain = &weight * m.transpose() * r_chol.inverse();
    let covariance = &weight * z2 * &weight;
    let covariance = (&covariance + covariance.transpose()) * 0.5;
    if let Some(&value) = weight
        .iter()
        .chain(covariance.iter())
        .find(|v| !v.is_finite())
    {
        return Err(Error::NonFinite {
            what: "steady-state matrix entry",
            value,
        });
    }
    Ok(SteadyState {
        information: z,
        weight,
        gain,
        covariance,
    })
}

/// `Z` from `(I − β Φ⁻ᵀ ⊗ Φ⁻ᵀ) vec Z = vec G` (column-major `vec`: `vec(A Z B) = (Bᵀ ⊗ A) vec Z`
/// with `A = Φ⁻ᵀ`, `B = Φ⁻¹`).
fn information(phi_inv: &DMatrix<f64>, g: &DMatrix<f64>, beta: f64) -> Result<DMatrix<f64>, Error> {
    let n = phi_inv.nrows();
    let a = phi_inv.transpose();
    let kron = phi_inv.transpose().kronecker(&a);
    let system = DMatrix::identity(n * n, n * n) - kron * beta;
    let rhs = DMatrix::from_column_slice(n * n, 1, g.as_slice());
    let vec_z = system
        .lu()
        .solve(&rhs)
        .ok_or_else(|| Error::InvalidParameter {
            name: Param::Phi,
            value: format!("{phi_inv:?} (inverse)"),
            reason: "the steady-state equation is singular: an eigenvalue of Φ lies inside the \
                 disc of radius β^(1/2) (§14.7: no steady state)"
                .into(),
        })?;
    let z = DMatrix::from_column_slice(n, n, vec_z.as_slice());
    Ok((&z + z.transpose()) * 0.5)
}
