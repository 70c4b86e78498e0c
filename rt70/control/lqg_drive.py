"""A DC drive whose armature voltage comes from a linear (LQG) controller's state space.

One job: close a model-based controller — any linear state space from the references
and measurements to the armature voltage, e.g. the Kalman filter + LQR with integral
action of :func:`rt70.control.lqg.design` — around the NONLINEAR model in simulation.
:class:`LqgDrive` is a :class:`rt70.control.drives.DcDrive` (formalism §4.5, (4.137)–(4.143))
whose states ``[I, α_m, ω_m]`` are followed by the controller's states ``x_c``:

    v = [r − y₀_angle, y − y₀],          u_lin = C_c x_c + D_c v,
    u = sat(u₀ + u_lin),                 ẋ_c = A_c x_c + B_c v + (b_u + b_aw)(u − u₀ − u_lin),

where ``y`` are the measurements read from ``q``, ``q̇`` and the drive's states
(:data:`MEASUREMENTS`), ``y₀`` their values at the operating point the controller was
designed about, ``u₀`` a voltage offset and ``sat`` the clamp at ``±voltage_limit``.
While the voltage is inside its limit, the last term is zero and the component's
controller is exactly ``(A_c, B_c, C_c, D_c)``.

Anti-windup, two parts (Åström & Murray, *Feedback Systems*, 2008, §10.4 — an observer
fed the applied input; Åström & Hägglund, *Advanced PID Control*, 2006, §3.5 —
back-calculation):

- ``b_u`` (``observer_input``) is the column through which the controller's own output
  enters its estimator (for :func:`rt70.control.lqg.design`, ``B − L D`` of the reduced
  plant): with it the estimator is driven by the voltage actually applied, so its
  estimate stays true while the voltage is clamped;
- ``b_aw`` back-calculates every integral state ``z_k`` (``integral_states``): its rate
  gets ``(u − u₀ − u_lin) / (C_c,k T_t)``, so the integral term ``C_c,k z_k`` relaxes
  to the limit with the tracking time ``T_t`` instead of winding up.

:meth:`LqgDrive.steady_controller` presets the controller at a held equilibrium: the
controller state at rest (``ẋ_c = 0``) whose output is the holding voltage — the
integral state then carries the holding voltage, and a hold starts at rest.

The component imports nothing of the RT-70 (its factory is
:mod:`rt70.reports.servo_lqg`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from rt70.bondgraph.parameters import DriveParameters
from rt70.control.drives import DcDrive
from rt70.errors import Rt70Error, ShapeError
from rt70.simulation.states import MechanicsForces

#: The measurements a controller may read: the drive's axis angle α(q) (rad) and rate
#: (rad/s), its armature current (A), rotor angle (rad) and speed (rad/s).
MEASUREMENTS = ("axis_angle", "axis_rate", "current", "motor_angle", "motor_speed")


class LqgDrive(DcDrive):
    """A DC drive closed by a linear controller ``(A_c, B_c, C_c, D_c)`` (module docstring).

    Parameters
    ----------
    name, coordinates, coordinate, parameters
        As :class:`rt70.control.drives.DcDrive`.
    matrices : (A_c, B_c, C_c, D_c)
        The controller: inputs the reference then ``measured`` (deviations from the
        operating point), output the armature voltage deviation (V), shape
        ``(n, n), (n, 1 + m), (1, n), (1, 1 + m)``.
    measured : sequence of str
        The measurements in the controller's input order, from :data:`MEASUREMENTS`.
    reference : callable
        The axis-angle reference ``r(t)``, rad (absolute, as ``α(q)``).
    voltage_limit : float
        The clamp of the armature voltage, V.
    operating : dict, optional
        Values of the measurements at the operating point (default 0); the reference
        enters as ``r − operating["axis_angle"]``.
    voltage_offset : float
        ``u₀``, V, added to the controller's output (default 0: the controller's
        integral state supplies the holding voltage, see :meth:`steady_controller`).
    observer_input : array_like, optional
        ``b_u``, shape (n,): where the applied voltage enters the controller's
        estimator (default none: the estimator sees the unclamped voltage).
    integral_states : sequence of int
        Indices of the controller's integral states (back-calculated).
    tracking_time : float
        ``T_t`` of the back-calculation, s.
    initial : array_like, optional
        ``[I, α_m, ω_m, x_c]``; default zero.
    atol : array_like, optional
        Absolute tolerances of the same states.
    coupling
        As :class:`rt70.control.drives.DcDrive`.

    Raises
    ------
    ShapeError
        If the matrices do not fit together or with ``measured``.
    Rt70Error
        An unknown measurement, a non-positive limit or tracking time, an integral state
        that does not act on the output.
    """

    def __init__(
        self,
        name: str,
        coordinates: list[str] | None,
        coordinate: str | None,
        parameters: DriveParameters,
        matrices: Sequence[np.ndarray],
        measured: Sequence[str],
        reference: Callable[[float], float],
        voltage_limit: float,
        operating: dict[str, float] | None = None,
        voltage_offset: float = 0.0,
        observer_input=None,
        integral_states: Sequence[int] = (),
        tracking_time: float = 1.0,
        initial=None,
        atol=None,
        *,
        coupling=None,
    ) -> None:
        A, B, C, D = (np.atleast_2d(np.asarray(m, dtype=float)) for m in matrices)
        n, m = A.shape[0], len(measured)
        shapes = {"A_c": (A.shape, (n, n)), "B_c": (B.shape, (n, 1 + m))}
        shapes |= {"C_c": (C.shape, (1, n)), "D_c": (D.shape, (1, 1 + m))}
        for what, (got, want) in shapes.items():
            if got != want:
                raise ShapeError(f"drive '{name}': {what} must have shape {want}, got {got}")
        unknown = [k for k in measured if k not in MEASUREMENTS]
        if unknown:
            raise Rt70Error(
                f"drive '{name}': unknown measurement {', '.join(unknown)} "
                f"(choose from {', '.join(MEASUREMENTS)})"
            )
        if not (voltage_limit > 0 and tracking_time > 0):
            raise Rt70Error(f"drive '{name}': voltage_limit and tracking_time must be positive")
        self.STATES = DcDrive.STATES + tuple(f"controller_{k}" for k in range(n))
        super().__init__(
            name, coordinates, coordinate, parameters, 0.0, initial, atol, coupling=coupling
        )
        self.A_c, self.B_c, self.C_c, self.D_c = A, B, C[0], D[0]
        self.measured = tuple(measured)
        self.reference = reference
        self.voltage_limit = float(voltage_limit)
        op = {k: 0.0 for k in MEASUREMENTS} | dict(operating or {})
        self.y0 = np.array([op[k] for k in self.measured])
        self.r0 = float(op["axis_angle"])
        self.u0 = float(voltage_offset)
        b_u = np.zeros(n) if observer_input is None else np.asarray(observer_input, float)
        if b_u.shape != (n,):
            raise ShapeError(f"drive '{name}': observer_input must have shape ({n},)")
        b_aw = np.zeros(n)
        for k in integral_states:
            if self.C_c[k] == 0.0:
                raise Rt70Error(f"drive '{name}': integral state {k} does not act on the voltage")
            b_aw[k] = 1.0 / (self.C_c[k] * tracking_time)
        self.b_clamp = b_u + b_aw

    def measure(self, q: np.ndarray, qd: np.ndarray, s: np.ndarray) -> np.ndarray:
        """The measurements (:attr:`measured`, absolute) at a state (``s`` = ``[I, α_m, ω_m]``).

        Parameters
        ----------
        q, qd : numpy.ndarray, shape (nv,)
            Generalised coordinates (m or rad) and velocities (m/s or rad/s), book order.
        s : numpy.ndarray, shape (3,)
            The drive's ``[I, α_m, ω_m]``: A, rad, rad/s.
        """
        values = {
            "axis_angle": lambda: self.coupling.angle(q),
            "axis_rate": lambda: self.coupling.rate(q, qd),
            "current": lambda: s[0],
            "motor_angle": lambda: s[1],
            "motor_speed": lambda: s[2],
        }
        return np.array([values[k]() for k in self.measured], dtype=float)

    def controller_inputs(self, t: float, q: np.ndarray, qd: np.ndarray, s: np.ndarray):
        """``v = [r − y₀_angle, y − y₀]``: the controller's inputs as deviations.

        Parameters
        ----------
        t : float
            Time, s (the reference is taken at t).
        q, qd : numpy.ndarray, shape (nv,)
            Generalised coordinates (m or rad) and velocities (m/s or rad/s), book order.
        s : numpy.ndarray
            The drive's states ``[I, α_m, ω_m]`` (A, rad, rad/s), then the controller's ``x_c``.
        """
        y = self.measure(q, qd, s[:3]) - self.y0
        return np.concatenate(([float(self.reference(t)) - self.r0], y))

    def _voltages(self, t, q, qd, s):
        """(controller inputs, the controller's output, the applied armature voltage)."""
        v = self.controller_inputs(t, q, qd, s)
        u_lin = float(self.C_c @ s[3:] + self.D_c @ v)
        u = min(max(self.u0 + u_lin, -self.voltage_limit), self.voltage_limit)
        return v, u_lin, u

    def voltage_of(self, t: float, q: np.ndarray, qd: np.ndarray, s: np.ndarray) -> float:
        """The armature voltage applied at a state (V), after the clamp.

        Parameters
        ----------
        t : float
            Time, s (the reference is taken at t).
        q, qd : numpy.ndarray, shape (nv,)
            Generalised coordinates (m or rad) and velocities (m/s or rad/s), book order.
        s : numpy.ndarray
            The drive's states ``[I, α_m, ω_m]`` (A, rad, rad/s), then the controller's ``x_c``.
        """
        return self._voltages(t, q, qd, s)[2]

    def derivative(
        self, t: float, q: np.ndarray, qd: np.ndarray, s: np.ndarray, forces: MechanicsForces
    ) -> np.ndarray:
        """The drive's ``[İ, α̇_m, ω̇_m]`` under the clamped voltage, then ``ẋ_c``.

        Parameters
        ----------
        t : float
            Time, s (the reference is taken at t).
        q, qd : numpy.ndarray, shape (nv,)
            Generalised coordinates (m or rad) and velocities (m/s or rad/s), book order.
        s : numpy.ndarray
            The drive's states ``[I, α_m, ω_m]`` (A, rad, rad/s), then the controller's ``x_c``.
        forces : MechanicsForces
            The mechanics' forces at this evaluation (unused).
        """
        v, u_lin, u = self._voltages(t, q, qd, s)
        drive = self.motor_rates(q, qd, s[:3], u)
        xc = self.A_c @ s[3:] + self.B_c @ v + self.b_clamp * (u - self.u0 - u_lin)
        return np.concatenate([drive, xc])

    def force(self, t: float, q: np.ndarray, qd: np.ndarray, s: np.ndarray) -> np.ndarray:
        """The reducer torque on the driven coordinate (from the drive's own states).

        Parameters
        ----------
        t : float
            Time, s (unused).
        q, qd : numpy.ndarray, shape (nv,)
            Generalised coordinates (m or rad) and velocities (m/s or rad/s), book order.
        s : numpy.ndarray
            The drive's states ``[I, α_m, ω_m]`` (A, rad, rad/s), then the controller's ``x_c``.
        """
        return super().force(t, q, qd, s[:3])

    @staticmethod
    def steady_controller(
        matrices: Sequence[np.ndarray], inputs: np.ndarray, voltage: float, tol: float = 1e-9
    ) -> np.ndarray:
        """The controller state at rest under ``inputs`` whose output is ``voltage``.

        Solves ``A_c x + B_c v = 0``, ``C_c x + D_c v = voltage`` (least squares; with
        integral action ``A_c`` is singular and the integral state takes the voltage).

        Parameters
        ----------
        matrices : (A_c, B_c, C_c, D_c)
            The controller (shapes as :class:`LqgDrive`'s).
        inputs : numpy.ndarray, shape (1 + m,)
            Its inputs ``v`` at rest (:meth:`controller_inputs`: deviations).
        voltage : float
            The output wanted, V (the holding voltage less ``u₀``).
        tol : float
            Relative residual above which an equation counts as unsolved.

        Raises
        ------
        Rt70Error
            If no such state exists (an equation's residual above ``tol`` of its terms).
        """
        A, B, C, D = (np.atleast_2d(np.asarray(m, dtype=float)) for m in matrices)
        v = np.asarray(inputs, dtype=float)
        M = np.vstack([A, C])
        rhs = np.r_[-B @ v, voltage - D @ v]
        x = np.linalg.lstsq(M, rhs, rcond=None)[0]
        # each equation against its own terms' size: the rounding of a consistent one
        scale = np.abs(rhs) + np.abs(M) @ np.abs(x) + 1e-300
        if (np.abs(M @ x - rhs) > tol * scale).any():
            raise Rt70Error("steady_controller: the controller has no rest state with that output")
        return x
