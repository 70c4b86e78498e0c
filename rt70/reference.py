"""The reference side: Pinocchio's recursive algorithms on the same URDF scene.

All methods take the state in the book's coordinates, in the user's order
(:func:`rt70.urdf.coordinate_names`: the file's depth-first order, the textbook side's):
one angle per revolute or continuous joint (Pinocchio stores cos/sin), one length per
prismatic joint, ``[x, y, z, β, θ, α]`` for a floating joint (Pinocchio: position and
quaternion, velocity ``v = M q̇`` with ``M = diag(cᵀ, ε)``), ``[x, y, α]`` for a planar
joint; mimic joints are not coordinates (``q_m = k q_s + o``). The map to Pinocchio's
``(q, v)`` and its Jacobian ``J`` (``v = J q̇``) are built here from Pinocchio's own
quaternion and roll-pitch-yaw functions, and every result is transformed back:
``A = Jᵀ A_pin J``, ``B q̇ = Jᵀ rnea(q, v, J̇ q̇)``, ``Q = Jᵀ τ`` (formalism §5).

Pinocchio parses the URDF itself and provides CRBA, RNEA, ABA, gravity and energies.
Pinocchio has no springs: their generalised forces are computed here from Pinocchio's
own kinematics — frame placements and frame Jacobians of the attachment points,
Pinocchio's roll-pitch-yaw Jacobian for the Euler-angle rates — and passed as ``tau``.
No textbook-side code is used for any of it; only the scene's extension data (gains,
attachment frames, gravity) comes from rt70's URDF description.
"""

from __future__ import annotations

import os
import sys
import tempfile
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin

from rt70.arrays import check_vector
from rt70.errors import Rt70Error, Rt70Warning, SingularConfigurationError, UrdfError
from rt70.resources import check_reference, run_with_stack
from rt70.urdf.coordinates import SUFFIXES, coordinate_names
from rt70.urdf.description import FrameRef, RobotDescription
from rt70.urdf.inertia import balanced_text
from rt70.urdf.text import prepare_text

#: Same threshold as the textbook side: |cos θ| of the 1–2–3 angles below it is gimbal lock.
GIMBAL_LOCK_COS = 1e-8


@dataclass(frozen=True)
class _Bushing:
    frame1: tuple[int, pin.SE3]  # (parent joint, placement in it)
    frame2: tuple[int, pin.SE3]
    stiffness: np.ndarray
    damping: np.ndarray


@dataclass(frozen=True)
class _Coordinate:
    """One Pinocchio joint seen in book coordinates."""

    joint: int
    kind: str  # "1dof", "continuous", "floating", "planar", "mimic"
    names: tuple[str, ...]
    iq: int
    iv: int
    book: int  # first book coordinate (for "mimic": the source's book coordinate)
    multiplier: float = 1.0
    offset: float = 0.0


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
        check_reference(desc)  # parser depth and memory, before Pinocchio sees the model
        self.model = _parse_urdf(urdf_text, desc.source)
        self.model.gravity.linear = np.asarray(desc.gravity, dtype=float)
        self.model.armature[:] = 0.0
        bodies = {f.name: f for f in self.model.frames if f.type == pin.BODY}
        self.bushings = [
            _Bushing(
                self._attachment(bodies, b.frame1),
                self._attachment(bodies, b.frame2),
                np.asarray(b.stiffness),
                np.asarray(b.damping),
            )
            for b in desc.bushings
        ]
        self._frames1 = [b.frame1 for b in self.bushings]
        self._frames2 = [b.frame2 for b in self.bushings]
        self._stiffness = np.array([b.stiffness for b in self.bushings]).reshape(-1, 6)
        self._damping = np.array([b.damping for b in self.bushings]).reshape(-1, 6)
        self._coordinates(desc)
        joint_id = {name: i for i, name in enumerate(self.model.names)}
        self.spring_v = np.array(
            [self.model.idx_vs[joint_id[s.joint]] for s in desc.joint_springs], dtype=int
        )
        self.spring_k = np.array([s.stiffness for s in desc.joint_springs], dtype=float)
        self.spring_d = np.array([s.damping for s in desc.joint_springs], dtype=float)
        self.data = self.model.createData()
        self.model_no_gravity = self.model.copy()
        self.model_no_gravity.gravity.setZero()
        self.data_no_gravity = self.model_no_gravity.createData()

    def _coordinates(self, desc: RobotDescription) -> None:
        """Book coordinates of every Pinocchio joint, numbered in the user's order.

        Pinocchio numbers sibling joints its own way; every result of this class is in
        the order of :func:`rt70.urdf.coordinate_names` (the file's depth-first order,
        the same as the textbook side's), so ``c.book`` is the user index of the
        joint's first coordinate.
        """
        m = self.model
        mimics = {j.name: j.mimic for j in desc.joints if j.mimic is not None}
        names = coordinate_names(desc)
        user = {n: i for i, n in enumerate(names)}
        coords: list[_Coordinate] = []
        seen: list[str] = []
        for i in range(1, m.njoints):
            name, jm = m.names[i], m.joints[i]
            short = jm.shortname()
            if short == "JointModelFreeFlyer":
                kind = "floating"
            elif short == "JointModelPlanar":
                kind = "planar"
            elif jm.nq == 2 and jm.nv == 1:
                kind = "continuous"
            elif jm.nq == 1 and jm.nv == 1:
                kind = "1dof"
            else:
                raise Rt70Error(
                    f"{desc.source}: joint '{name}': Pinocchio joint {short} unsupported"
                )
            if name in mimics:
                mimic = mimics[name]
                coords.append(
                    _Coordinate(
                        i,
                        "mimic-continuous" if kind == "continuous" else "mimic",
                        (),
                        jm.idx_q,
                        jm.idx_v,
                        user[mimic.joint],
                        mimic.multiplier,
                        mimic.offset,
                    )
                )
                continue
            labels = tuple(name + sfx for sfx in SUFFIXES.get(kind, ("",)))
            first = user.get(labels[0], -1)
            if [user.get(label) for label in labels] != list(range(first, first + len(labels))):
                raise Rt70Error(
                    f"{desc.source}: joint '{name}': Pinocchio's coordinates "
                    f"{', '.join(labels)} are not those rt70 reads from the file"
                )
            coords.append(_Coordinate(i, kind, labels, jm.idx_q, jm.idx_v, first))
            seen.extend(labels)
        if sorted(seen) != sorted(names):
            raise Rt70Error(
                f"{desc.source}: Pinocchio's coordinates differ from the file's: "
                f"{', '.join(sorted(set(seen) ^ set(names))[:5])}"
            )
        self.coords = coords
        self.coordinate_names = names
        self.identity_map = all(c.kind == "1dof" and c.book == c.iv for c in coords)

    @classmethod
    def from_file(cls, desc: RobotDescription, path: str | Path) -> ReferenceModel:
        """Build from a URDF file already read into ``desc`` (its repairs written in)."""
        text = Path(path).read_text(encoding="utf-8")
        if desc.inertia_repairs:  # read the repaired inertias, as the textbook side does
            text = balanced_text(prepare_text(text, desc.source), desc.inertia_repairs)
        return cls(desc, text)

    @property
    def nv(self) -> int:
        """Number of book coordinates (independent generalised coordinates)."""
        return len(self.coordinate_names)

    @staticmethod
    def _attachment(bodies: dict, ref: FrameRef) -> tuple[int, pin.SE3]:
        """Parent joint and placement in it of a frame fixed to a link.

        Kept as (joint, placement) rather than added to the model: ``Model.addFrame``
        searches every frame for a duplicate name, quadratic in the number of bushings.
        """
        if ref.link not in bodies:
            raise Rt70Error(f"Pinocchio has no frame for link '{ref.link}'")
        body = bodies[ref.link]
        offset = pin.SE3(pin.rpy.rpyToMatrix(*ref.rpy), np.asarray(ref.xyz, dtype=float))
        return body.parentJoint, body.placement * offset

    def coordinate_index(self, names: list[str]) -> np.ndarray:
        """Index among this model's book coordinates of each named coordinate."""
        position = {n: i for i, n in enumerate(self.coordinate_names)}
        return np.array([position[n] for n in names], dtype=int)

    # --- book coordinates -> Pinocchio ---------------------------------------------
    def to_pinocchio(self, q: np.ndarray, qd: np.ndarray | None = None):
        """Pinocchio's ``(q, v)``, the Jacobian ``J`` (``v = J q̇``) and ``J̇ q̇``.

        ``J`` is None when it is the identity (only 1-DOF joints in the user's order, no
        mimic); a mere reordering of 1-DOF joints is a permutation matrix. Every public
        method passes its state through here: a wrong shape raises
        :class:`~rt70.errors.ShapeError`, a NaN or infinity
        :class:`~rt70.errors.NonFiniteError` (as on the textbook side).
        """
        q = check_vector("q", q, self.nv)
        qd = None if qd is None else check_vector("qd", qd, self.nv)
        if self.identity_map:
            return q, qd, None, None
        m = self.model
        qp = np.zeros(m.nq)
        J = np.zeros((m.nv, self.nv))
        Jdqd = np.zeros(m.nv)
        qd_ = np.zeros(self.nv) if qd is None else qd
        for c in self.coords:
            b, iq, iv = c.book, c.iq, c.iv
            if c.kind == "1dof":
                qp[iq] = q[b]
                J[iv, b] = 1.0
            elif c.kind == "continuous":
                qp[iq : iq + 2] = np.cos(q[b]), np.sin(q[b])
                J[iv, b] = 1.0
            elif c.kind in ("mimic", "mimic-continuous"):
                angle = c.multiplier * q[b] + c.offset
                if c.kind == "mimic":
                    qp[iq] = angle
                else:
                    qp[iq : iq + 2] = np.cos(angle), np.sin(angle)
                J[iv, b] = c.multiplier
            elif c.kind == "floating":
                x, phi, dx, dphi = (
                    q[b : b + 3],
                    q[b + 3 : b + 6],
                    qd_[b : b + 3],
                    qd_[b + 3 : b + 6],
                )
                # c = Rx(β) Ry(θ) Rz(α); its transpose has Pinocchio rpy ρ = −φ
                rho = -phi
                rot = pin.rpy.rpyToMatrix(rho).T
                qp[iq : iq + 3] = x
                qp[iq + 3 : iq + 7] = pin.Quaternion(rot).coeffs()
                eps = pin.rpy.computeRpyJacobian(rho, pin.WORLD)
                J[iv : iv + 3, b : b + 3] = rot.T
                J[iv + 3 : iv + 6, b + 3 : b + 6] = eps
                omega = eps @ dphi
                eps_dot = pin.rpy.computeRpyJacobianTimeDerivative(rho, -dphi, pin.WORLD)
                Jdqd[iv : iv + 3] = -np.cross(omega, rot.T @ dx)
                Jdqd[iv + 3 : iv + 6] = eps_dot @ dphi
            else:  # planar: [x, y, α], v = [c3ᵀ (ẋ, ẏ); α̇] in the moving frame
                x, y, a = q[b : b + 3]
                ca, sa = np.cos(a), np.sin(a)
                qp[iq : iq + 4] = x, y, ca, sa
                J[iv : iv + 2, b : b + 2] = [[ca, sa], [-sa, ca]]
                J[iv + 2, b + 2] = 1.0
                dx, dy, da = qd_[b : b + 3]
                Jdqd[iv : iv + 2] = da * (-sa * dx + ca * dy), da * (-ca * dx - sa * dy)
        vp = None if qd is None else J @ qd
        return qp, vp, J, Jdqd

    # --- dynamics --------------------------------------------------------------------
    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        """``Jᵀ crba J``, symmetrised (``J`` includes the map to the user's order)."""
        qp, _, J, _ = self.to_pinocchio(q)
        A = pin.crba(self.model, self.data, qp)
        A = np.triu(A) + np.triu(A, 1).T
        return A if J is None else J.T @ A @ J

    def bias_force(self, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        """``B(q, q̇) q̇ = Jᵀ rnea(q, v, J̇ q̇)`` with gravity switched off."""
        qp, vp, J, Jdqd = self.to_pinocchio(q, qd)
        if J is None:
            return pin.rnea(self.model_no_gravity, self.data_no_gravity, qp, vp, np.zeros(self.nv))
        return J.T @ pin.rnea(self.model_no_gravity, self.data_no_gravity, qp, vp, Jdqd)

    def gravity_force(self, q: np.ndarray) -> np.ndarray:
        """Generalised gravity force on the right-hand side: ``−Jᵀ g(q)``."""
        qp, _, J, _ = self.to_pinocchio(q)
        g = pin.computeGeneralizedGravity(self.model, self.data, qp)
        return -g if J is None else -(J.T @ g)

    def spring_damper_force(self, q: np.ndarray, qd: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Spring and damper generalised forces from Pinocchio's frame kinematics."""
        qp, vp, J, _ = self.to_pinocchio(q, qd)
        Qc, Qd = self.element_torques(qp, vp)
        return (Qc, Qd) if J is None else (J.T @ Qc, J.T @ Qd)

    def element_torques(self, qp: np.ndarray, vp: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Spring and damper forces as Pinocchio joint torques τ_c, τ_d.

        ``qp``, ``vp`` are Pinocchio's own configuration and velocity (see
        :meth:`to_pinocchio`), and so are the results (its velocity space): the form
        ``pin.aba`` takes as ``tau``, used by the simulation's fast path.
        """
        nv = self.model.nv
        Qc, Qd = np.zeros(nv), np.zeros(nv)
        if self.spring_v.size:
            angles = self._joint_angles(qp)
            np.subtract.at(Qc, self.spring_v, self.spring_k * angles[self.spring_v])
            np.subtract.at(Qd, self.spring_v, self.spring_d * vp[self.spring_v])
        if self.bushings:
            delta, jac = self.deformations(qp)
            rate = jac @ vp  # δ̇ of every bushing, (n_b, 6)
            Qc -= np.einsum("bin,bi->n", jac, self._stiffness * delta)
            Qd -= np.einsum("bin,bi->n", jac, self._damping * rate)
        return Qc, Qd

    def element_gains(self, qp: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``Σ Jᵀ C J`` and ``Σ Jᵀ D J`` of the springs and dampers, in Pinocchio's space.

        ``−∂τ_c/∂v`` without the term of the deformation's second derivative (the
        Gauss–Newton part) and ``−∂τ_d/∂v`` exactly: what an implicit integrator's
        Jacobian needs besides ``pin.computeABADerivatives``.
        """
        n = self.model.nv
        K, D = np.zeros((n, n)), np.zeros((n, n))
        K[self.spring_v, self.spring_v] += self.spring_k
        D[self.spring_v, self.spring_v] += self.spring_d
        if self.bushings:
            _, jac = self.deformations(qp)
            K += np.einsum("bin,bi,bim->nm", jac, self._stiffness, jac)
            D += np.einsum("bin,bi,bim->nm", jac, self._damping, jac)
        return K, D

    def deformations(self, qp: np.ndarray, jacobian: bool = True):
        """δ of every bushing (n_b, 6) and ∂δ/∂v (n_b, 6, nv), from Pinocchio's kinematics.

        Frame placements ``oMi · placement`` and local frame Jacobians (Pinocchio's
        ``getFrameJacobian`` of a joint and a placement) come from Pinocchio; the
        relative placement, Pinocchio's roll-pitch-yaw of its transpose and the inverse
        world rpy Jacobian are evaluated for all bushings at once (the formulas of
        ``pin.rpy.matrixToRpy`` / ``computeRpyJacobianInverse``, checked against them in
        the tests). ``c12 = Rx(β) Ry(θ) Rz(α)`` has ``c12ᵀ`` with rpy ``ρ = −[β, θ, α]``;
        the angular velocity of frame 2 relative to frame 1 is ``ω = J_W(ρ) φ̇``.
        """
        m, d = self.model, self.data
        qp = check_vector("qp", qp, m.nq)
        if jacobian:
            pin.computeJointJacobians(m, d, qp)
        else:
            pin.forwardKinematics(m, d, qp)
        f1, f2 = self._frames1, self._frames2
        M1 = [d.oMi[joint] * placement for joint, placement in f1]
        M2 = [d.oMi[joint] * placement for joint, placement in f2]
        R1 = np.array([M.rotation for M in M1])
        R2 = np.array([M.rotation for M in M2])
        p1 = np.array([M.translation for M in M1])
        p2 = np.array([M.translation for M in M2])
        R1t = np.swapaxes(R1, -1, -2)
        c12 = R1t @ R2
        r12 = (R1t @ (p2 - p1)[..., None])[..., 0]
        ct = np.swapaxes(c12, -1, -2)  # ρ = rpy of c12ᵀ (Pinocchio's Rz(y) Ry(p) Rx(r))
        pitch = np.arctan2(-ct[:, 2, 0], np.hypot(ct[:, 0, 0], ct[:, 1, 0]))
        roll = np.arctan2(ct[:, 2, 1], ct[:, 2, 2])
        yaw = np.arctan2(ct[:, 1, 0], ct[:, 0, 0])
        cp = np.cos(pitch)
        if np.any(np.abs(cp) < GIMBAL_LOCK_COS):
            raise SingularConfigurationError("bushing at Euler-angle gimbal lock (θ = ±π/2)")
        delta = np.concatenate([r12, -np.stack([roll, pitch, yaw], axis=1)], axis=1)
        if not jacobian:
            return delta, None
        J1 = np.array([pin.getFrameJacobian(m, d, *f, pin.LOCAL) for f in f1]).reshape(-1, 6, m.nv)
        J2 = np.array([pin.getFrameJacobian(m, d, *f, pin.LOCAL) for f in f2]).reshape(-1, 6, m.nv)
        # J_rel = J2 − Ad(M12⁻¹) J1; δ̇_trans = c12 v_rel, φ̇ = J_W(ρ)⁻¹ ω_rel
        lin1 = J1[:, :3] - _skew(r12) @ J1[:, 3:]
        jac = np.empty_like(J2)
        jac[:, :3] = c12 @ J2[:, :3] - lin1
        w_rel = J2[:, 3:] - ct @ J1[:, 3:]
        cy, sy, tp = np.cos(yaw), np.sin(yaw), np.tan(pitch)
        inv = np.zeros((len(f1), 3, 3))
        inv[:, 0, 0], inv[:, 0, 1] = cy / cp, sy / cp
        inv[:, 1, 0], inv[:, 1, 1] = -sy, cy
        inv[:, 2, 0], inv[:, 2, 1], inv[:, 2, 2] = cy * tp, sy * tp, 1.0
        jac[:, 3:] = inv @ w_rel
        return delta, jac

    def _joint_angles(self, qp: np.ndarray) -> np.ndarray:
        """Coordinate of every 1-DOF joint, indexed by velocity index (cos/sin → angle)."""
        out = np.zeros(self.model.nv)
        for i in range(1, self.model.njoints):
            jm = self.model.joints[i]
            if jm.nv == 1 and jm.nq == 1:
                out[jm.idx_v] = qp[jm.idx_q]
            elif jm.nv == 1 and jm.nq == 2:
                out[jm.idx_v] = np.arctan2(qp[jm.idx_q + 1], qp[jm.idx_q])
        return out

    def forward_dynamics(self, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        """``pin.aba`` with the spring and damper forces as ``tau``, in book coordinates.

        With mimic joints (a constraint ABA cannot take) the reduced equations
        ``Jᵀ A J q̈ = Jᵀ (τ − rnea(q, v, J̇ q̇))`` are solved with Pinocchio's CRBA and RNEA.
        """
        qp, vp, J, Jdqd = self.to_pinocchio(q, qd)
        Qc, Qd = self.element_torques(qp, vp)
        tau = Qc + Qd
        if J is None:
            return pin.aba(self.model, self.data, qp, vp, tau)
        if J.shape[0] == J.shape[1]:
            vdot = pin.aba(self.model, self.data, qp, vp, tau)
            return np.linalg.solve(J, vdot - Jdqd)
        A = pin.crba(self.model, self.data, qp)
        A = np.triu(A) + np.triu(A, 1).T
        rhs = J.T @ (tau - pin.rnea(self.model, self.data, qp, vp, Jdqd))
        return np.linalg.solve(J.T @ A @ J, rhs)

    # --- energies --------------------------------------------------------------------
    def kinetic_energy(self, q: np.ndarray, qd: np.ndarray) -> float:
        """``pin.computeKineticEnergy``."""
        qp, vp, _, _ = self.to_pinocchio(q, qd)
        return float(pin.computeKineticEnergy(self.model, self.data, qp, vp))

    def gravity_potential(self, q: np.ndarray) -> float:
        """``pin.computePotentialEnergy`` (gravity only)."""
        qp, _, _, _ = self.to_pinocchio(q)
        return float(pin.computePotentialEnergy(self.model, self.data, qp))

    def spring_damper_magnitudes(
        self, q: np.ndarray, qd: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """Sizes of the terms of the spring and damper forces: ``Σ_e |J_e|ᵀ |C_e δ_e|``.

        The same sums as :meth:`spring_damper_force` with every term taken by its
        absolute value (joint springs ``|k q|``, bushings ``|∂δ/∂q|ᵀ |C δ|`` and
        ``|∂δ/∂q|ᵀ |D δ̇|``): forces of elements that oppose each other cancel in the
        sum but not here. The natural scale of :func:`rt70.validate.natural_scales`.
        """
        qp, vp, J, _ = self.to_pinocchio(q, qd)
        nv = self.model.nv
        Sc, Sd = np.zeros(nv), np.zeros(nv)
        if self.spring_v.size:
            angles = self._joint_angles(qp)
            np.add.at(Sc, self.spring_v, np.abs(self.spring_k * angles[self.spring_v]))
            np.add.at(Sd, self.spring_v, np.abs(self.spring_d * vp[self.spring_v]))
        if self.bushings:
            delta, jac = self.deformations(qp)
            rate = jac @ vp
            Sc += np.einsum("bin,bi->n", np.abs(jac), np.abs(self._stiffness * delta))
            Sd += np.einsum("bin,bi->n", np.abs(jac), np.abs(self._damping * rate))
        return (Sc, Sd) if J is None else (np.abs(J).T @ Sc, np.abs(J).T @ Sd)

    def weight_moment(self, q: np.ndarray) -> float:
        """``G₀ = Σ_b m_b |g| |c_b|``: the moment of the weights about the ground origin.

        ``c_b`` is body b's centre of mass in the ground frame (Pinocchio's joint
        placements ``oMi`` and inertia levers). It is the size of the terms that gravity
        torques and the gravity potential are sums and differences of (the natural
        scale of :func:`rt70.validate.natural_scales`), in N·m = J.
        """
        qp, _, _, _ = self.to_pinocchio(q)
        pin.forwardKinematics(self.model, self.data, qp)
        g = float(np.linalg.norm(self.model.gravity.linear))
        total = 0.0
        for i in range(1, self.model.njoints):
            inertia = self.model.inertias[i]
            com = self.data.oMi[i].act(inertia.lever)
            total += inertia.mass * g * float(np.linalg.norm(com))
        return total

    def spring_potential(self, q: np.ndarray) -> float:
        """``Σ ½ δᵀ C δ`` with δ from Pinocchio's frame placements."""
        qp, _, _, _ = self.to_pinocchio(q)
        U = 0.0
        if self.spring_v.size:
            angles = self._joint_angles(qp)
            U += 0.5 * float(np.sum(self.spring_k * angles[self.spring_v] ** 2))
        if self.bushings:
            delta, _ = self.deformations(qp, jacobian=False)
            U += 0.5 * float(np.sum(self._stiffness * delta**2))
        return U


def _parse_urdf(text: str, source: str) -> pin.Model:
    """``pin.buildModelFromXML`` with its parser's messages turned into rt70's.

    urdfdom (Pinocchio's parser) prints what it skips or rejects to the process's stderr
    (``Error: <message>`` and an ``at line N in <file>.cpp`` line) and raises a generic
    exception. Its stderr is captured: when it fails, its first message (naming the
    element) is the :class:`~rt70.errors.UrdfError`; when it succeeds, each distinct
    message is an :class:`~rt70.errors.Rt70Warning` (something was skipped).
    """
    sys.stderr.flush()
    saved = os.dup(2)
    error = None
    with tempfile.TemporaryFile() as capture:
        os.dup2(capture.fileno(), 2)
        try:
            # on a large stack: urdfdom recurses per level of the tree
            model = run_with_stack(lambda: pin.buildModelFromXML(text))
        except (RuntimeError, ValueError) as exc:
            error = exc
        finally:
            os.dup2(saved, 2)
            os.close(saved)
        capture.seek(0)
        chatter = capture.read().decode("utf-8", errors="replace")
    messages = []
    for line in chatter.splitlines():
        head, _, message = line.strip().partition(":")
        if head in ("Error", "Warning") and message.strip() and message.strip() not in messages:
            messages.append(" ".join(message.split()))
    if error is not None:
        detail = f"{messages[0]} ({error})" if messages else str(error)
        raise UrdfError(f"{source}: Pinocchio cannot load it: {detail}") from None
    for message in messages:
        warnings.warn(Rt70Warning(f"{source}: Pinocchio's URDF parser: {message}"), stacklevel=3)
    return model


def _skew(x: np.ndarray) -> np.ndarray:
    """Skew matrices of an array of 3-vectors (n, 3) → (n, 3, 3)."""
    out = np.zeros(x.shape + (3,))
    out[:, 0, 1], out[:, 0, 2], out[:, 1, 2] = -x[:, 2], x[:, 1], -x[:, 0]
    out[:, 1, 0], out[:, 2, 0], out[:, 2, 1] = x[:, 2], -x[:, 1], x[:, 0]
    return out
