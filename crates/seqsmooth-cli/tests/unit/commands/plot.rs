//! Unit tests of `commands::plot`: axis labels.

use seqsmooth_cli::commands::plot::*;

#[test]
fn labels_carry_units() {
    assert_eq!(derivative_label(0, Some("s"), Some("m")), "y (m)");
    assert_eq!(derivative_label(1, Some("s"), Some("m")), "dy/dt (m/s)");
    assert_eq!(derivative_label(2, Some("s"), Some("m")), "d²y/dt² (m/s²)");
    assert_eq!(derivative_label(12, None, None), "d¹²y/dt¹²");
    assert_eq!(derivative_label(1, Some("s"), None), "dy/dt (1/s)");
    assert_eq!(derivative_label(0, Some("s"), None), "y");
}
