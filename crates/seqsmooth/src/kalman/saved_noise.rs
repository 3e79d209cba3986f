//! The saved form of a filter's driving-noise model (Morrison ch. 15): the library's own
//! [`ProcessNoise`] models by their data, so that a Kalman filter holding one can be saved and
//! restored ([`crate::persist`]). A model of the caller's own type has no saved form; saving a
//! filter that holds one is refused, and the caller restores its model itself.

use super::noise::{MatrixNoise, ProcessNoise, WhiteNoiseDerivative};
use crate::model::continuous::ContinuousModel;
use crate::model::coordinated_turn::CoordinatedTurn;
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::sync::Arc;

/// A driving-noise model of the library's, by its data.
///
/// ```
/// use seqsmooth::kalman::noise::{ProcessNoise, WhiteNoiseDerivative};
/// let noise = WhiteNoiseDerivative::new(1, 1, 0.5).unwrap();
/// assert!(noise.saved().is_some());
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum SavedNoise {
    /// [`WhiteNoiseDerivative`].
    WhiteNoiseDerivative(WhiteNoiseDerivative),
    /// [`MatrixNoise`].
    Matrix(MatrixNoise),
    /// [`ContinuousModel`] (Van Loan's `Q(ζ)`).
    Continuous(ContinuousModel),
    /// [`CoordinatedTurn`]'s driving noise.
    CoordinatedTurn(CoordinatedTurn),
}

impl SavedNoise {
    /// The model again.
    pub fn model(self) -> Arc<dyn ProcessNoise> {
        match self {
            SavedNoise::WhiteNoiseDerivative(n) => Arc::new(n),
            SavedNoise::Matrix(n) => Arc::new(n),
            SavedNoise::Continuous(n) => Arc::new(n),
            SavedNoise::CoordinatedTurn(n) => Arc::new(n),
        }
    }
}

/// serde of `Option<Arc<dyn ProcessNoise>>` through [`SavedNoise`] (`#[serde(with)]`).
pub(crate) mod field {
    use super::*;

    pub(crate) fn serialize<S: Serializer>(
        noise: &Option<Arc<dyn ProcessNoise>>,
        s: S,
    ) -> Result<S::Ok, S::Error> {
        let saved = match noise {
            None => None,
            Some(n) => Some(n.saved().ok_or_else(|| {
                serde::ser::Error::custom(format!(
                    "the driving-noise model {n:?} has no saved form"
                ))
            })?),
        };
        saved.serialize(s)
    }

    pub(crate) fn deserialize<'de, D: Deserializer<'de>>(
        d: D,
    ) -> Result<Option<Arc<dyn ProcessNoise>>, D::Error> {
        Ok(Option::<SavedNoise>::deserialize(d)?.map(SavedNoise::model))
    }
}
