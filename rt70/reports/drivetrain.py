"""The RT-70 azimuth drive train on a rigid rig: friction, backlash and the counter-torque.

One job: build the single-axis rig of docs/drive-train.md from the RT-70's drive table
(:mod:`rt70.scenes.rt70_drives`) and run its two measurements,

- ``regularisation``: the cost (RHS evaluations, Jacobians, LU decompositions, wall time)
  of scipy's BDF and Radau against the width ω_ε of the friction's regularisation, and
  the position error it leaves against the exact switched (stick–slip) motion
  (:func:`rt70.control.friction.switched_rigid_axis`): a rigid axis of the azimuth's total
  inertia under a torque ``1.5 F_s sin(2π·0.5 t)`` that makes it stick and slip;
- ``rig``: the servo-closed axis (:class:`rt70.control.geartrains.TwoTrainServo`, 0.5 Hz
  position loop) holding a 2″ step and tracking at the sidereal rate, with and without
  backlash, friction, the counter-torque bias and a wind gust; the error in arc seconds
  over the second half of each run.

The rig's load is the listing's rigid azimuth inertia (``az.reference_inertia``) on one
gravity-free joint; the structure's compliance is left out (docs/drives.md §3 gives its
0.92 Hz locked-rotor limit). Run ``python -m rt70.reports.drivetrain {regularisation,rig}``.
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass

import numpy as np

from rt70.bondgraph.parameters import DriveParameters
from rt70.control.friction import AxisFriction, switched_rigid_axis
from rt70.control.geartrains import TwoTrainServo, train_gains
from rt70.model.scene import Scene, scene_from_text
from rt70.scenes.rt70_drives import AZIMUTH_DRIVE, FRICTION, MOTOR, TRAINS, WIND_TORQUE
from rt70.simulation.result import SimulationResult
from rt70.simulation.simulate import simulate
from rt70.units import RAD_PER_ARCSEC

#: Sidereal rate, rad/s (15.04″/s).
SIDEREAL = 7.2921e-5
#: The friction law's default regularisation: a linear zone 1e-6 of the top speed wide
#: (docs/drive-train.md §2: 6e-4″ from the exact stick–slip motion on the rig; an axis
#: held by half the static torque creeps at 3.2e-4″/s instead of sticking).
WIDTH = 1e-6 * FRICTION.top_speed
KIND = "linear"
#: Position-loop bandwidth of the rig, Hz (a factor ~2 below the rigid load's 2.5 Hz
#: reducer resonance; docs/drives.md §3 for the structure's lower limit).
POSITION_HZ = 0.5
#: Tolerances of the drive's states: currents (A), motor angles and speeds (rad, rad/s,
#: motor side), the integrals of the position (rad·s), rate (rad) and current (A·s) errors.
DRIVE_ATOL = np.array([1e-6, 1e-7, 1e-7] * 2 + [1e-12, 1e-7, 1e-6, 1e-6])
#: Absolute tolerance of the axis angle and speed (rad, rad/s): far below 1″ = 4.8e-6 rad.
AXIS_ATOL = 1e-12


def drive_parameters() -> DriveParameters:
    """One RT-70 motor (``*.motor.*``) with the azimuth reducer's totals (``az.reducer.*``)."""
    return AZIMUTH_DRIVE.motor_parameters(AZIMUTH_DRIVE.reference_inertia)


def axis_scene(inertia: float, name: str = "azimuth_rig") -> Scene:
    """One rigid body of ``inertia`` (kg·m², all principal moments) on a joint ``azimuth``."""
    return scene_from_text(
        f"""<robot name="{name}"><link name="ground"/>
  <link name="load"><inertial><mass value="1"/>
    <inertia ixx="{inertia!r}" iyy="{inertia!r}" izz="{inertia!r}" ixy="0" ixz="0" iyz="0"/>
  </inertial></link>
  <joint name="azimuth" type="continuous"><parent link="ground"/><child link="load"/>
    <axis xyz="0 0 1"/></joint>
</robot>""",
        name,
    )


@dataclass(frozen=True)
class Case:
    """One rig run: what is in the drive train and what the servo does.

    Attributes
    ----------
    label : str
        Row name.
    backlash, friction, bias : bool
        The trains' gap (``*.trains.backlash``), the axis's dry friction, the
        counter-torque (``*.trains.bias_torque``; off: the two trains act as one).
    step_arcsec : float
        Position step at t = 0, ″ (0: none).
    rate : float
        Reference rate, rad/s (0: hold).
    gust : float
        Amplitude of a 0.1 Hz sinusoidal wind torque, in units of the nominal wind torque.
    """

    label: str
    backlash: bool
    friction: bool
    bias: bool
    step_arcsec: float = 0.0
    rate: float = 0.0
    gust: float = 0.0


@dataclass(frozen=True)
class RigRun:
    """A rig run's error (″) over the second half, and its train torques (N·m)."""

    case: Case
    rms: float
    peak: float
    train1: tuple[float, float]
    train2: tuple[float, float]
    result: SimulationResult


def run_case(case: Case, t_end: float, rtol: float = 1e-6, width: float = WIDTH) -> RigRun:
    """Simulate ``case`` for ``t_end`` s from rest with the trains at their bias.

    Parameters
    ----------
    case : Case
        What is in the drive train and what the servo does.
    t_end : float
        Length of the run, s; the output grid has 20 points per second.
    rtol : float, optional
        Relative tolerance of BDF.
    width : float, optional
        ω_ε of the friction law's regularisation, rad/s (axis side).

    Returns
    -------
    RigRun
        The error over the second half of the run and the trains' torques there.
    """
    p = drive_parameters()
    scene = axis_scene(p.J_l)
    names = scene.coordinate_names
    gains = train_gains(
        p, p.J_l, position_hz=POSITION_HZ, current_limit=MOTOR.peak_torque / MOTOR.torque_constant,
        rate_limit=AZIMUTH_DRIVE.servo.rate_limit, voltage_limit=2 * MOTOR.rated_voltage,
    )  # fmt: skip
    step = case.step_arcsec * RAD_PER_ARCSEC

    def reference(t: float) -> float:
        return step + case.rate * t

    bias = TRAINS.bias_torque if case.bias else 0.0
    drive = TwoTrainServo(
        "az", names, "azimuth", p, gains, reference,
        backlash=TRAINS.backlash_half_width if case.backlash else 0.0,
        bias_torque=bias, atol=DRIVE_ATOL,
    )  # fmt: skip
    drive.initial = np.concatenate([drive.bias_state(0.0, bias), np.zeros(4)])
    components = [drive]
    if case.friction:
        components.append(AxisFriction("friction", names, "azimuth", FRICTION, width, KIND, 1e-3))

    def gust(t, q, qd):
        return np.array([case.gust * WIND_TORQUE * np.sin(2 * np.pi * 0.1 * t)])

    t = np.linspace(0.0, t_end, int(round(20 * t_end)) + 1)
    run = simulate(
        scene, (0.0, t_end), components=components, inputs=gust if case.gust else None,
        t_eval=t, method="BDF", rtol=rtol, atol=AXIS_ATOL,
    )  # fmt: skip
    error = (step + case.rate * t - run.q[:, 0]) / RAD_PER_ARCSEC
    late = t >= 0.5 * t_end
    s = np.array([run.states[n] for n in drive.names]).T
    taus = np.array(
        [drive.train_torques(q, v, x) for q, v, x in zip(run.q, run.qd, s, strict=True)]
    )
    return RigRun(
        case,
        float(np.sqrt(np.mean(error[late] ** 2))),
        float(np.abs(error[late]).max()),
        (float(taus[late, 0].min()), float(taus[late, 0].max())),
        (float(taus[late, 1].min()), float(taus[late, 1].max())),
        run,
    )


#: The rig's cases (docs/drive-train.md §4).
CASES = (
    Case("hold 2″ step: backlash, no bias", True, False, False, step_arcsec=2.0),
    Case("hold 2″ step: backlash, bias", True, False, True, step_arcsec=2.0),
    Case("hold 2″ step: friction, no backlash", False, True, True, step_arcsec=2.0),
    Case("hold 2″ step: backlash + friction, no bias", True, True, False, step_arcsec=2.0),
    Case("hold 2″ step: backlash + friction, bias", True, True, True, step_arcsec=2.0),
    Case("sidereal: backlash + friction, no bias", True, True, False, rate=SIDEREAL),
    Case("sidereal: backlash + friction, bias", True, True, True, rate=SIDEREAL),
    Case("gust: friction, no backlash", False, True, False, rate=SIDEREAL, gust=0.5),
    Case("gust: backlash + friction, no bias", True, True, False, rate=SIDEREAL, gust=0.5),
    Case("gust: backlash + friction, bias", True, True, True, rate=SIDEREAL, gust=0.5),
)  # fmt: skip


RIG_HEADER = (
    "| case | rms ″ | peak ″ | train 1 torque, N·m | train 2 torque, N·m | RHS evals |\n"
    "|---|---|---|---|---|---|"
)
REGULARISATION_HEADER = (
    "| method | law | ω_ε / top speed | RHS evals | Jacobians | LU | wall s | max error ″ |\n"
    "|---|---|---|---|---|---|---|---|"
)


def rig_table(t_end: float = 60.0, out=sys.stdout) -> list[RigRun]:
    """Run :data:`CASES` and print one row each."""
    print(f"# rig: 0.5 Hz cascade, {t_end:g} s, error over the second half (arc seconds)", file=out)
    print(
        "| case | rms ″ | peak ″ | train 1 torque, N·m | train 2 torque, N·m | RHS evals |",
        file=out,
    )
    print("|---|---|---|---|---|---|", file=out)
    runs = []
    for case in CASES:
        r = run_case(case, t_end)
        runs.append(r)
        print(
            f"| {case.label} | {r.rms:.3g} | {r.peak:.3g} | {r.train1[0]:.3g} … {r.train1[1]:.3g} "
            f"| {r.train2[0]:.3g} … {r.train2[1]:.3g} | {r.result.nfev} |",
            file=out, flush=True,
        )  # fmt: skip
    return runs


def stick_slip_torque(t: float) -> float:
    """The regularisation rig's applied torque, ``1.5 F_s sin(2π·0.5 t)`` (N·m)."""
    return 1.5 * FRICTION.static_torque * np.sin(np.pi * t)


def regularisation_run(
    width: float, kind: str, method: str, t_end: float = 4.0
) -> tuple[SimulationResult, float]:
    """The stick–slip rig with a regularised law: the run and its largest error (″).

    Parameters
    ----------
    width : float
        ω_ε of the regularisation, rad/s (axis side).
    kind : {"linear", "tanh"}
        The regularisation (:func:`rt70.control.friction.friction_torque`).
    method : str
        ``solve_ivp`` method, ``"BDF"`` or ``"Radau"`` in the report.
    t_end : float, optional
        Length of the run, s; the output grid has 100 points per second.

    Returns
    -------
    tuple of (SimulationResult, float)
        The run, and the largest distance of its axis angle from the exact switched
        motion (:func:`rt70.control.friction.switched_rigid_axis`), ″.
    """
    inertia = AZIMUTH_DRIVE.reference_inertia + AZIMUTH_DRIVE.reflected_motor_inertia
    scene = axis_scene(inertia, "friction_rig")
    t = np.linspace(0.0, t_end, int(round(100 * t_end)) + 1)
    exact = switched_rigid_axis(inertia, FRICTION, stick_slip_torque, t)
    friction = AxisFriction(
        "friction", scene.coordinate_names, "azimuth", FRICTION, width, kind, 1e-6
    )
    run = simulate(
        scene, (0.0, t_end), components=[friction], t_eval=t, method=method, rtol=1e-6,
        atol=AXIS_ATOL, inputs=lambda t, q, qd: np.array([stick_slip_torque(t)]),
    )  # fmt: skip
    return run, float(np.abs(run.q[:, 0] - exact.angle).max() / RAD_PER_ARCSEC)


def regularisation_table(
    widths: tuple[float, ...] = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8), out=sys.stdout
) -> list[tuple]:
    """Print the cost and error of each (method, kind, ω_ε / top speed)."""
    from rt70.errors import Rt70Error

    print(
        "| method | law | ω_ε / top speed | RHS evals | Jacobians | LU | wall s | max error ″ |",
        file=out,
    )
    print("|---|---|---|---|---|---|---|---|", file=out)
    rows = []
    for method in ("BDF", "Radau"):
        for kind in ("linear", "tanh"):
            for w in widths:
                try:
                    run, err = regularisation_run(w * FRICTION.top_speed, kind, method)
                    row = (method, kind, w, run.nfev, run.njev, run.nlu, run.wall_time_s, err)
                    text = (
                        f"{run.nfev} | {run.njev} | {run.nlu} | {run.wall_time_s:.2f} | {err:.3g}"
                    )
                except Rt70Error as exc:
                    row = (method, kind, w, None, None, None, None, None)
                    text = f"failed: {str(exc).split(': ', 1)[-1][:60]} | | | | "
                rows.append(row)
                print(f"| {method} | {kind} | {w:.0e} | {text} |", file=out, flush=True)
    return rows


def main(argv: list[str] | None = None) -> int:
    """``python -m rt70.reports.drivetrain {regularisation,rig} [--t-end S]``."""
    parser = argparse.ArgumentParser(prog="python -m rt70.reports.drivetrain")
    parser.add_argument("what", choices=("regularisation", "rig"))
    parser.add_argument("--t-end", type=float, default=60.0, help="rig run length, s")
    args = parser.parse_args(argv)
    if args.what == "regularisation":
        regularisation_table()
    else:
        rig_table(args.t_end)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
