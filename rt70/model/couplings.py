"""How a drive's reducer meets the structure: the angle θ_d(q) and its generalised force.

A drive (:class:`rt70.control.drives.DcDrive`) sees the structure through one angle θ_d(q):
its reducer twist is ``Δ = θ_d − α_m / i_r`` (4.139), its damping acts on
``Δ̇ = θ̇_d − ω_m / i_r`` with ``θ̇_d = ∂θ_d/∂q · q̇``, and its reducer torque K pushes
``Q = K ∂θ_d/∂q`` on the mechanics. Taking the force as the gradient of the very angle
the twist is measured on makes the drive energy-consistent: the power ``q̇ᵀQ = K θ̇_d``
it gives the structure is what the reducer spring and damper pass on
(tests/test_drive_energy.py). A coupling is that angle:

- :class:`CoordinateCoupling`: θ_d is one coordinate (``q[k]``, ``Q = K e_k``), the
  first session's DcDrive on a coordinate;
- :class:`SceneCoupling`: θ_d of a scene's ``<rt70:drive>``, computed on one side
  (:mod:`rt70.textbook.drives` or :mod:`rt70.reference.drives`: a joint's coordinate,
  or a gear sector's mesh angle (4.150)).
"""

from __future__ import annotations

import numpy as np

from rt70.errors import Rt70Error
from rt70.model.sides import check_side, side_of
from rt70.urdf.description import Drive


class CoordinateCoupling:
    """θ_d = q[k]: a drive on one generalised coordinate.

    Parameters
    ----------
    coordinates : list of str
        The scene's coordinate names.
    coordinate : str
        The driven coordinate.
    owner : str
        Name used in the error message.

    Raises
    ------
    Rt70Error
        If ``coordinate`` is not among ``coordinates``.
    """

    def __init__(self, coordinates: list[str], coordinate: str, owner: str = "drive") -> None:
        if coordinate not in coordinates:
            raise Rt70Error(f"drive '{owner}': no coordinate '{coordinate}'")
        self.index = coordinates.index(coordinate)
        self.n = len(coordinates)

    def angle(self, q: np.ndarray) -> float:
        """θ_d = q_k, rad."""
        return float(q[self.index])

    def rate(self, q: np.ndarray, qd: np.ndarray) -> float:
        """θ̇_d = q̇_k, rad/s."""
        return float(qd[self.index])

    def force(self, q: np.ndarray, torque: float) -> np.ndarray:
        """``Q = K e_k``: the torque on the coordinate."""
        Q = np.zeros(self.n)
        Q[self.index] = torque
        return Q


class SceneCoupling:
    """θ_d of a scene drive (``<rt70:drive>``), computed on one side of the cross-check.

    The angle and its gradient come together from the side's ``drive_force`` (at unit
    torque) and are kept for the last q, so the force and the twist of one evaluation
    of the right-hand side cost one computation.

    Parameters
    ----------
    scene : rt70.model.scene.Scene
        The scene.
    drive : rt70.urdf.Drive
        One of ``scene.description.drives``.
    side : {"reference", "textbook"}
        Which side's kinematics computes θ_d (:mod:`rt70.model.sides`).

    Raises
    ------
    Rt70Error
        If ``side`` is not a side.
    """

    def __init__(self, scene, drive: Drive, side: str) -> None:
        try:
            check_side(side)
        except Rt70Error as exc:
            raise Rt70Error(f"drive '{drive.name}': {exc}") from None
        s = side_of(scene, side)
        self.drive = drive
        self.side = s.name
        self.n = len(scene.coordinate_names)
        #: The driven joint's coordinate (the axis angle an encoder reads).
        self.index = scene.coordinate_names.index(drive.joint)
        mesh = None if drive.sector is None else s.drives.sector_mesh(s.model, s.data, drive)
        # the reference side compiles it where it can (the same numbers)
        self._gradient = s.drives.drive_force_function(s.model, s.data, drive, mesh)
        self._key: bytes | None = None
        self._value: tuple[float, np.ndarray] = (0.0, np.zeros(self.n))

    def angle_gradient(self, q: np.ndarray) -> tuple[float, np.ndarray]:
        """``(θ_d, ∂θ_d/∂q)`` at q (kept for the last q)."""
        q = np.asarray(q, dtype=float)
        key = q.tobytes()
        if key != self._key:
            self._value = self._gradient(q)
            self._key = key
        return self._value

    def angle(self, q: np.ndarray) -> float:
        """θ_d(q), rad."""
        return self.angle_gradient(q)[0]

    def rate(self, q: np.ndarray, qd: np.ndarray) -> float:
        """θ̇_d = ∂θ_d/∂q · q̇, rad/s."""
        return float(self.angle_gradient(q)[1] @ qd)

    def force(self, q: np.ndarray, torque: float) -> np.ndarray:
        """``Q = K ∂θ_d/∂q``."""
        return torque * self.angle_gradient(q)[1]
