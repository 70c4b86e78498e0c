"""The servo scenarios' whole-command targets (``rt70 bench simulate``).

What a user waits for is the command, start-up included:
``rt70 simulate rt70_servo --scenario S --no-plot`` (the scene's drives and both servos
closed, CVODE at the scenarios' rtol 1e-6, the scenario's default length) as a
subprocess, best of :data:`REPEATS` wall times, against the simulated time:

- hold (60 s), track (40 s), step-elevation (25 s), step-azimuth (40 s): ≥
  :data:`SCENARIO_TARGET` × real time;
- the hold with the book's dry friction on both axes (``--friction``): ≥
  :data:`FRICTION_TARGET` × real time.

The integration alone is judged by :func:`rt70.reports.simulation_targets.servo_target`
at a stated accuracy; these are the commands as run.
"""

from __future__ import annotations

from rt70.reports.targets import TargetCheck, wall_times

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


def servo_command_targets(repeats: int = REPEATS, quick: bool = False) -> list[TargetCheck]:
    """Each case of :data:`CASES` timed as a subprocess and judged (module docstring).

    Parameters
    ----------
    repeats : int, optional
        Runs of each command; the best wall time counts.
    quick : bool, optional
        A quick run: not timed (not judged).
    """
    from rt70.errors import Rt70Error
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
        try:
            walls = wall_times(command_args(scenario, friction), repeats)
        except Rt70Error as exc:
            out.append(TargetCheck(goal, f"failed: {exc}", False))
            continue
        factor = t_end / min(walls)
        measured = (
            f"{min(walls):.2f} s (best of {len(walls)}, wall, start-up included), "
            f"{factor:.1f}× real time"
        )
        out.append(TargetCheck(goal, measured, factor >= target))
    return out
