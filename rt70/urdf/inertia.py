"""Rotational inertias of links: what makes one impossible, and the opt-in repair.

A rigid body's rotational inertia is positive definite and its principal moments satisfy
the triangle inequality. rt70 refuses a moving link whose inertia breaks either rule; on
request it repairs it as MuJoCo's ``balanceinertia`` does (:func:`balanced_moments`) and
writes the repair into the text both sides read (:func:`balanced_text`).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np

from rt70.urdf.description import InertiaRepair
from rt70.urdf.text import RT70_NS

#: The triangle inequality is checked to this fraction of the largest principal moment:
#: a flat plate (``I₁ + I₂ = I₃`` exactly) written with ten significant digits passes.
INERTIA_RTOL = 1e-9

#: A principal moment within this many units in the last place of the inertia's scale
#: (:func:`inertia_scale`) of zero is zero to rounding: reading decimals (½ ulp per
#: entry), turning the tensor by ``<origin rpy>`` (a few ulps) and ``eigvalsh`` (a few
#: ulps of the largest moment) stay well inside it.
ZERO_ULPS = 32


def principal_moments(tensor: np.ndarray) -> np.ndarray:
    """Principal moments of a rotational inertia, ascending."""
    return np.linalg.eigvalsh(tensor)


def inertia_scale(tensor: np.ndarray, mass: float = 0.0, com=(0.0, 0.0, 0.0)) -> float:
    """The size of the terms a link's rotational inertia is used with: ``λ_max + m |c|²``.

    Both sides use the inertia about the link frame's origin,
    ``I_o = I_c + m (|c|² 1 − c cᵀ)`` (the textbook's Θ (4.77), the rotational block of
    Pinocchio's spatial inertia at the joint), so a principal moment of ``I_c`` below the
    rounding of these terms is indistinguishable from zero: ``λ_max`` the largest
    principal moment in magnitude, m the mass and c the centre of mass in the link frame
    (``<inertial><origin xyz>``).

    Parameters
    ----------
    tensor : numpy.ndarray
        Rotational inertia about the centre of mass, (3, 3), kg·m².
    mass : float
        The link's mass, kg.
    com : array_like
        The centre of mass in the link frame, m.

    Returns
    -------
    float
        The scale, kg·m².
    """
    moments = principal_moments(tensor)
    lever = float(np.dot(com, com))
    return float(np.max(np.abs(moments))) + abs(float(mass)) * lever


def zero_moment_tolerance(tensor: np.ndarray, mass: float = 0.0, com=(0.0, 0.0, 0.0)) -> float:
    """Principal moments within ± this of zero are zero to rounding: ``ZERO_ULPS · ε · scale``.

    Parameters
    ----------
    tensor : numpy.ndarray
        Rotational inertia about the centre of mass, (3, 3), kg·m².
    mass : float
        The link's mass, kg (0 for a tensor judged on its own).
    com : array_like
        The centre of mass in the link frame, (3,), m.

    Returns
    -------
    float
        The tolerance, kg·m² (the scale is :func:`inertia_scale`'s).
    """
    return ZERO_ULPS * float(np.finfo(float).eps) * inertia_scale(tensor, mass, com)


def is_point_mass(tensor: np.ndarray, mass: float, com=(0.0, 0.0, 0.0)) -> bool:
    """True if every principal moment is zero to rounding (:func:`zero_moment_tolerance`).

    A tensor written as zeros is a point mass (book §2.1); so is one whose moments are
    rounding noise of the inertia about the link frame (icub's ``head``: ``ixz =
    2.4e-35`` on 1.34 kg at 0.11 m, moments ±2.4e-35 against a scale of 0.017 kg·m²).
    A noise tensor at ``c = 0`` has only its own moments as a scale, so it is no point
    mass.

    Parameters
    ----------
    tensor : numpy.ndarray
        Rotational inertia about the centre of mass, (3, 3), kg·m².
    mass : float
        The link's mass, kg.
    com : array_like
        The centre of mass in the link frame, (3,), m.
    """
    if not np.any(tensor):
        return True
    tol = zero_moment_tolerance(tensor, mass, com)
    return bool(np.all(np.abs(principal_moments(tensor)) <= tol))


def inertia_defect(tensor: np.ndarray, mass: float = 0.0, com=(0.0, 0.0, 0.0)) -> str | None:
    """Why a rotational inertia is impossible, or None if it is a rigid body's.

    It must be positive definite — its smallest principal moment above zero by more than
    :func:`zero_moment_tolerance` — and its principal moments must satisfy the triangle
    inequality ``I₁ + I₂ ≥ I₃`` to ``INERTIA_RTOL · I₃`` plus that tolerance; or all its
    moments must be zero to rounding, a point mass (:func:`is_point_mass`).

    Parameters
    ----------
    tensor : numpy.ndarray
        Rotational inertia about the centre of mass, (3, 3), kg·m².
    mass : float
        The link's mass, kg (0 for a tensor judged on its own).
    com : array_like
        The centre of mass in the link frame, m.

    Returns
    -------
    str or None
        The defect, or None.
    """
    if is_point_mass(tensor, mass, com):
        return None
    moments = principal_moments(tensor)
    tol = zero_moment_tolerance(tensor, mass, com)
    if moments[0] <= tol:
        listed = ", ".join(f"{m:.6g}" for m in moments)
        return f"inertia tensor not positive definite (principal moments {listed})"
    if moments[2] > moments[0] + moments[1] + INERTIA_RTOL * moments[2] + tol:
        return (
            f"principal moment {moments[2]:.6g} exceeds the sum of the other "
            f"two ({moments[0]:.6g} + {moments[1]:.6g}): triangle inequality violated"
        )
    return None


def balanced_moments(tensor: np.ndarray) -> np.ndarray | None:
    """The repair of an impossible rotational inertia: its mean principal moment times 1.

    This is MuJoCo's ``<compiler balanceinertia="true">`` rule ("a valid diagonal inertia
    matrix must satisfy A+B>=C for all permutations of the three diagonal elements ...
    the compiler will silently set all three diagonal elements to their average value
    whenever the above condition is violated", MuJoCo XML reference, compiler/
    balanceinertia), applied to the principal moments and, in rt70, to every tensor
    :func:`inertia_defect` refuses (a negative moment always breaks the triangle
    inequality; a zero one, a rod, is refused by rt70 too). The trace — the sum of the
    moments, ``2 ∫ |r|² dm`` — is kept; the tensor becomes isotropic, so the frame of
    ``<inertial><origin rpy>`` no longer matters. Returns None when the trace is not
    positive (nothing to balance).
    """
    mean = float(np.trace(tensor)) / 3.0
    if not mean > 0.0:
        return None
    return np.full(3, mean)


def balanced_text(text: str, repairs: list[InertiaRepair]) -> str:
    """``text`` with each repaired link's ``<inertia>`` replaced by its balanced moments.

    The balanced tensor is isotropic (:func:`balanced_moments`), so it is written as
    ``ixx = iyy = izz``, products zero, whatever the ``<inertial><origin rpy>``: reading
    the result gives exactly the repaired description. This is the text handed to
    Pinocchio, so both sides read the same inertias. Comments and the XML declaration
    are not kept.
    """
    ET.register_namespace("rt70", RT70_NS)
    root = ET.fromstring(text)
    links = {elem.get("name"): elem for elem in root.findall("link")}
    for repair in repairs:
        inertia = links[repair.link].find("inertial").find("inertia")
        values = (*repair.new_moments, 0.0, 0.0, 0.0)
        for key, value in zip(("ixx", "iyy", "izz", "ixy", "ixz", "iyz"), values, strict=True):
            inertia.set(key, repr(float(value)))
    return ET.tostring(root, encoding="unicode")
