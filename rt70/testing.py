"""Comparisons with tolerances derived from the compared quantity's scale.

Every numerical assert of rt70's tests goes through :func:`assert_close` (or
:func:`close` where a boolean is needed), and so can a user's own tests of a model. The
rule it enforces:

- a tolerance is **relative**: ``|actual − expected| ≤ rel · scale``, entry by entry;
- the **scale** is the size of the compared quantity — by default the max-norm of
  ``expected`` — or, where the quantity is a sum of larger terms that cancel (a bias
  near zero, a spring force at rest, the difference of two energies), the size of those
  terms, stated by the caller as ``scale=`` (a number, or an array broadcast against the
  entries, as :func:`rt70.crosscheck.scales.natural_scales` derives them);
- ``rel`` is never taken below :data:`MIN_REL`, a few units in the last place: two
  correct computations on two CPUs may differ by that much (fused multiply–adds, another
  summation order, another libm), so a tighter bound would test the machine, not the
  code;
- a NaN or an infinity on either side, a shape mismatch, an empty comparison, or a zero
  scale that nobody stated fail — a check that compared nothing never passes;
- complex values are compared by the modulus of their difference (a frequency
  response), never by their real parts alone.

The default scale is one number for the whole array. Where entries span decades and
each must hold to its own size (a spectrum, the constants of a filter), pass
``scale=np.abs(expected)`` (per entry) instead.

Exact equality (``==``) stays the right test where one computation is repeated
bit-for-bit on one machine (determinism, a cache, a serial run against a cluster that
runs the same code); it is not a tolerance and not what this module is for.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

#: Machine epsilon of float64 (2.2e-16): one unit in the last place of 1.
EPS = float(np.finfo(float).eps)

#: Units in the last place that :data:`MIN_REL` allows.
ULPS = 8

#: The smallest relative tolerance a comparison may use: ``ULPS · EPS`` ≈ 1.8e-15.
MIN_REL = ULPS * EPS


def tolerance(rel: float, scale: ArrayLike) -> np.ndarray:
    """The absolute bound ``max(rel, MIN_REL) · scale`` of a comparison.

    Parameters
    ----------
    rel : float
        Relative tolerance, > 0 (raised to :data:`MIN_REL` when below it).
    scale : array_like
        Natural scale of the compared quantity, ≥ 0 and finite (a number or an array
        broadcast against the compared entries).

    Returns
    -------
    numpy.ndarray
        The bound, with ``scale``'s shape.

    Raises
    ------
    ValueError
        If ``rel`` is not a positive finite number or ``scale`` is negative or not finite.
    """
    if not (np.isfinite(rel) and rel > 0.0):
        raise ValueError(f"rel must be a positive finite number, got {rel!r}")
    scale = np.asarray(scale, dtype=float)
    if not np.all(np.isfinite(scale)) or np.any(scale < 0.0):
        raise ValueError(f"scale must be finite and non-negative, got {scale!r}")
    return max(rel, MIN_REL) * scale


def _compared(
    actual: ArrayLike, expected: ArrayLike, rel: float, scale: ArrayLike | None
) -> tuple[np.ndarray, np.ndarray, np.ndarray, str]:
    """Both sides as float arrays, the bound, and the reason they cannot be compared."""
    a = np.asarray(actual)
    e = np.asarray(expected)
    kind = complex if np.iscomplexobj(a) or np.iscomplexobj(e) else float
    a, e = a.astype(kind), e.astype(kind)
    if a.shape != e.shape:
        raise AssertionError(f"shapes differ: actual {a.shape}, expected {e.shape}")
    if a.size == 0:
        raise AssertionError("nothing compared: both arrays are empty")
    for side, values in (("actual", a), ("expected", e)):
        if not np.all(np.isfinite(values)):
            raise AssertionError(f"NaN or infinity on the {side} side: {values!r}")
    if scale is None:
        scale = float(np.max(np.abs(e)))
        if scale == 0.0:
            if np.array_equal(a, e):
                return a, e, np.zeros(()), ""
            return (
                a,
                e,
                np.zeros(1),
                (
                    "expected is exactly zero and actual is not: state the natural scale of "
                    "the terms that produce it (scale=...)"
                ),
            )
    bound = tolerance(rel, scale)
    if not np.any(bound > 0.0) and not np.array_equal(a, e):
        return a, e, bound, "the stated scale is zero"
    return a, e, bound, ""


def close(
    actual: ArrayLike, expected: ArrayLike, *, rel: float, scale: ArrayLike | None = None
) -> bool:
    """Whether ``|actual − expected| ≤ max(rel, MIN_REL) · scale`` entry by entry.

    Parameters
    ----------
    actual, expected : array_like
        The compared values; equal shapes, finite, not empty.
    rel : float
        Relative tolerance (raised to :data:`MIN_REL`).
    scale : array_like, optional
        Natural scale; default the max-norm of ``expected``.

    Returns
    -------
    bool
        False on a NaN, an infinity, a shape mismatch, an empty comparison or an
        unstated zero scale, as well as on a difference beyond the bound.
    """
    try:
        assert_close(actual, expected, rel=rel, scale=scale)
    except AssertionError:
        return False
    return True


def assert_close(
    actual: ArrayLike,
    expected: ArrayLike,
    *,
    rel: float,
    scale: ArrayLike | None = None,
    what: str = "",
) -> None:
    """Assert ``|actual − expected| ≤ max(rel, MIN_REL) · scale``, entry by entry.

    Parameters
    ----------
    actual, expected : array_like
        The compared values (numbers or arrays of one shape), finite and not empty.
    rel : float
        Relative tolerance, > 0; below :data:`MIN_REL` it is raised to it.
    scale : array_like, optional
        Natural scale of the quantity: a number, or an array broadcast against the
        entries. Default: the max-norm of ``expected``. State it where the quantity is a
        sum of larger terms (its size is then theirs), or where ``expected`` is zero.
    what : str, optional
        Name of the quantity, put in front of the failure message.

    Raises
    ------
    AssertionError
        Naming the largest error, the bound and where it occurred; also on a NaN or an
        infinity on either side, a shape mismatch, an empty comparison, and an expected
        value of exactly zero compared with a nonzero one without a stated scale.
    ValueError
        If ``rel`` or ``scale`` is not a valid tolerance (:func:`tolerance`).
    """
    prefix = f"{what}: " if what else ""
    try:
        a, e, bound, reason = _compared(actual, expected, rel, scale)
    except AssertionError as exc:
        raise AssertionError(prefix + str(exc)) from None
    if reason:
        raise AssertionError(prefix + reason)
    error = np.abs(a - e)
    excess = error - np.broadcast_to(bound, error.shape)
    if np.any(excess > 0.0):
        at = tuple(int(i) for i in np.unravel_index(int(np.argmax(excess)), error.shape))
        limit = np.broadcast_to(bound, error.shape)[at]
        raise AssertionError(
            f"{prefix}|actual − expected| = {error[at]:.3e} at index {at} exceeds "
            f"{limit:.3e} (rel {max(rel, MIN_REL):.1e}; actual {a[at]!r}, expected "
            f"{e[at]!r}); largest error {error.max():.3e}"
        )
