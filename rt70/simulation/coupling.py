"""The extra states' couplings in the Jacobian: differences over the columns that reach them.

The backend's analytic Jacobian is ``∂(q̇, q̈)/∂(q, q̇)`` at a fixed input force ``Q_u``.
A component that pushes a force on the mechanics (:meth:`StateComponent.force`: a drive's
motor torque through its reducer) makes ``Q_u`` depend on its own states and on the
coordinates it reads, and its states' derivatives depend on the mechanics: without
those terms the implicit methods' Newton iteration treats the drives explicitly, and
LSODA took a new Jacobian every 2.5 evaluations holding ``rt70_servo``.

:class:`Coupling` finds at the first Jacobian which columns of ``x = [q, q̇, s]`` reach
each coupled component: its force ``Q_s`` or its derivatives (a drive reads its axis
and motor coordinates, not the structure's hundreds). It probes at a slightly moved
state, so that a dependence that happens to vanish at the start (a current of zero) is
not missed. A column that reaches a component counts for all of its entries (its
force's rows and its states), and every later Jacobian moves all the other columns at
once in one more evaluation: if that moves a component, the search runs again and the
pattern grows. A dependence hidden where the pattern was found is then kept: a servo's
rate loop, saturated at the start of a large step, ignores the axis it reads. Without
this the 1° azimuth step of ``rt70_servo`` stalled once its loops let go (LSODA and
CVODE alike). At every Jacobian the columns are differenced forward, step
``√ε · max(|x_j|, 1)``:

- Columns that move disjoint entries share one evaluation (Curtis, Powell & Reid 1974).
  The azimuth drive's columns pair with the elevation drive's, for example.
- An evaluation is of those components alone: ``Q_s`` and their derivatives, not the
  mechanics.
- The ``q̈`` rows gain ``M⁻¹ ΔQ_s / h``, one Cholesky solve for all columns. q̈ is
  linear in ``Q_u``, and the backend's block holds ``Q_u`` fixed.

The columns of the other states, and the rows of components that only watch, stay as
they are. The energy audit is such a component: a quadrature that feeds nothing back.

A component that gives its own partial derivatives
(:meth:`~rt70.simulation.states.StateComponent.partials`) is not differenced: its rows
and its force's ``M⁻¹ ∂Q_s`` enter as given, in the same solve. Dry friction does
(:class:`rt70.control.friction.AxisFriction`): its zone at rest is 10⁻⁶ of the axis's top
speed wide, 3·10⁻⁹ rad/s on the RT-70, five times narrower than the difference step
(1.5·10⁻⁸ rad/s), so differences saw the sliding force's flat slope instead of the
zone's 2·10¹⁴ N·m·s/rad, and CVODE's Newton iteration failed 0.4 s into a hold.

A component that sets :attr:`~rt70.simulation.states.StateComponent.IN_JACOBIAN` False
is held fixed, as the ``inputs`` callable is. The wind's load
(:class:`rt70.wind.load.WindLoad`) does: its stiffness (the aerodynamic one) is small
beside the structure's, and it reads every coordinate of the bodies it loads, so that
differencing it cost one load evaluation per coordinate at every Jacobian (three
quarters of a gust run's time with LSODA). Friction, whose slope at rest is the
stiffest term of a drive, stays in, by its partials.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

from rt70.simulation.states import MechanicsForces, StateLayout

#: Relative forward-difference step (the square root of the machine epsilon).
FD_RSTEP = float(np.sqrt(np.finfo(float).eps))

#: Seed of the slightly moved state the couplings are probed at.
PROBE_SEED = 20261127

#: A change of an entry beyond this many of its block's size is not rounding
#: (:meth:`Coupling._reached_outside`).
ROUNDING = 1e3 * float(np.finfo(float).eps)


class Coupling:
    """The entries the components couple, found at ``(t, x)`` (module docstring).

    Parameters
    ----------
    rhs : object
        The right-hand side (rt70.simulation.simulate's: ``input_force(t, x)``,
        ``backend``, ``layout``).
    t : float
        Time of the start, s.
    x : numpy.ndarray
        The start state ``[q, q̇, s]``.
    """

    def __init__(self, rhs, t: float, x: np.ndarray) -> None:
        layout: StateLayout = rhs.layout
        self.nv = n = layout.nv
        q, qd = x[:n], x[n : 2 * n]
        included = [(c, w) for c, w in layout.pushing if c.IN_JACOBIAN]
        #: The components in the Jacobian by their own partial derivatives, and their
        #: slices of x.
        self.analytic = [(c, w) for c, w in included if c.partials(t, q, qd, x[w]) is not None]
        #: The differenced ones (the pushing components in the Jacobian without partials).
        self.coupled = [(c, w) for c, w in included if (c, w) not in self.analytic]
        #: Rows of the coupled components' states.
        self.rows = np.concatenate(
            [np.arange(w.start, w.stop) for _, w in self.coupled] or [np.zeros(0, dtype=int)]
        ).astype(int)
        patterns = {}
        if self.coupled:
            patterns = _patterns(rhs, self.coupled, t, _probe_state(x), self.rows)
        self._use(patterns)

    def _use(self, patterns: dict[int, np.ndarray]) -> None:
        """Take ``patterns``: the columns, their groups, and the columns outside them."""
        n = self.nv
        #: Per coupled column of x, the entries of ``[Q_s; ṡ_coupled]`` it may move.
        self.patterns = patterns
        #: The coupled columns, ascending.
        self.columns = np.array(sorted(patterns), dtype=int)
        #: Groups of columns that move disjoint entries: one evaluation each.
        self.groups = _groups(patterns, n + self.rows.size)
        #: The other columns, and the signs of the one probe over all of them
        #: (:meth:`_reached_outside`).
        candidates = [*range(2 * n), *self.rows.tolist()] if self.coupled else []
        self.outside = np.array([j for j in candidates if j not in patterns], dtype=int)
        self._signs = np.random.default_rng(PROBE_SEED).choice([-1.0, 1.0], self.outside.size)

    def _reached_outside(self, t: float, x: np.ndarray, Qd: np.ndarray, base: np.ndarray) -> bool:
        """Whether the columns outside the pattern, all moved at once, move a component.

        One evaluation of the components per Jacobian. A column that reached no
        component where the pattern was found (a dependence a clamp hid there, as a
        saturated loop hides its error) is found once it does.
        """
        if not self.outside.size:
            return False
        shifted = x.copy()
        steps = FD_RSTEP * np.maximum(np.abs(x[self.outside]), 1.0)
        shifted[self.outside] += self._signs * steps
        change = _components(self.coupled, t, shifted, self.nv, Qd, None) - base
        return bool(np.any(np.abs(change) > ROUNDING * self._scales(base)))

    def _scales(self, base: np.ndarray) -> np.ndarray:
        """Per entry of ``[Q_s; ṡ_coupled]``, the largest entry of its block.

        The blocks are ``Q_s`` and each component's states; rounding moves an entry by a
        few ε of its block's largest.
        """
        scales = np.empty_like(base)
        start = 0
        for stop in [self.nv, *(self.nv + np.cumsum([w.stop - w.start for _, w in self.coupled]))]:
            scales[start:stop] = np.max(np.abs(base[start:stop]), initial=0.0)
            start = stop
        return scales

    @property
    def empty(self) -> bool:
        """True when no component pushing a force is in the Jacobian (nothing to complete)."""
        return not self.coupled and not self.analytic

    def complete(
        self, J: np.ndarray, rhs, t: float, x: np.ndarray, Q_u: np.ndarray | None
    ) -> np.ndarray:
        """Add the components' couplings to ``J`` (in place; module docstring).

        The mechanics' damper force passed to the components is the one at x (none of
        rt70's drives reads it).

        Parameters
        ----------
        J : numpy.ndarray, shape (N, N)
            The Jacobian with the backend's mechanics block.
        rhs : object
            The right-hand side, as for the constructor.
        t : float
            Time, s.
        x : numpy.ndarray, shape (N,)
            The state.
        Q_u : numpy.ndarray or None
            ``rhs.input_force(t, x)``, which the caller has computed.
        """
        n = self.nv
        q = x[:n]
        columns, dQ = self._partials(J, t, x)
        if self.coupled:
            differenced, dQ_differenced = self._differences(J, rhs, t, x, Q_u)
            columns = np.concatenate([columns, differenced])
            dQ = np.hstack([dQ, dQ_differenced])
        if columns.size:
            unique, where = np.unique(columns, return_inverse=True)
            summed = np.zeros((n, unique.size))
            np.add.at(summed.T, where, dQ.T)
            mass = scipy.linalg.cho_factor(rhs.backend.mass_matrix(q), check_finite=False)
            J[n : 2 * n, unique] += scipy.linalg.cho_solve(mass, summed, check_finite=False)
        return J

    def _partials(self, J: np.ndarray, t: float, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The analytic components' rows into ``J``; their force's columns and ``∂Q_s``.

        Returns the columns of x the forces depend on and ``∂Q_s/∂x`` on them, shape
        (nv, columns), for the caller's one solve by the mass matrix.
        """
        n = self.nv
        q, qd = x[:n], x[n : 2 * n]
        columns, values = [], []
        for c, w in self.analytic:
            p = c.partials(t, q, qd, x[w])
            rows, cols, vals = (np.asarray(a) for a in p.states)
            np.add.at(J, (w.start + rows.astype(int), _columns(cols, w, n)), vals)
            rows, cols, vals = (np.asarray(a) for a in p.force)
            for row, col, val in zip(rows.astype(int), _columns(cols, w, n), vals, strict=True):
                column = np.zeros(n)
                column[row] = val
                columns.append(col)
                values.append(column)
        dQ = np.column_stack(values) if values else np.zeros((n, 0))
        return np.array(columns, dtype=int), dQ

    def _differences(
        self, J: np.ndarray, rhs, t: float, x: np.ndarray, Q_u: np.ndarray | None
    ) -> tuple[np.ndarray, np.ndarray]:
        """The differenced components' rows into ``J``; their columns and ``∂Q_s``."""
        n, coupled = self.nv, self.coupled
        q, qd = x[:n], x[n : 2 * n]
        _, Qd = rhs.backend.accelerations(q, qd, Q_u)
        base = _components(coupled, t, x, n, Qd, None)
        if self._reached_outside(t, x, Qd, base):  # the pattern grows, never shrinks
            found = _patterns(rhs, coupled, t, x, self.rows)
            for j, entries in self.patterns.items():
                found[j] = np.union1d(found.get(j, entries), entries)
            grown = set(found) != set(self.patterns)
            self._use(dict(sorted(found.items())))
            if not grown:  # moved only by the columns together: not searched again
                self.outside = self.outside[:0]
        rest = None if Q_u is None else Q_u - base[:n]  # the inputs' and the loads' force
        dQ = np.zeros((n, self.columns.size))
        where = {j: k for k, j in enumerate(self.columns)}
        for group in self.groups:
            steps = {j: _step(x, j) for j in group}
            shifted = x.copy()
            for j, h in steps.items():
                shifted[j] += h
            change = _components(coupled, t, shifted, n, Qd, rest) - base
            for j, h in steps.items():
                entries = self.patterns[j]
                forces, states = entries[entries < n], entries[entries >= n]
                dQ[forces, where[j]] = change[forces] / h
                J[self.rows[states - n], j] = change[states] / h
        return self.columns, dQ


def _columns(local: np.ndarray, w: slice, n: int) -> np.ndarray:
    """Columns of x of a component's local columns ``[q (nv), q̇ (nv), its states]``."""
    local = np.asarray(local, dtype=int)
    return np.where(local < 2 * n, local, w.start + local - 2 * n)


def _step(x: np.ndarray, j: int) -> float:
    """The forward-difference step of column j: ``√ε · max(|x_j|, 1)``."""
    return FD_RSTEP * max(abs(float(x[j])), 1.0)


def _components(coupled: list, t: float, x: np.ndarray, n: int, Qd: np.ndarray,
                rest: np.ndarray | None) -> np.ndarray:  # fmt: skip
    """``[Q_s; ṡ_coupled]`` at ``x``: the coupled components' force and derivatives.

    Their derivatives see ``Q_u = Q_s + rest`` (``rest``: the inputs' and the loads'
    force, held fixed; None for none).
    """
    q, qd = x[:n], x[n : 2 * n]
    Q_s = np.zeros(n)
    for c, w in coupled:
        Q = c.force(t, q, qd, x[w])
        if Q is not None:
            Q_s += Q
    forces = MechanicsForces(Qd, Q_s if rest is None else Q_s + rest)
    ds = [np.asarray(c.derivative(t, q, qd, x[w], forces), dtype=float) for c, w in coupled]
    return np.concatenate([Q_s, *ds])


def _probe_state(x: np.ndarray) -> np.ndarray:
    """``x`` moved by a fixed pseudo-random 1e-6 of each entry's size (at least 1e-6)."""
    rng = np.random.default_rng(PROBE_SEED)
    return x + 1e-6 * np.maximum(np.abs(x), 1.0) * rng.uniform(-1.0, 1.0, x.size)


def _patterns(rhs, coupled: list, t: float, x: np.ndarray, rows: np.ndarray) -> dict:
    """For each column of x that reaches a coupled component, the entries it may move.

    A component's entries are the rows of ``Q_s`` its force moves and its own states'
    rows. A column reaches the component when it moves any of them at x (its own
    states' columns always do), and then counts for all of them: a dependence that a
    clamp hides at x (a saturated loop ignores its error, as a servo's rate loop does
    at the start of a large step) appears once the clamp lets go, and a pattern of only
    the entries moved at x would leave it out of every later Jacobian.
    """
    n = rhs.layout.nv
    Qd = np.zeros(n)
    patterns: dict[int, set[int]] = {}
    offset = n
    for c, w in coupled:
        one = [(c, w)]
        base = _components(one, t, x, n, Qd, None)
        reached, force_rows = [], set()
        for j in [*range(2 * n), *rows]:
            shifted = x.copy()
            shifted[j] += _step(x, j)
            moved = _components(one, t, shifted, n, Qd, None) != base
            if moved.any() or w.start <= j < w.stop:
                reached.append(int(j))
                force_rows.update(np.flatnonzero(moved[:n]).tolist())
        entries = [*force_rows, *range(offset, offset + w.stop - w.start)]
        for j in reached:
            patterns.setdefault(j, set()).update(entries)
        offset += w.stop - w.start
    return {j: np.array(sorted(patterns[j]), dtype=int) for j in sorted(patterns)}


def _groups(patterns: dict, size: int) -> list[list[int]]:
    """Greedy groups of columns whose entries are disjoint (Curtis, Powell & Reid)."""
    groups: list[tuple[list[int], np.ndarray]] = []
    for j, entries in patterns.items():
        for columns, used in groups:
            if not used[entries].any():
                columns.append(j)
                used[entries] = True
                break
        else:
            used = np.zeros(size, dtype=bool)
            used[entries] = True
            groups.append(([j], used))
    return [columns for columns, _ in groups]
