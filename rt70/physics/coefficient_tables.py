"""Aerodynamic coefficient tables of bodies of revolution: read, checked, evaluated.

A :class:`CoefficientTable` holds C_A, C_N, C_M on θ ∈ [0°, 180°] (CSV
``theta_deg,axial,normal,moment``) and interpolates them by a periodic cubic spline of
the even (C_A) or odd (C_N, C_M) extension to the full circle, so that C_N/sin θ and
C_M/sin θ are smooth through θ = 0 and 180° (there: the spline's derivative). The
built-in tables ``dish`` and ``cylinder`` (:data:`BUILTIN_TABLES`) are engineering
estimates derived in their files' headers and in docs/wind.md, not wind-tunnel data.
The law that uses them is :mod:`rt70.physics.aerodynamics`. Imports nothing of rt70 but
the errors and :mod:`rt70.physics.cubic_pieces` (tests/test_import_rules.py, ``SHARED``).
"""

from __future__ import annotations

import math
import stat
from dataclasses import dataclass
from functools import cached_property
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from rt70.errors import Rt70Error
from rt70.physics.cubic_pieces import CubicPieces, horner

if TYPE_CHECKING:
    from scipy.interpolate import CubicSpline

#: Built-in coefficient tables (CSV files shipped in ``rt70/wind_tables/``).
BUILTIN_TABLES = ("dish", "cylinder")

#: Header of a coefficient table (after the ``#`` comment lines).
TABLE_HEADER = ("theta_deg", "axial", "normal", "moment")

#: Most rows of a coefficient table (θ every 0.018°; wind-tunnel tables have tens): the
#: periodic spline through 2·10⁵ rows takes 1.7 s to build, through 10⁴ under 0.1 s.
MAX_TABLE_ROWS = 10_000

#: Largest size of a coefficient table file, bytes (10⁴ rows of four numbers written in
#: full precision are about 0.8 MB).
MAX_TABLE_BYTES = 2**20

#: Largest magnitude of a coefficient: the bound of every number rt70 reads from a model
#: (``rt70.urdf.elements.MAX_MAGNITUDE``, docs/urdf-reader.md; a test holds the two equal).
MAX_COEFFICIENT = 1e30

#: How close to zero C_N and C_M must be at θ = 0° and 180° (a body of revolution).
END_TOLERANCE = 1e-12

#: Below this sin θ the ratios C/sin θ are the spline's derivative at 0 or π (the
#: neglected term is O(sin²θ) = 1e-16 relative).
SMALL_SINE = 1e-8


class WindError(Rt70Error):
    """A wind condition or a coefficient table is malformed."""


@dataclass(frozen=True, eq=False)
class CoefficientTable:
    """Axial, normal and moment coefficients of a body of revolution against θ.

    Build with :meth:`from_csv`, :meth:`from_text` or :func:`builtin_table`; the columns
    are checked (:meth:`from_rows`). Evaluate with :meth:`ratios`.

    Attributes
    ----------
    source : str
        Where the table came from (a file path, or ``built-in 'dish'``).
    theta_deg, axial, normal, moment : numpy.ndarray
        The rows as read: θ in degrees (0 … 180, increasing), C_A, C_N, C_M.
    """

    source: str
    theta_deg: np.ndarray
    axial: np.ndarray
    normal: np.ndarray
    moment: np.ndarray

    @cached_property
    def _fitted(self) -> tuple[tuple[CubicSpline, ...], CubicPieces]:
        """The periodic splines of C_A, C_N, C_M over 0 … 2π and their pieces in floats.

        Fitted at the first evaluation, not when a scene with wind elements is read.
        """
        from scipy.interpolate import CubicSpline

        theta = np.radians(self.theta_deg)
        full = np.concatenate([theta, 2.0 * np.pi - theta[::-1][1:]])  # 0 … 2π

        def extended(values: np.ndarray, parity: float) -> CubicSpline:
            y = np.concatenate([values, parity * values[::-1][1:]])
            return CubicSpline(full, y, bc_type="periodic")

        splines = (
            extended(self.axial, 1.0),
            extended(self.normal, -1.0),
            extended(self.moment, -1.0),
        )
        # the same polynomials in plain floats: per interval, (C_A, C_N, C_M)'s four each
        return splines, CubicPieces(full, np.stack([sp.c for sp in splines], axis=-1))

    @classmethod
    def from_rows(cls, source: str, rows: np.ndarray) -> CoefficientTable:
        """A table from rows ``[θ°, C_A, C_N, C_M]``, checked.

        Raises
        ------
        WindError
            (naming ``source``) if there are fewer than 3 rows, a value is not finite,
            θ does not increase strictly from 0 to 180, or C_N or C_M is not zero
            (within :data:`END_TOLERANCE`) at 0° and 180°.
        """
        rows = np.asarray(rows, dtype=float)
        if rows.ndim != 2 or rows.shape[1] != 4 or rows.shape[0] < 3:
            raise WindError(f"{source}: a coefficient table needs at least 3 rows of 4 numbers")
        if rows.shape[0] > MAX_TABLE_ROWS:
            raise WindError(
                f"{source}: {rows.shape[0]} rows; a coefficient table has at most "
                f"{MAX_TABLE_ROWS} (θ every {180 / MAX_TABLE_ROWS:g}°)"
            )
        if not np.all(np.isfinite(rows)):
            raise WindError(f"{source}: NaN or infinite value in the coefficient table")
        big = np.abs(rows[:, 1:]) > MAX_COEFFICIENT
        if big.any():
            i, k = np.argwhere(big)[0]
            raise WindError(
                f"{source}: {TABLE_HEADER[k + 1]} coefficient {rows[i, k + 1]:g} at theta_deg = "
                f"{rows[i, 0]:g}: magnitude above {MAX_COEFFICIENT:g}, the largest number rt70 "
                "reads (docs/urdf-reader.md)"
            )
        theta = rows[:, 0]
        if theta[0] != 0.0 or theta[-1] != 180.0 or np.any(np.diff(theta) <= 0.0):
            raise WindError(
                f"{source}: theta_deg must increase strictly from 0 to 180 "
                f"(got {theta[0]:g} … {theta[-1]:g})"
            )
        for k, name in ((2, "normal"), (3, "moment")):
            for i in (0, -1):
                if abs(rows[i, k]) > END_TOLERANCE:
                    raise WindError(
                        f"{source}: {name} coefficient must be 0 at theta_deg = "
                        f"{theta[i]:g} (a body of revolution), got {rows[i, k]:g}"
                    )
        rows = rows.copy()
        rows[[0, -1], 2:] = 0.0  # within END_TOLERANCE: exactly odd on the full circle
        return cls(source, rows[:, 0], rows[:, 1], rows[:, 2], rows[:, 3])

    @classmethod
    def from_text(cls, text: str, source: str) -> CoefficientTable:
        """Parse CSV text: ``#`` comment lines, the header :data:`TABLE_HEADER`, rows.

        Raises
        ------
        WindError
            (naming ``source`` and the line) if the header is missing or a row is not
            four numbers; and as :meth:`from_rows`.
        """
        header_seen = False
        rows = []
        for number, raw in enumerate(text.splitlines(), start=1):
            line = raw.strip()
            if not line or line.startswith("#"):
                continue
            cells = tuple(c.strip() for c in line.split(","))
            if not header_seen:
                if cells != TABLE_HEADER:
                    raise WindError(
                        f"{source}:{number}: expected the header '{','.join(TABLE_HEADER)}', "
                        f"got '{line}'"
                    )
                header_seen = True
                continue
            try:
                values = [float(c) for c in cells]
            except ValueError:
                raise WindError(f"{source}:{number}: not a row of numbers: '{line}'") from None
            if len(values) != 4:
                raise WindError(f"{source}:{number}: expected 4 numbers, got {len(values)}")
            rows.append(values)
        if not header_seen:
            raise WindError(f"{source}: no header '{','.join(TABLE_HEADER)}'")
        return cls.from_rows(source, np.array(rows, dtype=float).reshape(-1, 4))

    @classmethod
    def from_csv(cls, path: str | Path) -> CoefficientTable:
        """Read a CSV file (see :meth:`from_text`).

        Raises
        ------
        WindError
            If the file is missing or unreadable, is not a regular file (a FIFO or a
            device such as ``/dev/zero`` would block or never end), or is larger than
            :data:`MAX_TABLE_BYTES`; and as :meth:`from_text`.
        """
        path = Path(path)
        try:
            if not stat.S_ISREG(path.stat().st_mode):
                raise WindError(f"{path}: is not a regular file (a device or a pipe?)")
            with path.open("rb") as file:
                data = file.read(MAX_TABLE_BYTES + 1)
        except OSError as exc:
            raise WindError(f"{path}: cannot read the coefficient table ({exc})") from None
        if len(data) > MAX_TABLE_BYTES:
            raise WindError(
                f"{path}: larger than {MAX_TABLE_BYTES // 2**20} MiB, which no coefficient "
                f"table needs (at most {MAX_TABLE_ROWS} rows)"
            )
        try:
            text = data.decode("utf-8")
        except UnicodeDecodeError as exc:
            raise WindError(f"{path}: cannot read the coefficient table ({exc})") from None
        return cls.from_text(text, str(path))

    @property
    def splines(self) -> tuple[CubicSpline, ...]:
        """The periodic splines (scipy) of C_A, C_N and C_M over θ in [0, 2π] (radians)."""
        return self._fitted[0]

    def coefficients(self, theta: float) -> tuple[float, float, float]:
        """``(C_A, C_N, C_M)`` at θ (radians, in [0, π]) from the splines."""
        axial, normal, moment = self._fitted[0]
        return float(axial(theta)), float(normal(theta)), float(moment(theta))

    def ratios(self, cos_theta: float, sin_theta: float) -> tuple[float, float, float]:
        """``(C_A, C_N/sin θ, C_M/sin θ)`` at θ given by its cosine and (≥ 0) sine.

        The odd coefficients are evaluated on the spline interval that starts at 0
        (θ ≤ 90°) or, through ``C(θ) = −C(π + x)`` with ``x = π − θ`` taken as
        ``atan2(sin θ, −cos θ)``, on the one that starts at π, as the interval's
        polynomial in x itself: a small C near either end is then accurate to rounding
        relative to itself (not ε·π / x), so the ratio is too. Below
        :data:`SMALL_SINE` the ratio is the derivative, ``C'(0)`` or ``−C'(π)``.
        """
        theta = math.atan2(sin_theta, cos_theta)
        c_a, c_n, c_m = self._values(theta)
        m = len(self.theta_deg) - 1  # the interval [π, …] of the full circle
        fitted = self._fitted[1]
        pieces, knots = fitted.pieces, fitted.knots
        if sin_theta < SMALL_SINE:
            if cos_theta > 0.0:
                _, normal, moment = pieces[0]
                return c_a, normal[2], moment[2]
            _, normal, moment = pieces[m]
            return c_a, -normal[2], -moment[2]
        if cos_theta < 0.0:
            x = math.atan2(sin_theta, -cos_theta)
            if x <= knots[m + 1] - knots[m]:
                _, normal, moment = pieces[m]
                c_n, c_m = -horner(normal, x), -horner(moment, x)
            else:
                _, c_n, c_m = self._values(knots[m] + x)
                c_n, c_m = -c_n, -c_m
        return c_a, c_n / sin_theta, c_m / sin_theta

    def _values(self, theta: float) -> tuple[float, float, float]:
        """``(C_A, C_N, C_M)`` at θ in [0, 2π]: each spline's polynomial on θ's interval.

        The interval is scipy's (``x_i ≤ θ < x_{i+1}``, the last one closed); the
        polynomial is evaluated by Horner's rule, in plain floats (no array per call).
        """
        fitted = self._fitted[1]
        i, dx = fitted.locate(theta)
        return tuple(horner(c, dx) for c in fitted.pieces[i])


def builtin_table(name: str) -> CoefficientTable:
    """One of :data:`BUILTIN_TABLES`, read from the package's ``wind_tables/NAME.csv``.

    Raises
    ------
    WindError
        If ``name`` is not a built-in table.
    """
    if name not in BUILTIN_TABLES:
        raise WindError(f"no built-in coefficient table '{name}' (built in: {BUILTIN_TABLES})")
    text = resources.files("rt70").joinpath("wind_tables", f"{name}.csv").read_text("utf-8")
    return CoefficientTable.from_text(text, f"built-in table '{name}'")
