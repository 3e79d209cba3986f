"""The exceptions seqsmooth raises: every one a :class:`SeqsmoothError`, itself a
:class:`ValueError`, with the message of the Rust library's error and, for a bad sample of a
batch, the sample's ``index``."""

from __future__ import annotations


class SeqsmoothError(ValueError):
    """Base of every seqsmooth error.

    Attributes
    ----------
    index : int or None
        The position of the offending sample in the arrays passed, when one sample is to
        blame (a NaN, a time that does not increase); ``None`` otherwise.
    """

    index: int | None

    def __init__(self, message: str, index: int | None = None) -> None:
        super().__init__(message)
        self.index = index


class InvalidInputError(SeqsmoothError):
    """The data are unusable: NaN or infinite values, times that do not increase,
    mismatched lengths, empty arrays, the wrong shape."""


class InvalidTypeError(InvalidInputError, TypeError):
    """An array whose dtype is not a real number (complex, strings, objects, dates)."""


class ParameterError(SeqsmoothError):
    """A setting out of range: degree, theta, tau, window, engine, sigma."""


class TooFewSamplesError(SeqsmoothError):
    """Fewer samples than the fit needs (a window longer than the series, fewer samples
    than the degree plus one)."""


class NotDeterminedError(SeqsmoothError):
    """The filter has no estimate yet (too few samples, or too few distinct times)."""


class NumericalError(SeqsmoothError):
    """The answer cannot be given to working accuracy in doubles: a number beyond the
    double range, a singular fit, an iteration that diverged or did not converge."""


class DamagedStateError(SeqsmoothError):
    """A saved filter (a pickle, or the bytes of the library's saved form) that cannot be
    restored: truncated, a byte changed, another class's, a newer format, or numbers that
    break the filter's invariants."""


__all__ = [
    "SeqsmoothError",
    "InvalidInputError",
    "InvalidTypeError",
    "ParameterError",
    "TooFewSamplesError",
    "NotDeterminedError",
    "NumericalError",
    "DamagedStateError",
]
