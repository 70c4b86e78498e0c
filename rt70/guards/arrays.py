"""Validation of array arguments at the public entry points (shape and finiteness).

One cheap test per state vector: its shape, then one ``np.isfinite`` over it, counted
(about 1.5 µs; the dot product with zeros of :mod:`rt70.textbook.structured` is faster
but warns on the very inputs it rejects). A wrong shape is a :class:`~rt70.errors.ShapeError` (also
a ``ValueError``), a NaN or infinite entry a :class:`~rt70.errors.NonFiniteError`; both
name the argument. Both sides call it (it checks arguments, it computes no dynamics), so
they refuse bad input identically.
"""

from __future__ import annotations

import numpy as np

from rt70.errors import NonFiniteError, ShapeError


def check_vector(name: str, x: np.ndarray, size: int) -> np.ndarray:
    """Return ``x`` as a float vector of ``size`` entries, or raise naming ``name``.

    Parameters
    ----------
    name : str
        What ``x`` is, for the message (``"initial state q0"``).
    x : array_like
        The value given, in the caller's units.
    size : int
        The number of entries it must have.

    Raises
    ------
    ShapeError
        If ``x`` does not have shape ``(size,)``.
    NonFiniteError
        If an entry is NaN or infinite.
    """
    try:
        x = np.asarray(x, dtype=float)
    except (TypeError, ValueError):
        raise ShapeError(f"{name}: expected a vector of {size} numbers, got {x!r:.60}") from None
    if x.shape != (size,):
        raise ShapeError(f"{name}: expected shape ({size},), got shape {x.shape}")
    if np.count_nonzero(np.isfinite(x)) != size:  # twice as fast as np.isfinite(x).all()
        raise NonFiniteError(f"{name} contains NaN or infinite values")
    return x


def finite_numbers(value: object) -> bool:
    """True for a dict, list or tuple of 16 or more plain numbers, all finite.

    False for anything else (shorter, nested, text, None, or a NaN among the numbers):
    the caller then walks it item by item to name what is wrong. A mode shape of
    thousands of coordinates is thus checked in one array operation.

    Parameters
    ----------
    value : object
        What to check.
    """
    if not isinstance(value, dict | list | tuple) or len(value) < 16:
        return False
    try:
        numbers = np.fromiter(value.values() if isinstance(value, dict) else value, float)
    except (TypeError, ValueError):  # not numbers only
        return False
    return bool(np.isfinite(numbers).all())
