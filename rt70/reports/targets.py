"""A benchmark target against the value measured in one run; a command's wall time, cold or warm."""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from contextlib import contextmanager
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


def wall_times(
    args: list[str], repeats: int, env: dict[str, str] | None = None, cwd: str | None = None
) -> list[float]:
    """Wall times of ``rt70 ARGS`` (``python -m rt70``) run ``repeats`` times, s.

    Parameters
    ----------
    args : list of str
        The command's words.
    repeats : int
        Runs of the command.
    env : dict, optional
        Its environment: :func:`warm_process`'s to time it served warm; default this
        process's with ``RT70_WARM=0`` (each run in a fresh interpreter, start-up included).
    cwd : path, optional
        Where it runs (its output files go there); default this process's directory.

    Raises
    ------
    Rt70Error
        If a run fails: its exit code and the last line it printed on stderr.
    """
    from rt70.errors import Rt70Error

    cmd = [sys.executable, "-m", "rt70", *args]
    env = {**os.environ, "RT70_WARM": "0"} if env is None else env
    walls = []
    for _ in range(repeats):
        start = time.perf_counter()
        done = subprocess.run(cmd, capture_output=True, text=True, check=False, env=env, cwd=cwd)
        walls.append(time.perf_counter() - start)
        if done.returncode != 0:
            raise Rt70Error(f"{' '.join(cmd[1:])}: exit {done.returncode}: {_last_line(done)}")
    return walls


def run_kind(env: dict[str, str] | None) -> str:
    """How :func:`wall_times` ran a command with ``env``, as the measured values say it."""
    return "start-up included" if env is None else "served by the warm process"


def _last_line(done: subprocess.CompletedProcess) -> str:
    """The last line a failed command printed on stderr."""
    return (done.stderr.strip().splitlines() or ["(no output)"])[-1]


@contextmanager
def warm_process() -> Iterator[dict[str, str]]:
    """A warm process of its own (``rt70 warm start``, a temporary socket) for the block.

    Yields the environment whose ``rt70`` commands it serves (for :func:`wall_times`)
    once its compiled BDF is loaded as well (``rt70 warm start --settle``); stopped
    afterwards.

    Raises
    ------
    Rt70Error
        If it does not start: the last line it printed.
    """
    from rt70.errors import Rt70Error

    with tempfile.TemporaryDirectory(prefix="rt70w") as directory:
        env = {k: v for k, v in os.environ.items() if k != "RT70_WARM"}
        env["RT70_WARM_SOCKET"] = os.path.join(directory, "w.sock")
        cmd = [sys.executable, "-m", "rt70", "warm"]
        done = subprocess.run([*cmd, "start", "--idle", "30", "--settle"], env=env,
                              capture_output=True, text=True, check=False)  # fmt: skip
        if done.returncode != 0:
            raise Rt70Error(f"rt70 warm start: exit {done.returncode}: {_last_line(done)}")
        try:
            yield env
        finally:
            subprocess.run([*cmd, "stop"], env=env, capture_output=True, check=False)
