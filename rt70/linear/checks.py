"""Input checks shared by the modal analysis and the state-space models.

Matrices handed to :mod:`rt70.linear.modal` and :mod:`rt70.linear.responses` are
checked here: numeric, finite, of the expected shape, symmetric up to rounding where the
physics says so, and a mass matrix positive definite (its Cholesky factor is returned
for reuse). Every failure is an :class:`~rt70.errors.Rt70Error` naming the matrix.
The helpers are private to these modules (and :mod:`rt70.plotting.modal`, which labels
coordinates with :func:`_names`); they are imported from here, never copied.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import scipy.linalg

from rt70.errors import Rt70Error

#: Relative asymmetry ``max|X − Xᵀ| / max|X|`` tolerated in M, K and D (rounding).
SYMMETRY_RTOL = 1e-9


def _array(name: str, X: np.ndarray) -> np.ndarray:
    try:
        return np.asarray(X, dtype=float)
    except (TypeError, ValueError):
        raise Rt70Error(f"{name} is not a numeric array") from None


def _matrix(name: str, X: np.ndarray, shape: tuple[int | None, int | None]) -> np.ndarray:
    """Return ``X`` as a finite 2-D float array of ``shape`` (None: any), or raise."""
    X = _array(name, X)
    if X.ndim != 2 or any(s is not None and s != x for s, x in zip(shape, X.shape, strict=True)):
        want = " × ".join("·" if s is None else str(s) for s in shape)
        raise Rt70Error(f"{name} must be a {want} matrix, got shape {X.shape}")
    if not np.all(np.isfinite(X)):
        raise Rt70Error(f"{name} contains NaN or infinite values")
    return X


def _square(name: str, X: np.ndarray, n: int | None = None) -> np.ndarray:
    X = _matrix(name, X, (n, n))
    if X.shape[0] != X.shape[1]:
        raise Rt70Error(f"{name} must be square, got shape {X.shape}")
    if X.shape[0] == 0:
        raise Rt70Error(f"{name} is empty")
    return X


def _symmetric(name: str, X: np.ndarray, n: int | None = None) -> np.ndarray:
    """Square, finite and symmetric up to rounding; returns the symmetric part."""
    X = _square(name, X, n)
    if scipy.linalg.issymmetric(X):  # exactly: a copy (the check below is 10× slower)
        return np.array(X, dtype=float)
    scale = np.max(np.abs(X))
    asym = np.max(np.abs(X - X.T))
    if asym > SYMMETRY_RTOL * scale:
        raise Rt70Error(
            f"{name} is not symmetric: max|{name} − {name}ᵀ| = {asym:.3g} "
            f"(max|{name}| = {scale:.3g})"
        )
    return 0.5 * (X + X.T)


def _cholesky(M: np.ndarray) -> tuple[np.ndarray, bool]:
    """Cholesky factor of M (:func:`scipy.linalg.cho_factor`), or raise if not PD."""
    try:
        return scipy.linalg.cho_factor(M, lower=True)
    except np.linalg.LinAlgError:
        raise Rt70Error("mass matrix M is not positive definite (Cholesky failed)") from None


def _mass(M: np.ndarray) -> tuple[np.ndarray, tuple[np.ndarray, bool]]:
    M = _symmetric("M", M)
    return M, _cholesky(M)


def _columns(name: str, X: np.ndarray, n: int) -> np.ndarray:
    """An input matrix with n rows; a 1-D vector is one column."""
    X = _array(name, X)
    if X.ndim == 1:
        X = X.reshape(-1, 1)
    return _matrix(name, X, (n, None))


def _rows(name: str, X: np.ndarray, n: int) -> np.ndarray:
    """An output matrix with n columns; a 1-D vector is one row."""
    X = _array(name, X)
    if X.ndim == 1:
        X = X.reshape(1, -1)
    return _matrix(name, X, (None, n))


def _names(given: Sequence[str] | None, prefix: str, count: int, what: str) -> tuple[str, ...]:
    if given is None:
        return tuple(f"{prefix}{i + 1}" for i in range(count))
    names = tuple(str(s) for s in given)
    if len(names) != count:
        raise Rt70Error(f"{len(names)} {what} names given for {count} {what}s")
    return names
