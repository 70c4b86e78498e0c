"""A benchmark target against the value measured in one run, and a command's wall time."""

from __future__ import annotations

import subprocess
import sys
import time
from dataclasses import dataclass


@dataclass(frozen=True)
class TargetCheck:
    """One target and what this run measured for it.

    Attributes
    ----------
    target : str
        The target as stated, e.g. ``"per-call ratio ≤ 10 on rt70"``.
    measured : str
        The measured value, with what it was measured on.
    met : bool or None
        Whether the measurement meets the target; None when the run does not measure
        it (a quick run, another batch size): then it is ``not judged``.
    """

    target: str
    measured: str
    met: bool | None

    def line(self) -> str:
        """``target … — measured … — met`` (or ``NOT met``, or ``not judged``)."""
        verdict = {True: "met", False: "NOT met", None: "not judged"}[self.met]
        return f"target {self.target} — measured {self.measured} — {verdict}"


#: The problem the simulation targets are judged on: the work–precision report's 10 s
#: transient of the RT-70 with its axes free.
TRANSIENT_PROBLEM = "rt70_10s"


#: Accuracy of the simulation targets: centre-of-mass position error, m.
COM_TARGET_M = 1e-5


#: Integration speed of the free-axes transient, × real time (the speed issue's level;
#: an earlier issue asked 50×).
REAL_TIME_TARGET = 100.0


def wall_times(args: list[str], repeats: int) -> list[float]:
    """Wall times of ``rt70 ARGS`` (``python -m rt70``) run ``repeats`` times, s.

    Raises
    ------
    Rt70Error
        If a run fails: its exit code and the last line it printed on stderr.
    """
    from rt70.errors import Rt70Error

    cmd = [sys.executable, "-m", "rt70", *args]
    walls = []
    for _ in range(repeats):
        start = time.perf_counter()
        done = subprocess.run(cmd, capture_output=True, text=True, check=False)
        walls.append(time.perf_counter() - start)
        if done.returncode != 0:
            tail = (done.stderr.strip().splitlines() or ["(no output)"])[-1]
            raise Rt70Error(f"{' '.join(cmd[1:])}: exit {done.returncode}: {tail}")
    return walls
