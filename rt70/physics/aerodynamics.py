"""Steady wind on exposed bodies: the flow, the book's wind frame, coefficient tables, Wrenches.

Shared below both sides, as :mod:`rt70.physics.loads`: each side hands in a link's pose from its
own kinematics and turns the :class:`~rt70.physics.loads.Wrench` returned here into a
generalised force (``Q = S W`` on the textbook side, ``Q = Jᵀ f`` on the reference
side; formalism §4.4, (4.132)–(4.136)). Imports nothing of rt70 but the argument
checks, the errors and the Wrench (tests/test_import_rules.py, ``SHARED``).

Conventions (docs/wind.md)
--------------------------
**Direction.** :class:`WindCondition` ``direction_deg`` is a *telescope azimuth* (the
convention of ``--azimuth``, :func:`rt70.scenes.rt70_optics.pointing_source`): the dish
at azimuth A looks toward the horizontal direction ``h(A) = [cos(A − 90°), sin(A − 90°),
0]`` (:func:`horizontal_direction`), and the wind blows FROM ``h(direction)``: the flow
velocity in ground axes is ``v0 = −speed · h(direction)``. ``direction == azimuth`` is a
front wind, blowing into the dish's face.

**Wind frame (4.132)–(4.133).** The flow in body i's axes is ``v_i = c_0iᵀ v0``; its
slip ``β = −arcsin(v_x / |v|)`` and attack ``α = arctan2(v_z, v_y)`` define the wind
frame ``c_iv = R_x(α) R_z(β)`` whose y axis is the flow: ``c_iv [0, |v|, 0]ᵀ = v_i``
(:func:`wind_frame`).

**Coefficients.** A body is axisymmetric about its unit axis ``a`` (for a dish its
boresight, out of the concave face). ``u`` is the flow's unit vector and θ the angle
between ``a`` and ``−u`` (θ = 0: the flow hits the concave face head-on). With the
dynamic pressure ``q = ½ ρ |v|²``, the reference area S and length l,

    F = q S [ −C_A(θ) a + (C_N(θ)/sin θ) (u − (u·a) a) ],
    M = q S l (C_M(θ)/sin θ) (u × a),

F acting at the element's reference point, M a free moment. C_A > 0 pushes the body
back along −a (a dish face-on), C_N > 0 pushes along the flow's cross component, C_M > 0
turns the face toward the wind. In the wind frame this is the book's
``½ ρ |v|² S l [c]`` rotated back (4.134)–(4.136), with the coefficients as functions
of θ only (a body of revolution; no rate terms: a steady flow).

**Tables.** :class:`CoefficientTable` holds C_A, C_N, C_M on θ ∈ [0°, 180°] (CSV
``theta_deg,axial,normal,moment``) and interpolates them by a periodic cubic spline of
the even (C_A) or odd (C_N, C_M) extension to the full circle, so that C_N/sin θ and
C_M/sin θ are smooth through θ = 0 and 180° (there: the spline's derivative). The
built-in tables ``dish`` and ``cylinder`` (:data:`BUILTIN_TABLES`) are engineering
estimates derived in their files' headers and in docs/wind.md, not wind-tunnel data.

The structure's own velocity is neglected against the wind's (no aerodynamic damping),
and so is shielding of one body by another (conservative).
"""

from __future__ import annotations

import math
import stat
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Protocol

import numpy as np

from rt70.errors import Rt70Error
from rt70.physics.loads import Pose, Wrench

if TYPE_CHECKING:
    from scipy.interpolate import CubicSpline

#: ISA sea-level air density, kg/m³ (the default of ``<rt70:air density>``).
DEFAULT_AIR_DENSITY = 1.225

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


def horizontal_direction(azimuth_deg: float) -> np.ndarray:
    """``h(A) = [cos(A − 90°), sin(A − 90°), 0]``: where the dish at azimuth A looks."""
    a = math.radians(azimuth_deg - 90.0)
    return np.array([math.cos(a), math.sin(a), 0.0])


def _finite(name: str, value) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise WindError(f"wind {name} must be a number, got {value!r}") from None
    if not math.isfinite(x):
        raise WindError(f"wind {name} must be finite, got {value!r}")
    return x


@dataclass(frozen=True)
class WindCondition:
    """A steady, uniform wind.

    Parameters
    ----------
    speed : float
        Wind speed ``|v0|``, m/s (≥ 0).
    direction_deg : float
        The telescope azimuth the wind blows FROM, degrees: the flow velocity is
        ``v0 = −speed · h(direction_deg)`` (:func:`horizontal_direction`), so
        ``direction_deg`` equal to the pointing's azimuth is a front wind into the dish.
    density : float or None
        Air density ρ, kg/m³; None takes the scene's ``<rt70:air density>``.

    Raises
    ------
    WindError
        If a value is not finite, the speed negative or the density not positive.
    """

    speed: float
    direction_deg: float
    density: float | None = None

    def __post_init__(self) -> None:
        speed = _finite("speed", self.speed)
        if speed < 0.0:
            raise WindError(f"wind speed must be non-negative, got {speed:g} m/s")
        object.__setattr__(self, "speed", speed)
        object.__setattr__(self, "direction_deg", _finite("direction", self.direction_deg))
        if self.density is not None:
            rho = _finite("density", self.density)
            if rho <= 0.0:
                raise WindError(f"air density must be positive, got {rho:g} kg/m³")
            object.__setattr__(self, "density", rho)

    def velocity(self) -> np.ndarray:
        """Flow velocity v0 in ground axes, m/s: ``−speed · h(direction_deg)``."""
        return -self.speed * horizontal_direction(self.direction_deg)

    def air_density(self, default: float) -> float:
        """ρ of this condition, or ``default`` (the scene's) when it has none."""
        return default if self.density is None else self.density


def wind_frame(v_body: np.ndarray) -> tuple[float, float, np.ndarray]:
    """``(α, β, c_iv)`` of a flow velocity in body axes (4.132)–(4.133).

    ``β = −arcsin(v_x/|v|)``, ``α = arctan2(v_z, v_y)`` and ``c_iv = R_x(α) R_z(β)``:
    ``c_iv [0, |v|, 0]ᵀ = v_body`` (the wind frame's y axis is the flow).

    Raises
    ------
    WindError
        If the velocity is zero (no flow, no frame).
    """
    v = np.asarray(v_body, dtype=float)
    speed = float(np.linalg.norm(v))
    if speed == 0.0:
        raise WindError("no wind frame for a zero flow velocity")
    beta = -math.asin(max(-1.0, min(1.0, v[0] / speed)))
    alpha = math.atan2(v[2], v[1])
    ca, sa, cb, sb = math.cos(alpha), math.sin(alpha), math.cos(beta), math.sin(beta)
    rx = np.array([[1.0, 0.0, 0.0], [0.0, ca, -sa], [0.0, sa, ca]])
    rz = np.array([[cb, -sb, 0.0], [sb, cb, 0.0], [0.0, 0.0, 1.0]])
    return alpha, beta, rx @ rz


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
    _splines: tuple = field(init=False, repr=False)

    def __post_init__(self) -> None:
        from scipy.interpolate import CubicSpline  # only when a scene has wind elements

        theta = np.radians(self.theta_deg)
        full = np.concatenate([theta, 2.0 * np.pi - theta[::-1][1:]])  # 0 … 2π

        def extended(values: np.ndarray, parity: float) -> CubicSpline:
            y = np.concatenate([values, parity * values[::-1][1:]])
            return CubicSpline(full, y, bc_type="periodic")

        object.__setattr__(
            self,
            "_splines",
            (extended(self.axial, 1.0), extended(self.normal, -1.0), extended(self.moment, -1.0)),
        )

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

    def coefficients(self, theta: float) -> tuple[float, float, float]:
        """``(C_A, C_N, C_M)`` at θ (radians, in [0, π]) from the splines."""
        axial, normal, moment = self._splines
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
        axial, normal, moment = self._splines
        theta = math.atan2(sin_theta, cos_theta)
        c_a = float(axial(theta))
        if sin_theta < SMALL_SINE:
            if cos_theta > 0.0:
                return c_a, float(normal(0.0, 1)), float(moment(0.0, 1))
            m = len(self.theta_deg) - 1  # the interval [π, …] of the full circle
            return c_a, -float(normal.c[2, m]), -float(moment.c[2, m])
        if cos_theta >= 0.0:
            c_n, c_m = float(normal(theta)), float(moment(theta))
        else:
            x = math.atan2(sin_theta, -cos_theta)
            c_n, c_m = -self._from_pi(normal, x), -self._from_pi(moment, x)
        return c_a, c_n / sin_theta, c_m / sin_theta

    def _from_pi(self, spline: CubicSpline, x: float) -> float:
        """``C(π + x)``, x ≥ 0: the polynomial of the interval at π in ``dx = x`` exactly."""
        m = len(self.theta_deg) - 1
        if x <= spline.x[m + 1] - spline.x[m]:
            c = spline.c[:, m]
            return float(((c[0] * x + c[1]) * x + c[2]) * x + c[3])
        return float(spline(spline.x[m] + x))


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


class WindSurface(Protocol):
    """What :func:`wind_wrench` reads of a ``<rt70:wind>`` (:class:`rt70.urdf.Wind`)."""

    link: str
    xyz: np.ndarray
    axis: np.ndarray
    area: float
    length: float
    table: CoefficientTable


def body_load(
    table: CoefficientTable, axis: np.ndarray, flow: np.ndarray, force_scale: float, length: float
) -> tuple[np.ndarray, np.ndarray]:
    """``(F, M)`` of the axisymmetric model, in the axes ``axis`` and ``flow`` are given in.

    ``F = qS[−C_A a + (C_N/sinθ)(u − (u·a)a)]``, ``M = qSl (C_M/sinθ) (u × a)`` with
    ``cos θ = −u·a``, ``sin θ = |u × a|`` (θ the angle of attack, 0 when the flow
    meets the body head on).

    Parameters
    ----------
    table : CoefficientTable
        ``C_A(θ)``, ``C_N(θ)``, ``C_M(θ)`` of the body's shape.
    axis : ndarray, shape (3,)
        The unit body (symmetry) axis a.
    flow : ndarray, shape (3,)
        The unit flow direction u, in the same axes as ``axis``.
    force_scale : float
        ``q S``, N: the dynamic pressure ``½ ρ |v|²`` (Pa) times the reference area (m²).
    length : float
        The reference length l of the moment, m.

    Returns
    -------
    tuple of ndarray, shape (3,)
        The force F (N) and the free moment M (N·m), in those axes.
    """
    a, u = axis, flow
    cross = np.cross(u, a)
    cos_theta = -float(u @ a)
    sin_theta = float(np.linalg.norm(cross))
    c_a, n_ratio, m_ratio = table.ratios(cos_theta, sin_theta)
    force = force_scale * (-c_a * a + n_ratio * (u + cos_theta * a))
    torque = (force_scale * length * m_ratio) * cross
    return force, torque


def wind_wrench(
    surface: WindSurface, pose: Pose, condition: WindCondition, density: float
) -> Wrench:
    """The wind's Wrench on one exposed body at the link pose ``(R, p)`` (4.132)–(4.136).

    The flow in body axes ``v_i = Rᵀ v0`` (4.132) gives ``u`` and ``q = ½ ρ |v|²``
    (ρ the condition's, else ``density``); :func:`body_load` gives F and M in body axes,
    turned back to ground axes by R. F acts at ``surface.xyz``; M is a free moment. A
    uniform flow does not depend on the origin p (kept for a sheared profile).

    Parameters
    ----------
    surface : WindSurface
        The exposed body (a ``<rt70:wind>``): its link, reference point ``xyz`` (link
        frame, m), unit axis, area (m²), length (m) and coefficient table.
    pose : Pose
        The link's pose in ground axes: rotation R, shape (3, 3), and origin p,
        shape (3,), m.
    condition : WindCondition
        The steady wind: speed (m/s), direction and, optionally, the air density.
    density : float
        The scene's air density ρ, kg/m³, used when ``condition`` gives none.

    Returns
    -------
    Wrench
        On ``surface.link`` at ``surface.xyz``: force (N) and moment (N·m) in ground
        axes (zero in still air).
    """
    R = np.asarray(pose[0], dtype=float)
    v = R.T @ condition.velocity()
    speed = float(np.linalg.norm(v))
    if speed == 0.0:
        return Wrench(surface.link, tuple(surface.xyz))
    rho = condition.air_density(density)
    force_scale = 0.5 * rho * speed * speed * surface.area
    force, torque = body_load(
        surface.table, np.asarray(surface.axis, dtype=float), v / speed, force_scale, surface.length
    )
    return Wrench(surface.link, tuple(surface.xyz), tuple(R @ force), tuple(R @ torque))
