"""The energy balance of a drive and the structure it turns (formalism §4.5, (1.73)).

One job: integrate a drive's energy flows with the motion and close the balance

    ∫ u I dt − ∫ (R_a I² + D_m ω_m² + D_r Δ̇²) dt
        = Δ(½ L_a I² + ½ J_m ω_m² + ½ C_r Δ²) + Δ(T + U_g + U_c) + E_ψ,

electrical energy in, less the armature's, the rotor's and the reducer's losses, equals
the change of the drive's stored energy (the armature's field, the rotor, the reducer
spring), of the structure's kinetic, gravity and elastic energy, plus the structure's
dissipation E_ψ. It holds because ``c_m = c_e`` (the motor is a gyrator) and because the
reducer's force on the structure is ``K ∂θ_d/∂q`` for the same θ_d as the twist
``Δ = θ_d − α_m / i_r`` (:mod:`rt70.model.couplings`): the structure receives ``q̇ᵀ Q = K θ̇_d``,
which the energy audit (:class:`rt70.simulation.states.EnergyAudit`) integrates as input work.

:class:`AuditedDrive` wraps any :class:`rt70.control.drives.DcDrive` (a
:class:`rt70.control.servo.ServoDrive` too) and integrates the four flows as extra states of
the drive, so they carry the integrator's own error control; the stored energies are
functions of the state, taken after the run (:func:`stored_energy`); :func:`energy_balance`
closes the sum.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from rt70.control.drives import DcDrive
from rt70.simulation.states import MechanicsForces, StateComponent

#: The integrated flows (after ``name:``), J: ∫u I, ∫R_a I², ∫D_m ω_m², ∫D_r Δ̇².
FLOWS = ("electrical_work", "armature_loss", "motor_loss", "reducer_loss")


class AuditedDrive(StateComponent):
    """A drive with its electrical work and its three losses as four more states.

    States: the drive's own (``name:current`` …), then ``name:electrical_work``,
    ``name:armature_loss``, ``name:motor_loss``, ``name:reducer_loss``, all zero at the
    start. The armature voltage is read back from the drive's own equation,
    ``u = L_a İ + R_a I + c_e ω_m``, so any voltage law or servo loop is audited.

    Parameters
    ----------
    drive : DcDrive
        The drive (or a subclass); its force and states are passed through unchanged.
    atol : float
        Absolute tolerance of the four energies, J.
    """

    def __init__(self, drive: DcDrive, atol: float = 1e-6) -> None:
        self.drive = drive
        self.k = len(drive.names)
        prefix = drive.names[0].rsplit(":", 1)[0]
        self.names = drive.names + tuple(f"{prefix}:{flow}" for flow in FLOWS)
        self.initial = np.concatenate([np.asarray(drive.initial, dtype=float), np.zeros(4)])
        self.atol = np.concatenate([np.asarray(drive.atol, dtype=float), np.full(4, atol)])

    def unit(self, name: str) -> str:
        """The drive's unit for its own states, J for the four flows."""
        return self.drive.unit(name) if name in self.drive.names else "J"

    def force(self, t: float, q: np.ndarray, qd: np.ndarray, s: np.ndarray) -> np.ndarray:
        """The drive's generalised force, from its own states.

        Parameters
        ----------
        t : float
            Time, s (passed to the drive).
        q, qd : numpy.ndarray, shape (nv,)
            Generalised coordinates (m or rad) and velocities (m/s or rad/s), book order.
        s : numpy.ndarray
            The drive's own states (A, rad, rad/s, …), then the four flows of :data:`FLOWS`, J.
        """
        return self.drive.force(t, q, qd, s[: self.k])

    def derivative(
        self, t: float, q: np.ndarray, qd: np.ndarray, s: np.ndarray, forces: MechanicsForces
    ) -> np.ndarray:
        """The drive's rates, then ``[u I, R_a I², D_m ω_m², D_r Δ̇²]``.

        Parameters
        ----------
        t : float
            Time, s (passed to the drive).
        q, qd : numpy.ndarray, shape (nv,)
            Generalised coordinates (m or rad) and velocities (m/s or rad/s), book order.
        s : numpy.ndarray
            The drive's own states (A, rad, rad/s, …), then the four flows of :data:`FLOWS`, J.
        forces : MechanicsForces
            The mechanics' forces at this evaluation (passed to the drive).
        """
        own = s[: self.k]
        ds = np.asarray(self.drive.derivative(t, q, qd, own, forces), dtype=float)
        p = self.drive.p
        current, speed = own[0], own[2]
        u = p.L_a * ds[0] + p.R_a * current + p.c_e * speed
        _, twist_rate = self.drive.twist(q, qd, own[:3])
        flows = (u * current, p.R_a * current**2, p.D_m * speed**2, p.D_r * twist_rate**2)
        return np.concatenate([ds, flows])


def stored_energy(drive: DcDrive, q: np.ndarray, s: np.ndarray) -> float:
    """``½ L_a I² + ½ J_m ω_m² + ½ C_r Δ²`` at q and the drive's states s, J.

    Parameters
    ----------
    drive : DcDrive
        The drive (its parameters and coupling).
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates, m or rad, book order.
    s : numpy.ndarray
        The drive's states ``[I, α_m, ω_m, …]``: A, rad, rad/s.
    """
    p = drive.p
    twist = drive.coupling.angle(q) - s[1] / p.i_r
    return 0.5 * (p.L_a * s[0] ** 2 + p.J_m * s[2] ** 2 + p.C_r * twist**2)


def energy_balance(result, audited: Sequence[AuditedDrive]) -> tuple[np.ndarray, float]:
    """The balance's residual over a run and the energy it is relative to.

    Parameters
    ----------
    result : rt70.simulation.result.SimulationResult
        A run with the audited drives among its components.
    audited : sequence of AuditedDrive
        The drives.

    Returns
    -------
    residual : numpy.ndarray
        ``Σ (electrical − losses − Δ stored) − Δ(T + U_g + U_c) − E_ψ`` at every output
        time, J (zero at the start).
    scale : float
        The largest of the energies exchanged (electrical work, the losses, the
        structure's input work, its change of T, U_g, U_c and its dissipation), J:
        the residual's natural size.
    """
    mechanical = result.kinetic + result.gravity + result.elastic
    residual = -(mechanical - mechanical[0]) - result.dissipated
    scale = max(
        float(np.max(np.abs(x)))
        for x in (
            result.input_work,
            result.dissipated,
            *(y - y[0] for y in (result.kinetic, result.gravity, result.elastic)),
        )
    )
    q = result.q if result.q.shape[0] == len(result.t) else result.q.T
    for a in audited:
        drive, names = a.drive, a.names
        s = np.array([result.states[name] for name in names[: a.k]]).T
        stored = np.array([stored_energy(drive, qi, si) for qi, si in zip(q, s, strict=True)])
        electrical = result.states[names[a.k]]
        losses = sum(result.states[name] for name in names[a.k + 1 :])
        residual += electrical - losses - (stored - stored[0])
        scale = max(scale, float(np.max(np.abs(electrical))), float(np.max(np.abs(losses))))
    return residual, scale
