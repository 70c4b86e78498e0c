"""Dry friction on one axis: the book's relay law, its regularisations and a switched reference.

The book (§2.4, p. 51) gives the RT-70 axes' dry friction as a moment of 7·10⁴ kgf·m at
rest rising to (1–2)·10⁵ kgf·m at top speed, "relay-like near zero speed"
(``rt70.scenes.rt70_drives.DryFriction``; this module takes any object with its
``static_torque`` and ``slope``, so it knows no telescope). Taken linear between the two points,
the friction torque on the axis is ::

    τ_f(ω) = −sign(ω) (F_s + k |ω|) = −F_s sign(ω) − k ω,      ω ≠ 0,           (relay)

and at ω = 0 anything in [−F_s, F_s] (the axis sticks while the other torques on it stay
below F_s). An integrator cannot follow the jump of sign(ω); two regularisations replace
it by a steep continuous law of width ω_ε:

- ``"tanh"``:   τ_f = −F_s tanh(ω/ω_ε) − k ω;
- ``"linear"``: τ_f = −F_s clip(ω/ω_ε, −1, 1) − k ω (a viscous zone of slope F_s/ω_ε).

Both tend to the relay law as ω_ε → 0 for every ω ≠ 0. Their error is that a stuck axis
creeps: under a torque τ with ``|τ| < F_s`` it moves at ω_ε·atanh(τ/F_s) (tanh) or about
ω_ε·τ/F_s (linear) instead of sticking. docs/drive-train.md measures the price of a
small ω_ε in integrator steps against that creep.

:class:`AxisFriction` pushes the regularised law on one coordinate as a state component
(:mod:`rt70.simulation.states`), integrates the heat it dissipates and gives the
implicit methods its slope (:func:`friction_slope`). :func:`switched_rigid_axis`
is the exact stick–slip motion of one rigid axis under the relay law (a switched model
with events, no regularisation), the reference the regularisations are measured against.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import ClassVar, Protocol

import numpy as np

from rt70.errors import Rt70Error
from rt70.simulation.states import MechanicsForces, Partials, StateComponent


class DryFriction(Protocol):
    """What the law needs of an axis's friction (the RT-70's: ``rt70_drives.FRICTION``).

    Attributes
    ----------
    static_torque : float
        F_s, N·m: the friction at rest.
    slope : float
        k, N·m·s/rad: its rise per unit speed.
    """

    static_torque: float
    slope: float


#: The regularisations of sign(ω) (module docstring).
KINDS = ("tanh", "linear")


def relay_torque(friction: DryFriction, speed):
    """The book's relay law −sign(ω)(F_s + k|ω|) (zero at ω = 0, where it is set-valued)."""
    w = np.asarray(speed, dtype=float)
    return -np.sign(w) * (friction.static_torque + friction.slope * np.abs(w))


def friction_torque(friction: DryFriction, speed, width: float, kind: str = "tanh"):
    """The regularised friction torque on an axis turning at ``speed`` (rad/s).

    Parameters
    ----------
    friction : DryFriction
        F_s (``static_torque``), k (``slope``).
    speed : float or array
        ω, rad/s.
    width : float
        ω_ε, rad/s: the speed below which the law is no longer the relay's.
    kind : {"tanh", "linear"}
        The regularisation (module docstring).

    Returns
    -------
    float or numpy.ndarray
        τ_f, N·m, opposing ω.
    """
    check_width(width, kind)
    w = np.asarray(speed, dtype=float)
    if kind == "tanh":
        relay = np.tanh(w / width)
    else:
        relay = np.clip(w / width, -1.0, 1.0)
    out = -friction.static_torque * relay - friction.slope * w
    return float(out) if out.ndim == 0 else out


def friction_slope(friction: DryFriction, speed: float, width: float, kind: str = "tanh") -> float:
    """``dτ_f/dω`` of :func:`friction_torque`, N·m·s/rad (the zone's at its edge).

    Parameters
    ----------
    friction : DryFriction
        F_s (``static_torque``), k (``slope``).
    speed : float
        ω, rad/s.
    width : float
        ω_ε, rad/s.
    kind : {"tanh", "linear"}
        The regularisation (module docstring).
    """
    check_width(width, kind)
    ratio = float(speed) / width
    if kind == "tanh":
        zone = 1.0 - np.tanh(ratio) ** 2
    else:
        zone = 1.0 if abs(ratio) <= 1.0 else 0.0
    return -friction.static_torque / width * zone - friction.slope


def creep_speed(friction: DryFriction, torque: float, width: float, kind: str = "tanh") -> float:
    """Speed at which a regularised axis creeps under a steady torque ``|torque| < F_s``.

    The ideal axis sticks (speed 0); this is the regularisation's error. Solved from
    ``τ + τ_f(ω) = 0`` by bisection (the law is monotonic in ω).

    Parameters
    ----------
    friction : DryFriction
        F_s (``static_torque``, N·m), k (``slope``, N·m·s/rad).
    torque : float
        The steady torque on the axis, N·m, ``|torque| < F_s``.
    width : float
        ω_ε, rad/s.
    kind : {"tanh", "linear"}
        The regularisation (module docstring).
    """
    check_width(width, kind)
    F_s = friction.static_torque
    if not abs(torque) < F_s:
        raise Rt70Error(f"creep_speed: |torque| = {abs(torque):g} must be below F_s = {F_s:g}")
    lo, hi = 0.0, width * 50.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if abs(torque) + friction_torque(friction, mid, width, kind) > 0.0:
            lo = mid
        else:
            hi = mid
    return float(np.sign(torque) * 0.5 * (lo + hi))


def check_width(width: float, kind: str) -> None:
    """Refuse an unknown regularisation or a width that is not finite and positive."""
    if kind not in KINDS:
        choices = ", ".join(KINDS)
        raise Rt70Error(f"unknown friction regularisation {kind!r} (choose from {choices})")
    if not (np.isfinite(width) and width > 0.0):
        raise Rt70Error(f"friction regularisation width must be finite and positive, got {width!r}")


class AxisFriction(StateComponent):
    """The regularised dry friction of one axis, pushed on its coordinate.

    One state, ``name:dissipated``: the heat ``∫ −τ_f ω dt ≥ 0`` (J). The friction torque
    enters the mechanics through the extra-state seam's force, so the simulation's energy
    audit counts it in the input work ``W_u`` (negative); this state gives its share.

    Parameters
    ----------
    name : str
        Prefix of the state's name.
    coordinates : list of str
        The scene's coordinate names.
    coordinate : str
        The axis the friction acts on.
    friction : DryFriction
        F_s and k (``rt70.scenes.rt70_drives.FRICTION`` for the RT-70).
    width : float
        ω_ε, rad/s.
    kind : {"tanh", "linear"}
        The regularisation.
    atol : float
        Absolute tolerance of the dissipated heat, J.
    """

    STATE_UNITS: ClassVar[dict[str, str]] = {"dissipated": "J"}

    def __init__(
        self,
        name: str,
        coordinates: list[str],
        coordinate: str,
        friction: DryFriction,
        width: float,
        kind: str = "tanh",
        atol: float = 1e-6,
    ) -> None:
        if coordinate not in coordinates:
            raise Rt70Error(f"friction '{name}': no coordinate '{coordinate}'")
        check_width(width, kind)
        self.names = (f"{name}:dissipated",)
        self.index = coordinates.index(coordinate)
        self.n = len(coordinates)
        self.friction, self.width, self.kind = friction, float(width), kind
        self.initial = np.zeros(1)
        self.atol = np.array([float(atol)])

    def torque(self, qd: np.ndarray) -> float:
        """τ_f at the axis speed ``qd[index]``."""
        return friction_torque(self.friction, qd[self.index], self.width, self.kind)

    def force(self, t: float, q: np.ndarray, qd: np.ndarray, s: np.ndarray) -> np.ndarray:
        """τ_f as a generalised force on the axis's coordinate.

        Parameters
        ----------
        t : float
            Time, s (unused).
        q : numpy.ndarray, shape (nv,)
            Generalised coordinates, m or rad (unused).
        qd : numpy.ndarray, shape (nv,)
            Generalised velocities, m/s or rad/s; the axis's is ``qd[index]``.
        s : numpy.ndarray, shape (1,)
            The heat dissipated so far, J (unused).
        """
        Q = np.zeros(self.n)
        Q[self.index] = self.torque(qd)
        return Q

    def derivative(
        self, t: float, q: np.ndarray, qd: np.ndarray, s: np.ndarray, forces: MechanicsForces
    ) -> np.ndarray:
        """The heat rate ``−τ_f ω`` (≥ 0).

        Parameters
        ----------
        t : float
            Time, s (unused).
        q : numpy.ndarray, shape (nv,)
            Generalised coordinates, m or rad (unused).
        qd : numpy.ndarray, shape (nv,)
            Generalised velocities, m/s or rad/s; the axis's is ``qd[index]``.
        s : numpy.ndarray, shape (1,)
            The heat dissipated so far, J (unused).
        forces : MechanicsForces
            The mechanics' forces at this evaluation (unused).
        """
        return np.array([-self.torque(qd) * qd[self.index]])

    def partials(self, t: float, q: np.ndarray, qd: np.ndarray, s: np.ndarray) -> Partials:
        """``∂τ_f/∂ω`` on the axis's row and the heat rate's ``−(τ_f + ω ∂τ_f/∂ω)``.

        Given, not differenced: the zone at rest is narrower than a difference step
        (:mod:`rt70.simulation.coupling`).

        Parameters
        ----------
        t : float
            Time, s (unused).
        q : numpy.ndarray, shape (nv,)
            Generalised coordinates, m or rad (unused).
        qd : numpy.ndarray, shape (nv,)
            Generalised velocities, m/s or rad/s; the axis's is ``qd[index]``.
        s : numpy.ndarray, shape (1,)
            The heat dissipated so far, J (unused).
        """
        w = float(qd[self.index])
        slope = friction_slope(self.friction, w, self.width, self.kind)
        one = np.ones(1)
        column = np.array([self.n + self.index])
        heat = -(self.torque(qd) + w * slope)
        return Partials(
            force=(np.array([self.index]), column, slope * one),
            states=(np.zeros(1, dtype=int), column, heat * one),
        )


@dataclass(frozen=True)
class SwitchedRun:
    """The exact stick–slip motion of :func:`switched_rigid_axis`.

    Attributes
    ----------
    t, angle, speed : numpy.ndarray
        At the requested times.
    switches : int
        Number of stick/slip transitions.
    """

    t: np.ndarray
    angle: np.ndarray
    speed: np.ndarray
    switches: int


def switched_rigid_axis(
    inertia: float,
    friction: DryFriction,
    torque: Callable[[float], float],
    t_eval: np.ndarray,
    rtol: float = 1e-11,
) -> SwitchedRun:
    """Motion of a rigid axis from rest under ``torque(t)`` and the relay law, exactly.

    A switched model (Karnopp's idea without the velocity window): *stuck*, the axis stays
    at rest while ``|τ(t)| ≤ F_s`` and leaves in the direction of τ when ``|τ|`` reaches
    F_s; *slipping* in direction σ, ``J ω̇ = τ(t) − σ (F_s + k |ω|)`` until ω reaches
    zero, where it sticks again if ``|τ| ≤ F_s`` there (else it reverses). Each phase ends
    at an event located by the solver (DOP853), so no regularisation enters.

    Parameters
    ----------
    inertia : float
        J, kg·m².
    friction : DryFriction
        F_s, k.
    torque : callable t -> float
        The applied torque, N·m (smooth in t).
    t_eval : numpy.ndarray
        Increasing output times, starting at the initial time.
    rtol : float
        Relative tolerance of each phase.
    """
    F_s = friction.static_torque
    t_eval = np.asarray(t_eval, dtype=float)
    t, t_end = float(t_eval[0]), float(t_eval[-1])
    angle = np.zeros_like(t_eval)
    speed = np.zeros_like(t_eval)
    a, switches, stuck = 0.0, 0, True
    sigma = 0.0
    scale = F_s / inertia * (t_end - t_eval[0]) + 1e-300
    while t < t_end:
        if stuck:
            t_go = _breakaway(torque, F_s, t, t_eval)
            if t_go is None:
                angle[t_eval >= t] = a
                break
            angle[(t_eval >= t) & (t_eval <= t_go)] = a
            t, sigma, stuck = t_go, float(np.sign(torque(t_go))), False
            switches += 1
            continue
        t_stop, path = _slip(inertia, friction, torque, sigma, (t, t_end), a, rtol, rtol * scale)
        mask = (t_eval > t) & (t_eval <= t_stop)
        y = path(t_eval[mask])
        angle[mask], speed[mask] = y[0], y[1]
        a, t = float(path(t_stop)[0]), float(t_stop)
        if t >= t_end:
            break
        switches += 1
        if abs(torque(t)) <= F_s:
            stuck = True
        else:  # passes through zero speed: slips on in the direction of τ
            sigma = float(np.sign(torque(t)))
    return SwitchedRun(t_eval, angle, speed, switches)


def _breakaway(
    torque: Callable[[float], float], F_s: float, t: float, t_eval: np.ndarray
) -> float | None:
    """When a stuck axis leaves: the first time from t on that ``|τ|`` reaches F_s.

    The output grid after t is scanned, then the crossing refined by Brent's method;
    None if ``|τ|`` stays at or below F_s to the end of the grid.
    """
    from scipy.optimize import brentq

    later = t_eval[t_eval > t]
    grid = np.concatenate([[t], later])
    over = np.flatnonzero(np.abs([torque(s) for s in grid]) > F_s)
    if over.size == 0:
        return None
    j = over[0]

    def excess(s):
        return abs(torque(s)) - F_s

    return grid[0] if j == 0 else brentq(excess, grid[j - 1], grid[j])


def _slip(
    inertia: float,
    friction: DryFriction,
    torque: Callable[[float], float],
    sigma: float,
    span: tuple[float, float],
    angle: float,
    rtol: float,
    atol: float,
) -> tuple[float, Callable[[np.ndarray], np.ndarray]]:
    """One slip phase from rest: ``J ω̇ = τ(t) − σ (F_s + k |ω|)`` until ω returns to 0.

    Integrated by DOP853 over ``span`` from ``(angle, 0)``, with the return of the
    speed through zero as a terminal event. Returns the phase's end (the event, or the
    end of ``span``) and the dense solution ``t ↦ (angle, speed)``.
    """
    from scipy.integrate import solve_ivp

    F_s, k = friction.static_torque, friction.slope

    def rhs(s, y):
        return [y[1], (torque(s) - sigma * (F_s + k * abs(y[1]))) / inertia]

    def stop(s, y):
        return y[1] * sigma  # the speed falls back through zero (it starts at zero)

    stop.terminal, stop.direction = True, -1
    sol = solve_ivp(
        rhs, span, [angle, 0.0], method="DOP853", rtol=rtol, atol=atol,
        events=stop, dense_output=True,
    )  # fmt: skip
    t_stop = sol.t_events[0][0] if sol.t_events[0].size else span[1]
    return t_stop, sol.sol
