//! The Singer model's `Φ` and `Q` from `model::continuous` (Van Loan's block exponential by
//! scaling and squaring) against their closed forms on long steps (ACCURACY.md, "Continuous
//! models discretised exactly"): `Φ_aa = e^{−αζ}` (also nalgebra's `exp` through
//! `LinearDynamics`), the acceleration's variance `σ_m² (1 − e^{−2αζ})` and the velocity's
//! `q/(2α³) (4e^{−αζ} − 3 − e^{−2αζ} + 2αζ)`, `q = 2ασ_m²` (Singer 1970), relative errors.
//!
//! Run: `cargo run --release -p seqsmooth --example accuracy_continuous`

use seqsmooth::model::continuous::ContinuousModel;

fn main() {
    let rel = |got: f64, want: f64| ((got - want) / want).abs();
    for (alpha, zeta) in [(0.25, 100.0), (2.0, 12.5), (2.0, 100.0), (1.0, 700.0)] {
        let m = ContinuousModel::singer(1, alpha, 1.0).unwrap();
        let (phi, q) = m.discretise(zeta).unwrap();
        let az: f64 = alpha * zeta;
        let decay = (-az).exp();
        let q_acc = -(-2.0 * az).exp_m1();
        let q_vel = 2.0 * alpha / (2.0 * alpha.powi(3))
            * (4.0 * decay - 3.0 - (-2.0 * az).exp() + 2.0 * az);
        println!(
            "alpha {alpha} step {zeta} (alpha step {az}): Phi_aa {:.1e}, Q_aa {:.1e}, Q_vv {:.1e}",
            rel(phi[(2, 2)], decay),
            rel(q[(2, 2)], q_acc),
            rel(q[(1, 1)], q_vel)
        );
    }
}
