"""The extra states' couplings in the Jacobian: differences over the columns that reach them.

The backend's analytic Jacobian is ``∂(q̇, q̈)/∂(q, q̇)`` at a fixed input force ``Q_u``.
A component that pushes a force on the mechanics (:meth:`StateComponent.force`: a drive's
motor torque through its reducer) makes ``Q_u`` depend on its own states and on the
coordinates it reads, and its states' derivatives depend on the mechanics: without
those terms the implicit methods' Newton iteration treats the drives explicitly, and
LSODA took a new Jacobian every 2.5 evaluations holding ``rt70_servo``.

:class:`Coupling` finds once, at the start, which columns of ``x = [q, q̇, s]`` reach
``Q_u`` or a pushing component's derivative (a drive reads its axis and motor
coordinates, not the structure's hundreds), and at every Jacobian replaces those
columns' ``q̈`` rows and the pushing components' rows by forward differences of the
right-hand side, one evaluation per column, step ``√ε · max(|x_j|, 1)``. The columns
of the other states and the rows of components that only watch (the energy audit: a
quadrature that feeds nothing back) stay as they are.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

from rt70.simulation.states import MechanicsForces, StateLayout

#: Relative forward-difference step (the square root of the machine epsilon).
FD_RSTEP = float(np.sqrt(np.finfo(float).eps))


class Coupling:
    """The columns and rows the components couple, found at ``(t, x)`` (module docstring).

    Parameters
    ----------
    rhs : callable
        The right-hand side ``f(t, x)`` (with ``input_force(t, x)``, ``backend`` and
        ``layout`` attributes: rt70.simulation.simulate's).
    t : float
        Time of the start, s.
    x : numpy.ndarray
        The start state ``[q, q̇, s]``.
    """

    def __init__(self, rhs, t: float, x: np.ndarray) -> None:
        layout: StateLayout = rhs.layout
        n = self.nv = layout.nv
        pushing = [(c, where) for c, where in layout.pushing]
        #: Rows of the pushing components' states.
        self.rows = np.concatenate(
            [np.arange(w.start, w.stop) for _, w in pushing] or [np.zeros(0, dtype=int)]
        )
        states = self.rows  # their own columns always couple
        reach = _reaching(rhs, pushing, t, x, n)
        #: Columns replaced by differences: the coordinates and rates that reach the
        #: components, then the pushing components' states.
        self.columns = np.concatenate([np.flatnonzero(reach), states]).astype(int)

    @property
    def empty(self) -> bool:
        """True when no component pushes a force (nothing to complete)."""
        return self.rows.size == 0

    def complete(self, J: np.ndarray, rhs, t: float, x: np.ndarray) -> np.ndarray:
        """Add the components' couplings to ``J`` (in place; module docstring).

        For each coupled column j, with ``x' = x + h e_j``: the ``q̈`` rows gain
        ``M⁻¹ (Q_u(x') − Q_u(x)) / h`` (q̈ is linear in ``Q_u``: the backend's block holds
        ``Q_u`` fixed), and the pushing components' rows are their derivatives' forward
        differences. The mechanics' damper force passed to the components is the one at
        x (none of rt70's drives reads it).

        Parameters
        ----------
        J : numpy.ndarray, shape (N, N)
            The Jacobian with the backend's mechanics block.
        rhs : object
            The right-hand side (rt70.simulation.simulate's: ``input_force``,
            ``backend``, ``layout``).
        t : float
            Time, s.
        x : numpy.ndarray, shape (N,)
            The state.
        """
        n, pushing = self.nv, rhs.layout.pushing
        q, qd = x[:n], x[n : 2 * n]
        Q0 = rhs.input_force(t, x)
        _, Qd = rhs.backend.accelerations(q, qd, Q0)
        mass = scipy.linalg.cho_factor(rhs.backend.mass_matrix(q))
        ds0 = _pushing_derivatives(pushing, t, x, n, MechanicsForces(Qd, Q0))
        for j in self.columns:
            h = FD_RSTEP * max(abs(float(x[j])), 1.0)
            shifted = x.copy()
            shifted[j] += h
            Q = rhs.input_force(t, shifted)
            if Q is not None and Q0 is not None:
                J[n : 2 * n, j] += scipy.linalg.cho_solve(mass, (Q - Q0) / h)
            ds = _pushing_derivatives(pushing, t, shifted, n, MechanicsForces(Qd, Q))
            J[self.rows, j] = (ds - ds0) / h
        return J


def _pushing_derivatives(pushing: list, t: float, x: np.ndarray, n: int, forces) -> np.ndarray:
    """The pushing components' state derivatives at ``x``, concatenated in row order."""
    q, qd = x[:n], x[n : 2 * n]
    return np.concatenate(
        [np.asarray(c.derivative(t, q, qd, x[w], forces), dtype=float) for c, w in pushing]
    )


def _reaching(rhs, pushing: list, t: float, x: np.ndarray, n: int) -> np.ndarray:
    """Which of the 2n coordinate and rate columns change ``Q_u`` or a pushing derivative."""
    reach = np.zeros(2 * n, dtype=bool)
    if not pushing:
        return reach
    base_Q = rhs.input_force(t, x)
    forces = MechanicsForces(np.zeros(n), base_Q)
    base_ds = [c.derivative(t, x[:n], x[n : 2 * n], x[w], forces) for c, w in pushing]
    for j in range(2 * n):
        shifted = x.copy()
        shifted[j] += FD_RSTEP * max(abs(float(x[j])), 1.0)
        Q = rhs.input_force(t, shifted)
        if Q is not None and base_Q is not None and np.any(Q != base_Q):
            reach[j] = True
            continue
        q, qd = shifted[:n], shifted[n : 2 * n]
        ds = [c.derivative(t, q, qd, shifted[w], forces) for c, w in pushing]
        reach[j] = any(np.any(a != b) for a, b in zip(ds, base_ds, strict=True))
    return reach
