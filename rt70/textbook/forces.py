"""Spring and damper generalised forces of the textbook side (formalism §4.4).

Every elastic element is defined by its deformation δ(q): its potential is
``U = ½ δᵀ C δ``, its force ``Q_c = −(∂δ/∂q)ᵀ C δ`` and its damper's force
``Q_d = −(∂δ/∂q)ᵀ D δ̇`` with ``δ̇ = (∂δ/∂q) q̇`` (C and D symmetric positive
semi-definite; a bushing's are 6 × 6 matrices, which may couple its axes) —
conservative by construction, so the energy audit (1.73) closes. The book's direct
pair (4.83) and strut package (4.85)–(4.110) are both bushings between two frames.

The element kinds are listed once, in :data:`ELEMENTS`: the ``RobotDescription`` list
each is read into, and the function giving the deformations of all its elements
(:class:`CoordinateElements` when each δ is a pair coordinate, :class:`GeneralElements`
with a δ and a dense ∂δ/∂q per element otherwise — one :class:`Deformation` each, the
readable form; bushings are computed all at once by its vectorised twin). The sums over them —
:func:`spring_damper_force`, :func:`spring_potential` — are written once, for every kind.
The reference side (:mod:`rt70.reference.forces`) lists the same kinds, computed
independently from Pinocchio's kinematics.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from rt70.errors import SingularConfigurationError
from rt70.guards.arrays import check_vector
from rt70.textbook import modal_bodies
from rt70.textbook.data import Data
from rt70.textbook.kinematics import (
    frame_jacobian,
    frame_pose,
    update_structure,
)
from rt70.textbook.model import BushingModel, Model
from rt70.textbook.spatial import (
    GIMBAL_LOCK_COS,
    euler123_angles,
    euler_matrix_inverse,
    placement,
)


@dataclass(frozen=True)
class Deformation:
    """Deformation δ of one elastic element and its Jacobian ``∂δ/∂q`` (6 × nv)."""

    delta: np.ndarray
    jacobian: np.ndarray


def bushing_deformation(data: Data, b: BushingModel) -> Deformation:
    """Deformation of a bushing: frame 2's position in frame 1, and its 1–2–3 angles.

    With ``V_rel`` the velocity of frame 2 relative to frame 1 in frame 2's axes,
    ``δ̇ = M⁻¹ V_rel``, ``M = diag(cᵀ, ε)`` (1.38), c the relative rotation — the
    kinematic Euler equations of one body (formalism §1), read backwards.
    """
    R1, p1 = frame_pose(data, b.body1, b.r1, b.c1)
    R2, p2 = frame_pose(data, b.body2, b.r2, b.c2)
    r12 = R1.T @ (p2 - p1)
    c12 = R1.T @ R2
    try:
        phi = euler123_angles(c12)
    except SingularConfigurationError as exc:
        raise SingularConfigurationError(f"bushing '{b.name}': {exc}") from None
    J1 = frame_jacobian(data, b.body1, b.r1, b.c1)
    J2 = frame_jacobian(data, b.body2, b.r2, b.c2)
    J_rel = J2 - placement(r12, c12).T @ J1
    jac = np.empty_like(J_rel)
    jac[:3] = c12 @ J_rel[:3]
    jac[3:] = euler_matrix_inverse(phi) @ J_rel[3:]
    return Deformation(np.concatenate([r12, phi]), jac)


@dataclass(frozen=True)
class CoordinateElements:
    """Elements of one kind whose deformation is one pair coordinate each (joint springs).

    ``δ_e = q_full[coords_e]``, so ``∂δ_e/∂q`` is row ``coords_e`` of G
    (``q_full = G q + q_offset``, the mimic constraints): ``Jᵀ f`` is ``f`` scattered on
    the pair coordinates and reduced, ``Gᵀ``, without forming J.

    Attributes
    ----------
    coords : numpy.ndarray
        Pair coordinate of each element, shape (n_e,).
    delta, stiffness, damping : numpy.ndarray
        δ, C and D of each element, shape (n_e,).
    """

    coords: np.ndarray
    delta: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray

    def rate(self, model: Model, qd: np.ndarray) -> np.ndarray:
        """``δ̇ = (∂δ/∂q) q̇`` of each element, shape (n_e,)."""
        return model.expand(qd, offset=False)[self.coords]

    def subtract_jt(self, model: Model, Q: np.ndarray, f: np.ndarray) -> None:
        """``Q −= Σ_e (∂δ_e/∂q)ᵀ f_e`` in place.

        Parameters
        ----------
        model : Model
            The textbook model (its mimic map reduces the pair coordinates to q).
        Q : numpy.ndarray, shape (nv,)
            A generalised force, N or N·m; changed in place.
        f : numpy.ndarray, shape (n_e,)
            One value per element, e.g. ``C δ``, N or N·m.
        """
        Q_full = np.zeros(model.n_full)
        np.subtract.at(Q_full, self.coords, f)
        Q += model.reduce(Q_full)

    def weighted(self, w: np.ndarray, x: np.ndarray) -> np.ndarray:
        """``W_e x_e`` of each element (``w``: one weight each, shape (n_e,))."""
        return w * x

    def squares(self, w: np.ndarray) -> list[float]:
        """``Σ_e δ_eᵀ W_e δ_e`` (``w``: one weight each), as a list of partial sums."""
        return [float(np.sum(w * self.delta**2))]


@dataclass(frozen=True)
class GeneralElements:
    """Elements of one kind with a deformation and a dense Jacobian each (bushings).

    Attributes
    ----------
    delta : numpy.ndarray
        δ of each element, shape (n_e, k).
    jacobian : numpy.ndarray
        ``∂δ/∂q`` of each element, shape (n_e, k, nv).
    stiffness, damping : numpy.ndarray
        C and D of each element, shape (n_e, k, k).
    """

    delta: np.ndarray
    jacobian: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray

    @classmethod
    def of(
        cls, deformations: list[Deformation], stiffness: np.ndarray, damping: np.ndarray
    ) -> GeneralElements:
        """The elements of a list of :class:`Deformation` (one per element), stacked.

        Parameters
        ----------
        deformations : list of Deformation
            One per element: δ (k,) and ∂δ/∂q (k, nv).
        stiffness, damping : numpy.ndarray, shape (n_e, k, k)
            Each element's C (N/m, N·m/rad) and D (N·s/m, N·m·s/rad).
        """
        return cls(
            np.array([d.delta for d in deformations]),
            np.array([d.jacobian for d in deformations]),
            stiffness,
            damping,
        )

    def rate(self, model: Model, qd: np.ndarray) -> np.ndarray:
        """``δ̇ = (∂δ/∂q) q̇`` of each element, shape (n_e, k)."""
        return self.jacobian @ qd

    def subtract_jt(self, model: Model, Q: np.ndarray, f: np.ndarray) -> None:
        """``Q −= Σ_e (∂δ_e/∂q)ᵀ f_e`` in place.

        Parameters
        ----------
        model : Model
            The textbook model (unused: these Jacobians are already on q).
        Q : numpy.ndarray, shape (nv,)
            A generalised force, N or N·m; changed in place.
        f : numpy.ndarray, shape (n_e, k)
            One k-vector per element, e.g. ``C δ``, N and N·m.
        """
        Q -= np.einsum("ekn,ek->n", self.jacobian, f)

    def weighted(self, w: np.ndarray, x: np.ndarray) -> np.ndarray:
        """``W_e x_e`` of each element (``w``: (n_e, k, k), ``x``: (n_e, k))."""
        return np.einsum("ekl,el->ek", w, x)

    def squares(self, w: np.ndarray) -> list[float]:
        """``δ_eᵀ W_e δ_e`` of each element (``w``: (n_e, k, k))."""
        return np.einsum("ek,ek->e", self.delta, self.weighted(w, self.delta)).tolist()


Elements = CoordinateElements | GeneralElements


def joint_spring_elements(model: Model, data: Data) -> CoordinateElements | None:
    """Joint springs (``<rt70:joint_spring>``): δ is the joint's coordinate (4.83)."""
    if not model.spring_coords.size:
        return None
    idx = model.spring_coords
    return CoordinateElements(idx, data.q_full[idx], model.spring_stiffness, model.spring_damping)


def bushing_deformations(model: Model, data: Data) -> tuple[np.ndarray, np.ndarray]:
    """δ (n_b, 6) and ``∂δ/∂q`` (n_b, 6, nv) of every bushing, all at once.

    :func:`bushing_deformation` on every bushing of the model: the same steps on stacks
    of bushings (numpy's batched products), so that a scene with tens of thousands of
    bushings costs a few array operations rather than a Python call each;
    :func:`bushing_deformation` is the readable form and the reference, and the tests
    hold the two equal.

    Raises
    ------
    SingularConfigurationError
        If a bushing is at gimbal lock (the message of :func:`bushing_deformation`).
    """
    bs = model.bushings
    body1, body2 = (np.array([getattr(b, k) for b in bs], dtype=int) for k in ("body1", "body2"))
    r1, c1, r2, c2 = (np.array([getattr(b, k) for b in bs]) for k in ("r1", "c1", "r2", "c2"))
    R1, p1 = _frame_poses(data, body1, r1, c1)
    R2, p2 = _frame_poses(data, body2, r2, c2)
    R1t = np.swapaxes(R1, -1, -2)
    r12 = (R1t @ (p2 - p1)[..., None])[..., 0]
    c12 = R1t @ R2
    cos_theta = np.hypot(c12[:, 0, 0], c12[:, 0, 1])
    locked = np.flatnonzero(cos_theta < GIMBAL_LOCK_COS)
    if locked.size:
        bushing_deformation(data, bs[int(locked[0])])  # raises, naming the bushing
    sin_theta = np.clip(c12[:, 0, 2], -1.0, 1.0)
    beta = np.arctan2(-c12[:, 1, 2], c12[:, 2, 2])
    theta = np.arctan2(sin_theta, cos_theta)
    alpha = np.arctan2(-c12[:, 0, 1], c12[:, 0, 0])
    J1 = _frame_jacobians(data, body1, r1, c1)
    J2 = _frame_jacobians(data, body2, r2, c2)
    J_rel = J2 - np.swapaxes(_placements(r12, c12), -1, -2) @ J1
    jac = np.empty_like(J_rel)
    jac[:, :3] = c12 @ J_rel[:, :3]
    jac[:, 3:] = _euler_matrix_inverses(theta, alpha) @ J_rel[:, 3:]
    return np.column_stack([r12, beta, theta, alpha]), jac


def _frame_poses(
    data: Data, body: np.ndarray, r: np.ndarray, c: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`~rt70.textbook.kinematics.frame_pose` of a stack of frames (body −1: ground)."""
    on_ground = body < 0
    R_body = np.where(on_ground[:, None, None], np.eye(3), data.R[body])
    p_body = np.where(on_ground[:, None], 0.0, data.p[body])
    return R_body @ c, p_body + (R_body @ r[..., None])[..., 0]


def _frame_jacobians(data: Data, body: np.ndarray, r: np.ndarray, c: np.ndarray) -> np.ndarray:
    """:func:`~rt70.textbook.kinematics.frame_jacobian` of a stack of frames, (n, 6, nv)."""
    nv = data.S.shape[0]
    S_body = data.S.reshape(nv, -1, 6)[:, np.maximum(body, 0)]  # (nv, n, 6)
    S_body = np.where((body < 0)[None, :, None], 0.0, S_body)
    return np.swapaxes(_placements(r, c), -1, -2) @ np.transpose(S_body, (1, 2, 0))


def _placements(r: np.ndarray, c: np.ndarray) -> np.ndarray:
    """:func:`~rt70.textbook.spatial.placement` ``T(r) [c]`` of a stack, (n, 6, 6)."""
    out = np.zeros((len(r), 6, 6))
    out[:, :3, :3] = c
    out[:, 3:, 3:] = c
    out[:, 3:, :3] = _skews(r) @ c
    return out


def _skews(x: np.ndarray) -> np.ndarray:
    """:func:`~rt70.textbook.spatial.skew` of a stack of vectors, (n, 3, 3)."""
    out = np.zeros((len(x), 3, 3))
    out[:, 0, 1], out[:, 0, 2] = -x[:, 2], x[:, 1]
    out[:, 1, 0], out[:, 1, 2] = x[:, 2], -x[:, 0]
    out[:, 2, 0], out[:, 2, 1] = -x[:, 1], x[:, 0]
    return out


def _euler_matrix_inverses(theta: np.ndarray, alpha: np.ndarray) -> np.ndarray:
    """:func:`~rt70.textbook.spatial.euler_matrix_inverse` of a stack of angles, (n, 3, 3)."""
    ct, st = np.cos(theta), np.sin(theta)
    ca, sa = np.cos(alpha), np.sin(alpha)
    out = np.zeros((len(theta), 3, 3))
    out[:, 0, 0], out[:, 0, 1] = ca / ct, -sa / ct
    out[:, 1, 0], out[:, 1, 1] = sa, ca
    out[:, 2, 0], out[:, 2, 1], out[:, 2, 2] = -st * ca / ct, st * sa / ct, 1.0
    return out


def bushing_elements(model: Model, data: Data) -> GeneralElements | None:
    """Bushings and struts (``<rt70:bushing>``, ``<rt70:strut_package>``), (4.85)–(4.110).

    Their deformations all at once (:func:`bushing_deformations`, the vectorised form of
    :func:`bushing_deformation`).
    """
    if not model.bushings:
        return None
    delta, jac = bushing_deformations(model, data)
    return GeneralElements(
        delta,
        jac,
        np.array([b.stiffness for b in model.bushings]),
        np.array([b.damping for b in model.bushings]),
    )


#: Every element kind of the textbook side: the ``RobotDescription`` list its elements are
#: read into → the function giving their deformations at the configuration of ``data``
#: (after :func:`~rt70.textbook.kinematics.update_structure`), None when the model has
#: none. In summation order; the reference side lists the same kinds (tested).
ELEMENTS: dict[str, Callable[[Model, Data], Elements | None]] = {
    "joint_springs": joint_spring_elements,
    "bushings": bushing_elements,
}


def elements(model: Model, data: Data, q: np.ndarray) -> list[Elements]:
    """The deformations of every element at ``q``, kind by kind (:data:`ELEMENTS`).

    Parameters
    ----------
    model : Model
        The textbook model.
    data : Data
        Its work buffers; the forward pass fills them.
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the model's order (``Model.coordinate_names``).
    """
    update_structure(model, data, q)
    found = (kind(model, data) for kind in ELEMENTS.values())
    return [e for e in found if e is not None]


def spring_damper_force(
    model: Model, data: Data, q: np.ndarray, qd: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Spring force ``Q_c = −Σ Jᵀ C δ`` and damper force ``Q_d = −Σ Jᵀ D J q̇`` (J = ∂δ/∂q).

    Parameters
    ----------
    model : Model
        The textbook model.
    data : Data
        Its work buffers; the forward pass fills them.
    q, qd : numpy.ndarray, shape (nv,)
        Generalised coordinates (rad or m) and velocities (rad/s or m/s) in the model's
        order (``Model.coordinate_names``).
    """
    q = check_vector("q", q, model.nv)
    qd = check_vector("qd", qd, model.nv)
    Qc = np.zeros(model.nv)
    Qd = np.zeros(model.nv)
    for e in elements(model, data, q):
        e.subtract_jt(model, Qc, e.weighted(e.stiffness, e.delta))
        e.subtract_jt(model, Qd, e.weighted(e.damping, e.rate(model, qd)))
    if model.modal:  # the modal bodies' own stiffness and damping on η
        Kc, Kd = modal_bodies.elastic_force(model, q, qd)
        Qc += Kc
        Qd += Kd
    return Qc, Qd


def spring_potential(model: Model, data: Data, q: np.ndarray) -> float:
    """Elastic potential ``Σ ½ δᵀ C δ`` of all elements.

    Parameters
    ----------
    model : Model
        The textbook model.
    data : Data
        Its work buffers; the forward pass fills them.
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, rad or m, in the model's order (``Model.coordinate_names``).
    """
    q = check_vector("q", q, model.nv)
    U = 0.0
    for e in elements(model, data, q):
        for square in e.squares(e.stiffness):
            U += 0.5 * square
    return U + modal_bodies.elastic_potential(model, q)
