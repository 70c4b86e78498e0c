"""Compiled spring and damper forces of the reference side: the simulation's fast path.

:mod:`rt70.reference.forces` computes every element from Pinocchio's frame placements
and frame Jacobians — two dozen Python calls and a hundred small numpy operations per
evaluation of the RT-70, six times the cost of ``pin.aba`` itself. Here the same
deformations, forces, gains and potential come from one numba kernel that walks, for
each bushing, the joints between its two frames:

- ``frame i = Π_k (placement_k · X_k(q_k)) · P_i`` from the frames' lowest common
  ancestor down to each frame (the element depends on those joints only);
- ``δ = [r12; −rpy(c12ᵀ)]`` with ``c12 = R1ᵀ R2``, ``r12 = R1ᵀ (p2 − p1)`` — the
  definition of :func:`rt70.reference.forces.deformations`, so the two agree to rounding
  (tested on every scene);
- ``∂δ/∂q̇_k``: joint k moves one side relative to the other by the twist
  ``s_k (a_k, −a_k × o_k)`` (axis ``a_k`` through ``o_k``, in the ancestor's frame;
  ``s_k = +1`` on frame 2's branch, −1 on frame 1's), so ``ṙ12 = R1ᵀ (v + ω × p2)``
  and the rotation rows are ``J_W(ρ)⁻¹ R2ᵀ ω`` as on the Pinocchio path;
- ``τ_c = −Σ Jᵀ C δ``, ``τ_d = −Σ Jᵀ D δ̇``, gains ``Σ JᵀCJ``, ``Σ JᵀDJ`` (the
  Gauss–Newton part of ``−∂τ_c/∂q``, as :func:`rt70.reference.forces.element_gains`)
  and ``U_c = Σ ½ δᵀ C δ``, scattered only on each element's own joints.

Joint springs (δ = the joint's coordinate) are in the same kernel. The tables are
read once from Pinocchio's model (:mod:`rt70.reference.element_tables`); a model whose
elements cross a joint other than revolute, prismatic or continuous has no tables
(None) and keeps the Python path. The kernels (:mod:`rt70.reference.joint_walk`) are
compiled on first use and cached on disk (``cache=True``): a second process pays no
compilation. They use no BLAS (explicit 3×3 loops), so they import nothing beyond numba
and numpy. This module holds their Python face: :class:`ElementKernels` for the
elements, :class:`RelativePoints` for points of one body seen from another.
"""

from __future__ import annotations

import numpy as np

from rt70.errors import SingularConfigurationError
from rt70.reference.element_tables import Tables, pack, paths, tables
from rt70.reference.joint_walk import WORK_SMALL, evaluate_packed, relative_points, sector_angle
from rt70.reference.model import ReferenceModel


class ElementKernels:
    """The compiled forces, gains and potential of one model's elements.

    Same results as :func:`rt70.reference.forces.element_torques`,
    :func:`~rt70.reference.forces.element_gains` and
    :func:`~rt70.reference.forces.spring_potential`, in Pinocchio's (q, v) spaces.
    Build with :meth:`of`, which gives None when the model is not supported.

    ``guard`` (optional): the indices ``theta`` of angles in q that must keep
    ``|cos θ| ≥ theta_cos`` and the function that raises the detailed error when one
    does not (the simulation passes the book's Euler-pair check, so that the check
    costs nothing beside the kernel).
    """

    def __init__(self, model: ReferenceModel, found: Tables, guard=None) -> None:
        self.nv = model.pin_model.nv
        self.tables = found
        theta, self._theta_cos, self._raise = (
            (np.zeros(0, dtype=int), 0.0, None) if guard is None else guard
        )
        self._ints, self._floats = pack(found, theta)
        self._none = np.zeros((0, 0))
        self._work = np.zeros(12 * len(found.kind) + WORK_SMALL)

    @classmethod
    def of(cls, model: ReferenceModel, guard=None) -> ElementKernels | None:
        """The kernels of ``model``, or None if it is not supported.

        Not supported: what :func:`rt70.reference.element_tables.tables` gives no tables
        for. ``guard`` as in the class docstring.
        """
        found = tables(model)
        return None if found is None else cls(model, found, guard)

    def _run(self, qp, vp, gains, tau_c, tau_d, K, D) -> float:
        qp, vp = np.ascontiguousarray(qp, dtype=float), np.ascontiguousarray(vp, dtype=float)
        U, bad = evaluate_packed(qp, vp, gains, tau_c, tau_d, K, D, self._work, self._ints,
                                 self._floats, self._theta_cos)  # fmt: skip
        if bad == -2:
            self._raise(qp)
        if bad >= 0:
            raise SingularConfigurationError("bushing at Euler-angle gimbal lock (θ = ±π/2)")
        return U

    def torques(self, qp: np.ndarray, vp: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Spring and damper forces ``τ_c``, ``τ_d`` (as ``element_torques``)."""
        tau_c, tau_d = np.zeros(self.nv), np.zeros(self.nv)
        self._run(qp, vp, False, tau_c, tau_d, self._none, self._none)
        return tau_c, tau_d

    def torques_and_gains(
        self, qp: np.ndarray, vp: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``τ_c``, ``τ_d``, ``Σ JᵀCJ`` and ``Σ JᵀDJ`` in one pass (for a Jacobian)."""
        n = self.nv
        tau_c, tau_d, K, D = np.zeros(n), np.zeros(n), np.zeros((n, n)), np.zeros((n, n))
        self._run(qp, vp, True, tau_c, tau_d, K, D)
        return tau_c, tau_d, K, D

    def gains(self, qp: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``Σ JᵀCJ`` and ``Σ JᵀDJ`` (as ``element_gains``)."""
        n = self.nv
        K, D = np.zeros((n, n)), np.zeros((n, n))
        self._run(qp, np.zeros(n), True, np.zeros(n), np.zeros(n), K, D)
        return K, D

    def potential(self, qp: np.ndarray) -> float:
        """``U_c = Σ ½ δᵀ C δ`` (as ``spring_potential``)."""
        n = self.nv
        return self._run(qp, np.zeros(n), False, np.zeros(n), np.zeros(n), self._none, self._none)


class RelativePoints:
    """Compiled positions of points in other bodies' frames and their Jacobians.

    For pairs of frames ``(joint, SE3)``: frame 2's origin in frame 1's axes,
    ``r12 = R1ᵀ (p2 − p1)``, and ``∂r12/∂v`` (3 × nv, Pinocchio's v), from the same
    joint walk as the elements (:func:`rt70.reference.joint_walk.relative_points`). A
    gear sector's mesh point in its stator is one
    (:func:`rt70.reference.drives.drive_force_function`). Build with :meth:`of`, which
    gives None when a pair's path is not supported.
    """

    def __init__(self, model: ReferenceModel, found: dict[str, np.ndarray]) -> None:
        self.nv = model.pin_model.nv
        self.n = len(found["split"])
        self.v_index = found["v_index"]
        names = ("start", "split", "kind", "q_index", "axis", "place_R", "place_p")
        self._args = tuple(found[k] for k in names + ("frame_R", "frame_p"))
        self.start = found["start"]
        self._work = np.zeros(12 * len(found["kind"]) + WORK_SMALL)
        self._jac = np.zeros((len(found["kind"]), 6))

    @classmethod
    def of(cls, model: ReferenceModel, frames1, frames2) -> RelativePoints | None:
        """The kernels of these pairs, or None if their paths are not supported.

        Parameters
        ----------
        model : ReferenceModel
            The reference model.
        frames1, frames2 : sequence of (int, pinocchio.SE3)
            Frame 1 and frame 2 of each pair: Pinocchio's parent joint and the frame's
            placement in it (:func:`rt70.reference.element_tables.paths`, which gives
            None for a path through a joint other than revolute, prismatic or
            continuous).
        """
        found = paths(model, frames1, frames2)
        return None if found is None else cls(model, found)

    def frames(self, qp: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(c12, r12, J)``: frame 2's rotation and origin in frame 1, and their Jacobian.

        Shapes (n, 3, 3), (n, 3) and (n, 6, nv): ``J = [∂r12/∂v; ∂ω12/∂v]``, the origin's
        velocity and frame 2's angular velocity relative to frame 1, in frame 1's axes.
        """
        c, r = np.zeros((self.n, 3, 3)), np.zeros((self.n, 3))
        qp = np.ascontiguousarray(qp, dtype=float)
        relative_points(qp, self._work, *self._args, c, r, self._jac)
        J = np.zeros((self.n, 6, self.nv))
        for b in range(self.n):
            lo, hi = self.start[b], self.start[b + 1]
            J[b][:, self.v_index[lo:hi]] = self._jac[lo:hi].T
        return c, r, J

    def __call__(self, qp: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(r12, ∂r12/∂v)`` of every pair: shapes (n, 3) and (n, 3, nv)."""
        _, r, J = self.frames(qp)
        return r, J[:, :3]

    def sector_angle(
        self, qp: np.ndarray, centre: np.ndarray, u: np.ndarray, v: np.ndarray
    ) -> tuple[float, np.ndarray]:
        """A gear sector's ``(θ_d, ∂θ_d/∂v)`` from pair 0 (stator, mesh point), compiled.

        ``θ_d = atan2(v·d, u·d)`` with ``d = r12 − centre`` (the pitch circle's centre and
        in-plane axes ``u``, ``v`` in the stator's frame, :class:`rt70.physics.loads.SectorMesh`):
        :func:`rt70.reference.joint_walk.sector_angle`.

        Parameters
        ----------
        qp : numpy.ndarray, shape (nq,)
            Pinocchio's configuration.
        centre, u, v : numpy.ndarray, shape (3,)
            The pitch circle's centre (m) and its in-plane unit axes, in the stator's frame.
        """
        c, r, gradient = np.empty((self.n, 3, 3)), np.empty((self.n, 3)), np.empty(self.nv)
        qp = np.ascontiguousarray(qp, dtype=float)
        angle = sector_angle(qp, self._work, *self._args, c, r, self._jac, self.v_index,
                             centre, u, v, gradient)  # fmt: skip
        return float(angle), gradient
