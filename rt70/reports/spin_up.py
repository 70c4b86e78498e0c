"""The spin-up beam (Kane, Ryan & Banerjee 1987): rigid finite elements against linear modes.

One job: the two models of the benchmark and their tip deflection in the hub's frame
(validation/spin_up_beam.py writes the study; docs/beams.md). The hub's angle is
prescribed, ``Ω(t) = (Ω_s/T)[t − (T/2π) sin(2πt/T)]`` for t < T, then Ω_s; the beam:
L = 10 m, EI = 1.4e4 N·m², ρA = 1.2 kg/m (E = 7e10 Pa, A = 4e-4 m², I = 2e-7 m⁴,
ρ = 3000 kg/m³), inextensible, gravity off.

- :func:`tip_rigid_elements`: ``<rt70:beam>``'s full nonlinear equations (Pinocchio's
  side), the hub's acceleration an input to the beam's coordinates — the segments turn
  with the beam, so the centrifugal tension stiffens it;
- :func:`tip_linear_modes`: the same beam's M and K at rest with the hub's acceleration
  as input and the centrifugal softening ``−Ω² M`` (the "conventional" linear model),
  which loses its first mode once Ω passes the first frequency, 3.8 rad/s.
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp

from rt70.linear.linearize import stiffness_matrix
from rt70.model.scene import scene_from_text
from rt70.model.sides import side_of

T_UP, DURATION = 15.0, 20.0
BEAM = 'E="7e10" G="2.7e10" rho="3000" A="4e-4" Iy="2e-7" Iz="2e-7" J="4e-7" axial="false"'


def hub_motion(t: float, speed: float) -> tuple[float, float, float]:
    """θ, θ̇, θ̈ of the prescribed spin-up, rad, rad/s, rad/s²."""
    if t >= T_UP:
        theta_up = speed / T_UP * (T_UP**2 / 2)  # ∫ of the ramp over [0, T]
        return theta_up + speed * (t - T_UP), speed, 0.0
    w = 2 * np.pi / T_UP
    theta = speed / T_UP * (t**2 / 2 + (np.cos(w * t) - 1) / w**2)
    rate = speed / T_UP * (t - np.sin(w * t) / w)
    return theta, rate, speed / T_UP * (1 - np.cos(w * t))


def scene_text(segments: int) -> str:
    """A hub turning about ground z with the beam along its x axis."""
    return (
        '<?xml version="1.0"?>\n<robot name="spin_up" xmlns:rt70="urn:rt70:urdf-extensions:1">'
        '<link name="world"/><link name="hub"><inertial><mass value="1"/><inertia ixx="1" '
        'ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>'
        '<joint name="hub_joint" type="revolute"><parent link="world"/><child link="hub"/>'
        '<axis xyz="0 0 1"/><limit lower="-1e9" upper="1e9" effort="1e12" velocity="1e6"/>'
        '</joint><rt70:gravity xyz="0 0 0"/>'
        f'<rt70:beam name="b" parent="hub" length="10" segments="{segments}" {BEAM}/></robot>'
    )


def _hub_and_beam(segments: int) -> tuple:
    """The scene, its reference side, the hub's coordinate and the beam's coordinates."""
    scene = scene_from_text(scene_text(segments))
    hub = scene.coordinate_names.index("hub_joint")
    rest = [i for i in range(len(scene.coordinate_names)) if i != hub]
    return scene, side_of(scene, "reference"), hub, rest


def tip_rigid_elements(segments: int, speed: float, times: np.ndarray) -> np.ndarray:
    """The RFEM beam's tip deflection in the hub frame at ``times``, m.

    Parameters
    ----------
    segments : int
        The beam's primary segments.
    speed : float
        Ω_s, the final spin rate, rad/s.
    times : numpy.ndarray
        Output times from 0, s (the last is the end of the run).
    """
    scene, s, hub, rest = _hub_and_beam(segments)
    n = len(scene.coordinate_names)

    def full(t: float, y: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
        theta, rate, accel = hub_motion(t, speed)
        q, qd = np.zeros(n), np.zeros(n)
        q[hub], qd[hub] = theta, rate
        q[rest], qd[rest] = y[: n - 1], y[n - 1 :]
        return q, qd, accel

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        q, qd, accel = full(t, y)
        M = s.dynamics.mass_matrix(s.model, s.data, q)
        Qc, Qd = s.forces.spring_damper_force(s.model, s.data, q, qd)
        force = Qc + Qd - s.dynamics.bias_force(s.model, s.data, q, qd)
        qdd = np.linalg.solve(M[np.ix_(rest, rest)], force[rest] - M[rest, hub] * accel)
        return np.concatenate([y[n - 1 :], qdd])

    sol = solve_ivp(
        rhs, (0.0, times[-1]), np.zeros(2 * (n - 1)), "Radau", times, rtol=1e-8, atol=1e-10
    )
    tip = []
    for t, y in zip(sol.t, sol.y.T, strict=True):
        q, _, _ = full(t, y)
        p = s.points.point_position(s.model, s.data, q, "b_end", np.zeros(3))
        theta = q[hub]
        tip.append(-np.sin(theta) * p[0] + np.cos(theta) * p[1])  # hub-frame y
    return np.array(tip)


def tip_linear_modes(segments: int, speed: float, times: np.ndarray) -> np.ndarray:
    """The linear-modes model's tip deflection: ``M q̈ + (K − Ω² M) q = −m_θ θ̈``, m.

    NaN after the integrator gives up (the model runs away).

    Parameters
    ----------
    segments : int
        The beam's primary segments (M and K of that division at rest).
    speed : float
        Ω_s, the final spin rate, rad/s.
    times : numpy.ndarray
        Output times from 0, s.
    """
    scene, s, hub, rest = _hub_and_beam(segments)
    zero = np.zeros(len(scene.coordinate_names))
    M = s.dynamics.mass_matrix(s.model, s.data, zero)
    K = stiffness_matrix(scene, zero)
    Mb, Kb, coupling = M[np.ix_(rest, rest)], K[np.ix_(rest, rest)], M[rest, hub]
    # the tip's in-plane deflection: each sde's rotation about z times its lever to the tip
    (beam,) = scene.description.beams
    tip_row = np.zeros(len(rest))
    for i in range(1, beam.segments + 1):
        column = rest.index(scene.coordinate_names.index(f"{beam.name}_sde{i}_rz"))
        tip_row[column] = beam.length - (i - 0.5) * beam.step

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        _, rate, accel = hub_motion(t, speed)
        m = len(rest)
        qdd = np.linalg.solve(Mb, -(Kb - rate**2 * Mb) @ y[:m] - coupling * accel)
        return np.concatenate([y[m:], qdd])

    sol = solve_ivp(
        rhs, (0.0, times[-1]), np.zeros(2 * len(rest)), "Radau", times, rtol=1e-8, atol=1e-10
    )
    out = np.full(len(times), np.nan)
    out[: sol.y.shape[1]] = tip_row @ sol.y[: len(rest)]
    return out
