"""Frequency-domain measures of a linear loop: response, margins, bandwidth, stability.

One job: the numbers a servo engineer reads off a loop, the same for any controller
(the PI cascade of :mod:`rt70.control.loops`, the LQG of :mod:`rt70.control.lqg`): the
complex frequency response of a SISO state space (:func:`siso_response`, through rt70's
one :func:`rt70.linear.responses.frequency_response`), the gain and phase margins of a
loop transfer (:func:`margins`: python-control's ``stability_margins`` on an ``FRD`` on
:data:`FREQ_HZ` — never a transfer-function conversion of a high-order, lightly damped
plant, see :mod:`rt70.linear.plant`), the −3 dB bandwidth of a closed loop (:func:`bandwidth_hz`)
and its stability (:func:`stable`).
"""

from __future__ import annotations

from dataclasses import dataclass

import control
import numpy as np

from rt70.errors import Rt70Error
from rt70.linear.responses import frequency_response

#: Frequencies of the margins and bandwidths, Hz: 200 points per decade, a step of 1.2 %,
#: a third of the half-power width 2ζ of the plant's least damped resonance (ζ ≈ 0.03).
FREQ_HZ = np.logspace(-3, 2, 1001)
#: Adequate margins (antenna practice): gain margin, dB, and phase margin, degrees.
MIN_GM_DB = 6.0
MIN_PM_DEG = 30.0


def siso_response(sys: control.StateSpace, freq_hz: np.ndarray = FREQ_HZ) -> np.ndarray:
    """Complex frequency response of a SISO state space at ``freq_hz`` (no TF conversion).

    :func:`rt70.linear.responses.frequency_response` (python-control's evaluation), its
    one input/output pair.
    """
    if sys.ninputs != 1 or sys.noutputs != 1:
        raise Rt70Error(
            f"a loop measure needs one input and one output, got {sys.ninputs} and {sys.noutputs}"
        )
    return frequency_response(sys, np.asarray(freq_hz, dtype=float)).H[:, 0, 0]


@dataclass(frozen=True)
class Margins:
    """Gain and phase margins of a loop and where they are, from its frequency response.

    Attributes
    ----------
    gm_db : float
        Gain (increase) margin, dB: the least ``1/|L|`` over the phase crossovers where
        ``|L| < 1`` (inf if there is none).
    gm_down_db : float
        Gain-reduction margin, dB (negative): the largest ``1/|L|`` over the phase
        crossovers where ``|L| > 1`` — a nested loop broken inside a closed outer loop
        is conditionally stable (−inf if there is none).
    pm_deg : float
        Phase margin, degrees: the least phase distance ``180° − |∠L|`` of a gain
        crossover from −1.
    f_gc_hz : float
        The gain crossover with the least phase margin, Hz (NaN if none).
    f_pc_hz : float
        The phase crossover of ``gm_db``, Hz (NaN if none).
    """

    gm_db: float
    gm_down_db: float
    pm_deg: float
    f_gc_hz: float
    f_pc_hz: float

    @property
    def adequate(self) -> bool:
        """Both gain margins at least :data:`MIN_GM_DB`, PM at least :data:`MIN_PM_DEG`."""
        return bool(
            self.gm_db >= MIN_GM_DB and self.gm_down_db <= -MIN_GM_DB and self.pm_deg >= MIN_PM_DEG
        )


def margins(L: control.StateSpace, freq_hz: np.ndarray = FREQ_HZ) -> Margins:
    """Margins of the loop ``L``: python-control's ``stability_margins`` on its ``FRD``."""
    frd = control.frd(siso_response(L, freq_hz), 2 * np.pi * freq_hz)
    gm, pm, _, w_pc, w_gc, _ = (np.atleast_1d(x) for x in control.stability_margins(frd, True))
    up, down = gm > 1.0, gm < 1.0
    gm_db = float(20 * np.log10(gm[up].min())) if up.any() else np.inf
    f_pc = float(w_pc[up][np.argmin(gm[up])]) / (2 * np.pi) if up.any() else np.nan
    gm_down_db = float(20 * np.log10(gm[down].max())) if down.any() else -np.inf
    if pm.size == 0:
        return Margins(gm_db, gm_down_db, np.inf, np.nan, f_pc)
    # python-control's pm is ∠L + 180° folded to (−180°, 180°]; the phase distance of a
    # gain crossover from −1 is 180° − |∠L| with ∠L in (−180°, 180°] (stability itself is
    # checked on the closed loop's poles)
    angle = pm % 360.0 - 180.0  # ∠L in [−180°, 180°)
    distance = 180.0 - np.abs(angle)
    k = int(np.argmin(distance))
    return Margins(gm_db, gm_down_db, float(distance[k]), float(w_gc[k]) / (2 * np.pi), f_pc)


def bandwidth_hz(T: control.StateSpace, freq_hz: np.ndarray = FREQ_HZ) -> float:
    """First frequency where ``|T|`` falls 3 dB below its low-frequency gain, Hz.

    Linear interpolation in log frequency between the grid points around the crossing;
    NaN if it never falls.
    """
    mag_db = 20 * np.log10(np.abs(siso_response(T, freq_hz)))
    below = np.flatnonzero(mag_db < mag_db[0] - 3.0)
    if below.size == 0:
        return np.nan
    i = int(below[0])
    level = mag_db[0] - 3.0
    x0, x1 = np.log10(freq_hz[i - 1]), np.log10(freq_hz[i])
    t = (mag_db[i - 1] - level) / (mag_db[i - 1] - mag_db[i])
    return float(10 ** (x0 + t * (x1 - x0)))


def stable(sys: control.StateSpace) -> bool:
    """All poles strictly in the left half-plane."""
    return bool(np.all(np.real(control.poles(sys)) < 0.0))
