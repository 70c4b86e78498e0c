"""Wind gusts: the Davenport spectrum, its shaping filter, and exact realisations.

The longitudinal gust v′ (m/s, along the mean wind) has Davenport's (1961) one-sided
spectrum in Hz (:func:`davenport_spectrum`)::

    n·S_u(n) = 4 κ U² x² / (1 + x²)^(4/3),   x = L n / U,

with L = 1200 m and the surface drag coefficient κ = 0.005 (open country): Davenport,
A. G. (1961), "The spectrum of horizontal gustiness near the ground in high winds",
Q. J. R. Meteorol. Soc. 87:194–211; reproduced in Simiu & Scanlan, *Wind Effects on
Structures* (3rd ed., 1996). Its variance is exactly ``σ_u² = 6 κ U²`` (σ_u/U = 0.173
for κ = 0.005): ``∫ 4x/(1 + x²)^(4/3) dx = 6`` over x > 0.

Simplifications, as documented in docs/wind-gusts.md: U is the mean wind at the
antenna, taken as Davenport's reference speed (no height profile); the gust is coherent
over the whole structure (one v′ for every exposed body) — conservative. Gawronski's
DSN gust model made the same coherent assumption (and found azimuth errors in front and
back winds underestimated).

The spectrum is self-similar: ``S_u(n) = κ U L · g(x)`` with ``g(x) = 4x/(1+x²)^(4/3)``
universal. One rational filter H₀ of order 4 (a zero at s = 0, since S_u(0) = 0) is
fitted once, in dimensionless time τ = t U/L, so that ``2|H₀(j2πx)|² ≈ g(x)``
(:func:`fit_dimensionless_filter`, constants :data:`FILTER_GAIN`, :data:`FILTER_ZEROS`,
:data:`FILTER_POLES`). For a wind U and scale L the filter is
``H(s) = √(κ U L) · H₀(s L/U)``; with ``a = U/L`` its state space is
``(a A₀, √a B₀, √κ U C₀)``, whose stationary state covariance is H₀'s, independent of U
(:class:`GustFilter`). Driven by unit-intensity white noise w, ``E[w(t)w(s)] = δ(t−s)``,
its output has the one-sided spectrum ``2|H(j2πn)|² ≈ S_u(n)``.

:func:`realise` samples the continuous process exactly (Van Loan's discretisation, the
initial state drawn from the stationary covariance) with a reproducible seed; the
:class:`GustSeries` it returns interpolates linearly between samples, as
``scipy.signal.lsim`` and python-control's ``forced_response`` do; its
:meth:`~GustSeries.smooth` form (:class:`SmoothGust`) is the C² cubic spline through
the same samples, which a nonlinear simulation integrates without a kink per sample.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np
import scipy.linalg
import scipy.optimize
import scipy.signal

from rt70.errors import Rt70Error
from rt70.linear.covariance import _no_feedthrough, _system, state_covariance
from rt70.physics.cubic_pieces import CubicPieces, horner

#: Davenport's surface drag coefficient κ for open country (referred to U).
DAVENPORT_KAPPA = 0.005
#: Davenport's length scale L (m).
DAVENPORT_LENGTH = 1200.0

#: The dimensionless shaping filter ``H₀(s) = K s (s + z₁)(s + z₂) / Π(s + p_j)`` in
#: dimensionless time τ = t U/L (s in rad per unit τ), fitted by
#: :func:`fit_dimensionless_filter` (the test tests/test_gusts.py refits it).
FILTER_GAIN = 25.01568100852877
FILTER_ZEROS = (0.15713243024608245, 360.5780042373111)
FILTER_POLES = (0.02445067619349725, 0.9750404521588651, 15.407499275077594, 666.9602898310475)

#: The fit's range of x = L n/U and its number of log-spaced points.
FIT_RANGE = (1e-3, 1e3)
FIT_POINTS = 601


def davenport_spectrum(
    n_hz: float | np.ndarray,
    speed: float,
    kappa: float = DAVENPORT_KAPPA,
    length: float = DAVENPORT_LENGTH,
) -> np.ndarray:
    """Davenport's one-sided longitudinal gust spectrum S_u(n), (m/s)²/Hz.

    ``n S_u(n) = 4 κ U² x² / (1 + x²)^(4/3)``, ``x = L n/U`` (Davenport 1961; Simiu &
    Scanlan 1996). Its integral over n > 0 is ``6 κ U²``.

    Parameters
    ----------
    n_hz : float or ndarray
        Frequencies (Hz), ≥ 0 (S_u(0) = 0).
    speed : float
        Mean wind speed U (m/s), > 0.
    kappa : float
        Surface drag coefficient κ.
    length : float
        Length scale L (m).

    Returns
    -------
    ndarray
        S_u(n) in (m/s)²/Hz, the shape of ``n_hz``.
    """
    _check_wind(speed, kappa, length)
    x = length * _frequencies(n_hz) / speed
    return kappa * speed * length * 4.0 * x / (1.0 + x**2) ** (4.0 / 3.0)


def _frequencies(n_hz: float | np.ndarray) -> np.ndarray:
    n = np.asarray(n_hz, dtype=float)
    if not np.all(np.isfinite(n)) or np.any(n < 0):
        raise Rt70Error("gust spectrum: frequencies must be finite and ≥ 0 Hz")
    return n


def _check_wind(speed: float, kappa: float, length: float) -> None:
    for name, value in (("wind speed", speed), ("kappa", kappa), ("length scale", length)):
        number = isinstance(value, int | float | np.floating | np.integer)
        if isinstance(value, bool) or not (number and np.isfinite(value)):
            raise Rt70Error(f"gusts: {name} must be a finite number, got {value!r}")
        if value <= 0:
            raise Rt70Error(f"gusts: {name} must be positive, got {value}")


def _cascade(gain: float, zeros: tuple[float, ...], poles: tuple[float, ...]):
    """``K s Π(s + z_i) / Π(s + p_j)`` as a cascade of first-order sections (A, B, C).

    Sections in order: ``1/(s + p₁)``, ``s/(s + p₂)``, ``(s + z_i)/(s + p_{i+2})``; A is
    lower triangular with −p on its diagonal, so the realisation stays well conditioned
    over the six decades the poles span (a companion form would not).
    """
    n = len(poles)
    sections = [(None, poles[0]), (0.0, poles[1])] + list(zip(zeros, poles[2:], strict=True))
    A = np.zeros((n, n))
    B = np.zeros((n, 1))
    row, direct = np.zeros(n), 1.0  # the signal entering the section: row·x + direct·w
    for i, (zero, pole) in enumerate(sections):
        A[i] = row
        A[i, i] = -pole
        B[i, 0] = direct
        unit = np.eye(n)[i]
        if zero is None:  # 1/(s + p): y = x_i
            row, direct = unit, 0.0
        else:  # (s + z)/(s + p) = 1 + (z − p)/(s + p)
            row, direct = row + (zero - pole) * unit, direct
    return A, B, gain * row.reshape(1, -1)


def _dimensionless_response(params: np.ndarray, x: np.ndarray, nz: int) -> np.ndarray:
    """``2|H₀(j2πx)|²`` for log-parameters ``[ln K, ln z…, ln p…]``."""
    s = 2j * np.pi * x
    k, z, p = np.exp(params[0]), np.exp(params[1 : 1 + nz]), np.exp(params[1 + nz :])
    h = k * s * np.prod(s[None] + z[:, None], axis=0) / np.prod(s[None] + p[:, None], axis=0)
    return 2.0 * np.abs(h) ** 2


def dimensionless_spectrum(x: float | np.ndarray) -> np.ndarray:
    """``g(x) = 4x/(1 + x²)^(4/3)``: ``S_u(n) = κ U L g(L n/U)`` (per unit x)."""
    x = np.asarray(x, dtype=float)
    return 4.0 * x / (1.0 + x**2) ** (4.0 / 3.0)


def fit_dimensionless_filter() -> tuple[float, tuple[float, ...], tuple[float, ...], float]:
    """Fit H₀ (order 4, a zero at 0) to g(x) in log magnitude over :data:`FIT_RANGE`.

    Least squares (``scipy.optimize.least_squares``, Levenberg–Marquardt) of
    ``log10(2|H₀(j2πx)|²) − log10 g(x)`` at :data:`FIT_POINTS` log-spaced x, over the
    logarithms of the gain, the two finite zeros and the four poles (so the filter is
    stable and minimum phase by construction), from poles a decade apart at
    ``2π·10^{−2.5…2.5}`` and zeros between them.

    Returns
    -------
    gain, zeros, poles, cost
        The constants stored as :data:`FILTER_GAIN`, :data:`FILTER_ZEROS`,
        :data:`FILTER_POLES` (sorted), and the least-squares cost ``½ Σ r²``.
    """
    x = np.logspace(np.log10(FIT_RANGE[0]), np.log10(FIT_RANGE[1]), FIT_POINTS)
    target = np.log10(dimensionless_spectrum(x))
    poles0 = 2 * np.pi * np.logspace(-2.5, 2.5, 4)
    zeros0 = np.sqrt(poles0[1:3] * poles0[2:4])
    start = np.concatenate([[0.0], np.log(zeros0), np.log(poles0)])
    result = scipy.optimize.least_squares(
        lambda p: np.log10(_dimensionless_response(p, x, 2)) - target,
        start,
        method="lm",
        xtol=1e-14,
        ftol=1e-14,
    )
    if not result.success:  # pragma: no cover - the fit is deterministic
        raise Rt70Error(f"gust filter fit failed: {result.message}")
    zeros = tuple(float(z) for z in np.sort(np.exp(result.x[1:3])))
    poles = tuple(float(p) for p in np.sort(np.exp(result.x[3:])))
    return float(np.exp(result.x[0])), zeros, poles, float(result.cost)


def filter_fit_errors(
    x_range: tuple[float, float] = (1e-2, 1e2), points: int = 401
) -> tuple[float, float]:
    """The stored filter's fit errors.

    Returns
    -------
    max_log10_ratio : float
        ``max |log10(2|H₀(j2πx)|² / g(x))|`` over log-spaced x in ``x_range``.
    variance_error : float
        ``(σ²_filter − 6)/6``: the filter's Lyapunov variance vs the spectrum's exact
        variance (dimensionless, κ = U = L = 1).
    """
    x = np.logspace(np.log10(x_range[0]), np.log10(x_range[1]), points)
    params = np.log([FILTER_GAIN, *FILTER_ZEROS, *FILTER_POLES])
    ratio = _dimensionless_response(params, x, 2) / dimensionless_spectrum(x)
    variance = GustFilter(1.0, kappa=1.0, length=1.0).variance()
    return float(np.max(np.abs(np.log10(ratio)))), (variance - 6.0) / 6.0


@dataclass(frozen=True)
class GustFilter:
    """The shaping filter of Davenport gusts at a mean wind U.

    Driven by unit-intensity white noise w (``E[w(t)w(s)] = δ(t−s)``), its output v′
    (m/s) has the one-sided spectrum ``2|H(j2πn)|² ≈ S_u(n)``
    (:func:`davenport_spectrum`); ``H(s) = √(κ U L) H₀(s L/U)``, state space
    ``(a A₀, √a B₀, √κ U C₀)``, ``a = U/L``, strictly proper and stable.

    Attributes
    ----------
    speed : float
        Mean wind U (m/s).
    kappa, length : float
        Davenport's κ and L (m).
    input_name, output_name : str
        Names of the white-noise input and of the gust output of :attr:`system`.
    """

    speed: float
    kappa: float = DAVENPORT_KAPPA
    length: float = DAVENPORT_LENGTH
    input_name: str = "w"
    output_name: str = "v"

    def __post_init__(self) -> None:
        _check_wind(self.speed, self.kappa, self.length)

    def matrices(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(A, B, C)`` of the filter at this wind (D = 0)."""
        A0, B0, C0 = _cascade(FILTER_GAIN, FILTER_ZEROS, FILTER_POLES)
        a = self.speed / self.length
        return a * A0, np.sqrt(a) * B0, np.sqrt(self.kappa) * self.speed * C0

    @property
    def system(self):
        """The filter as a python-control ``StateSpace`` (named input, output, states)."""
        import control

        A, B, C = self.matrices()
        return control.ss(
            A,
            B,
            C,
            np.zeros((1, 1)),
            inputs=[self.input_name],
            outputs=[self.output_name],
            states=[f"gust{i + 1}" for i in range(A.shape[0])],
        )

    def spectrum(self, n_hz: float | np.ndarray) -> np.ndarray:
        """The filter's one-sided output spectrum ``2|H(j2πn)|²`` ((m/s)²/Hz)."""
        n = _frequencies(n_hz)
        params = np.log([FILTER_GAIN, *FILTER_ZEROS, *FILTER_POLES])
        x = (self.length * n / self.speed).ravel()
        response = _dimensionless_response(params, x, 2).reshape(n.shape)
        return self.kappa * self.speed * self.length * response

    def variance(self) -> float:
        """The output's stationary variance ``C P Cᵀ`` (Lyapunov), (m/s)²."""
        A, B, C = self.matrices()
        return float((C @ state_covariance((A, B, C)) @ C.T)[0, 0])


class GustSeries(NamedTuple):
    """A realised gust record: sample times t (s) and values v (m/s; one column per output).

    Calling it, ``series(t)``, interpolates linearly between the samples — what a
    nonlinear simulation's wind force reads, and what ``scipy.signal.lsim`` and
    python-control's ``forced_response`` assume between input samples. Times outside
    the record raise :class:`~rt70.errors.Rt70Error` (no silent extrapolation).
    """

    t: np.ndarray
    v: np.ndarray

    def __call__(self, time: float | np.ndarray) -> np.ndarray:
        """The gust at ``time`` (scalar or array), linearly interpolated."""
        time = np.asarray(time, dtype=float)
        span = self.t[-1] - self.t[0]
        slack = 1e-9 * max(span, 1.0)
        if not np.all(np.isfinite(time)) or np.any(
            (time < self.t[0] - slack) | (time > self.t[-1] + slack)
        ):
            raise Rt70Error(
                f"gust series: time outside the record [{self.t[0]:g}, {self.t[-1]:g}] s"
            )
        if self.v.ndim == 1:
            return np.interp(time, self.t, self.v)
        return np.stack([np.interp(time, self.t, col) for col in self.v.T], axis=-1)

    def smooth(self) -> SmoothGust:
        """The C² cubic spline through the samples (:class:`SmoothGust`)."""
        return SmoothGust(self)


class SmoothGust:
    """A gust record read through the C² cubic spline of its samples (not-a-knot ends).

    What a nonlinear simulation's wind force reads (:mod:`rt70.telescope.gust_run`): the
    linear interpolant of :class:`GustSeries` kinks at every sample, and an implicit
    integrator steps through each kink with a short step and a low order, while the
    spline's third derivative alone jumps there. Both pass through the exact samples;
    they differ between them by what the samples do not determine (the process above
    their Nyquist frequency). ``gust(t)`` of a scalar evaluates the interval's cubic in
    plain floats (the integrator calls it at every evaluation); times outside the record
    raise :class:`~rt70.errors.Rt70Error`, as :class:`GustSeries`.

    Parameters
    ----------
    series : GustSeries
        The record (at least two samples, times increasing).
    """

    def __init__(self, series: GustSeries) -> None:
        from scipy.interpolate import CubicSpline

        self.series = series
        self.spline = CubicSpline(series.t, series.v, axis=0)
        self._pieces = CubicPieces(series.t, self.spline.c)

    def __call__(self, time: float | np.ndarray) -> float | np.ndarray:
        """The gust at ``time`` (scalar or array), m/s, from the spline."""
        knots = self._pieces.knots
        if isinstance(time, float | int) and knots[0] <= time <= knots[-1]:
            i, dx = self._pieces.locate(time)
            c = self._pieces.pieces[i]
            if self.series.v.ndim == 1:
                return horner(c, dx)
            return np.array([horner(column, dx) for column in c])
        self.series(time)  # its range check
        return self.spline(np.asarray(time, dtype=float))


def _factor(S: np.ndarray) -> np.ndarray:
    """L with ``L Lᵀ = S`` for a symmetric positive semi-definite S (rounding clipped)."""
    w, U = np.linalg.eigh(0.5 * (S + S.T))
    return U * np.sqrt(np.clip(w, 0.0, None))


def discretise(A: np.ndarray, B: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Exact sampling of ``ẋ = A x + B w`` (unit white noise) at the interval dt.

    Van Loan (1978): ``expm([[−A, B Bᵀ], [0, Aᵀ]] h) = [[·, F₁₂], [0, F₂₂]]`` gives
    ``Φ(h) = F₂₂ᵀ = e^{A h}`` and ``Q(h) = Φ F₁₂ = ∫₀^h e^{As} B Bᵀ e^{Aᵀs} ds``. Its
    block ``e^{−A h}`` grows like ``e^{|λ|h}`` for a fast stable pole and ``Φ F₁₂`` then
    cancels catastrophically (at ``|λ|·h ≈ 300`` the result is garbage), so Van Loan's formula
    is applied at ``h = dt/2^k`` with ``‖A‖₁ h ≤ 1/2`` and doubled k times:
    ``Q(2h) = Q(h) + Φ(h) Q(h) Φ(h)ᵀ``, ``Φ(2h) = Φ(h)²`` (sums of positive
    semi-definite terms, no cancellation). Then ``x_{k+1} = Φ x_k + e_k``,
    ``e_k ~ N(0, Q_d)`` independent, with ``Q_d = Q(dt)`` and ``Φ = e^{A dt}``
    (``scipy.linalg.expm`` at dt).

    Parameters
    ----------
    A : ndarray, shape (n, n)
        The continuous system's matrix, 1/s.
    B : ndarray, shape (n, m)
        Its input matrix for m unit white noises.
    dt : float
        The sampling interval, s.

    Returns
    -------
    Phi, Qd : ndarray
        The transition matrix ``e^{A dt}`` and the covariance of the sampled noise, both
        (n, n).
    """
    n = A.shape[0]
    norm = np.linalg.norm(A, 1) * dt
    doublings = int(np.ceil(np.log2(norm / 0.5))) if norm > 0.5 else 0
    h = dt / 2**doublings
    M = np.block([[-A, B @ B.T], [np.zeros((n, n)), A.T]]) * h
    F = scipy.linalg.expm(M)
    Phi = F[n:, n:].T
    Qd = Phi @ F[:n, n:]
    for _ in range(doublings):
        Qd = Qd + Phi @ Qd @ Phi.T
        Phi = Phi @ Phi
    return scipy.linalg.expm(A * dt), 0.5 * (Qd + Qd.T)


def _propagate(Phi: np.ndarray, x0: np.ndarray, e: np.ndarray) -> np.ndarray:
    """States ``x_0 … x_N`` of ``x_{k+1} = Φ x_k + e_k`` (rows).

    In modal coordinates ``z = V⁻¹ x`` each mode is a first-order recursion that
    ``scipy.signal.lfilter`` runs in compiled code; a (nearly) defective Φ is stepped
    through by :func:`_propagate_steps` instead.
    """
    lam, V = np.linalg.eig(Phi)
    if not np.linalg.cond(V) < 1e8:
        return _propagate_steps(Phi, x0, e)
    Vinv = np.linalg.inv(V)
    z0, u = Vinv @ x0, e @ Vinv.T
    z = np.empty((len(e) + 1, len(x0)), dtype=complex)
    z[0] = z0
    for k, lk in enumerate(lam):
        z[1:, k] = scipy.signal.lfilter([1.0], [1.0, -lk], u[:, k], zi=[lk * z0[k]])[0]
    return np.real(z @ V.T)


def _propagate_steps(Phi: np.ndarray, x0: np.ndarray, e: np.ndarray) -> np.ndarray:
    """:func:`_propagate` one step at a time (any Φ; slow for long records)."""
    x = np.empty((len(e) + 1, len(x0)))
    x[0] = x0
    for k, ek in enumerate(e):
        x[k + 1] = Phi @ x[k] + ek
    return x


def realise(filter: Any, t_end: float, dt: float, seed: int) -> GustSeries:
    """A stationary realisation of a shaping filter's output, sampled exactly.

    Parameters
    ----------
    filter : GustFilter, control.StateSpace or tuple (A, B, C)
        A stable, strictly proper filter driven by unit-intensity white noise on each
        input (independent).
    t_end : float
        Length of the record (s); samples at ``0, dt, …`` up to ``t_end``.
    dt : float
        Sampling interval (s). The samples are exact for any dt (no discretisation
        error); the interpolation between them is linear.
    seed : int
        Seed of ``numpy.random.Generator(PCG64(seed))``: the same seed gives the same
        record. Draw order: the initial state, then the increments.

    Returns
    -------
    GustSeries
        ``(t, v)``; v is 1-D for a single-output filter, else one column per output.

    Notes
    -----
    ``x₀ ~ N(0, P)`` with P the stationary covariance (so the series is stationary from
    t = 0), ``x_{k+1} = Φ x_k + e_k`` with Φ and Q_d from :func:`discretise`; the
    recursion runs per mode (``scipy.signal.lfilter``) when Φ's eigenvectors are well
    conditioned, else step by step.
    """
    s = _system(filter.matrices() if isinstance(filter, GustFilter) else filter)
    _no_feedthrough(s)
    for name, value in (("t_end", t_end), ("dt", dt)):
        if not (isinstance(value, int | float | np.floating | np.integer) and np.isfinite(value)):
            raise Rt70Error(f"realise: {name} must be a finite number, got {value!r}")
    if dt <= 0 or t_end <= 0 or dt > t_end:
        raise Rt70Error(f"realise: need 0 < dt ≤ t_end, got dt = {dt}, t_end = {t_end}")
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer) or seed < 0:
        raise Rt70Error(f"realise: seed must be a non-negative integer, got {seed!r}")
    P = state_covariance((s.A, s.B, s.C))
    Phi, Qd = discretise(s.A, s.B, dt)
    steps = int(np.floor(t_end / dt * (1 + 1e-12)))
    rng = np.random.Generator(np.random.PCG64(int(seed)))
    n = s.A.shape[0]
    x0 = _factor(P) @ rng.standard_normal(n)
    e = rng.standard_normal((steps, n)) @ _factor(Qd).T
    x = _propagate(Phi, x0, e)
    v = x @ s.C.T
    return GustSeries(np.arange(steps + 1) * dt, v[:, 0] if v.shape[1] == 1 else v)
