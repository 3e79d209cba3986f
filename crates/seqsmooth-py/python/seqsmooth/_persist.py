"""Pickling of seqsmooth's filters: ``__reduce__`` of every filter class returns
``(restore, (cls, state))``, where ``state`` holds the library's saved form (bytes: a tagged,
versioned, checksummed envelope, ``seqsmooth::persist``) and, for the classes over the
caller's own model, the caller's callables (pickled by Python's own rules: module-level
functions pickle, a lambda raises Python's ``PicklingError``)."""

from __future__ import annotations


def restore(cls, state):
    """The filter of class ``cls`` saved as ``state`` (raises ``DamagedStateError`` if the
    state is damaged, another class's, or of a newer format)."""
    return cls._from_state(state)
