"""The large-model targets, measured and judged (``rt70 bench large``).

A hanging chain of 334 bodies on the book's 6-DOF elastic pairs
(:func:`rt70.scenes.synthetic.elastic_chain` with ``hanging=True``: 2004 coordinates,
334 bushings, gravity) is written to a temporary file, and three whole commands run on it
as subprocesses, each timed (wall) with its peak resident memory (``os.wait4``'s
``ru_maxrss``):

- ``rt70 modes FILE`` (its default above 500 coordinates: the 20 lowest modes, by
  shift-invert Lanczos, :mod:`rt70.linear.lowest_modes`): ≤ :data:`MODES_TARGET_S`;
- ``rt70 plant FILE --out FILE.npz``: ≤ :data:`PLANT_TARGET_S`;
- ``rt70 simulate FILE --t-end 1``: ≤ :data:`SIMULATE_TARGET_S`;

each within :data:`MEMORY_TARGET_GB` of peak memory. A command that fails is reported
with its last line and not met. One warm-up run of ``rt70 modes`` and of ``rt70 simulate``
on a 40-body chain first fills numba's on-disk cache, so that no timed run compiles the
kernels (a fresh install compiles them once, some 20–40 s). ``--quick`` runs a 60-body chain (360
coordinates) and judges nothing.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

from rt70.reports.targets import TargetCheck, run_kind, wall_times, warm_process

#: Bodies of the chain the targets are judged on (6 coordinates each).
BODIES = 334
#: ``rt70 modes``, s.
MODES_TARGET_S = 5.0
#: ``rt70 plant``, s.
PLANT_TARGET_S = 10.0
#: ``rt70 simulate --t-end 1``, s.
SIMULATE_TARGET_S = 30.0
#: Peak resident memory of each command, GB (1e9 bytes).
MEMORY_TARGET_GB = 4.0
#: The commands' environment: each in its own interpreter (a warm process's worker would
#: not be the process whose memory and time are measured).
COLD = {**os.environ, "RT70_WARM": "0"}


def run_command(args: list[str], cwd: Path) -> tuple[float, float, int, str]:
    """``python -m rt70 ARGS`` in ``cwd``: ``(wall s, peak memory GB, exit code, last line)``.

    The last line is stderr's (stdout's when stderr is empty).

    Parameters
    ----------
    args : list of str
        The command line after ``rt70``.
    cwd : pathlib.Path
        Where it runs (its output files go there).
    """
    out, err = cwd / "stdout.txt", cwd / "stderr.txt"
    with out.open("w") as fo, err.open("w") as fe:
        start = time.perf_counter()
        proc = subprocess.Popen([sys.executable, "-m", "rt70", *args], cwd=cwd, stdout=fo,
                                stderr=fe, env=COLD)  # fmt: skip
        _, status, usage = os.wait4(proc.pid, 0)
        wall = time.perf_counter() - start
    proc.returncode = os.waitstatus_to_exitcode(status)
    lines = (err.read_text().strip() or out.read_text().strip()).splitlines()
    peak_gb = usage.ru_maxrss * 1024 / 1e9  # kilobytes on Linux
    return wall, peak_gb, proc.returncode, lines[-1] if lines else "(no output)"


def check(quick: bool = False, progress: Callable[[str], None] | None = None) -> list[TargetCheck]:
    """Run the three commands on the chain and judge them (module docstring).

    Parameters
    ----------
    quick : bool
        A 60-body chain, nothing judged.
    progress : callable, optional
        Called with a line before each command.
    """
    from rt70.scenes.synthetic import elastic_chain

    say = progress or (lambda _msg: None)
    bodies = 60 if quick else BODIES
    checks = []
    with tempfile.TemporaryDirectory(prefix="rt70-large-") as tmp:
        where = Path(tmp)
        (where / "warm.urdf").write_text(elastic_chain(40, hanging=True))
        (where / "chain.urdf").write_text(elastic_chain(bodies, hanging=True))
        say("warm-up: rt70 modes and simulate on a 40-body chain (fills the kernels' cache)")
        run_command(["modes", "warm.urdf"], where)
        run_command(["simulate", "warm.urdf", "--t-end", "0.001"], where)
        runs = (
            (["modes", "chain.urdf"], MODES_TARGET_S),
            (["plant", "chain.urdf", "--out", "plant.npz"], PLANT_TARGET_S),
            (["simulate", "chain.urdf", "--t-end", "1"], SIMULATE_TARGET_S),
        )
        for args, limit in runs:
            say(f"rt70 {' '.join(args)} ({6 * bodies} coordinates)")
            checks.append(_judged(args, limit, run_command(args, where), 6 * bodies, quick))
        if not quick:
            say("the same commands served by a warm process (rt70 warm start)")
            with warm_process() as warm:
                checks += [_judged_warm(args, limit, where, warm) for args, limit in runs]
    return checks


def _judged_warm(args: list[str], limit: float, cwd: Path, env: dict[str, str]) -> TargetCheck:
    """The time target of one command served by the warm process ``env`` (one run).

    The peak memory is the cold run's: the worker is not the process that is waited for.
    """
    from rt70.errors import Rt70Error

    goal = f"`rt70 {args[0]}` on a {6 * BODIES}-coordinate chain ≤ {limit:g} s, warm process"
    try:
        (wall,) = wall_times(args, 1, env, cwd=str(cwd))
    except Rt70Error as exc:
        return TargetCheck(goal, f"failed: {exc}", False)
    measured = f"{wall:.1f} s (wall, one run, {run_kind(env)}; memory: the cold run's)"
    return TargetCheck(goal, measured, wall <= limit)


def _judged(args: list[str], limit: float, run: tuple, nv: int, quick: bool) -> TargetCheck:
    """The target of one command from its ``(wall, peak, code, last line)``."""
    wall, peak, code, last = run
    goal = (
        f"`rt70 {args[0]}` on a {6 * BODIES}-coordinate chain ≤ {limit:g} s, "
        f"≤ {MEMORY_TARGET_GB:g} GB"
    )
    if code != 0:
        return TargetCheck(
            goal, f"exit {code} on {nv} coordinates: {last}", None if quick else False
        )
    measured = f"{wall:.1f} s, {peak:.2f} GB peak (wall, one run, {nv} coordinates)"
    met = wall <= limit and peak <= MEMORY_TARGET_GB
    return TargetCheck(goal, measured, None if quick else met)
