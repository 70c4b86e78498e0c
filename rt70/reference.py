"""The reference side: Pinocchio's recursive algorithms on the same URDF scene.

Pinocchio parses the URDF itself and provides CRBA, RNEA, ABA, gravity and energies.
Pinocchio has no springs: their generalised forces are computed here from Pinocchio's
own kinematics — frame placements and frame Jacobians of the attachment points,
Pinocchio's roll-pitch-yaw Jacobian for the Euler-angle rates — and passed as ``tau``.
No textbook-side code is used for any of it; only the scene's extension data (gains,
attachment frames, gravity) comes from rt70's URDF description.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin

from rt70.errors import Rt70Error, SingularConfigurationError, UrdfError
from rt70.urdf.description import FrameRef, RobotDescription

#: Same threshold as the textbook side: |cos θ| of the 1–2–3 angles below it is gimbal lock.
GIMBAL_LOCK_COS = 1e-8


@dataclass(frozen=True)
class _Bushing:
    frame1: int
    frame2: int
    stiffness: np.ndarray
    damping: np.ndarray


class ReferenceModel:
    """Pinocchio model, data and spring elements of one scene.

    Parameters
    ----------
    desc : RobotDescription
        The scene as read by :func:`rt70.urdf.read_urdf` (validated).
    urdf_text : str
        The URDF text itself, handed to Pinocchio's own parser.
    """

    def __init__(self, desc: RobotDescription, urdf_text: str) -> None:
        try:
            self.model = pin.buildModelFromXML(urdf_text)
        except (RuntimeError, ValueError) as exc:
            raise UrdfError(f"{desc.source}: Pinocchio cannot load it: {exc}") from None
        self.model.gravity.linear = np.asarray(desc.gravity, dtype=float)
        self.model.armature[:] = 0.0
        self.bushings = [
            _Bushing(
                self._add_frame(f"{b.name}#1", b.frame1),
                self._add_frame(f"{b.name}#2", b.frame2),
                np.asarray(b.stiffness),
                np.asarray(b.damping),
            )
            for b in desc.bushings
        ]
        self.spring_v = np.array(
            [self.model.idx_vs[self.model.getJointId(s.joint)] for s in desc.joint_springs],
            dtype=int,
        )
        self.spring_q = np.array(
            [self.model.idx_qs[self.model.getJointId(s.joint)] for s in desc.joint_springs],
            dtype=int,
        )
        self.spring_k = np.array([s.stiffness for s in desc.joint_springs], dtype=float)
        self.spring_d = np.array([s.damping for s in desc.joint_springs], dtype=float)
        self.data = self.model.createData()
        self.model_no_gravity = self.model.copy()
        self.model_no_gravity.gravity.setZero()
        self.data_no_gravity = self.model_no_gravity.createData()

    @classmethod
    def from_file(cls, desc: RobotDescription, path: str | Path) -> ReferenceModel:
        """Build from a URDF file already read into ``desc``."""
        return cls(desc, Path(path).read_text(encoding="utf-8"))

    @property
    def nv(self) -> int:
        """Number of velocity coordinates."""
        return self.model.nv

    def _add_frame(self, name: str, ref: FrameRef) -> int:
        body = self.model.getFrameId(ref.link, pin.BODY)
        if body >= len(self.model.frames):
            raise Rt70Error(f"Pinocchio has no frame for link '{ref.link}'")
        parent = self.model.frames[body]
        offset = pin.SE3(pin.rpy.rpyToMatrix(*ref.rpy), np.asarray(ref.xyz, dtype=float))
        frame = pin.Frame(name, parent.parentJoint, body, parent.placement * offset, pin.OP_FRAME)
        return self.model.addFrame(frame, False)

    def coordinate_index(self, joint_names: list[str]) -> np.ndarray:
        """Velocity index in Pinocchio of each named 1-DOF joint."""
        return np.array([self.model.idx_vs[self.model.getJointId(n)] for n in joint_names])

    # --- dynamics --------------------------------------------------------------------
    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        """``pin.crba``, symmetrised."""
        A = pin.crba(self.model, self.data, q)
        return np.triu(A) + np.triu(A, 1).T

    def bias_force(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """``B(q, q̇) q̇ = rnea(q, q̇, 0)`` with gravity switched off."""
        return pin.rnea(self.model_no_gravity, self.data_no_gravity, q, v, np.zeros(self.nv))

    def gravity_force(self, q: np.ndarray) -> np.ndarray:
        """Generalised gravity force on the right-hand side: ``−g(q)``."""
        return -pin.computeGeneralizedGravity(self.model, self.data, q)

    def spring_damper_force(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Spring and damper generalised forces from Pinocchio's frame kinematics."""
        Qc = np.zeros(self.nv)
        Qd = np.zeros(self.nv)
        np.subtract.at(Qc, self.spring_v, self.spring_k * q[self.spring_q])
        np.subtract.at(Qd, self.spring_v, self.spring_d * v[self.spring_v])
        if self.bushings:
            pin.computeJointJacobians(self.model, self.data, q)
            pin.updateFramePlacements(self.model, self.data)
            for b in self.bushings:
                delta, jac = self._deformation(b)
                Qc -= jac.T @ (b.stiffness * delta)
                Qd -= jac.T @ (b.damping * (jac @ v))
        return Qc, Qd

    def _deformation(self, b: _Bushing) -> tuple[np.ndarray, np.ndarray]:
        """δ = [position of frame 2 in frame 1; 1–2–3 angles], and ∂δ/∂q."""
        m, d = self.model, self.data
        M12 = d.oMf[b.frame1].actInv(d.oMf[b.frame2])
        c12 = M12.rotation
        # c12 = Rx(β) Ry(θ) Rz(α), so c12ᵀ = Rz(−α) Ry(−θ) Rx(−β): Pinocchio's rpy of c12ᵀ
        # is −[β, θ, α].
        rho = pin.rpy.matrixToRpy(c12.T)
        if abs(np.cos(rho[1])) < GIMBAL_LOCK_COS:
            raise SingularConfigurationError("bushing at Euler-angle gimbal lock (θ = ±π/2)")
        J1 = pin.getFrameJacobian(m, d, b.frame1, pin.LOCAL)
        J2 = pin.getFrameJacobian(m, d, b.frame2, pin.LOCAL)
        J_rel = J2 - M12.inverse().toActionMatrix() @ J1
        jac = np.empty_like(J_rel)
        jac[:3] = c12 @ J_rel[:3]
        # ω (frame-2 axes) of c12 is the world-frame rate of c12ᵀ with the sign flipped:
        # ω = J_W(ρ) φ̇, hence φ̇ = J_W(ρ)⁻¹ ω.
        jac[3:] = pin.rpy.computeRpyJacobianInverse(rho, pin.WORLD) @ J_rel[3:]
        return np.concatenate([M12.translation, -rho]), jac

    def forward_dynamics(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """``pin.aba`` with the spring and damper forces as ``tau``."""
        Qc, Qd = self.spring_damper_force(q, v)
        return pin.aba(self.model, self.data, q, v, Qc + Qd)

    # --- energies --------------------------------------------------------------------
    def kinetic_energy(self, q: np.ndarray, v: np.ndarray) -> float:
        """``pin.computeKineticEnergy``."""
        return float(pin.computeKineticEnergy(self.model, self.data, q, v))

    def gravity_potential(self, q: np.ndarray) -> float:
        """``pin.computePotentialEnergy`` (gravity only)."""
        return float(pin.computePotentialEnergy(self.model, self.data, q))

    def spring_potential(self, q: np.ndarray) -> float:
        """``Σ ½ δᵀ C δ`` with δ from Pinocchio's frame placements."""
        U = 0.5 * float(np.sum(self.spring_k * q[self.spring_q] ** 2))
        if self.bushings:
            pin.computeJointJacobians(self.model, self.data, q)
            pin.updateFramePlacements(self.model, self.data)
            for b in self.bushings:
                delta, _ = self._deformation(b)
                U += 0.5 * float(delta @ (b.stiffness * delta))
        return U
