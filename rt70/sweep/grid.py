"""The grid of a sweep: its axes and their values, checked, and the chunks it is cut into.

An axis's values come from the command line (:func:`parse_values`: ``A:B:N``,
``A,B,…`` or ``A``); :func:`make_grid` checks them against the RT-70's range and makes
the Cartesian product of the fixed axes (:data:`AXES`) and the scene parameters' factors
(:class:`Grid`), which :meth:`Grid.chunks` cuts into runs of consecutive elevations
(:class:`Chunk`), the unit of work and of resumption. docs/sweeps.md.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from rt70.guards.resources import check_memory
from rt70.model.antenna import ELEVATION_SPAN_DEG
from rt70.sweep.errors import SweepError
from rt70.sweep.quantities import PARAMETERS, SweepPoint

#: The fixed axes of every grid, in order, with units and defaults (one value each).
AXES = (("elevation", "deg", 90.0), ("azimuth", "deg", 0.0), ("wind", "m/s", 0.0))
AXES += (("direction", "deg", 0.0),)

#: Largest magnitude of an azimuth or a wind direction, degrees: one turn either way
#: holds every pointing; beyond it a float's spacing grows until the angle means nothing.
MAX_TURN_DEG = 360.0

#: Memory per value of an axis, bytes: the Python float, the tuple slot, the grid's
#: JSON (key, metadata) and numpy's transient ``linspace`` (90 B measured by
#: ``python validation/sweep_memory.py --points 9000``, rounded up).
BYTES_PER_AXIS_VALUE = 150


def parse_values(text: str) -> tuple[float, ...]:
    """Values of an axis: ``A:B:N`` (N equally spaced, ends included), ``A,B,…`` or ``A``.

    Raises
    ------
    SweepError
        For anything else (``1:2``, N < 2 with A ≠ B, a non-finite number).
    ResourceError
        More values than this machine can hold (checked before they are made).
    """

    def number(s: str) -> float:
        try:
            v = float(s)
        except ValueError:
            raise SweepError(f"'{s}' is not a number (in '{text}')") from None
        if not math.isfinite(v):
            raise SweepError(f"'{s}' is not a finite number (in '{text}')")
        return v

    if ":" in text:
        parts = text.split(":")
        if len(parts) != 3:
            raise SweepError(f"'{text}': a range is START:STOP:COUNT, e.g. 0:90:91")
        a, b = number(parts[0]), number(parts[1])
        try:
            n = int(parts[2])
        except ValueError:
            raise SweepError(f"'{text}': COUNT '{parts[2]}' is not an integer") from None
        if n < 1 or (n == 1 and a != b):
            raise SweepError(f"'{text}': COUNT must be at least 2 (1 only when START = STOP)")
        check_memory(n * BYTES_PER_AXIS_VALUE, f"{n} values of an axis", f"'{text}'")
        return tuple(float(v) for v in np.linspace(a, b, n))
    return tuple(number(s) for s in text.split(","))


@dataclass(frozen=True)
class Axis:
    """One axis of a grid: its name (``scale:NAME`` for a scene parameter), unit, values."""

    name: str
    unit: str
    values: tuple[float, ...]


@dataclass(frozen=True)
class Chunk:
    """Points ``start … stop − 1`` along elevation at the indices ``rest`` of the other axes."""

    number: int
    rest: tuple[int, ...]
    start: int
    stop: int

    def indices(self) -> list[tuple[int, ...]]:
        """Grid indices of the chunk's points, in order of increasing elevation index."""
        return [(i, *self.rest) for i in range(self.start, self.stop)]


@dataclass(frozen=True)
class Grid:
    """The Cartesian product of :attr:`axes` (elevation first: the chunks run along it)."""

    axes: tuple[Axis, ...]

    @property
    def shape(self) -> tuple[int, ...]:
        """Number of values per axis."""
        return tuple(len(a.values) for a in self.axes)

    @property
    def size(self) -> int:
        """Number of points."""
        return math.prod(self.shape)

    def point(self, index: Sequence[int]) -> SweepPoint:
        """The point at a grid index."""
        values = {a.name: a.values[i] for a, i in zip(self.axes, index, strict=True)}
        scales = {k.removeprefix("scale:"): v for k, v in values.items() if k.startswith("scale:")}
        return SweepPoint(
            values["elevation"], values["azimuth"], values["wind"], values["direction"], scales
        )

    def chunks(self, size: int) -> list[Chunk]:
        """The grid cut into runs of at most ``size`` consecutive elevations, numbered."""
        out = []
        for rest in np.ndindex(*self.shape[1:]):
            for start in range(0, self.shape[0], size):
                stop = min(start + size, self.shape[0])
                out.append(Chunk(len(out), tuple(int(i) for i in rest), start, stop))
        return out

    def chunk(self, size: int, number: int) -> Chunk:
        """Chunk ``number`` of :meth:`chunks` (``size``), without listing the others."""
        per_run = math.ceil(self.shape[0] / size)
        run, k = divmod(number, per_run)
        rest = (
            tuple(int(i) for i in np.unravel_index(run, self.shape[1:])) if self.shape[1:] else ()
        )
        start = k * size
        return Chunk(number, rest, start, min(start + size, self.shape[0]))

    def as_dict(self) -> dict[str, Any]:
        """The axes as JSON: ``{name: {"unit": …, "values": […]}}``, in order."""
        return {a.name: {"unit": a.unit, "values": list(a.values)} for a in self.axes}


def make_grid(
    values: Mapping[str, Sequence[float]] | None = None,
    scales: Mapping[str, Sequence[float]] | None = None,
) -> Grid:
    """A grid from axis values (missing axes take their default) and parameter factors.

    Raises
    ------
    SweepError
        An elevation beyond a quarter turn past the horizon or the zenith (the scene's
        own range is checked by :func:`rt70.sweep.plan.plan`), an azimuth or direction
        beyond one turn, a negative wind speed, an unknown axis or scene parameter, a
        factor ≤ 0, an empty or repeated axis.
    """
    values = dict(values or {})
    unknown = [k for k in values if k not in {name for name, _, _ in AXES}]
    if unknown:
        raise SweepError(f"unknown sweep axis {', '.join(unknown)}")
    axes = []
    for name, unit, default in AXES:
        axes.append(Axis(name, unit, tuple(float(v) for v in values.get(name, (default,)))))
    for name, factors in (scales or {}).items():
        if name not in PARAMETERS:
            raise SweepError(
                f"--scale {name}: unknown scene parameter (known: {', '.join(PARAMETERS)})"
            )
        if any(not f > 0.0 for f in factors):
            raise SweepError(f"--scale {name}: factors must be greater than 0")
        axes.append(Axis(f"scale:{name}", "1", tuple(float(f) for f in factors)))
    for axis in axes:
        if not axis.values:
            raise SweepError(f"--{axis.name}: no values")
        if len(set(axis.values)) != len(axis.values):
            raise SweepError(f"--{axis.name}: a value is repeated")
    low, high = ELEVATION_SPAN_DEG
    if any(not low <= e <= high for e in axes[0].values):
        raise SweepError(f"--elevation: elevations lie between {low:g}° and {high:g}°")
    if any(w < 0.0 for w in axes[2].values):
        raise SweepError("--wind: speeds must be at least 0 m/s")
    for axis in (axes[1], axes[3]):
        if any(abs(v) > MAX_TURN_DEG for v in axis.values):
            raise SweepError(
                f"--{axis.name}: angles from {-MAX_TURN_DEG:g}° to {MAX_TURN_DEG:g}° "
                "(one turn either way holds every pointing)"
            )
    return Grid(tuple(axes))
