"""The wind as a simulation component: a steady mean wind plus an optional gust.

:class:`WindLoad` is a :class:`~rt70.simulation.states.StateComponent` without states whose
:meth:`~WindLoad.force` is the scene's wind generalised force (``<rt70:wind>``,
:mod:`rt70.physics.aerodynamics`) at the speed ``v(t) = mean + gust(t)`` along the fixed
mean direction, computed on one side of the cross-check (:mod:`rt70.textbook.wind` or
:mod:`rt70.reference.wind`, through :func:`rt70.model.sides.side_of`). The
force is exact in the speed — ``½ ρ (v̄ + v′)² S [c]`` — not linearised about the mean. A
negative ``v(t)`` (a gust stronger than the mean, against it) is the same flow turned by
180°. The simulation adds the force to ``Q_u``, so its work is the energy audit's input
work.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from rt70.errors import Rt70Error
from rt70.model.sides import check_side, side_of
from rt70.physics.aerodynamics import WindCondition
from rt70.simulation.states import StateComponent


class WindLoad(StateComponent):
    """The wind's generalised force on a scene's exposed bodies, as a component.

    Parameters
    ----------
    scene : rt70.model.scene.Scene
        A scene with ``<rt70:wind>`` elements.
    condition : rt70.physics.aerodynamics.WindCondition
        The mean wind: its speed v̄, direction and (optional) air density.
    gust : callable t -> float, optional
        The gust speed v′(t), m/s, along the mean direction; None: a steady wind.
    side : {"reference", "textbook"}
        Which side's kinematics computes the force; use the simulation's side.

    Raises
    ------
    Rt70Error
        If the scene has no wind elements, the side is unknown or ``gust`` is not
        callable.
    """

    names: tuple[str, ...] = ()
    #: Held fixed in the implicit methods' Jacobian (:mod:`rt70.simulation.coupling`).
    IN_JACOBIAN = False

    def __init__(
        self,
        scene,
        condition: WindCondition,
        gust: Callable[[float], float] | None = None,
        side: str = "reference",
    ) -> None:
        try:
            check_side(side)
        except Rt70Error as exc:
            raise Rt70Error(f"wind load: {exc}") from None
        if not scene.description.winds:
            raise Rt70Error(
                f"{scene.name}: no <rt70:wind> elements: nothing for the wind to act on "
                "(docs/wind.md)"
            )
        if not isinstance(condition, WindCondition):
            raise Rt70Error(f"wind load: condition must be a WindCondition, got {condition!r}")
        if gust is not None and not callable(gust):
            raise Rt70Error(f"wind load: gust must be a callable t -> m/s or None, got {gust!r}")
        self.condition = condition
        self.gust = gust
        self.side = side
        self.initial = np.zeros(0)
        self.atol = np.zeros(0)
        s = side_of(scene, side)  # the reference side compiles it where it can (same numbers)
        self._force = s.wind.wind_force_function(s.model, s.data)

    def speed(self, t: float) -> float:
        """The wind speed ``v̄ + v′(t)`` along the mean direction, m/s.

        Raises
        ------
        Rt70Error
            If the gust is not a finite number.
        """
        if self.gust is None:
            return self.condition.speed
        gust = float(self.gust(t))
        if not math.isfinite(gust):
            raise Rt70Error(f"wind load: gust({t:g}) = {gust!r} is not finite")
        return self.condition.speed + gust

    def condition_at(self, t: float) -> WindCondition:
        """The steady condition equal to the wind at time t (a negative speed turned by 180°)."""
        v = self.speed(t)
        c = self.condition
        direction = c.direction_deg if v >= 0.0 else c.direction_deg + 180.0
        return WindCondition(abs(v), direction, c.density)

    def derivative(self, t, q, qd, s, forces) -> np.ndarray:
        """No states: an empty derivative.

        Parameters
        ----------
        t : float
            Time, s.
        q, qd : numpy.ndarray, shape (nv,)
            The mechanics' coordinates and velocities (unused).
        s : numpy.ndarray, shape (0,)
            The component's (no) states.
        forces : rt70.simulation.states.MechanicsForces
            The mechanics' forces of this evaluation (unused).
        """
        return np.zeros(0)

    def force(self, t: float, q: np.ndarray, qd: np.ndarray, s: np.ndarray) -> np.ndarray:
        """The wind's generalised force at time t and configuration q (nv,), N·m or N.

        Parameters
        ----------
        t : float
            Time, s: the gust's speed is the one at t.
        q : numpy.ndarray, shape (nv,)
            Generalised coordinates in the file's order, rad or m.
        qd : numpy.ndarray, shape (nv,)
            Their velocities (unused: the load depends on the wind, not on the motion).
        s : numpy.ndarray, shape (0,)
            The component's (no) states.
        """
        return self._force(q, self.condition_at(t))
