"""Extra states of a simulation: components integrated together with the mechanics.

:func:`rt70.simulation.simulate.simulate` integrates ``x = [q, q̇, s_1, s_2, …]``: the coordinates
and velocities of the mechanics, then the states ``s_i`` of every
:class:`StateComponent` in order. A component

- names its states (:attr:`StateComponent.names`, unique within a simulation) and gives
  their initial values and absolute tolerances;
- returns their time derivative ``ṡ = f(t, q, q̇, s, forces)`` at every evaluation of
  the right-hand side, where ``forces`` (:class:`MechanicsForces`) carries what the
  mechanics computed at that evaluation (the damper force ``Q_d``, the input force
  ``Q_u``);
- may push a generalised force back on the mechanics from its own states
  (:meth:`StateComponent.force`: what a drive does with its motor current). That force
  is added to the input force ``Q_u``: the energy audit counts it as input work.

The analytic Jacobian of the implicit methods gets the couplings of the components that
push a force — their rows, their states' columns, and the coordinates that reach them —
by differences over those columns (:mod:`rt70.simulation.coupling`), or from the
component's own partial derivatives where it gives them (:meth:`StateComponent.partials`:
a law steeper than any difference step can see, such as dry friction's zone at rest);
the rows of the components that only watch (the energy audit) are zero: the solver's
Newton iteration treats them explicitly.

The first component is the energy audit (:class:`EnergyAudit`, (1.73)), which every
simulation carries; drives with motor states come next. The simulation's result holds
every component's states by name (:attr:`rt70.simulation.result.SimulationResult.states`).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Sequence
from typing import ClassVar, NamedTuple

import numpy as np

from rt70.errors import Rt70Error, ShapeError


class Partials(NamedTuple):
    """A component's analytic partial derivatives, as ``(rows, columns, values)`` triplets.

    The columns number the component's arguments ``[q (nv), q̇ (nv), s (its own states)]``;
    an entry that appears twice is summed.

    Attributes
    ----------
    force : tuple of numpy.ndarray
        ``∂Q_s/∂(q, q̇, s)``: rows of the component's force (0 … nv − 1).
    states : tuple of numpy.ndarray
        ``∂ṡ/∂(q, q̇, s)``: rows of its states (0 … len(names) − 1), with the mechanics'
        forces held fixed.
    """

    force: tuple[np.ndarray, np.ndarray, np.ndarray]
    states: tuple[np.ndarray, np.ndarray, np.ndarray]


class MechanicsForces(NamedTuple):
    """Generalised forces the mechanics computed at one evaluation (book coordinates).

    Attributes
    ----------
    Q_d : numpy.ndarray
        Damper force ``−Σ (∂δ/∂q)ᵀ D δ̇`` of all elements, shape (nv,).
    Q_u : numpy.ndarray or None
        Input force: the ``inputs`` callable's plus every component's
        :meth:`~StateComponent.force`; None when there is none.
    """

    Q_d: np.ndarray
    Q_u: np.ndarray | None


class StateComponent(ABC):
    """States with their own equations, integrated together with the mechanics.

    Attributes
    ----------
    names : tuple of str
        Names of the component's states (keys of ``SimulationResult.states``).
    initial : numpy.ndarray
        Their initial values, shape (len(names),).
    atol : numpy.ndarray
        Their absolute tolerances for the integrator, shape (len(names),).
    """

    names: tuple[str, ...]
    initial: np.ndarray
    atol: np.ndarray

    #: Unit of each state by the last part of its name (``current`` of
    #: ``azimuth:current``); a state not listed is written with the unit "unknown".
    STATE_UNITS: ClassVar[dict[str, str]] = {}

    #: Whether the implicit methods' Jacobian gets this component's couplings, by
    #: differences (:mod:`rt70.simulation.coupling`). A load whose stiffness is small
    #: beside the structure's and which reads many coordinates (the wind's) sets False:
    #: its force is then held fixed there, as the ``inputs`` callable's is.
    IN_JACOBIAN: ClassVar[bool] = True

    def unit(self, name: str) -> str:
        """The unit of the state ``name`` (one of :attr:`names`), from :attr:`STATE_UNITS`."""
        return self.STATE_UNITS.get(name.rsplit(":", 1)[-1], "unknown")

    @abstractmethod
    def derivative(
        self, t: float, q: np.ndarray, qd: np.ndarray, s: np.ndarray, forces: MechanicsForces
    ) -> np.ndarray:
        """Time derivative ``ṡ`` of the component's states ``s``, shape (len(names),).

        Parameters
        ----------
        t : float
            Time, s.
        q, qd : numpy.ndarray, shape (nv,)
            The mechanics' coordinates (rad or m) and velocities (rad/s or m/s).
        s : numpy.ndarray, shape (len(names),)
            The component's states.
        forces : MechanicsForces
            The dampers' and the inputs' generalised forces of this evaluation.
        """

    def force(self, t: float, q: np.ndarray, qd: np.ndarray, s: np.ndarray) -> np.ndarray | None:
        """Generalised force on the mechanics from the states ``s`` (shape (nv,)), or None.

        Added to the input force ``Q_u`` before the accelerations are computed. The
        default is None: the component only watches.

        Parameters
        ----------
        t : float
            Time, s.
        q, qd : numpy.ndarray, shape (nv,)
            The mechanics' coordinates (rad or m) and velocities (rad/s or m/s).
        s : numpy.ndarray, shape (len(names),)
            The component's states.
        """
        return None

    def partials(self, t: float, q: np.ndarray, qd: np.ndarray, s: np.ndarray) -> Partials | None:
        """The analytic partial derivatives of :meth:`force` and :meth:`derivative`, or None.

        None (the default) leaves them to differences (:mod:`rt70.simulation.coupling`),
        whose step ``√ε · max(|x_j|, 1)`` cannot see a law that changes over a smaller
        width of its argument. A component that returns them is not differenced; its
        derivatives must then not read the mechanics' forces.

        Parameters
        ----------
        t : float
            Time, s.
        q, qd : numpy.ndarray, shape (nv,)
            The mechanics' coordinates (rad or m) and velocities (rad/s or m/s).
        s : numpy.ndarray, shape (len(names),)
            The component's states.
        """
        return None


class EnergyAudit(StateComponent):
    """Dissipated energy and input work, integrated with the motion (1.73).

    ``E_ψ = ∫ q̇ᵀ D q̇ dt = −∫ q̇ᵀ Q_d dt`` (state ``"dissipated"``) and
    ``W_u = ∫ q̇ᵀ Q_u dt`` (state ``"input_work"``), both zero at the start; along any
    trajectory ``T + U_g + U_c + E_ψ − W_u`` is constant.

    Parameters
    ----------
    atol : float
        Absolute tolerance of both energies, J.
    """

    names = ("dissipated", "input_work")
    STATE_UNITS: ClassVar[dict[str, str]] = {"dissipated": "J", "input_work": "J"}

    def __init__(self, atol: float) -> None:
        self.initial = np.zeros(2)
        self.atol = np.full(2, atol)

    def derivative(self, t, q, qd, s, forces):
        """``[−q̇ᵀ Q_d, q̇ᵀ Q_u]``: the dampers' and the inputs' power, W.

        Parameters
        ----------
        t : float
            Time, s (unused).
        q, qd : numpy.ndarray, shape (nv,)
            The mechanics' coordinates and velocities (only q̇ is used).
        s : numpy.ndarray, shape (2,)
            ``[E_ψ, W_u]`` (unused).
        forces : MechanicsForces
            ``Q_d`` and ``Q_u`` of this evaluation.
        """
        Q_d, Q_u = forces
        return np.array((-(qd @ Q_d), 0.0 if Q_u is None else qd @ Q_u))


class StateLayout:
    """Where each component's states sit in ``x = [q, q̇, s_1, s_2, …]``.

    Parameters
    ----------
    components : sequence of StateComponent
        The components, in state order.
    nv : int
        Number of coordinates of the mechanics (its states are the first ``2 nv``).

    Raises
    ------
    Rt70Error
        If two states have the same name, or a component's initial values or tolerances
        do not match its names.
    """

    def __init__(self, components: Sequence[StateComponent], nv: int) -> None:
        self.components = list(components)
        self.nv = nv
        self.names: list[str] = [name for c in self.components for name in c.names]
        repeated = sorted({name for name in self.names if self.names.count(name) > 1})
        if repeated:
            raise Rt70Error(f"simulation states named twice: {', '.join(repeated)}")
        #: (component, its slice of x, its number of states), in state order.
        self.placed: list[tuple[StateComponent, slice, int]] = []
        start = 2 * nv
        for c in self.components:
            k = len(c.names)
            for what in ("initial", "atol"):
                if np.shape(getattr(c, what)) != (k,):
                    raise ShapeError(
                        f"state component {type(c).__name__}: {what} must have shape ({k},), "
                        f"got {np.shape(getattr(c, what))}"
                    )
            self.placed.append((c, slice(start, start + k), k))
            start += k
        self.size = start - 2 * nv
        #: The components that push a force on the mechanics (override ``force``).
        self.pushing = [
            (c, where) for c, where, _ in self.placed if type(c).force is not StateComponent.force
        ]

    def initial(self) -> list[np.ndarray]:
        """Initial values of the extra states, one array per component."""
        return [np.asarray(c.initial, dtype=float) for c in self.components]

    def atol(self) -> list[np.ndarray]:
        """Absolute tolerances of the extra states, one array per component."""
        return [np.asarray(c.atol, dtype=float) for c in self.components]

    def force(self, t: float, q: np.ndarray, qd: np.ndarray, x: np.ndarray) -> np.ndarray | None:
        """Sum of the components' generalised forces at state ``x``, or None if none.

        Parameters
        ----------
        t : float
            Time, s.
        q, qd : numpy.ndarray, shape (nv,)
            The mechanics' coordinates (rad or m) and velocities (rad/s or m/s).
        x : numpy.ndarray, shape (2 nv + size,)
            The whole state ``[q, q̇, s_1, s_2, …]``.
        """
        n, total = self.nv, None
        for c, where in self.pushing:
            Q = c.force(t, q, qd, x[where])
            if Q is None:
                continue
            Q = np.asarray(Q, dtype=float)
            if Q.shape != (n,):
                raise ShapeError(
                    f"state component {type(c).__name__}: force must have shape ({n},), "
                    f"got {Q.shape}"
                )
            total = Q if total is None else total + Q
        return total

    def derivatives(
        self, t: float, q: np.ndarray, qd: np.ndarray, x: np.ndarray, forces: MechanicsForces
    ) -> list[np.ndarray]:
        """Time derivatives of the extra states at state ``x``, one array per component.

        Parameters
        ----------
        t : float
            Time, s.
        q, qd : numpy.ndarray, shape (nv,)
            The mechanics' coordinates (rad or m) and velocities (rad/s or m/s).
        x : numpy.ndarray, shape (2 nv + size,)
            The whole state ``[q, q̇, s_1, s_2, …]``.
        forces : MechanicsForces
            The dampers' and the inputs' generalised forces of this evaluation.
        """
        out = []
        for c, where, k in self.placed:
            ds = c.derivative(t, q, qd, x[where], forces)
            if type(ds) is not np.ndarray or ds.shape != (k,):
                ds = np.asarray(ds, dtype=float)
                if ds.shape != (k,):
                    raise ShapeError(
                        f"state component {type(c).__name__}: derivative must have shape "
                        f"({k},), got {ds.shape}"
                    )
            out.append(ds)
        return out

    def read(self, y: np.ndarray) -> dict[str, np.ndarray]:
        """Every extra state's trajectory by name, from the solver's ``y`` (states × times)."""
        start = 2 * self.nv
        return {name: y[start + i] for i, name in enumerate(self.names)}
