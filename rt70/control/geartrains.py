"""Backlash in the reducer and the book's remedy: two counter-torqued gear trains on one axis.

The book (§1.4, Fig. 1.4 c–d; §2.4, p. 51) names backlash ("мёртвый ход", a dead zone)
as the reducer nonlinearity that matters at ratios of 10⁵–10⁶, and gives the RT-70's
remedy: each axis has two gear trains, each with its own motor, closed on the main gear,
and the motors apply opposing ("распорные") torques that take up the dead travel. This
module models both.

Backlash (the "dead-zone spring" model, e.g. Nordin & Gutman, Automatica 38, 2002): one
train of stiffness C and damping D with a gap of half-width b (axis side) transmits ::

    τ = C dz(Δ) + D Δ̇     while the teeth touch (|Δ| > b),   τ = 0 inside the gap,
    dz(Δ) = Δ − b sign(Δ),

where ``Δ = α_m / i_r − α`` is the twist of (4.139). Teeth in contact can only push:
the damping term may not pull them apart faster than the spring lets go, so τ is clipped
at zero on the side of contact (``max(0, …)`` for Δ > b, ``min(0, …)`` for Δ < −b).
With b = 0 it is the linear reducer of :class:`rt70.control.drives.DcDrive`.

:class:`TwoTrainDrive` puts two DC motors, each with its own train of half the axis's
stiffness and damping (docs/drives.md gives C_r, D_r as the axis totals), on ONE
coordinate; its force is the sum of the two trains' torques. :class:`TwoTrainServo`
closes it with the cascade of :mod:`rt70.control.servo` (same PI laws, limits and conditional
integration) whose rate loop commands one current ``i`` per motor, split by the torque
bias (Gawronski et al., IEEE Antennas Propag. Mag. 42(6), 2000):

    i₁* = i + i_b,   i₂* = i − i_b,    i_b = bias_torque / (i_r c_m),

so train 1 pushes and train 2 holds back while the net torque ``2 c_m i_r i`` stays
below twice the bias: both stay engaged, and the axis never crosses a gap. With no bias
and no backlash the pair is the series equivalent of one drive (:func:`equivalent_drive`),
which tests/test_geartrains.py checks against :class:`rt70.control.servo.ServoDrive`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from typing import ClassVar

import numpy as np

from rt70.bondgraph.parameters import DriveParameters
from rt70.control.servo import CascadeGains, cascade_gains, clamped_pi
from rt70.errors import Rt70Error
from rt70.simulation.states import MechanicsForces, StateComponent

#: Armature voltages of the two motors as a function of (t, q, q̇, the drive's states).
Voltages = Callable[[float, np.ndarray, np.ndarray, np.ndarray], tuple[float, float]]

#: States of one train (after ``name:``, with the train's number 1 or 2 appended).
TRAIN_STATES = ("current", "motor_angle", "motor_speed")


def dead_zone(twist, half_width: float):
    """``dz(Δ) = Δ − b sign(Δ)`` outside the gap ``|Δ| ≤ b``, zero inside."""
    d = np.asarray(twist, dtype=float)
    out = d - np.clip(d, -half_width, half_width)
    return float(out) if out.ndim == 0 else out


def backlash_torque(
    twist: float, rate: float, stiffness: float, damping: float, half_width: float
) -> float:
    """Torque one train with a gap of half-width ``b`` transmits to the axis.

    ``C dz(Δ) + D Δ̇`` while the teeth touch, zero inside the gap; in contact it never
    pulls (clipped at zero on the contact side). ``half_width = 0``: the linear reducer
    (no gap: the other flank is already in contact, so the torque may change sign).

    Parameters
    ----------
    twist : float
        Δ = α_m / i_r − α, the train's twist, rad (axis side).
    rate : float
        Δ̇, rad/s.
    stiffness : float
        C, the train's stiffness, N·m/rad.
    damping : float
        D, its damping, N·m·s/rad.
    half_width : float
        b, half the gap, rad (axis side; 0: no backlash).
    """
    if half_width == 0.0:
        return stiffness * twist + damping * rate
    if twist > half_width:
        return max(0.0, stiffness * (twist - half_width) + damping * rate)
    if twist < -half_width:
        return min(0.0, stiffness * (twist + half_width) + damping * rate)
    return 0.0


def equivalent_drive(p: DriveParameters, count: int = 2) -> DriveParameters:
    """One drive equal to ``count`` identical motors in series driving one rigid train.

    Each motor carries the same current I; in series their voltages, inductances,
    resistances, EMFs and torques add: ``L, R, c_m, c_e, J_m, D_m`` times ``count``;
    ``C_r, D_r`` are already the axis totals. Its current is a motor's current, its
    voltage the sum of theirs.
    """
    n = count
    return replace(p, L_a=n * p.L_a, R_a=n * p.R_a, c_m=n * p.c_m, c_e=n * p.c_e,
                   J_m=n * p.J_m, D_m=n * p.D_m)  # fmt: skip


def parallel_drive(p: DriveParameters, count: int = 2) -> DriveParameters:
    """One drive equal to ``count`` identical motors with their armatures in parallel.

    The motors turn at one speed (same ratio) on one voltage, so they share the EMF and
    carry ``count`` times one motor's current: ``L_a / count``, ``R_a / count``, the same
    ``c_m``, ``c_e``, and ``count`` times ``J_m``, ``D_m``; ``C_r, D_r`` are already the
    axis totals. Its torque at a current is ``count`` motors' torque; its voltage a
    motor's (the scene's ``<rt70:drive>``, docs/urdf-extensions.md).
    """
    n = count
    return replace(p, L_a=p.L_a / n, R_a=p.R_a / n, J_m=n * p.J_m, D_m=n * p.D_m)


def train_gains(
    p: DriveParameters, load_inertia: float, position_hz: float = 1.0, ratio: float = 5.0, **limits
) -> CascadeGains:
    """:func:`rt70.control.servo.cascade_gains` for the two-motor axis, per motor.

    The rate and position loops are those of :func:`equivalent_drive` (total motor-side
    inertia ``2 J_m + J_l / i_r²`` over the pair's torque constant ``2 c_m``: the rate
    loop commands one motor's current); each motor's current loop is that of one motor
    (``K_p = L_a ω_c``, ``K_i = R_a ω_c``), its voltage limit a motor's.

    Parameters
    ----------
    p : DriveParameters
        ONE motor of the pair, the ratio i_r and the axis's total C_r, D_r.
    load_inertia : float
        Inertia of the axis, kg·m².
    position_hz : float
        Position-loop bandwidth, Hz.
    ratio : float
        Bandwidth ratio between a loop and the one inside it.
    **limits : float
        ``current_limit`` (A, per motor), ``rate_limit`` (rad/s) and ``voltage_limit``
        (V, of the series pair: each motor gets half) of :func:`rt70.control.servo.cascade_gains`.
    """
    g = cascade_gains(equivalent_drive(p), load_inertia, position_hz, ratio, **limits)
    return replace(g, kp_i=g.kp_i / 2, ki_i=g.ki_i / 2, voltage_limit=g.voltage_limit / 2)


class TwoTrainDrive(StateComponent):
    """Two DC motors, each through its own compliant train with backlash, on one coordinate.

    States ``name:current1, motor_angle1, motor_speed1, current2, …`` (per motor as in
    :class:`rt70.control.drives.DcDrive`, (4.137)); force: ``τ₁ + τ₂`` (:func:`backlash_torque`
    of each train's twist) on the coordinate; motor k feels ``τ_k / i_r``.

    Parameters
    ----------
    name : str
        Prefix of the state names.
    coordinates : list of str
        The scene's coordinate names.
    coordinate : str
        The driven coordinate (axis angle, rad).
    parameters : DriveParameters
        ONE motor (L_a, R_a, c_m, c_e, J_m, D_m), the ratio i_r, and the axis's total
        reducer stiffness C_r and damping D_r: each train gets half.
    backlash : float
        Half-width b of each train's gap, rad, axis side (0: no backlash).
    voltages : callable or (float, float)
        The two armature voltages, or ``u(t, q, q̇, s) -> (u₁, u₂)``.
    initial, atol : array_like, optional
        Initial states and tolerances (default zero; 1e-9).
    """

    STATES: tuple[str, ...] = tuple(f"{s}{k}" for k in (1, 2) for s in TRAIN_STATES)
    STATE_UNITS: ClassVar[dict[str, str]] = {
        f"{s}{k}": u
        for k in (1, 2)
        for s, u in zip(TRAIN_STATES, ("A", "rad", "rad/s"), strict=True)
    }

    def __init__(
        self,
        name: str,
        coordinates: list[str],
        coordinate: str,
        parameters: DriveParameters,
        backlash: float = 0.0,
        voltages: Voltages | tuple[float, float] = (0.0, 0.0),
        initial=None,
        atol=None,
    ) -> None:
        if coordinate not in coordinates:
            raise Rt70Error(f"drive '{name}': no coordinate '{coordinate}'")
        if not (np.isfinite(backlash) and backlash >= 0.0):
            raise Rt70Error(f"drive '{name}': backlash must be finite and >= 0, got {backlash!r}")
        self.names = tuple(f"{name}:{state}" for state in self.STATES)
        self.index = coordinates.index(coordinate)
        self.n = len(coordinates)
        self.p = parameters
        self.backlash = float(backlash)
        if callable(voltages):
            self.voltages = voltages
        else:
            u = tuple(float(v) for v in voltages)
            self.voltages = lambda t, q, qd, s, u=u: u
        k = len(self.STATES)
        self.initial = np.zeros(k) if initial is None else np.asarray(initial, dtype=float)
        self.atol = np.full(k, 1e-9) if atol is None else np.asarray(atol, dtype=float)

    def train_torques(self, q: np.ndarray, qd: np.ndarray, s: np.ndarray) -> tuple[float, float]:
        """``(τ₁, τ₂)``: each train's torque on the axis (:func:`backlash_torque`).

        Parameters
        ----------
        q, qd : numpy.ndarray, shape (nv,)
            Generalised coordinates (m or rad) and velocities (m/s or rad/s); the axis's
            are ``q[index]``, ``qd[index]``.
        s : numpy.ndarray
            ``[I₁, α_m1, ω_m1, I₂, α_m2, ω_m2, …]``: A, rad, rad/s per motor (:attr:`STATES`).
        """
        p, k = self.p, self.index
        C, D = 0.5 * p.C_r, 0.5 * p.D_r
        return tuple(
            backlash_torque(
                s[3 * j + 1] / p.i_r - q[k], s[3 * j + 2] / p.i_r - qd[k], C, D, self.backlash
            )
            for j in (0, 1)
        )  # type: ignore[return-value]

    def force(self, t: float, q: np.ndarray, qd: np.ndarray, s: np.ndarray) -> np.ndarray:
        """``τ₁ + τ₂`` as a generalised force on the driven coordinate.

        Parameters
        ----------
        t : float
            Time, s (unused).
        q, qd : numpy.ndarray, shape (nv,)
            Generalised coordinates (m or rad) and velocities (m/s or rad/s); the axis's
            are ``q[index]``, ``qd[index]``.
        s : numpy.ndarray
            ``[I₁, α_m1, ω_m1, I₂, α_m2, ω_m2, …]``: A, rad, rad/s per motor (:attr:`STATES`).
        """
        Q = np.zeros(self.n)
        Q[self.index] = sum(self.train_torques(q, qd, s))
        return Q

    def derivative(
        self, t: float, q: np.ndarray, qd: np.ndarray, s: np.ndarray, forces: MechanicsForces
    ) -> np.ndarray:
        """``[İ₁, α̇_m1, ω̇_m1, İ₂, α̇_m2, ω̇_m2]`` under the two voltages.

        Parameters
        ----------
        t : float
            Time, s (used by the voltage law only).
        q, qd : numpy.ndarray, shape (nv,)
            Generalised coordinates (m or rad) and velocities (m/s or rad/s); the axis's
            are ``q[index]``, ``qd[index]``.
        s : numpy.ndarray
            ``[I₁, α_m1, ω_m1, I₂, α_m2, ω_m2, …]``: A, rad, rad/s per motor (:attr:`STATES`).
        forces : MechanicsForces
            The mechanics' forces at this evaluation (unused).
        """
        return self.motor_rates(q, qd, s, self.voltages(t, q, qd, s))

    def motor_rates(self, q: np.ndarray, qd: np.ndarray, s: np.ndarray, u) -> np.ndarray:
        """Both motors' rates (4.137) under the voltages ``u = (u₁, u₂)``.

        Parameters
        ----------
        q, qd : numpy.ndarray, shape (nv,)
            Generalised coordinates (m or rad) and velocities (m/s or rad/s); the axis's
            are ``q[index]``, ``qd[index]``.
        s : numpy.ndarray
            ``[I₁, α_m1, ω_m1, I₂, α_m2, ω_m2, …]``: A, rad, rad/s per motor (:attr:`STATES`).
        u : tuple of float
            The two armature voltages ``(u₁, u₂)``, V.
        """
        p = self.p
        taus = self.train_torques(q, qd, s)
        out = np.empty(6)
        for j in (0, 1):
            current, speed = s[3 * j], s[3 * j + 2]
            out[3 * j] = (u[j] - p.R_a * current - p.c_e * speed) / p.L_a
            out[3 * j + 1] = speed
            out[3 * j + 2] = (p.c_m * current - p.D_m * speed - taus[j] / p.i_r) / p.J_m
        return out

    def bias_state(self, angle: float, bias_torque: float, load_torque: float = 0.0) -> np.ndarray:
        """The states holding the axis at ``angle`` at rest, trains at ``±bias`` + half the load.

        Train 1 carries ``load/2 + bias`` (twist past +b), train 2 ``load/2 − bias``.

        Parameters
        ----------
        angle : float
            The axis angle held, rad.
        bias_torque : float
            The counter-torque of each train, N·m, axis side.
        load_torque : float
            The torque the pair holds on the axis together, N·m (shared equally).
        """
        p, b = self.p, self.backlash
        out = np.zeros(6)
        for j, tau in enumerate((0.5 * load_torque + bias_torque, 0.5 * load_torque - bias_torque)):
            twist = tau / (0.5 * p.C_r) + (np.sign(tau) * b if tau else 0.0)
            out[3 * j : 3 * j + 3] = (tau / (p.i_r * p.c_m), p.i_r * (angle + twist), 0.0)
        return out


class TwoTrainServo(TwoTrainDrive):
    """:class:`TwoTrainDrive` closed by the current–rate–position cascade, torque-biased.

    The position loop (on the axis angle) and the rate loop (on the mean motor speed)
    are :class:`rt70.control.servo.ServoDrive`'s; the rate loop's current reference ``i`` (one
    motor's) is split into ``i ± i_b`` (module docstring), each clipped to the current
    limit, and each motor has its own current loop. States: the drive's six, then the
    integrals of the position and rate errors and of the two current errors.

    Parameters
    ----------
    gains : CascadeGains
        Per motor, from :func:`train_gains`.
    reference : callable t -> float
        Position reference, rad.
    bias_torque : float
        Counter-torque of each train, N·m, axis side (0: no bias, the trains act as one).
    Other parameters as :class:`TwoTrainDrive` (no ``voltages``: the cascade sets them).
    """

    STATES = TwoTrainDrive.STATES + ("int_position", "int_rate", "int_current1", "int_current2")
    STATE_UNITS: ClassVar[dict[str, str]] = {
        **TwoTrainDrive.STATE_UNITS,
        "int_position": "rad·s",
        "int_rate": "rad",
        "int_current1": "A·s",
        "int_current2": "A·s",
    }

    def __init__(
        self,
        name: str,
        coordinates: list[str],
        coordinate: str,
        parameters: DriveParameters,
        gains: CascadeGains,
        reference: Callable[[float], float],
        backlash: float = 0.0,
        bias_torque: float = 0.0,
        initial=None,
        atol=None,
    ) -> None:
        super().__init__(name, coordinates, coordinate, parameters, backlash, (0.0, 0.0),
                         initial, atol)  # fmt: skip
        if not (np.isfinite(bias_torque) and bias_torque >= 0.0):
            raise Rt70Error(f"drive '{name}': bias_torque must be finite and >= 0")
        self.g = gains
        self.reference = reference
        self.bias_current = bias_torque / (parameters.i_r * parameters.c_m)

    def current_references(self, i: float) -> tuple[float, float]:
        """The torque-bias split of one motor's current reference ``i``: ``i ± i_b``, clipped."""
        lim = self.g.current_limit
        return (float(np.clip(i + self.bias_current, -lim, lim)),
                float(np.clip(i - self.bias_current, -lim, lim)))  # fmt: skip

    def derivative(
        self, t: float, q: np.ndarray, qd: np.ndarray, s: np.ndarray, forces: MechanicsForces
    ) -> np.ndarray:
        """The motors' rates under the cascade's voltages, then the four integrators.

        Parameters
        ----------
        t : float
            Time, s (the position reference is taken at t).
        q, qd : numpy.ndarray, shape (nv,)
            Generalised coordinates (m or rad) and velocities (m/s or rad/s); the axis's
            are ``q[index]``, ``qd[index]``.
        s : numpy.ndarray, shape (10,)
            The two motors' ``[I, α_m, ω_m]`` (A, rad, rad/s), then the integrals of the
            position (rad·s) and rate (rad) errors and of the two current errors (A·s).
        forces : MechanicsForces
            The mechanics' forces at this evaluation (unused).
        """
        g, p = self.g, self.p
        e_p = float(self.reference(t)) - q[self.index]
        rate_ref, sat_p = clamped_pi(g.kp_p, g.ki_p, e_p, s[6], g.rate_limit)
        e_v = p.i_r * rate_ref - 0.5 * (s[2] + s[5])  # on the mean motor speed
        i_ref, sat_v = clamped_pi(g.kp_v, g.ki_v, e_v, s[7], g.current_limit)
        u, e_i, sat_i = [], [], []
        for j, ref in enumerate(self.current_references(i_ref)):
            e = ref - s[3 * j]
            v, sat = clamped_pi(g.kp_i, g.ki_i, e, s[8 + j], g.voltage_limit)
            sat_i.append(sat)
            u.append(v)
            e_i.append(e)
        drive = self.motor_rates(q, qd, s, u)
        errors = (e_p, e_v, *e_i)
        saturated = (sat_p, sat_v, *sat_i)
        integrals = [0.0 if sat else e for e, sat in zip(errors, saturated, strict=True)]
        return np.concatenate([drive, integrals])
