"""Natural frequencies of uniform beams from beam theory: the answers beams are checked on.

One job: the exact bending frequencies of a uniform member, clamped–free (cantilever) or
free–free, for three theories —

- **Euler–Bernoulli**: ``f_k = (β_k L)² / (2π L²) · sqrt(EI / ρA)`` with ``β_k L`` the
  roots of ``cos βL cosh βL = −1`` (cantilever) or ``= +1`` (free–free), found here by
  bracketing rather than typed in (1.8751, 4.6941, 7.8548; 4.7300, 7.8532, 10.9956);
- **Rayleigh** (Euler–Bernoulli with the sections' rotary inertia ρI) and
- **Timoshenko** (rotary inertia and shear deformation, shear stiffness ``κGA = G A_s``),

the last two as the zeros of the boundary determinant of the exact solution: the
harmonic equations are a linear system ``y' = 𝒜(ω) y`` with constant coefficients, so
``y(L) = exp(𝒜 L) y(0)``, and ω is a natural frequency where the two end conditions at
``x = L`` have a non-zero solution for the two unknowns left free at ``x = 0``.

Timoshenko (Timoshenko 1921; Han, Benaroya & Wei, J. Sound Vib. 225(5), 1999, eqs. for
the cantilever), with ``W`` the deflection and ``Ψ`` the section's rotation::

    ρA ω² W + G A_s (W'' − Ψ') = 0,     ρI ω² Ψ + EI Ψ'' + G A_s (W' − Ψ) = 0,

moment ``EI Ψ'``, shear force ``G A_s (W' − Ψ)``; state ``y = [W, W', Ψ, Ψ']``.
Rayleigh: ``EI W'''' + ρI ω² W'' − ρA ω² W = 0``, moment ``EI W''``, shear force
``EI W''' + ρI ω² W'``; state ``y = [W, W', W'', W''']``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg
import scipy.optimize

#: Supports the frequencies are given for.
SUPPORTS = ("cantilever", "free-free", "pinned-pinned")


@dataclass(frozen=True)
class UniformBeam:
    """A uniform member bending in one principal plane.

    Attributes
    ----------
    length : float
        L, m.
    EI : float
        Bending stiffness, N·m².
    rhoA : float
        Mass per length, kg/m.
    rhoI : float
        Rotary inertia per length ``ρ I``, kg·m (0: none, Euler–Bernoulli or a pure
        shear beam).
    GAs : float or None
        Shear stiffness ``G A_s``, N (None: the section does not shear).
    """

    length: float
    EI: float
    rhoA: float
    rhoI: float = 0.0
    GAs: float | None = None

    def euler_bernoulli(self, support: str, count: int = 3) -> np.ndarray:
        """The first ``count`` Euler–Bernoulli frequencies, Hz (rotary inertia and shear aside)."""
        roots = euler_bernoulli_roots(support, count)
        return roots**2 / (2 * np.pi * self.length**2) * np.sqrt(self.EI / self.rhoA)

    def frequencies(self, support: str, count: int = 3) -> np.ndarray:
        """The first ``count`` natural frequencies of this beam's theory, Hz.

        Rayleigh when :attr:`GAs` is None, Timoshenko otherwise; Euler–Bernoulli's
        closed form when both rotary inertia and shear are absent.
        """
        _check_support(support)
        if self.rhoI == 0.0 and self.GAs is None:
            return self.euler_bernoulli(support, count)
        guess = self.euler_bernoulli(support, count + 2) * 2 * np.pi
        det = lambda w: _boundary_determinant(self, support, w)  # noqa: E731
        found: list[float] = []
        grid = np.linspace(1e-3 * guess[0], 1.05 * guess[-1], 4000)
        values = [det(w) for w in grid]
        for a, b, fa, fb in zip(grid[:-1], grid[1:], values[:-1], values[1:], strict=True):
            if np.sign(fa) != np.sign(fb):
                found.append(scipy.optimize.brentq(det, a, b, xtol=1e-14 * b, rtol=1e-15))
            if len(found) == count:
                break
        if len(found) < count:
            raise ValueError(f"found {len(found)} of {count} frequencies below {grid[-1]:g} rad/s")
        return np.array(found) / (2 * np.pi)


def euler_bernoulli_roots(support: str, count: int = 3) -> np.ndarray:
    """``β_k L``: roots of ``cos x cosh x = −1`` (cantilever), ``+1`` (free–free); kπ (pinned).

    Each root lies within ``π/2`` of ``(k − ½)π`` (cantilever) or ``(k + ½)π`` (free–free),
    where the equation written as ``cos x + sign / cosh x`` changes sign.
    """
    _check_support(support)
    if support == "pinned-pinned":
        return np.arange(1, count + 1) * np.pi
    sign = 1.0 if support == "cantilever" else -1.0
    shift = -0.5 if support == "cantilever" else 0.5
    f = lambda x: np.cos(x) + sign / np.cosh(x)  # noqa: E731
    centres = (np.arange(1, count + 1) + shift) * np.pi
    return np.array([scipy.optimize.brentq(f, c - 1.2, c + 1.2, xtol=1e-15) for c in centres])


def _check_support(support: str) -> None:
    if support not in SUPPORTS:
        raise ValueError(f"support {support!r} is not one of {', '.join(SUPPORTS)}")


def _boundary_determinant(beam: UniformBeam, support: str, omega: float) -> float:
    """The determinant whose zeros are the natural frequencies (module docstring).

    The solution is written in bounded functions so the determinant stays well scaled
    however stiff the shear: ``W = e^{λx}`` solves the equations where ``s = λ²`` is a root
    of ``EI s² + (ρIω² + ρAω² EI/GA_s) s + ρAω²/GA_s (ρIω² − GA_s) = 0`` (Timoshenko) or
    ``EI s² + ρIω² s − ρAω² = 0`` (Rayleigh); a positive root gives ``e^{−ax}`` and
    ``e^{a(x−L)}``, a negative one ``cos bx`` and ``sin bx``. Each column (a function's
    state at both ends) is scaled to unit size, which changes no sign.
    """
    w2 = omega**2
    if beam.GAs is None:
        roots = np.roots([beam.EI, beam.rhoI * w2, -beam.rhoA * w2])
        shear = None
        # y = [W, W', W'', W''']: moment EI W'', shear force EI W''' + ρIω² W'
        free = np.array([[0.0, 0.0, 1.0, 0.0], [0.0, beam.rhoI * w2 / beam.EI, 0.0, 1.0]])
        clamped = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0]])
        pinned = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]])
    else:
        shear = beam.rhoA * w2 / beam.GAs
        middle = beam.rhoI * w2 + shear * beam.EI
        roots = np.roots([beam.EI, middle, shear * (beam.rhoI * w2 - beam.GAs)])
        # y = [W, W', Ψ, Ψ']: moment EI Ψ', shear force G A_s (W' − Ψ)
        free = np.array([[0.0, 0.0, 0.0, 1.0], [0.0, 1.0, -1.0, 0.0]])
        clamped = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]])
        pinned = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]])
    columns = []
    for root in sorted(np.real(roots), reverse=True):
        for at0, at_end in _functions(float(root), beam.length, shear):
            column = np.concatenate([at0, at_end])
            columns.append(column / np.abs(column).max())
    both = np.array(columns).T
    start, end = {"cantilever": (clamped, free), "free-free": (free, free)}.get(
        support, (pinned, pinned)
    )
    return float(np.linalg.det(np.vstack([start @ both[:4], end @ both[4:]])))


def _functions(s: float, length: float, shear: float | None) -> list:
    """The two solutions for ``λ² = s``: their states ``y`` at ``x = 0`` and ``x = L``.

    ``shear`` is ``ρAω²/GA_s`` (Timoshenko, ``y = [W, W', Ψ, Ψ']`` with
    ``Ψ' = W'' + shear · W``) or None (Rayleigh, ``y = [W, W', W'', W''']``).
    """
    if s > 0.0:
        a = np.sqrt(s)
        decay = np.exp(-a * length)
        return [  # e^{−ax} and e^{a(x−L)}: their values at 0 and at L
            (_state_exp(-a, 1.0, shear), _state_exp(-a, decay, shear)),
            (_state_exp(a, decay, shear), _state_exp(a, 1.0, shear)),
        ]
    b = np.sqrt(-s)
    c, sn = np.cos(b * length), np.sin(b * length)
    return [  # cos bx and sin bx: (W, W'/b) at 0 and at L
        (_state_trig(b, 1.0, 0.0, shear), _state_trig(b, c, -sn, shear)),
        (_state_trig(b, 0.0, 1.0, shear), _state_trig(b, sn, c, shear)),
    ]


def _state_exp(lam: float, f: float, shear: float | None) -> np.ndarray:
    """``y`` where ``W = f`` and ``W' = λ f`` (an exponential of rate λ)."""
    if shear is None:
        return f * np.array([1.0, lam, lam**2, lam**3])
    psi_rate = lam**2 + shear  # Ψ' = W'' + shear W
    return f * np.array([1.0, lam, psi_rate / lam, psi_rate])


def _state_trig(b: float, w: float, slope_b: float, shear: float | None) -> np.ndarray:
    """``y`` of a solution ``W`` of ``W'' = −b² W`` where ``W = w`` and ``W'/b = slope_b``."""
    slope = b * slope_b
    if shear is None:
        return np.array([w, slope, -(b**2) * w, -(b**2) * slope])
    factor = (shear - b**2) / b**2  # Ψ' = (shear − b²) W, so Ψ = −factor · W'
    return np.array([w, slope, -factor * slope, factor * b**2 * w])
