"""The two sides as the simulation sees them: q̈, the Jacobian and the energies of a state.

:func:`rt70.simulation.simulate.simulate` integrates ``A q̈ + B q̇ = Q_g + Q_c + Q_d + Q_u``
through one :class:`Backend` per side (:data:`BACKENDS`, by the side's name): the
reference side by Pinocchio's ABA with the spring and damper forces as ``tau`` and the
analytic Jacobian of ``computeABADerivatives``, the textbook side by the structured
``S Θ Sᵀ`` algorithm and a Cholesky solve, its Jacobian left to the solver's difference
quotients. Both take and return vectors in the file's coordinate order; both report the
energies of the energy audit, T, U_g and U_c (formalism §1, (1.73)); each closes the
scene's loops its own way (:meth:`Backend.constrained_accelerations`).
"""

from __future__ import annotations

import numpy as np

from rt70.errors import Rt70Error, SimulationError
from rt70.model.scene import Scene
from rt70.physics.baumgarte import Baumgarte, consistent_rhs, constraint_rhs
from rt70.physics.kkt import solve_kkt
from rt70.simulation.loop_constraints import Constraint, stacked
from rt70.textbook.spatial import DYNAMICS_GIMBAL_COS, check_euler_pairs, euler_theta_indices


class Backend:
    """Right-hand side, Jacobian and energies of one side of the cross-check."""

    #: The side (:data:`rt70.model.sides.SIDES`).
    side = ""

    def __init__(self, scene: Scene) -> None:
        self.scene = scene
        self.nv = scene.textbook.nv

    def accelerations(self, q, qd, Q_u) -> tuple[np.ndarray, np.ndarray]:
        """``(q̈, Q_d)``: the accelerations and the dampers' force (for the energy audit).

        Parameters
        ----------
        q : numpy.ndarray, shape (nv,)
            Generalised coordinates in the file's order, rad or m.
        qd : numpy.ndarray, shape (nv,)
            Their velocities, rad/s or m/s.
        Q_u : numpy.ndarray, shape (nv,), or None
            Generalised input force (drives, wind, extra states), N·m or N; None for none.
        """
        raise NotImplementedError

    def mass_matrix(self, q) -> np.ndarray:
        """A(q), shape (nv, nv), in the file's coordinate order."""
        raise NotImplementedError

    def jacobian(self, q, qd, Q_u) -> np.ndarray | None:
        """``∂(q̇, q̈)/∂(q, q̇)``, shape (2 nv, 2 nv), or None: the solver differences.

        Parameters
        ----------
        q, qd : numpy.ndarray, shape (nv,)
            The state: coordinates (rad or m) and velocities (rad/s or m/s).
        Q_u : numpy.ndarray, shape (nv,), or None
            Generalised input force, N·m or N (held constant in the derivative).
        """
        return None

    def energies(self, q, qd) -> tuple[float, float, float]:
        """``(T, U_g, U_c)``, J: kinetic, gravity and elastic energy at ``(q, q̇)``."""
        raise NotImplementedError

    def constrained_accelerations(
        self,
        q: np.ndarray,
        qd: np.ndarray,
        Q_u: np.ndarray | None,
        constraints: list[Constraint],
        stabilization: Baumgarte | None,
    ) -> tuple[np.ndarray, np.ndarray]:
        """``(q̈, Q_d)`` of the constrained equations (14) with Baumgarte's (2.2).

        Parameters
        ----------
        q, qd : numpy.ndarray, shape (nv,)
            The state: coordinates (rad or m) and velocities (rad/s or m/s).
        Q_u : numpy.ndarray, shape (nv,), or None
            Generalised input force, N·m or N; None for none.
        constraints : list of rt70.simulation.loop_constraints.Constraint
            The scene's loop closures on this side.
        stabilization : rt70.physics.baumgarte.Baumgarte or None
            Baumgarte's gains; None lets Φ drift.
        """
        raise NotImplementedError


class PinocchioBackend(Backend):
    """Pinocchio's ABA with springs as tau; analytic Jacobian from computeABADerivatives.

    The springs and dampers come from the compiled kernels of
    :mod:`rt70.reference.element_kernels` where the model allows (the same forces as
    :mod:`rt70.reference.forces`, tested); ``kernels=False`` keeps the Python path.
    """

    side = "reference"

    def __init__(self, scene: Scene, kernels: bool = True) -> None:
        super().__init__(scene)
        import pinocchio as pin

        from rt70 import reference

        self.pin, self.reference = pin, reference
        self.ref, self.rd = scene.reference, scene.reference_data
        self.direct = self.ref.identity_map  # book coordinates are Pinocchio's (q, v)
        self.theta = euler_theta_indices(scene.textbook)
        self.kernels = None
        if kernels and self.direct and (self.ref.bushings or self.ref.spring_v.size):
            from rt70.reference.element_kernels import ElementKernels

            guard = lambda q: check_euler_pairs(scene.textbook, q)  # noqa: E731
            self.kernels = ElementKernels.of(self.ref, (self.theta, DYNAMICS_GIMBAL_COS, guard))

    def mass_matrix(self, q):
        """Pinocchio's A(q) in the file's coordinate order."""
        return self.reference.mass_matrix(self.ref, self.rd, q)

    def _check_pairs(self, q) -> None:
        """check_euler_pairs, vectorised for the common case that nothing is near lock."""
        q_full = self.scene.textbook.expand(q)
        if self.theta.size and np.min(np.abs(np.cos(q_full[self.theta]))) < DYNAMICS_GIMBAL_COS:
            check_euler_pairs(self.scene.textbook, q_full)

    def torques(self, q, qd) -> tuple[np.ndarray, np.ndarray]:
        """Spring and damper forces τ_c, τ_d in Pinocchio's velocity space."""
        if self.kernels is not None:
            return self.kernels.torques(q, qd)
        return self.reference.element_torques(self.ref, self.rd, q, qd)

    def accelerations(self, q, qd, Q_u):
        """``(q̈, Q_d)`` by ABA with the springs and dampers as ``tau``.

        Parameters
        ----------
        q, qd : numpy.ndarray, shape (nv,)
            The state: coordinates (rad or m) and velocities (rad/s or m/s).
        Q_u : numpy.ndarray, shape (nv,), or None
            Generalised input force, N·m or N; None for none.
        """
        if self.kernels is None:  # the kernels check the pairs themselves
            self._check_pairs(q)
        reference, ref, rd = self.reference, self.ref, self.rd
        if not self.direct:  # general coordinates: through the book-coordinate map
            a = reference.forward_dynamics(ref, rd, q, qd)
            _, Qd = reference.spring_damper_force(ref, rd, q, qd)
            if Q_u is not None:
                a = a + np.linalg.solve(reference.mass_matrix(ref, rd, q), Q_u)
            return a, Qd
        Qc, Qd = self.torques(q, qd)
        tau = Qc + Qd if Q_u is None else Qc + Qd + Q_u
        return self.pin.aba(ref.pin_model, rd.pin_data, q, qd, tau), Qd

    def jacobian(self, q, qd, Q_u):
        """``∂(q̇, q̈)/∂(q, q̇)`` from computeABADerivatives and the springs' ``Σ JᵀCJ``, ``Σ JᵀDJ``.

        None when the book's coordinates are not Pinocchio's (q, v).

        Parameters
        ----------
        q, qd : numpy.ndarray, shape (nv,)
            The state: coordinates (rad or m) and velocities (rad/s or m/s).
        Q_u : numpy.ndarray, shape (nv,), or None
            Generalised input force, N·m or N (held constant in the derivative).
        """
        if not self.direct:
            return None
        reference, ref, rd, pin = self.reference, self.ref, self.rd, self.pin
        if self.kernels is not None:
            Qc, Qd, Kc, Dc = self.kernels.torques_and_gains(q, qd)
        else:
            Qc, Qd = reference.element_torques(ref, rd, q, qd)
            Kc, Dc = reference.element_gains(ref, rd, q)
        tau = Qc + Qd if Q_u is None else Qc + Qd + Q_u
        dq, dv, Minv = pin.computeABADerivatives(ref.pin_model, rd.pin_data, q, qd, tau)
        n = self.nv
        J = np.zeros((2 * n, 2 * n))
        J[:n, n:] = np.eye(n)
        Minv = np.triu(Minv) + np.triu(Minv, 1).T
        J[n:, :n] = dq - Minv @ Kc
        J[n:, n:] = dv - Minv @ Dc
        return J

    def energies(self, q, qd):
        """``(T, U_g, U_c)``, J, on Pinocchio's side (the elastic energy from the kernels)."""
        reference, ref, rd = self.reference, self.ref, self.rd
        if self.kernels is not None:
            U_c = self.kernels.potential(q)
        else:
            U_c = reference.spring_potential(ref, rd, q)
        return (
            reference.kinetic_energy(ref, rd, q, qd),
            reference.gravity_potential(ref, rd, q),
            U_c,
        )

    def constrained_accelerations(self, q, qd, Q_u, constraints, stabilization):
        """``(q̈, Q_d)``: Pinocchio's ``constraintDynamics`` on the loops it holds itself.

        The loops are those of the scene's Pinocchio model
        (:func:`rt70.reference.loops.constrained_forward_dynamics`); the dampers' force
        is for the energy audit.

        Parameters
        ----------
        q, qd : numpy.ndarray, shape (nv,)
            The state: coordinates (rad or m) and velocities (rad/s or m/s).
        Q_u : numpy.ndarray, shape (nv,), or None
            Generalised input force, N·m or N; None for none.
        constraints : list of rt70.simulation.loop_constraints.Constraint
            The scene's loop closures (Pinocchio's model holds the same).
        stabilization : rt70.physics.baumgarte.Baumgarte or None
            Baumgarte's gains; None lets Φ drift.
        """
        from rt70.reference import loops

        qdd, _ = loops.constrained_forward_dynamics(self.ref, self.rd, q, qd, Q_u, stabilization)
        _, Qd = self.reference.spring_damper_force(self.ref, self.rd, q, qd)
        return qdd, Qd


class TextbookBackend(Backend):
    """The structured S Θ Sᵀ algorithm; the Jacobian by finite differences (scipy's)."""

    side = "textbook"

    def __init__(self, scene: Scene) -> None:
        super().__init__(scene)
        from rt70.textbook import structured

        scene.textbook_data  # noqa: B018  (its memory guard covers the structured form too)
        self.structured = structured
        self.bdata = structured.BatchData(scene.textbook, 1)

    def mass_matrix(self, q):
        """The structured algorithm's A(q)."""
        return self.structured.mass_matrix(self.scene.textbook, self.bdata, q)

    def system(self, q, qd, Q_u) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(A, f, Q_d)`` of ``A q̈ = f``: f = gravity, springs, dampers, inputs − B q̇.

        Parameters
        ----------
        q, qd : numpy.ndarray, shape (nv,)
            The state: coordinates (rad or m) and velocities (rad/s or m/s).
        Q_u : numpy.ndarray, shape (nv,), or None
            Generalised input force, N·m or N; None for none.
        """
        from rt70.textbook import forces

        st, model = self.structured, self.scene.textbook
        check_euler_pairs(model, model.expand(q))
        A = st.mass_matrix(model, self.bdata, q)
        Qc, Qd = forces.spring_damper_force(model, self.scene.textbook_data, q, qd)
        rhs = st.gravity_force_batch(model, self.bdata, q[None])[0] + Qc + Qd
        rhs -= st.bias_force(model, self.bdata, q, qd)
        if Q_u is not None:
            rhs += Q_u
        return A, rhs, Qd

    def accelerations(self, q, qd, Q_u):
        """``(q̈, Q_d)``: :meth:`system` solved by Cholesky.

        Parameters
        ----------
        q, qd : numpy.ndarray, shape (nv,)
            The state: coordinates (rad or m) and velocities (rad/s or m/s).
        Q_u : numpy.ndarray, shape (nv,), or None
            Generalised input force, N·m or N; None for none.
        """
        import scipy.linalg

        A, rhs, Qd = self.system(q, qd, Q_u)
        try:
            factor = scipy.linalg.cho_factor(A)
        except np.linalg.LinAlgError:
            raise Rt70Error(f"{self.scene.name}: mass matrix not positive definite") from None
        return scipy.linalg.cho_solve(factor, rhs), Qd

    def energies(self, q, qd):
        """``(T, U_g, U_c)``, J, on the textbook's side."""
        from rt70.textbook import dynamics, forces

        model, data = self.scene.textbook, self.scene.textbook_data
        return (
            dynamics.kinetic_energy(model, data, q, qd),
            dynamics.gravity_potential(model, data, q),
            forces.spring_potential(model, data, q),
        )

    def constrained_accelerations(self, q, qd, Q_u, constraints, stabilization):
        """``(q̈, Q_d)``: the tree's ``A q̈ = f`` and the constraints by the KKT system.

        The range-space method of :func:`rt70.physics.kkt.solve_kkt` on :meth:`system`
        and the stacked rows of ``constraints``.

        Parameters
        ----------
        q, qd : numpy.ndarray, shape (nv,)
            The state: coordinates (rad or m) and velocities (rad/s or m/s).
        Q_u : numpy.ndarray, shape (nv,), or None
            Generalised input force, N·m or N; None for none.
        constraints : list of rt70.simulation.loop_constraints.Constraint
            The scene's loop closures on the textbook side.
        stabilization : rt70.physics.baumgarte.Baumgarte or None
            Baumgarte's gains; None lets Φ drift.
        """
        A, f, Qd = self.system(q, qd, Q_u)  # the tree's A q̈ = f
        phi, B, C = stacked(constraints, q, qd)
        g = consistent_rhs(B, constraint_rhs(C, B @ qd, phi, stabilization))
        try:
            sol = solve_kkt(A, B, f, g)
        except Rt70Error as exc:
            raise SimulationError(str(exc)) from None
        return sol.x, Qd


#: The backends by side, the ``side`` :func:`rt70.simulation.simulate.simulate` takes.
BACKENDS = {"reference": PinocchioBackend, "textbook": TextbookBackend}
