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

#: Principal moments are checked to this fraction of the largest one (rounding of eigvalsh).
INERTIA_RTOL = 1e-9


def principal_moments(tensor: np.ndarray) -> np.ndarray:
    """Principal moments of a rotational inertia, ascending."""
    return np.linalg.eigvalsh(tensor)


def inertia_defect(tensor: np.ndarray) -> str | None:
    """Why a non-zero rotational inertia is impossible, or None if it is a rigid body's.

    It must be positive definite and its principal moments must satisfy the triangle
    inequality ``I₁ + I₂ ≥ I₃`` (to :data:`INERTIA_RTOL` of the largest moment).
    """
    moments = principal_moments(tensor)
    scale = max(float(np.max(np.abs(moments))), np.finfo(float).tiny)
    if moments[0] <= 0.0:
        listed = ", ".join(f"{m:.6g}" for m in moments)
        return f"inertia tensor not positive definite (principal moments {listed})"
    if moments[2] > moments[0] + moments[1] + INERTIA_RTOL * scale:
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
