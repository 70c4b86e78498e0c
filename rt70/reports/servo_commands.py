"""The servo scenarios' whole-command targets (``rt70 bench simulate``).

What a user waits for is the command, start-up included:
``rt70 simulate rt70_servo --scenario S --no-plot`` (the scene's drives and both servos
closed, CVODE at the scenarios' rtol 1e-6, the scenario's default length) as a
subprocess, best of :data:`REPEATS` wall times, against the simulated time:

- hold (60 s), track (40 s), step-elevation (25 s), step-azimuth (40 s): ≥
  :data:`SCENARIO_TARGET` × real time;
- the hold with the book's dry friction on both axes (``--friction``): ≥
  :data:`FRICTION_TARGET` × real time.

Each is judged cold (a fresh interpreter: start-up included) and, when a warm process is
given, served by it (``rt70 warm start``: the start-up paid once, docs/performance.md).
The integration alone is judged by :func:`rt70.reports.simulation_targets.servo_target`
at a stated accuracy; these are the commands as run.
"""

from __future__ import annotations

from rt70.reports.targets import TargetCheck, run_kind, wall_times

#: Whole command, × real time, of the frictionless scenarios and of the hold with friction.
SCENARIO_TARGET = 50.0
FRICTION_TARGET = 10.0
#: Attempts of each command (best wall time).
REPEATS = 2
#: ``(scenario, with dry friction)`` of each command judged.
CASES = (
    ("hold", False),
    ("track", False),
    ("step-elevation", False),
    ("step-azimuth", False),
    ("hold", True),
)


def command_args(scenario: str, friction: bool) -> list[str]:
    """``rt70`` arguments of one case (no plot, nothing written)."""
    args = ["simulate", "rt70_servo", "--scenario", scenario, "--no-plot"]
    return [*args, "--friction"] if friction else args


def servo_command_targets(
    repeats: int = REPEATS, quick: bool = False, warm: dict[str, str] | None = None
) -> list[TargetCheck]:
    """Each case of :data:`CASES` timed as a subprocess and judged (module docstring).

    Parameters
    ----------
    repeats : int, optional
        Runs of each command; the best wall time counts.
    quick : bool, optional
        A quick run: not timed (not judged).
    warm : dict, optional
        The environment of a warm process (:func:`rt70.reports.targets.warm_process`):
        each case is judged a second time, served by it.
    """
    from rt70.telescope.scenario import DEFAULT_T_END

    out = []
    for scenario, friction in CASES:
        target = FRICTION_TARGET if friction else SCENARIO_TARGET
        t_end = DEFAULT_T_END[scenario]
        extra = " --friction" if friction else ""
        goal = (
            f"whole command `rt70 simulate rt70_servo --scenario {scenario}{extra}` "
            f"({t_end:g} s): ≥ {target:g}× real time"
        )
        if quick:
            out.append(TargetCheck(goal, "— (not measured in a quick run)", None))
            continue
        args, speed = command_args(scenario, friction), (t_end, target)
        out.append(_timed(f"{goal}, cold", args, speed, repeats, None))
        if warm is not None:
            out.append(_timed(f"{goal}, warm process", args, speed, repeats, warm))
    return out


def _timed(goal: str, args: list[str], speed: tuple[float, float], repeats: int,
           env: dict[str, str] | None) -> TargetCheck:  # fmt: skip
    """``rt70 ARGS`` timed (best wall time) and judged: ``speed = (t_end, target ×)``."""
    from rt70.errors import Rt70Error

    try:
        walls = wall_times(args, repeats, env)
    except Rt70Error as exc:
        return TargetCheck(goal, f"failed: {exc}", False)
    factor = speed[0] / min(walls)
    how = run_kind(env)
    measured = f"{min(walls):.2f} s (best of {len(walls)}, wall, {how}), {factor:.1f}× real time"
    return TargetCheck(goal, measured, factor >= speed[1])
