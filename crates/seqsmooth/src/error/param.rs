//! The parameters an [`Error`](enum@super::Error) can name: one variant per setting or piece of
//! data a caller hands in, so that the kind of a refusal follows from what was refused (a
//! setting: [`ErrorKind::Parameter`]; the data: [`ErrorKind::InvalidInput`]) and each front end
//! can name it in its own words (the command by its flag, Python by its keyword).
//!
//! ```
//! use seqsmooth::error::{Error, ErrorKind, Param};
//! assert_eq!(Param::Window.name(), "window");
//! assert_eq!(Param::Window.kind(), ErrorKind::Parameter);
//! assert_eq!(Param::Azimuth.kind(), ErrorKind::InvalidInput);
//! let e = Error::InvalidParameter { name: Param::Window, value: "0".into(), reason: "must be at least 1".into() };
//! assert_eq!(e.to_string(), "window 0 is invalid: must be at least 1");
//! ```

use super::ErrorKind;
use std::fmt;

/// What an [`Error`](enum@super::Error) names: a setting (degree, θ, τ, window, …) or a piece
/// of the data handed in (a time, a radar row's component, the arrays' lengths). Its
/// [`name`](Param::name) is the library's word for it; its [`kind`](Param::kind) says whose
/// fault a bad value is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[non_exhaustive]
pub enum Param {
    /// The polynomial degree `m`.
    Degree,
    /// The discount `θ` of a fading memory (Morrison (13.2.1)).
    Theta,
    /// The discount `β` per unit of time of a Bayes or Kalman fading memory.
    Beta,
    /// The time interval `τ` that `θ` discounts over.
    Tau,
    /// The samples in a fixed-memory window `L + 1`.
    Window,
    /// A fixed-memory window's span `L` (its samples less one).
    Span,
    /// How far ahead (in samples or time) an estimate is made.
    Lead,
    /// The derivative asked for.
    Derivative,
    /// The order of a derivative of a basis or a fit.
    DerivativeOrder,
    /// The derivatives a state carries.
    Derivatives,
    /// The order of a difference of the noise estimator.
    DifferenceOrder,
    /// The noise standard deviation `σ` of the values.
    Sigma,
    /// The measurement noise `σ_ν` of a fixed-memory design.
    NoiseSigma,
    /// The output `σ` a fixed-memory design aims at.
    TargetSigma,
    /// The bound on the next derivative of a fixed-memory design.
    ANext,
    /// The ratio of a balanced fixed-memory design.
    Ratio,
    /// A time step.
    Step,
    /// A time interval.
    Interval,
    /// The time elapsed since the start.
    Elapsed,
    /// A duration.
    Duration,
    /// The unit of timestamps.
    TimeUnit,
    /// A fading memory's discount, as a whole (which of its names were given).
    Discount,
    /// The discount over one step.
    DiscountOverStep,
    /// A variance-reduction factor.
    VarianceFactor,
    /// The channels of a bank.
    Channels,
    /// One channel of a bank.
    Channel,
    /// The batches of a run.
    Batches,
    /// The runs of a Monte Carlo.
    Runs,
    /// The memory levels of the automatic filter.
    MemoryLevels,
    /// A filter's configuration.
    Configuration,
    /// The prototype filter of a bank.
    Prototype,
    /// The automatic filter's first degree.
    StartDegree,
    /// The derivative a switch is decided on.
    SwitchDerivative,
    /// The samples of the automatic filter's review.
    ReviewWindow,
    /// The samples of the noise estimate.
    NoiseWindow,
    /// The screen on the noise estimate.
    NoiseScreen,
    /// The samples of a χ² test.
    ChiSquaredWindow,
    /// The significance of a χ² test.
    ChiSquaredSignificance,
    /// The significance of a restart.
    RestartSignificance,
    /// The multiplier of a gate.
    GateMultiplier,
    /// The multiplier of the outlier gate.
    OutlierGateMultiplier,
    /// The VRF below which a gate applies.
    GateVrfLimit,
    /// The VRF at which a filter has settled.
    SettleVrf,
    /// The refreshes of a recursion.
    Refreshes,
    /// What to do on a failure.
    Failure,
    /// A probability.
    Probability,
    /// A test's false-alarm rate.
    FalseAlarmRate,
    /// A test's significance.
    Significance,
    /// A confidence level.
    Confidence,
    /// A distribution's degrees of freedom.
    DegreesOfFreedom,
    /// A NEES or NIS value.
    NeesOrNisValue,
    /// The normalised innovation squared (NIS).
    NormalisedInnovationSquared,
    /// The components of an innovation.
    InnovationComponents,
    /// An innovation's variance.
    InnovationVariance,
    /// An innovation's covariance `M S Mᵀ + R`.
    InnovationCovariance,
    /// A residual sum of squares.
    ResidualSumOfSquares,
    /// An estimate to test.
    Estimate,
    /// The truth an estimate is tested against.
    Truth,
    /// A noise variance.
    NoiseVariance,
    /// Noise variances.
    NoiseVariances,
    /// A model.
    Model,
    /// A state vector.
    State,
    /// The dimension of the state.
    StateDimension,
    /// The state a filter starts from.
    StartState,
    /// A nominal trajectory.
    Nominal,
    /// A nominal state.
    NominalState,
    /// A model's parameters.
    Parameters,
    /// A dynamics model.
    Dynamics,
    /// The dynamics matrix `A`.
    DynamicsMatrixA,
    /// The transition matrix `Φ`.
    Phi,
    /// An observation model.
    ObservationModel,
    /// The observation matrix `M`.
    ObservationMatrixM,
    /// The stacked observation matrix `T`.
    ObservationMatrixT,
    /// The measurement noise.
    MeasurementNoise,
    /// The measurement covariance.
    MeasurementCovariance,
    /// A noise covariance.
    NoiseCovariance,
    /// The error covariance `R`.
    ErrorCovarianceR,
    /// The measurement covariance `R`.
    R,
    /// The process noise.
    ProcessNoise,
    /// The driving-noise spectral density `q`.
    Q,
    /// The driving-noise spectral density `q` of a model.
    DrivingNoiseQ,
    /// A covariance.
    Covariance,
    /// A prior state and covariance.
    Prior,
    /// A prior covariance.
    PriorCovariance,
    /// A predicted covariance.
    PredictedCovariance,
    /// The shapes of a model's matrices.
    Shapes,
    /// The axes of a model.
    Axes,
    /// A radar's site and geometry.
    RadarGeometry,
    /// A radar's site, its east, north and up coordinates.
    Site,
    /// The start-up of a radar track.
    RadarStart,
    /// The iterations a fit may take.
    MaxIterations,
    /// The iteration limits of a fit.
    IterationLimits,
    /// A fit's tolerance.
    Tolerance,
    /// An integrator's relative tolerance.
    RelativeTolerance,
    /// An integrator's absolute tolerance.
    AbsoluteTolerance,
    /// A timestamp.
    Time,
    /// A sample's time.
    SampleTime,
    /// A value handed in.
    InputValue,
    /// The length of an input.
    InputLength,
    /// The lengths of the arrays handed in.
    InputLengths,
    /// The length of a matrix handed in.
    MatrixLength,
    /// The lengths of a batch's arrays.
    BatchLengths,
    /// The lengths of a chunk's arrays.
    ChunkLengths,
    /// The length of the estimates' buffer.
    EstimatesLength,
    /// The length of the rows' buffer.
    RowsLength,
    /// The length of an output buffer.
    OutputLength,
    /// A row of input.
    Row,
    /// A radar row's range.
    Range,
    /// A radar row's azimuth.
    Azimuth,
    /// A radar row's elevation.
    Elevation,
    /// A radar row's range σ.
    SigmaRange,
    /// A radar row's angle σ.
    SigmaAngle,
    /// A sample's weight.
    Weight,
    /// The samples' weights.
    Weights,
    /// A segment of the data.
    Segment,
    /// The samples' σ.
    Sigmas,
    /// A measurement handed in.
    Measurement,
    /// The stacked observations `Y`.
    ObservationsY,
    /// The unscented transform's spread `α` of its sigma points.
    SigmaPointAlpha,
    /// The unscented transform's `β` (the prior's fourth moment; 2 for a Gaussian).
    SigmaPointBeta,
    /// The unscented transform's secondary spread `κ`.
    SigmaPointKappa,
    /// The white noise's spectral density matrix `Q_c` of a continuous model.
    SpectralDensity,
    /// The Singer model's manoeuvre rate `α` (the reciprocal of its time constant).
    ManoeuvreAlpha,
    /// The Singer model's manoeuvre variance `σ_m²`.
    ManoeuvreVariance,
    /// The length of the segments a series is cut into (PAML's).
    SegmentLength,
    /// How a radar's azimuth is measured ([`crate::model::radar::AzimuthConvention`]).
    AzimuthConvention,
    /// The 0-based index `n` of the newest sample of an expanding memory's table.
    NewestIndex,
    /// The coefficients `n` of a continuous-time expanding memory's gains (Luenberger's).
    Coefficients,
    /// The time a fit's state refers to.
    Epoch,
    /// A discrete-time model's transition matrix `F` (`x_k = F x_{k−1} + B u + w`).
    TransitionMatrixF,
    /// A discrete-time model's observation matrix `H` (`z = H x + v`).
    ObservationMatrixH,
    /// A discrete-time model's process-noise covariance `Q` over one step.
    ProcessNoiseQ,
    /// A discrete-time model's measurement-noise covariance `R`.
    MeasurementNoiseR,
    /// A discrete-time model's control matrix `B`.
    ControlMatrixB,
    /// A discrete-time model's control input `u`.
    ControlInputU,
    /// A discrete-time model's state covariance `P` set or handed in.
    StateCovarianceP,
    /// A user's state transition `f(x, t0, t1)`.
    TransitionFunction,
    /// The Jacobian `∂f/∂x` of a user's state transition.
    TransitionJacobian,
    /// A user's observation function `h(x, t)`.
    ObservationFunction,
    /// The Jacobian `∂h/∂x` of a user's observation function.
    ObservationJacobian,
    /// A user's driving-noise covariance `Q(t0, t1)`.
    ProcessNoiseFunction,
    /// The observation components that are angles (their residuals wrapped to `(−π, π]`).
    AngleComponents,
    /// A user's state derivative `dxdt(x, t)` of `dX/dt = F(X, t)`, integrated by the library.
    DerivativeFunction,
    /// The Jacobian `∂F/∂X` of a user's state derivative.
    DerivativeJacobian,
    /// The coordinated turn's known turn rate `ω`.
    TurnRate,
    /// The coordinated turn's random-walk density `q_ω` of an estimated turn rate.
    TurnRateNoise,
    /// A built-in motion model's name (`seqsmooth track --model`).
    MotionModel,
}

impl Param {
    /// Every parameter, in the order of their declaration.
    pub const ALL: &[Param] = &[
        Param::Degree,
        Param::Theta,
        Param::Beta,
        Param::Tau,
        Param::Window,
        Param::Span,
        Param::Lead,
        Param::Derivative,
        Param::DerivativeOrder,
        Param::Derivatives,
        Param::DifferenceOrder,
        Param::Sigma,
        Param::NoiseSigma,
        Param::TargetSigma,
        Param::ANext,
        Param::Ratio,
        Param::Step,
        Param::Interval,
        Param::Elapsed,
        Param::Duration,
        Param::TimeUnit,
        Param::Discount,
        Param::DiscountOverStep,
        Param::VarianceFactor,
        Param::Channels,
        Param::Channel,
        Param::Batches,
        Param::Runs,
        Param::MemoryLevels,
        Param::Configuration,
        Param::Prototype,
        Param::StartDegree,
        Param::SwitchDerivative,
        Param::ReviewWindow,
        Param::NoiseWindow,
        Param::NoiseScreen,
        Param::ChiSquaredWindow,
        Param::ChiSquaredSignificance,
        Param::RestartSignificance,
        Param::GateMultiplier,
        Param::OutlierGateMultiplier,
        Param::GateVrfLimit,
        Param::SettleVrf,
        Param::Refreshes,
        Param::Failure,
        Param::Probability,
        Param::FalseAlarmRate,
        Param::Significance,
        Param::Confidence,
        Param::DegreesOfFreedom,
        Param::NeesOrNisValue,
        Param::NormalisedInnovationSquared,
        Param::InnovationComponents,
        Param::InnovationVariance,
        Param::InnovationCovariance,
        Param::ResidualSumOfSquares,
        Param::Estimate,
        Param::Truth,
        Param::NoiseVariance,
        Param::NoiseVariances,
        Param::Model,
        Param::State,
        Param::StateDimension,
        Param::StartState,
        Param::Nominal,
        Param::NominalState,
        Param::Parameters,
        Param::Dynamics,
        Param::DynamicsMatrixA,
        Param::Phi,
        Param::ObservationModel,
        Param::ObservationMatrixM,
        Param::ObservationMatrixT,
        Param::MeasurementNoise,
        Param::MeasurementCovariance,
        Param::NoiseCovariance,
        Param::ErrorCovarianceR,
        Param::R,
        Param::ProcessNoise,
        Param::Q,
        Param::DrivingNoiseQ,
        Param::Covariance,
        Param::Prior,
        Param::PriorCovariance,
        Param::PredictedCovariance,
        Param::Shapes,
        Param::Axes,
        Param::RadarGeometry,
        Param::Site,
        Param::RadarStart,
        Param::MaxIterations,
        Param::IterationLimits,
        Param::Tolerance,
        Param::RelativeTolerance,
        Param::AbsoluteTolerance,
        Param::Time,
        Param::SampleTime,
        Param::InputValue,
        Param::InputLength,
        Param::InputLengths,
        Param::MatrixLength,
        Param::BatchLengths,
        Param::ChunkLengths,
        Param::EstimatesLength,
        Param::RowsLength,
        Param::OutputLength,
        Param::Row,
        Param::Range,
        Param::Azimuth,
        Param::Elevation,
        Param::SigmaRange,
        Param::SigmaAngle,
        Param::Weight,
        Param::Weights,
        Param::Segment,
        Param::Sigmas,
        Param::Measurement,
        Param::ObservationsY,
        Param::SigmaPointAlpha,
        Param::SigmaPointBeta,
        Param::SigmaPointKappa,
        Param::SpectralDensity,
        Param::ManoeuvreAlpha,
        Param::ManoeuvreVariance,
        Param::SegmentLength,
        Param::AzimuthConvention,
        Param::NewestIndex,
        Param::Coefficients,
        Param::Epoch,
        Param::TransitionMatrixF,
        Param::ObservationMatrixH,
        Param::ProcessNoiseQ,
        Param::MeasurementNoiseR,
        Param::ControlMatrixB,
        Param::ControlInputU,
        Param::StateCovarianceP,
        Param::TransitionFunction,
        Param::TransitionJacobian,
        Param::ObservationFunction,
        Param::ObservationJacobian,
        Param::ProcessNoiseFunction,
        Param::AngleComponents,
        Param::DerivativeFunction,
        Param::DerivativeJacobian,
        Param::TurnRate,
        Param::TurnRateNoise,
        Param::MotionModel,
    ];

    /// The library's word for the parameter (the one its messages use).
    pub fn name(self) -> &'static str {
        match self {
            Param::Degree => "degree",
            Param::Theta => "theta",
            Param::Beta => "beta",
            Param::Tau => "tau",
            Param::Window => "window",
            Param::Span => "span",
            Param::Lead => "lead",
            Param::Derivative => "derivative",
            Param::DerivativeOrder => "derivative order",
            Param::Derivatives => "derivatives",
            Param::DifferenceOrder => "difference order",
            Param::Sigma => "sigma",
            Param::NoiseSigma => "noise sigma",
            Param::TargetSigma => "target sigma",
            Param::ANext => "a_next",
            Param::Ratio => "ratio",
            Param::Step => "step",
            Param::Interval => "interval",
            Param::Elapsed => "elapsed",
            Param::Duration => "duration",
            Param::TimeUnit => "time unit",
            Param::Discount => "discount",
            Param::DiscountOverStep => "discount over the step",
            Param::VarianceFactor => "variance factor",
            Param::Channels => "channels",
            Param::Channel => "channel",
            Param::Batches => "batches",
            Param::Runs => "runs",
            Param::MemoryLevels => "memory levels",
            Param::Configuration => "configuration",
            Param::Prototype => "prototype",
            Param::StartDegree => "start degree",
            Param::SwitchDerivative => "switch derivative",
            Param::ReviewWindow => "review window",
            Param::NoiseWindow => "noise window",
            Param::NoiseScreen => "noise screen",
            Param::ChiSquaredWindow => "chi-squared window",
            Param::ChiSquaredSignificance => "chi-squared significance",
            Param::RestartSignificance => "restart significance",
            Param::GateMultiplier => "gate multiplier",
            Param::OutlierGateMultiplier => "outlier gate multiplier",
            Param::GateVrfLimit => "gate VRF limit",
            Param::SettleVrf => "settle VRF",
            Param::Refreshes => "refreshes",
            Param::Failure => "failure",
            Param::Probability => "probability",
            Param::FalseAlarmRate => "false-alarm rate",
            Param::Significance => "significance",
            Param::Confidence => "confidence",
            Param::DegreesOfFreedom => "degrees of freedom",
            Param::NeesOrNisValue => "NEES or NIS value",
            Param::NormalisedInnovationSquared => "normalised innovation squared",
            Param::InnovationComponents => "innovation components",
            Param::InnovationVariance => "innovation variance",
            Param::InnovationCovariance => "innovation covariance M S Mᵀ + R",
            Param::ResidualSumOfSquares => "residual sum of squares",
            Param::Estimate => "estimate",
            Param::Truth => "truth",
            Param::NoiseVariance => "noise variance",
            Param::NoiseVariances => "noise variances",
            Param::Model => "model",
            Param::State => "state",
            Param::StateDimension => "state dimension",
            Param::StartState => "start state",
            Param::Nominal => "nominal",
            Param::NominalState => "nominal state",
            Param::Parameters => "parameters",
            Param::Dynamics => "dynamics",
            Param::DynamicsMatrixA => "dynamics matrix A",
            Param::Phi => "Φ",
            Param::ObservationModel => "observation model",
            Param::ObservationMatrixM => "observation matrix M",
            Param::ObservationMatrixT => "observation matrix T",
            Param::MeasurementNoise => "measurement noise",
            Param::MeasurementCovariance => "measurement covariance",
            Param::NoiseCovariance => "noise covariance",
            Param::ErrorCovarianceR => "error covariance R",
            Param::R => "R",
            Param::ProcessNoise => "process noise",
            Param::Q => "q",
            Param::DrivingNoiseQ => "driving-noise spectral density q",
            Param::Covariance => "covariance",
            Param::Prior => "prior",
            Param::PriorCovariance => "prior covariance",
            Param::PredictedCovariance => "predicted covariance",
            Param::Shapes => "shapes",
            Param::Axes => "axes",
            Param::RadarGeometry => "radar geometry",
            Param::Site => "site",
            Param::RadarStart => "radar start",
            Param::MaxIterations => "max_iterations",
            Param::IterationLimits => "iteration limits",
            Param::Tolerance => "tolerance",
            Param::RelativeTolerance => "relative tolerance",
            Param::AbsoluteTolerance => "absolute tolerance",
            Param::Time => "time",
            Param::SampleTime => "sample time",
            Param::InputValue => "input value",
            Param::InputLength => "input length",
            Param::InputLengths => "input lengths",
            Param::MatrixLength => "matrix length",
            Param::BatchLengths => "batch lengths",
            Param::ChunkLengths => "chunk lengths",
            Param::EstimatesLength => "estimates length",
            Param::RowsLength => "rows length",
            Param::OutputLength => "output length",
            Param::Row => "row",
            Param::Range => "range",
            Param::Azimuth => "azimuth",
            Param::Elevation => "elevation",
            Param::SigmaRange => "sigma_range",
            Param::SigmaAngle => "sigma_angle",
            Param::Weight => "weight",
            Param::Weights => "weights",
            Param::Segment => "segment",
            Param::Sigmas => "sigmas",
            Param::Measurement => "measurement",
            Param::ObservationsY => "observations Y",
            Param::SigmaPointAlpha => "sigma-point alpha",
            Param::SigmaPointBeta => "sigma-point beta",
            Param::SigmaPointKappa => "sigma-point kappa",
            Param::SpectralDensity => "spectral density Q_c",
            Param::ManoeuvreAlpha => "manoeuvre alpha",
            Param::ManoeuvreVariance => "manoeuvre variance",
            Param::SegmentLength => "segment length",
            Param::AzimuthConvention => "azimuth convention",
            Param::NewestIndex => "n",
            Param::Coefficients => "coefficients",
            Param::Epoch => "epoch",
            Param::TransitionMatrixF => "transition matrix F",
            Param::ObservationMatrixH => "observation matrix H",
            Param::ProcessNoiseQ => "process noise Q",
            Param::MeasurementNoiseR => "measurement noise R",
            Param::ControlMatrixB => "control matrix B",
            Param::ControlInputU => "control input u",
            Param::StateCovarianceP => "state covariance P",
            Param::TransitionFunction => "transition function",
            Param::TransitionJacobian => "transition Jacobian",
            Param::ObservationFunction => "observation function",
            Param::ObservationJacobian => "observation Jacobian",
            Param::ProcessNoiseFunction => "process noise function",
            Param::AngleComponents => "angle components",
            Param::DerivativeFunction => "state derivative function",
            Param::DerivativeJacobian => "state derivative Jacobian",
            Param::TurnRate => "turn rate",
            Param::TurnRateNoise => "turn rate noise",
            Param::MotionModel => "motion model",
        }
    }

    /// Whose fault a bad value is: the data's ([`ErrorKind::InvalidInput`]: a sample, a row's
    /// component or σ, the arrays' lengths) or the settings' ([`ErrorKind::Parameter`]).
    pub fn kind(self) -> ErrorKind {
        match self {
            Param::Time
            | Param::SampleTime
            | Param::InputValue
            | Param::InputLength
            | Param::InputLengths
            | Param::MatrixLength
            | Param::BatchLengths
            | Param::ChunkLengths
            | Param::EstimatesLength
            | Param::RowsLength
            | Param::OutputLength
            | Param::Row
            | Param::Range
            | Param::Azimuth
            | Param::Elevation
            | Param::SigmaRange
            | Param::SigmaAngle
            | Param::Weight
            | Param::Weights
            | Param::Segment
            | Param::Sigmas
            | Param::Measurement
            | Param::ObservationsY
            | Param::ControlInputU => ErrorKind::InvalidInput,
            _ => ErrorKind::Parameter,
        }
    }
}

impl fmt::Display for Param {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::super::Error;
    use super::*;

    /// Each parameter has its own word, and a refusal of it takes its kind and is named in
    /// the words of the interface it was called through.
    #[test]
    fn every_parameter_has_its_own_name_and_kind() {
        let mut names: Vec<&str> = Param::ALL.iter().map(|p| p.name()).collect();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), Param::ALL.len(), "two parameters share a name");
        for &p in Param::ALL {
            let e = Error::InvalidParameter {
                name: p,
                value: "7".into(),
                reason: "test".into(),
            };
            assert_eq!(e.kind(), p.kind());
            assert_eq!(e.to_string(), format!("{} 7 is invalid: test", p.name()));
            let batch = Error::InBatch {
                index: 3,
                source: Box::new(e.clone()),
            };
            assert_eq!(batch.kind(), p.kind());
            assert_eq!(
                batch.message_in(&|q| (q == p).then_some("--flag")),
                "sample 3 of the batch: --flag 7 is invalid: test"
            );
            assert_eq!(batch.message_in(&|_| None), batch.to_string());
        }
        assert_eq!(Param::Time.kind(), ErrorKind::InvalidInput);
        assert_eq!(Param::Theta.kind(), ErrorKind::Parameter);
    }
}
