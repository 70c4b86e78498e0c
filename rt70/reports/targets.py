"""A benchmark target against the value measured in one run."""

from __future__ import annotations

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


#: Integration speed of the free-axes transient, × real time.
REAL_TIME_TARGET = 50.0
