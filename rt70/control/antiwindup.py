"""The servo cascade with back-calculation anti-windup: a right-hand side an ODE solver can take.

One job: :class:`BackCalculationServo`, a :class:`rt70.control.servo.ServoDrive` whose rate and
current integrators are kept from winding up by *back-calculation* (Åström & Hägglund,
*Advanced PID Control*, 2006, §3.5; Åström & Murray, *Feedback Systems*, 2008, §10.4)
instead of conditional integration; the position integrator keeps conditional
integration.

Why: conditional integration switches an integrator's rate between the error and zero
at the clamp. When a loop's output rides its limit (the armature voltage during a slew
at top speed: the back-EMF alone is 90 % of the rated voltage) the integrator is
pushed onto the clamp from below and held there from above — a sliding mode on a
discontinuous right-hand side. An implicit solver then cuts its step to nothing
(``Required step size is less than spacing between numbers``, measured on the RT-70's
1° azimuth step, docs/servo-scenarios.md). Back-calculation feeds the clamp's excess
back into the integrator,

    ṡ = e + (u_clamped − u) / K_p,

(tracking time constant T_t = T_i = K_p/K_i: the integral term relaxes to the limit at
the rate of the PI zero). The rate is continuous in the state, equal to ``e`` while the
loop is unclamped, so holding and linear behaviour are those of :class:`ServoDrive`.

The position loop is different: its clamp (the top speed during a slew) is left once,
as the error shrinks, so conditional integration does not chatter there; and
back-calculation would make its integral hold the top speed through the slew (measured:
7.9 % overshoot on the RT-70's 1° azimuth step instead of 1.3 %), so it keeps
conditional integration.
"""

from __future__ import annotations

import numpy as np

from rt70.control.servo import ServoDrive
from rt70.simulation.states import MechanicsForces


class BackCalculationServo(ServoDrive):
    """:class:`rt70.control.servo.ServoDrive` with back-calculation anti-windup (module docstring).

    Same states, parameters and gains; only the integrators' rates differ while a loop
    is clamped.
    """

    def _clamped_loops(self, t: float, q: np.ndarray, s: np.ndarray):
        """The three loops: (errors, raw − clamped output of each, armature voltage)."""
        g, p = self.g, self.p
        e_p = float(self.reference(t)) - self.encoder(q)
        raw_rate = g.kp_p * e_p + g.ki_p * s[3]
        rate_ref = min(max(raw_rate, -g.rate_limit), g.rate_limit)
        e_v = p.i_r * rate_ref - s[2]  # on the motor speed
        raw_current = g.kp_v * e_v + g.ki_v * s[4]
        current_ref = min(max(raw_current, -g.current_limit), g.current_limit)
        e_i = current_ref - s[0]
        raw_u = g.kp_i * e_i + g.ki_i * s[5]
        u = min(max(raw_u, -g.voltage_limit), g.voltage_limit)
        excess = (raw_rate - rate_ref, raw_current - current_ref, raw_u - u)
        return (e_p, e_v, e_i), excess, u

    def voltage_of(self, t: float, q: np.ndarray, s: np.ndarray) -> float:
        """The armature voltage the cascade applies at state ``s`` (V).

        Parameters
        ----------
        t : float
            Time, s (the position reference is taken at t).
        q : numpy.ndarray, shape (nv,)
            Generalised coordinates, m or rad, book order.
        s : numpy.ndarray, shape (6,)
            ``[I, α_m, ω_m]`` (A, rad, rad/s), then the integrals of the position (rad·s),
            rate (rad, on the motor speed) and current (A·s) errors.
        """
        return self._clamped_loops(t, q, s)[2]

    def derivative(
        self, t: float, q: np.ndarray, qd: np.ndarray, s: np.ndarray, forces: MechanicsForces
    ) -> np.ndarray:
        """The drive's ``[İ, α̇_m, ω̇_m]``, then the integrators' rates (module docstring).

        Parameters
        ----------
        t : float
            Time, s (the position reference is taken at t).
        q, qd : numpy.ndarray, shape (nv,)
            Generalised coordinates (m or rad) and velocities (m/s or rad/s), book order.
        s : numpy.ndarray, shape (6,)
            ``[I, α_m, ω_m]`` (A, rad, rad/s), then the integrals of the position (rad·s),
            rate (rad, on the motor speed) and current (A·s) errors.
        forces : MechanicsForces
            The mechanics' forces at this evaluation (unused).
        """
        (e_p, e_v, e_i), (x_p, x_v, x_i), u = self._clamped_loops(t, q, s)
        g = self.g
        drive = self.motor_rates(q, qd, s[:3], u)
        # the position loop integrates conditionally (frozen while its rate reference is
        # clamped: a slew leaves the clamp once, and its integral does not hold the top
        # speed after it); the inner loops back-calculate
        integrals = (0.0 if x_p else e_p, e_v - x_v / g.kp_v, e_i - x_i / g.kp_i)
        return np.concatenate([drive, integrals])
