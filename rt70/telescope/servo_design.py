"""A servo designed for the model it drives: the highest position bandwidth with margins.

One job: for each axis whose ``<rt70:servo>`` gives no ``position_bandwidth_hz``, find the
highest position-loop bandwidth of the PI cascade (:func:`rt70.control.servo.cascade_gains`,
each loop ``loop_ratio`` faster than the one around it) at which, over the elevation
range, every loop of that axis keeps a gain margin of at least 6 dB and a phase margin
of at least 30° (:data:`rt70.control.loop_measures.MIN_GM_DB`, ``MIN_PM_DEG``) and the
closed loop is stable — on the model's own linear plant: the structure linearised at the
drive-held equilibrium, every ``<rt70:drive>`` with its motor, compliant reducer and
gear sector (:func:`rt70.control.scene_loop.loop_gain`), so the locked-rotor resonances,
the inertias and the limits are the scene's. Declared bandwidths are kept and checked.

The search scans a geometric grid of bandwidths from :data:`HIGH_HZ` down to
:data:`LOW_HZ` (ratio :data:`GRID_RATIO`) for the first adequate one, then bisects in log
frequency between it and the inadequate one above: first with every tuned axis at one
common bandwidth (each axis's loops see the others closed, so the others must hold
too), then each axis alone upwards from there, the others at theirs.
Adequacy is not monotonic in the bandwidth: below some bandwidth the current loop is
slower than the motor's back-EMF pole and the rigid-axis cascade loses its margins too,
so the scan comes from above. One design per scene text, kept for the process
(:func:`design`): the linear loops, ``simulate``, ``pointing`` and ``sweep`` all use it.
The search reads the margins on :data:`SEARCH_FREQ_HZ` (100 points a decade); the design
is then checked on :data:`rt70.control.loop_measures.FREQ_HZ` (200).
"""

from __future__ import annotations

import hashlib
import math
import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from rt70.errors import Rt70Error
from rt70.linear import linearize as lin
from rt70.model.antenna import mount_of, pointing, range_deg
from rt70.model.scene import Scene
from rt70.telescope.axis_servos import Tuning, axis_servos, drive_servos
from rt70.telescope.drive_equilibrium import drive_held_linearization

if TYPE_CHECKING:  # python-control (≈ 1.5 s to import) only where a design is made
    from rt70.control.loop_measures import Margins

#: Bracket of the position-loop bandwidth search, Hz.
LOW_HZ, HIGH_HZ = 0.01, 5.0
#: Ratio between the scanned bandwidths, and the bisection steps after the scan (to
#: 1.5^(1/16), 2.6 %).
GRID_RATIO, STEPS = 1.5, 4
#: Frequencies of the search's margins, Hz: 100 points a decade.
SEARCH_FREQ_HZ = np.logspace(-3, 2, 501)
#: The loops whose margins the search holds (the current loop's is checked and reported).
SEARCHED_LOOPS = ("position", "rate")
#: Every loop reported.
LOOPS = ("position", "rate", "current")

_DESIGNS: dict[str, ServoDesign] = {}


@dataclass
class ServoDesign:
    """A scene's servo design and what it was checked against.

    Attributes
    ----------
    tuning : dict
        ``{axis: (position bandwidth Hz, loop ratio)}``.
    tuned : dict of str to bool
        Whether each axis's bandwidth was tuned here (False: declared).
    elevations_deg : tuple of float
        The elevations of the check (the range's ends and middle).
    margins : dict
        ``{axis: {loop: Margins}}``: the least margins over the elevations.
    bandwidth_hz : dict of str to float
        The closed loop's −3 dB bandwidth reference → encoder per axis, the least over
        the elevations.
    stable : bool
        The closed loop is stable at every elevation.
    seconds : float
        Time the design took.
    """

    tuning: Tuning
    tuned: dict[str, bool]
    elevations_deg: tuple[float, ...]
    margins: dict[str, dict[str, Margins]] = field(default_factory=dict)
    bandwidth_hz: dict[str, float] = field(default_factory=dict)
    stable: bool = True
    seconds: float = 0.0

    @property
    def adequate(self) -> bool:
        """Stable, and every loop of every axis with adequate margins."""
        return self.stable and all(
            m.adequate for loops in self.margins.values() for m in loops.values()
        )

    def lines(self) -> list[str]:
        """The design in a few printed lines."""
        out = []
        for axis, (hz, ratio) in self.tuning.items():
            how = "tuned on the model" if self.tuned[axis] else "declared"
            m = self.margins.get(axis, {})
            worst = ", ".join(
                f"{loop} GM {x.gm_db:.1f} dB PM {x.pm_deg:.0f}°" for loop, x in m.items()
            )
            out.append(
                f"{axis}: position loop {hz:.3g} Hz ({how}), loops ×{ratio:g}; closed-loop "
                f"bandwidth {self.bandwidth_hz.get(axis, math.nan):.3g} Hz; {worst}"
            )
        span = ", ".join(f"{e:g}°" for e in self.elevations_deg)
        out.append(f"checked at elevations {span}; {'stable' if self.stable else 'UNSTABLE'}")
        return out


def design_elevations(scene: Scene) -> tuple[float, ...]:
    """The elevations a design is checked at: the range's ends and middle, degrees."""
    axis = mount_of(scene).axis("elevation")
    low, high = range_deg(axis)
    return (low, 0.5 * (low + high), high)


def design(scene: Scene) -> ServoDesign:
    """The scene's servo design, computed once per scene text (module docstring).

    Raises
    ------
    Rt70Error
        If an axis declares no servo, or no bandwidth down to :data:`LOW_HZ` has
        adequate margins.
    """
    key = hashlib.sha256(scene.text.encode("utf-8")).hexdigest()
    if key not in _DESIGNS:
        _DESIGNS[key] = _design(scene)
    return _DESIGNS[key]


def _design(scene: Scene) -> ServoDesign:
    start = time.perf_counter()
    servos = axis_servos(scene)
    elevations = design_elevations(scene)
    plants = [_plant(scene, e) for e in elevations]
    tuning = {
        k: (d.servo.position_bandwidth_hz or LOW_HZ, d.servo.loop_ratio) for k, d in servos.items()
    }
    tuned = {k: d.servo.position_bandwidth_hz is None for k, d in servos.items()}
    free = tuple(k for k, untuned in tuned.items() if untuned)
    if free:  # all free axes together first: a start where every loop holds
        common = _highest(scene, plants, tuning, free, None)
        tuning.update({a: (common, tuning[a][1]) for a in free})
    for axis in free if len(free) > 1 else ():  # then each as high as it goes alone
        tuning[axis] = (_highest(scene, plants, tuning, (axis,), tuning[axis][0]), tuning[axis][1])
    result = ServoDesign(tuning, tuned, elevations)
    _check(scene, plants, result)
    result.seconds = time.perf_counter() - start
    return result


def _plant(scene: Scene, elevation_deg: float) -> lin.Linearization:
    """The structure linearised at the drive-held equilibrium of a pointing."""
    return drive_held_linearization(scene, pointing(scene, elevation_deg, 0.0))


def _adequate(scene: Scene, plants: list, tuning: Tuning, axes: tuple[str, ...]) -> bool:
    """Whether the searched loops of ``axes`` have adequate margins on every plant, stably.

    Stops at the first failing margin; the closed loop's stability is checked last.
    """
    from rt70.control.loop_measures import margins, stable
    from rt70.control.scene_loop import closed_loop, loop_gain

    servos = drive_servos(scene, tuning)
    declared = axis_servos(scene)
    for lm in plants:
        for axis in axes:
            for loop in SEARCHED_LOOPS:
                L = loop_gain(scene, lm, servos, declared[axis].drive.name, loop)
                if not margins(L, SEARCH_FREQ_HZ).adequate:
                    return False
    return all(stable(closed_loop(scene, lm, {}, [], servos)) for lm in plants)


def _highest(
    scene: Scene, plants: list, tuning: Tuning, axes: tuple[str, ...], floor: float | None
) -> float:
    """The highest adequate position bandwidth given to all of ``axes`` together, Hz.

    Scans down from :data:`HIGH_HZ` to ``floor`` (a bandwidth known adequate, returned
    if nothing above it is) or, without one, to :data:`LOW_HZ`; then bisects between the
    adequate bandwidth found and the inadequate one above it.
    """

    def ok(hz: float) -> bool:
        trial = {**tuning, **{a: (hz, tuning[a][1]) for a in axes}}
        return _adequate(scene, plants, trial, axes)

    bottom = LOW_HZ if floor is None else floor
    above, hz = None, HIGH_HZ
    while hz > bottom * (1.0 + 1e-12):
        if ok(hz):
            break
        above, hz = hz, hz / GRID_RATIO
    else:
        if floor is not None:
            hz = floor
        elif not ok(LOW_HZ):
            raise Rt70Error(
                f"{scene.name}: the {', '.join(axes)} servo has no adequate margins "
                f"(GM ≥ 6 dB, PM ≥ 30°) at any position-loop bandwidth from {HIGH_HZ:g} down to "
                f"{LOW_HZ:g} Hz: check its drive and structure"
            )
        else:
            hz = LOW_HZ
    if above is None:
        return hz
    low, high = hz, above
    for _ in range(STEPS):
        mid = math.sqrt(low * high)
        low, high = (mid, high) if ok(mid) else (low, mid)
    return low


def _check(scene: Scene, plants: list, result: ServoDesign) -> None:
    """Fill in the least margins of every loop and the closed-loop bandwidths."""
    from rt70.control.loop_measures import bandwidth_hz, margins, stable
    from rt70.control.scene_loop import closed_loop, loop_gain

    servos = drive_servos(scene, result.tuning)
    declared = axis_servos(scene)
    for axis, d in declared.items():
        drive = d.drive.name
        worst: dict[str, Margins] = {}
        bandwidths = []
        for lm in plants:
            closed = closed_loop(scene, lm, {}, [], servos)
            result.stable = result.stable and stable(closed)
            response = closed[f"{drive}_encoder", f"{drive}_reference"]
            bandwidths.append(bandwidth_hz(response))
            for loop in LOOPS:
                m = margins(loop_gain(scene, lm, servos, drive, loop))
                if loop not in worst or _worse(m, worst[loop]):
                    worst[loop] = m
        result.margins[axis] = worst
        result.bandwidth_hz[axis] = float(np.nanmin(bandwidths))


def _worse(a: Margins, b: Margins) -> bool:
    """Whether margins ``a`` are closer to inadequate than ``b`` (least GM, then PM)."""
    return (a.gm_db, a.pm_deg) < (b.gm_db, b.pm_deg)


def declared_tuning(scene: Scene) -> Tuning:
    """Each axis's ``(position_bandwidth_hz, loop_ratio)`` as declared.

    An axis whose servo gives no bandwidth is tuned on the model
    (:func:`design`) — once per scene.
    """
    servos = axis_servos(scene)
    if all(d.servo.position_bandwidth_hz is not None for d in servos.values()):
        return {k: (d.servo.position_bandwidth_hz, d.servo.loop_ratio) for k, d in servos.items()}
    return design(scene).tuning


def tuning_text(tuning: Tuning) -> str:
    """The position-loop bandwidths in one phrase: ``position loops azimuth 0.2 Hz, …``."""
    parts = ", ".join(f"{axis} {hz:.3g} Hz" for axis, (hz, _) in tuning.items())
    return f"position loops {parts}"
