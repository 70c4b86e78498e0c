"""A DC motor driving one axis through a compliant reducer, as simulation states.

The drive of formalism §4.5 ((4.137)–(4.143)) on one axis: an armature circuit
(inductance L_a, resistance R_a, back-EMF c_e ω_m), a rotor (inertia J_m, viscous D_m,
torque c_m I) and a reducer of ratio i_r whose compliance C_r and damping D_r sit
between the rotor, seen through the ratio (α_m / i_r), and the driven coordinate α of
the structure. Its states are the armature current I, the rotor angle α_m and speed ω_m;
it pushes the reducer torque

    τ_r = C_r (α_m / i_r − α) + D_r (ω_m / i_r − α̇)

on the structure as the generalised force ``τ_r ∂α/∂q`` (the extra-state seam's
``force``, :mod:`rt70.simulation.states`) and feels ``τ_r / i_r`` back on the rotor:

    L_a İ = u − R_a I − c_e ω_m,   α̇_m = ω_m,   J_m ω̇_m = c_m I − D_m ω_m − τ_r / i_r.

The angle α(q) is the drive's coupling (:mod:`rt70.model.couplings`): one coordinate
(``coordinate=``), or a scene's ``<rt70:drive>`` computed on one side — a joint's
coordinate (4.143) or a gear sector's mesh angle (4.150) — built by
:func:`scene_drives`. The structure's own forces (gravity, springs, the load's damping)
come from the scene. The same drive assembled as a bond graph (:mod:`rt70.bondgraph`)
and in Lagrange form (:func:`rt70.bondgraph.lagrange.drive_lagrange`) gives the linear
equations this component must reproduce on a rigid load (tests/test_drives.py). Dry
friction and backlash are not modelled.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import ClassVar

import numpy as np

from rt70.bondgraph.parameters import DriveParameters
from rt70.errors import Rt70Error
from rt70.model.couplings import CoordinateCoupling, SceneCoupling
from rt70.simulation.states import MechanicsForces, StateComponent
from rt70.urdf.description import DRIVE_PARAMETERS

#: Armature voltage as a function of (t, q, q̇, the drive's states [I, α_m, ω_m]).
Voltage = Callable[[float, np.ndarray, np.ndarray, np.ndarray], float]


class DcDrive(StateComponent):
    """A DC motor and compliant reducer driving one axis (formalism §4.5).

    Parameters
    ----------
    name : str
        Prefix of the state names (``name:current``, ``name:motor_angle``,
        ``name:motor_speed``).
    coordinates : sequence of str or None
        The scene's coordinate names (``scene.coordinate_names``); None with ``coupling``.
    coordinate : str or None
        The driven coordinate (an axis angle, rad); None with ``coupling``.
    parameters : DriveParameters
        L_a, R_a, c_m, c_e, J_m, D_m, i_r, C_r, D_r (``J_l``, ``D_l`` are the scene's:
        its inertia and damping; they are not used here).
    voltage : float or callable
        Armature voltage u, V: a constant or ``u(t, q, q̇, s)`` (a servo law).
    initial : array_like, optional
        ``[I, α_m, ω_m]`` at the start; default zero. :meth:`holding` gives the state
        that holds a torque at rest.
    atol : array_like, optional
        Absolute tolerances of the states (default 1e-9 A, rad, rad/s).
    coupling : CoordinateCoupling or SceneCoupling, optional
        The angle α(q) the reducer acts on (:mod:`rt70.model.couplings`); default the
        coordinate ``coordinate``. :attr:`index` is its axis coordinate.
    """

    #: The drive's states (after ``name:``); a subclass appends its own.
    STATES: tuple[str, ...] = ("current", "motor_angle", "motor_speed")
    STATE_UNITS: ClassVar[dict[str, str]] = {
        "current": "A",
        "motor_angle": "rad",
        "motor_speed": "rad/s",
    }

    def __init__(
        self,
        name: str,
        coordinates: list[str],
        coordinate: str,
        parameters: DriveParameters,
        voltage: float | Voltage = 0.0,
        initial=None,
        atol=None,
        *,
        coupling: CoordinateCoupling | SceneCoupling | None = None,
    ) -> None:
        if coupling is None:
            if coordinates is None or coordinate is None:
                raise Rt70Error(f"drive '{name}': give a coordinate or a coupling")
            coupling = CoordinateCoupling(list(coordinates), coordinate, name)
        self.coupling = coupling
        self.names = tuple(f"{name}:{state}" for state in self.STATES)
        self.index = coupling.index
        self.n = coupling.n
        self.p = parameters
        self.voltage = voltage if callable(voltage) else (lambda t, q, qd, s, u=float(voltage): u)
        k = len(self.STATES)
        self.initial = np.zeros(k) if initial is None else np.asarray(initial, dtype=float)
        self.atol = np.full(k, 1e-9) if atol is None else np.asarray(atol, dtype=float)

    @staticmethod
    def holding(parameters: DriveParameters, angle: float, torque: float) -> np.ndarray:
        """``[I, α_m, ω_m]`` holding ``torque`` on the coordinate at ``angle``, at rest.

        The reducer is twisted by ``torque / C_r`` and the motor supplies
        ``torque / i_r``: ``I = torque / (i_r c_m)``, ``α_m = i_r (angle + torque / C_r)``.

        Parameters
        ----------
        parameters : DriveParameters
            The drive's parameters (i_r, c_m, C_r are used).
        angle : float
            The driven angle α the load is held at, rad.
        torque : float
            The torque held on the driven coordinate, N·m.
        """
        p = parameters
        return np.array([torque / (p.i_r * p.c_m), p.i_r * (angle + torque / p.C_r), 0.0])

    def fastest_rate(self) -> tuple[float, str]:
        """The drive's fastest rate, 1/s, and which it is (a stiffness check's input).

        The rates of the motor seen alone, the load held: the armature's ``R_a/L_a``, the
        electromechanical ``√(c_m c_e/(L_a J_m))``, the reducer's ``√(C_r/(J_m i_r²))``
        and its damping's ``D_r/(J_m i_r²)``, the rotor's ``D_m/J_m``. The implicit
        methods' Jacobian treats the drive's states explicitly (:mod:`rt70.simulation.states`), so
        a run needs steps of about the inverse of the fastest (rt70_servo: 50 1/s, the
        armature).
        """
        p = self.p
        with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
            rates = {
                "R_a/L_a": p.R_a / p.L_a,
                "√(c_m c_e/(L_a J_m))": np.sqrt(p.c_m * p.c_e / (p.L_a * p.J_m)),
                "√(C_r/(J_m i_r²))": np.sqrt(p.C_r / (p.J_m * p.i_r**2)),
                "D_r/(J_m i_r²)": p.D_r / (p.J_m * p.i_r**2),
                "D_m/J_m": p.D_m / p.J_m,
            }
        label = max(rates, key=lambda k: np.nan_to_num(rates[k], nan=np.inf))
        rate = float(rates[label])
        return (rate if np.isfinite(rate) else np.inf), label

    def twist(self, q: np.ndarray, qd: np.ndarray, s: np.ndarray) -> tuple[float, float]:
        """The reducer's twist and its rate, ``(Δ, Δ̇) = (α − α_m/i_r, α̇ − ω_m/i_r)`` (4.139).

        Parameters
        ----------
        q, qd : numpy.ndarray, shape (nv,)
            Generalised coordinates (m or rad) and velocities (m/s or rad/s), book order.
        s : numpy.ndarray
            The drive's states ``[I, α_m, ω_m, …]``: A, rad, rad/s (:attr:`STATES`).
        """
        p, c = self.p, self.coupling
        return c.angle(q) - s[1] / p.i_r, c.rate(q, qd) - s[2] / p.i_r

    def reducer_torque(self, q: np.ndarray, qd: np.ndarray, s: np.ndarray) -> float:
        """``τ_r = C_r (α_m/i_r − α) + D_r (ω_m/i_r − α̇) = −C_r Δ − D_r Δ̇`` (4.143).

        Parameters
        ----------
        q, qd : numpy.ndarray, shape (nv,)
            Generalised coordinates (m or rad) and velocities (m/s or rad/s), book order.
        s : numpy.ndarray
            The drive's states ``[I, α_m, ω_m, …]``: A, rad, rad/s (:attr:`STATES`).
        """
        delta, rate = self.twist(q, qd, s)
        return -self.p.C_r * delta - self.p.D_r * rate

    def force(self, t: float, q: np.ndarray, qd: np.ndarray, s: np.ndarray) -> np.ndarray:
        """The reducer torque as a generalised force, ``τ_r ∂α/∂q``.

        Parameters
        ----------
        t : float
            Time, s (unused).
        q, qd : numpy.ndarray, shape (nv,)
            Generalised coordinates (m or rad) and velocities (m/s or rad/s), book order.
        s : numpy.ndarray
            The drive's states ``[I, α_m, ω_m, …]``: A, rad, rad/s (:attr:`STATES`).
        """
        return self.coupling.force(q, self.reducer_torque(q, qd, s))

    def derivative(
        self, t: float, q: np.ndarray, qd: np.ndarray, s: np.ndarray, forces: MechanicsForces
    ) -> np.ndarray:
        """``[İ, α̇_m, ω̇_m]`` of the armature and the rotor (4.137)–(4.143).

        Parameters
        ----------
        t : float
            Time, s (used by the voltage law only).
        q, qd : numpy.ndarray, shape (nv,)
            Generalised coordinates (m or rad) and velocities (m/s or rad/s), book order.
        s : numpy.ndarray
            The drive's states ``[I, α_m, ω_m, …]``: A, rad, rad/s (:attr:`STATES`).
        forces : MechanicsForces
            The mechanics' forces at this evaluation (unused).
        """
        return self.motor_rates(q, qd, s, float(self.voltage(t, q, qd, s)))

    def motor_rates(self, q: np.ndarray, qd: np.ndarray, s: np.ndarray, u: float) -> np.ndarray:
        """``[İ, α̇_m, ω̇_m]`` under the armature voltage ``u`` (s = ``[I, α_m, ω_m]``).

        Parameters
        ----------
        q, qd : numpy.ndarray, shape (nv,)
            Generalised coordinates (m or rad) and velocities (m/s or rad/s), book order.
        s : numpy.ndarray
            The drive's states ``[I, α_m, ω_m, …]``: A, rad, rad/s (:attr:`STATES`).
        u : float
            The armature voltage, V.
        """
        p = self.p
        current, _, speed = s[0], s[1], s[2]
        tau = self.reducer_torque(q, qd, s)
        return np.array(
            (
                (u - p.R_a * current - p.c_e * speed) / p.L_a,
                speed,
                (p.c_m * current - p.D_m * speed - tau / p.i_r) / p.J_m,
            )
        )


def scene_drives(
    scene,
    side: str,
    voltage: float | Voltage | dict[str, float | Voltage] = 0.0,
    load_inertia: float = 1.0,
) -> list[DcDrive]:
    """The scene's ``<rt70:drive>`` elements as simulation components, on one side.

    Each is a :class:`DcDrive` named after the element (states ``name:current``,
    ``name:motor_angle``, ``name:motor_speed``) with a :class:`SceneCoupling`: the
    reducer acts on θ_d computed by ``side``'s kinematics.

    Parameters
    ----------
    scene : rt70.model.scene.Scene
        The scene.
    side : {"reference", "textbook"}
        The side whose kinematics computes θ_d (use the simulation's side).
    voltage : float, callable or dict
        Armature voltage of every drive, or a dict by drive name (missing: 0 V).
    load_inertia : float
        ``J_l`` of the :class:`DriveParameters` (not used by the drive; the scene's
        inertia is the load).

    Raises
    ------
    Rt70Error
        If ``voltage`` names a drive the scene does not have.
    """
    drives = scene.description.drives
    volts = voltage if isinstance(voltage, dict) else {d.name: voltage for d in drives}
    unknown = sorted(set(volts) - {d.name for d in drives})
    if unknown:
        raise Rt70Error(f"{scene.name}: no drive named {', '.join(unknown)}")
    return [
        DcDrive(
            d.name,
            None,
            None,
            drive_parameters(d, load_inertia),
            volts.get(d.name, 0.0),
            coupling=SceneCoupling(scene, d, side),
        )
        for d in drives
    ]


def scene_drive(scene, name: str):
    """The scene's ``<rt70:drive>`` called ``name`` (:class:`rt70.urdf.Drive`).

    For a drive built by hand on a scene element, e.g. a servo:
    ``ServoDrive(name, None, None, drive_parameters(d, J), gains, reference,
    coupling=SceneCoupling(scene, d, side))`` with ``d = scene_drive(scene, name)``.

    Raises
    ------
    Rt70Error
        If the scene has no drive of that name.
    """
    for drive in scene.description.drives:
        if drive.name == name:
            return drive
    known = ", ".join(d.name for d in scene.description.drives) or "none"
    raise Rt70Error(f"{scene.name}: no drive named {name} (drives: {known})")


def drive_parameters(drive, load_inertia: float = 1.0, load_damping: float = 0.0):
    """:class:`DriveParameters` of a ``<rt70:drive>`` (:class:`rt70.urdf.Drive`).

    The load's ``J_l``, ``D_l`` are not in the element (the scene is the load): pass
    them when a design needs them (:func:`rt70.control.servo.cascade_gains` takes its own).

    Parameters
    ----------
    drive : rt70.urdf.Drive
        The ``<rt70:drive>`` element: L_a, R_a, c_m, c_e, J_m, D_m, i_r, C_r, D_r.
    load_inertia : float
        ``J_l``, the load's inertia about the driven axis, kg·m².
    load_damping : float
        ``D_l``, the load's viscous damping about it, N·m·s/rad.
    """
    return DriveParameters(
        **{k: getattr(drive, k) for k in DRIVE_PARAMETERS}, J_l=load_inertia, D_l=load_damping
    )
