"""A lock engaging during a simulation: the motion up to it, the impact, the energy audit.

:func:`engage_after` integrates a scene with :func:`rt70.simulation.simulate.simulate` (which
carries the energy audit, (1.73)) up to the engagement time, applies the impact (15) of
the locks there (:func:`rt70.mechanics.locks.engage`) and returns the audit across the event:

``T + U_g + U_c + E_ψ − W_u`` before, and after with the impact's loss as its own term,
``T⁺ + U_g + U_c + E_ψ + E_impact − W_u`` — positions do not jump, so neither do the
potentials, the dissipated energy nor the input work; the two totals differ only by
rounding (:attr:`rt70.physics.impact.Impact.balance`), while the simulation's own drift up to
the engagement is reported as it is (:attr:`rt70.simulation.result.SimulationResult.balance`).

Continuing the motion with the lock held needs the constrained integration of the loop
closures (the KKT equations (14)); it is not done here.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict, dataclass

import numpy as np

from rt70.errors import Rt70Error
from rt70.mechanics.locks import Lock, check_locks, engage
from rt70.model.scene import Scene
from rt70.physics.impact import Impact
from rt70.simulation.result import SimulationResult
from rt70.simulation.simulate import Inputs, simulate


@dataclass(frozen=True)
class EngagementAudit:
    """The energy audit across an engagement at time ``t``, J.

    Attributes
    ----------
    t : float
        Engagement time, s.
    kinetic_before, kinetic_after : float
        T⁻ (the simulation's, at t) and T⁺ (the impact's).
    gravity, elastic, dissipated, input_work : float
        U_g, U_c, E_ψ, W_u at t (unchanged by the impact).
    impact_lost : float
        The energy the impact dissipates, ``E_impact``.
    total_before, total_after : float
        ``T⁻ + U_g + U_c + E_ψ − W_u`` and ``T⁺ + U_g + U_c + E_ψ + E_impact − W_u``.
    drift_before : float
        The simulation's balance at t: the total's change since the start (the
        integrator's error).
    """

    t: float
    kinetic_before: float
    kinetic_after: float
    gravity: float
    elastic: float
    dissipated: float
    input_work: float
    impact_lost: float
    total_before: float
    total_after: float
    drift_before: float

    @property
    def jump(self) -> float:
        """``total_after − total_before``: what the audit fails to close across the event."""
        return self.total_after - self.total_before

    def to_dict(self) -> dict:
        """The audit as a JSON-ready dict (with :attr:`jump`)."""
        return {**asdict(self), "jump": self.jump}


def audit_across(result: SimulationResult, impact: Impact, kinetic_after: float) -> EngagementAudit:
    """The audit at the end of ``result`` across ``impact``.

    ``kinetic_after`` is T⁺ as the simulation's side computes it (so that T⁻ and T⁺ come
    from one function); the impact's own T⁻ → T⁺ is :attr:`Impact.kinetic_before`,
    :attr:`Impact.kinetic_after`.

    Parameters
    ----------
    result : SimulationResult
        The simulation up to the engagement: its last sample is the state at impact.
    impact : Impact
        The impact of the locks at that state (its ``energy_lost``, J).
    kinetic_after : float
        T⁺, J, from the simulation's side at ``q̇⁺``.
    """
    T0, Ug, Uc = float(result.kinetic[-1]), float(result.gravity[-1]), float(result.elastic[-1])
    E_psi, W_u = float(result.dissipated[-1]), float(result.input_work[-1])
    before = T0 + Ug + Uc + E_psi - W_u
    after = kinetic_after + Ug + Uc + E_psi + impact.energy_lost - W_u
    return EngagementAudit(
        t=float(result.t[-1]),
        kinetic_before=T0,
        kinetic_after=kinetic_after,
        gravity=Ug,
        elastic=Uc,
        dissipated=E_psi,
        input_work=W_u,
        impact_lost=impact.energy_lost,
        total_before=before,
        total_after=after,
        drift_before=float(result.balance[-1]),
    )


def engage_after(
    scene: Scene,
    x0: tuple[np.ndarray, np.ndarray],
    t_engage: float,
    locks: Sequence[Lock],
    restitution: float = 0.0,
    side: str = "textbook",
    rtol: float = 1e-8,
    inputs: Inputs | None = None,
) -> tuple[SimulationResult, Impact, EngagementAudit]:
    """Simulate ``t_engage`` seconds from ``x0``, then engage ``locks`` (impact (15)).

    Parameters
    ----------
    scene : Scene
        The scene.
    x0 : (q0, q̇0)
        Initial state.
    t_engage : float
        Engagement time, s (> 0).
    locks : sequence of Lock
        The brakes and stow pins that engage (:mod:`rt70.mechanics.locks`).
    restitution : float
        e (0: plastic).
    side : {"textbook", "reference"}
        Who solves the impact. The simulation runs on the reference side (BDF).
    rtol : float
        The simulation's relative tolerance.
    inputs : callable (t, q, q̇) -> Q_u, optional
        Generalised input forces during the simulation (holding torques); their work
        is the audit's W_u.

    Returns
    -------
    (SimulationResult, Impact, EngagementAudit)
    """
    if not (np.isfinite(t_engage) and t_engage > 0.0):
        raise Rt70Error(f"engagement time must be a positive number of seconds, got {t_engage!r}")
    check_locks(scene, locks)  # before the simulation
    result = simulate(scene, (0.0, float(t_engage)), x0, rtol=rtol, inputs=inputs)
    q, qd = result.q[-1], result.qd[-1]
    impact = engage(scene, q, qd, locks, side, restitution)
    from rt70 import reference

    T_after = reference.kinetic_energy(scene.reference, scene.reference_data, q, impact.qd_after)
    return result, impact, audit_across(result, impact, float(T_after))
