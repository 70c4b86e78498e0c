"""Newton's step of a static equilibrium: the stiffness factorised once, or a clear error.

A stiffness singular to working precision means no equilibrium; the error names the
coordinates of its null space (the ones nothing holds), so the user knows what to hold,
lock or give a spring (:func:`rt70.linear.linearize.equilibrium`).
"""

from __future__ import annotations

import warnings

import numpy as np
import scipy.linalg

from rt70.errors import Rt70Error

#: An eigenvalue of a singular stiffness below this fraction of its largest is in its null
#: space (the coordinates an equilibrium error names; the stiffness is differenced to
#: about 1e-8 of its scale, so its rounding floor is far above machine precision).
NULL_RTOL = 1e-8


def factor(scene: str, K: np.ndarray, names: tuple[str, ...]):
    """Newton's step ``r ↦ K⁻¹ r`` on the free coordinates ``names``, K factorised once.

    A K singular to working precision (reciprocal condition number below ε, the test of
    :func:`scipy.linalg.solve`: no equilibrium) is a clear error naming the coordinates
    of its null space.

    Parameters
    ----------
    scene : str
        The scene's name (the error's first word).
    K : numpy.ndarray, shape (n, n)
        The stiffness on the free coordinates, N·m/rad or N/m.
    names : tuple of str
        The free coordinates' names, in K's order.
    """
    if not np.isfinite(K).all():
        raise Rt70Error(
            f"{scene}: the stiffness matrix overflows (a stiffness or mass near the "
            "largest floating-point number?)"
        )
    with warnings.catch_warnings():
        warnings.simplefilter("error", scipy.linalg.LinAlgWarning)
        try:
            lu = scipy.linalg.lu_factor(K)
            rcond, info = scipy.linalg.lapack.dgecon(lu[0], np.linalg.norm(K, 1), norm="1")
            if info == 0 and rcond >= np.finfo(float).eps:
                return lambda r: scipy.linalg.lu_solve(lu, r)
        except (np.linalg.LinAlgError, ValueError, scipy.linalg.LinAlgWarning):
            pass
    raise Rt70Error(
        f"{scene}: no static equilibrium: the free coordinates have no stiffness along "
        f"{null_coordinates(K, names)} (hold or lock them, or give them a spring)"
    )


def null_coordinates(K: np.ndarray, names: tuple[str, ...]) -> str:
    """The coordinates that K's (numerical) null space moves, as a quoted list."""
    w, V = np.linalg.eigh(0.5 * (K + K.T))
    null = V[:, np.abs(w) <= NULL_RTOL * max(float(np.abs(w).max()), np.finfo(float).tiny)]
    if null.size == 0:
        null = V[:, [int(np.argmin(np.abs(w)))]]
    weight = np.linalg.norm(null, axis=1)
    moved = [n for n, x in zip(names, weight, strict=True) if x >= 0.1 * weight.max()]
    return ", ".join(f"'{n}'" for n in moved[:8]) + (" …" if len(moved) > 8 else "")
