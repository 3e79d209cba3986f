//! `seqsmooth gains`: Morrison's scaled current-estimate gains `h_0..h_m` of the expanding-
//! and fading-memory filters (Reyneke et al. §6.4, §6.6), in `f64` or exact rationals.

use crate::args::{GainsArgs, Memory};
use crate::commands::shared::table::{cells, write_table};
use crate::error::CliError;
use seqsmooth::polynomial::expanding::gains::expanding_gains;
use seqsmooth::polynomial::fading::gains::fading_gains;
use seqsmooth::polynomial::form::GainForm;
use seqsmooth::scalar::Rational;

/// Runs `seqsmooth gains`: header `k,gain`, one row per derivative order `k = 0..m`.
pub fn run(a: &GainsArgs) -> Result<(), CliError> {
    let (m, form) = (a.memory.degree, GainForm::Current);
    let values: Vec<String> = match (a.memory.of(a.kind)?, a.exact) {
        (Memory::Expanding(n), true) => cells(&expanding_gains::<Rational>(m, n, form)),
        (Memory::Expanding(n), false) => cells(&expanding_gains::<f64>(m, n, form)),
        (Memory::Fading(theta), true) => cells(&fading_gains::<Rational>(m, theta.exact, form)),
        (Memory::Fading(theta), false) => cells(&fading_gains(m, theta.value_f64()?, form)),
    };
    let mut rows = vec![vec!["k".to_string(), "gain".to_string()]];
    let row = |(k, g): (usize, String)| vec![k.to_string(), g];
    rows.extend(values.into_iter().enumerate().map(row));
    write_table(&rows, a.format)
}
