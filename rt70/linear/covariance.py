"""Stationary covariances of linear systems driven by white noise (the covariance route).

A stable system ``ẋ = A x + B w``, ``y = C x`` driven by white noise of intensity W,
``E[w(t) w(s)ᵀ] = W δ(t − s)``, has the stationary state covariance P of the Lyapunov
equation ``A P + P Aᵀ + B W Bᵀ = 0`` and output covariance ``C P Cᵀ`` — the same
number as the frequency-domain integral ``(1/2π) ∫ G(jω) W G(jω)ᴴ dω`` without a
frequency grid. This module gives:

- :func:`state_covariance` and :func:`output_covariance` (the Lyapunov route);
- :func:`cascade_with_filter`: a shaping filter (e.g. :class:`rt70.wind.gusts.GustFilter`)
  in series with one named input of a plant, so that the plant's outputs are driven by
  coloured noise through an augmented system driven by white noise;
- :func:`mode_contributions`: one output's variance split over the modes of the
  (augmented) system, for "which mode causes it";
- :func:`sample_variance_error`: the standard deviation of the mean square of a
  finite record, the statistical error to state when a simulation's rms is compared with
  the Lyapunov rms.

The functions take a python-control ``StateSpace`` (rt70's plants are ones) or a tuple
``(A, B, C)`` / ``(A, B, C, D)``.
See docs/wind-gusts.md for the formulas and the checks.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.linalg

from rt70.errors import Rt70Error
from rt70.linear.checks import _matrix, _square
from rt70.linear.state_space import StateSpace

#: Largest condition number of the eigenvector matrix V for which :func:`mode_contributions`
#: splits a variance over modes (beyond it A is numerically defective and the split is noise).
MAX_EIGENVECTOR_CONDITION = 1e10


def _labels(sys: Any, attribute: str, count: int, prefix: str) -> tuple[str, ...]:
    labels = getattr(sys, attribute, None)
    if labels is not None:
        return tuple(str(s) for s in labels)
    return tuple(f"{prefix}[{i}]" for i in range(count))


def _system(sys: Any) -> StateSpace:
    """Read ``sys`` (a python-control StateSpace or a tuple of arrays), checked.

    Returned as a :class:`rt70.linear.state_space.StateSpace` (labels included).
    """
    if isinstance(sys, tuple):
        if len(sys) not in (3, 4):
            raise Rt70Error(f"a system tuple is (A, B, C) or (A, B, C, D), got {len(sys)} items")
        A, B, C = sys[:3]
        D = sys[3] if len(sys) == 4 else None
    elif all(hasattr(sys, name) for name in ("A", "B", "C", "D")):
        A, B, C, D = sys.A, sys.B, sys.C, sys.D
    else:
        raise Rt70Error(f"not a state-space system: {type(sys).__name__}")
    A = _square("A", A)
    n = A.shape[0]
    B = _matrix("B", B, (n, None))
    C = _matrix("C", C, (None, n))
    D = (
        np.zeros((C.shape[0], B.shape[1]))
        if D is None
        else _matrix("D", D, (C.shape[0], B.shape[1]))
    )
    return StateSpace(
        A,
        B,
        C,
        D,
        states=_labels(sys, "state_labels", n, "x"),
        inputs=_labels(sys, "input_labels", B.shape[1], "u"),
        outputs=_labels(sys, "output_labels", C.shape[0], "y"),
    )


def _stable(s: StateSpace) -> np.ndarray:
    """The eigenvalues of A, after checking they all have negative real parts."""
    eigenvalues = np.linalg.eigvals(s.A)
    worst = eigenvalues[np.argmax(eigenvalues.real)]
    if worst.real >= 0.0:
        raise Rt70Error(
            f"the system is not asymptotically stable (eigenvalue {worst:.6g}): "
            "its stationary covariance under white noise is infinite"
        )
    return eigenvalues


def _no_feedthrough(s: StateSpace) -> None:
    if np.any(s.D != 0.0):
        raise Rt70Error(
            "the system has a feedthrough D ≠ 0: white noise passed straight to an output "
            "has infinite variance (shape the noise with a strictly proper filter first)"
        )


def _intensity(W: float | np.ndarray, m: int) -> np.ndarray:
    """The noise intensity as an m × m symmetric positive semi-definite matrix."""
    W = np.asarray(W, dtype=float)
    if W.ndim == 0:
        W = float(W) * np.eye(m)
    W = _matrix("W", W, (m, m))
    if np.max(np.abs(W - W.T)) > 1e-12 * max(np.max(np.abs(W)), 1e-300):
        raise Rt70Error("the noise intensity W is not symmetric")
    if m and np.min(np.linalg.eigvalsh(W)) < -1e-12 * max(np.max(np.abs(W)), 1e-300):
        raise Rt70Error("the noise intensity W is not positive semi-definite")
    return 0.5 * (W + W.T)


def _covariance(s: StateSpace, W: float | np.ndarray) -> np.ndarray:
    _stable(s)
    Q = s.B @ _intensity(W, s.B.shape[1]) @ s.B.T
    P = scipy.linalg.solve_continuous_lyapunov(s.A, -Q)
    return 0.5 * (P + P.T)


def state_covariance(sys: Any, W: float | np.ndarray = 1.0) -> np.ndarray:
    """The stationary state covariance P of a stable system driven by white noise.

    Parameters
    ----------
    sys : control.StateSpace or tuple (A, B, C[, D])
        A stable system.
    W : float or ndarray
        Intensity of the white noise on the inputs, ``E[w(t) w(s)ᵀ] = W δ(t − s)``
        (a scalar is ``W·I``).

    Returns
    -------
    ndarray
        P solving ``A P + P Aᵀ + B W Bᵀ = 0`` (symmetric).

    Raises
    ------
    Rt70Error
        If A has an eigenvalue with a non-negative real part, or W is not a symmetric
        positive semi-definite matrix of the input count.
    """
    return _covariance(_system(sys), W)


def output_covariance(sys: Any, W: float | np.ndarray = 1.0) -> np.ndarray:
    """The stationary output covariance ``C P Cᵀ`` of a stable system driven by white noise.

    Parameters
    ----------
    sys : control.StateSpace or tuple (A, B, C[, D])
        A stable, strictly proper system (D = 0).
    W : float or ndarray
        Intensity of the white noise (see :func:`state_covariance`).

    Returns
    -------
    ndarray
        The p × p output covariance; its diagonal holds the output variances.

    Raises
    ------
    Rt70Error
        If D ≠ 0 (infinite variance), or as :func:`state_covariance`.
    """
    s = _system(sys)
    _no_feedthrough(s)
    P = _covariance(s, W)
    Y = s.C @ P @ s.C.T
    return 0.5 * (Y + Y.T)


def _output_row(s: StateSpace, output: str | int) -> tuple[int, str]:
    if isinstance(output, str):
        if output not in s.output_labels:
            raise Rt70Error(f"no output named '{output}' (outputs: {', '.join(s.output_labels)})")
        index = s.output_labels.index(output)
    else:
        index = int(output)
        if not 0 <= index < len(s.output_labels):
            raise Rt70Error(f"output index {output} out of range (0…{len(s.output_labels) - 1})")
    return index, s.output_labels[index]


def cascade_with_filter(
    plant: Any,
    filter: Any,
    input_name: str | Sequence[str],
    gain: float | Sequence[float] = 1.0,
):
    """The series connection shaping filter → the plant's named input(s).

    The filter's single output drives the plant input ``input_name`` (or, coherently,
    every input of a list, times ``gain``: ``u_i = gain_i · v``). The plant's other
    inputs are left at zero and dropped.

    Parameters
    ----------
    plant : control.StateSpace or tuple
        The plant, with named inputs and outputs.
    filter : control.StateSpace or tuple
        The shaping filter (one output), e.g. ``rt70.wind.gusts.GustFilter(...).system``.
    input_name : str or sequence of str
        The plant input(s) the filter output feeds.
    gain : float or sequence of float
        The gain from the filter output to each input (one per input, or one for all).

    Returns
    -------
    control.StateSpace
        States ``[filter states; plant states]`` (named), inputs the filter's inputs,
        outputs the plant's outputs: ``A = [[A_f, 0], [B_p g C_f, A_p]]``,
        ``B = [B_f; B_p g D_f]``, ``C = [D_p g C_f, C_p]``, ``D = D_p g D_f`` with
        ``B_p`` the named columns — the same system as ``control.series`` of the filter
        and the plant's columns, with the names kept.
    """
    import control

    p = _system(plant)
    f = _system(filter)
    if f.C.shape[0] != 1:
        raise Rt70Error(f"the filter must have one output, it has {f.C.shape[0]}")
    names = [input_name] if isinstance(input_name, str) else [str(n) for n in input_name]
    if not names:
        raise Rt70Error("no plant input named for the filter output")
    missing = [n for n in names if n not in p.input_labels]
    if missing:
        raise Rt70Error(
            f"the plant has no input {', '.join(repr(n) for n in missing)} "
            f"(inputs: {', '.join(p.input_labels)})"
        )
    g = np.broadcast_to(np.asarray(gain, dtype=float), (len(names),)).reshape(-1, 1)
    if not np.all(np.isfinite(g)):
        raise Rt70Error("the filter-to-plant gain contains NaN or infinite values")
    Bp = p.B[:, [p.input_labels.index(n) for n in names]] @ g  # n_p × 1
    Dp = p.D[:, [p.input_labels.index(n) for n in names]] @ g  # p_p × 1
    nf, np_ = f.A.shape[0], p.A.shape[0]
    A = np.block([[f.A, np.zeros((nf, np_))], [Bp @ f.C, p.A]])
    B = np.vstack([f.B, Bp @ f.D])
    C = np.hstack([Dp @ f.C, p.C])
    D = Dp @ f.D
    return control.ss(
        A,
        B,
        C,
        D,
        states=[f"filter.{s}" for s in f.state_labels] + [f"plant.{s}" for s in p.state_labels],
        inputs=list(f.input_labels),
        outputs=list(p.output_labels),
    )


@dataclass(frozen=True)
class ModeShare:
    """One mode's part of an output's variance (see :func:`mode_contributions`).

    Attributes
    ----------
    frequency_hz : float
        ``|λ| / 2π`` (Hz, or per time unit of the system).
    damping : float
        ``−Re λ / |λ|`` (1 for a real eigenvalue).
    variance : float
        The mode's contribution to the output variance (may be negative: the cross
        terms with other modes are split between them).
    share : float
        ``variance`` / the output variance; the shares sum to 1.
    eigenvalue : complex
        λ (the one with ``Im λ ≥ 0`` of a complex pair).
    eigenvector : ndarray
        The right eigenvector of λ (state coordinates), for the caller to name the mode.
    """

    frequency_hz: float
    damping: float
    variance: float
    share: float
    eigenvalue: complex
    eigenvector: np.ndarray


def _pairs(eigenvalues: np.ndarray) -> list[list[int]]:
    """Indices grouped into complex-conjugate pairs (the ``Im ≥ 0`` one first) and singles."""
    scale = np.maximum(np.abs(eigenvalues), 1e-300)
    real = np.abs(eigenvalues.imag) <= 1e-9 * scale
    upper = [i for i in range(len(eigenvalues)) if not real[i] and eigenvalues[i].imag > 0]
    lower = [i for i in range(len(eigenvalues)) if not real[i] and eigenvalues[i].imag < 0]
    groups = [[i] for i in np.flatnonzero(real)]
    for i in upper:
        if not lower:
            raise Rt70Error("the eigenvalues of A do not come in complex-conjugate pairs")
        j = min(lower, key=lambda k: abs(eigenvalues[k] - np.conj(eigenvalues[i])))
        lower.remove(j)
        groups.append([i, j])
    if lower:
        raise Rt70Error("the eigenvalues of A do not come in complex-conjugate pairs")
    return groups


def mode_contributions(
    sys: Any, output: str | int | Sequence[str | int], W: float | np.ndarray = 1.0
) -> list[ModeShare]:
    """One output's stationary variance split over the modes of A.

    With ``A = V Λ V⁻¹`` and modal coordinates ``z = V⁻¹ x``, the modal covariance is
    ``P_z = V⁻¹ P V⁻ᴴ`` and ``y = (C V) z``, so ``var y = Σ_k Re[(CV)_k Σ_l P_z,kl
    (CV)_l*]``: term k is mode k's variance plus half of each cross term with another
    mode. A complex-conjugate pair is one mode (its two terms summed). For well-separated,
    lightly damped modes the cross terms are small and each share is that mode's own
    variance; for close modes they are not, and a share may be negative or above 1.

    Parameters
    ----------
    sys : control.StateSpace or tuple
        A stable, strictly proper system (e.g. a plant cascaded with its disturbance
        filter, :func:`cascade_with_filter`), diagonalisable.
    output : str or int, or a sequence of them
        The output (name or index); several outputs (the components of a vector) split
        the sum of their variances, ``E|y|²``.
    W : float or ndarray
        Intensity of the white noise on the inputs.

    Returns
    -------
    list of ModeShare
        One per mode (real eigenvalue or complex pair), by increasing frequency; the
        variances sum to ``output_covariance(sys, W)[i, i]`` (or the trace over the
        outputs) up to rounding.

    Raises
    ------
    Rt70Error
        As :func:`output_covariance`; or if A is numerically defective (the eigenvector
        matrix's condition number exceeds :data:`MAX_EIGENVECTOR_CONDITION`).
    """
    s = _system(sys)
    _no_feedthrough(s)
    outputs = [output] if isinstance(output, str | int | np.integer) else list(output)
    rows = [_output_row(s, o)[0] for o in outputs]
    P = _covariance(s, W)
    eigenvalues, V = scipy.linalg.eig(s.A)
    condition = np.linalg.cond(V)
    if not condition <= MAX_EIGENVECTOR_CONDITION:
        raise Rt70Error(
            f"A is numerically defective (eigenvector condition number {condition:.3g}): "
            "its variance cannot be split over modes"
        )
    Vinv = np.linalg.inv(V)
    Pz = Vinv @ P @ Vinv.conj().T
    terms = np.zeros(len(eigenvalues))
    for row in rows:
        c = s.C[row] @ V
        terms += np.real(c * (Pz @ c.conj()))
    total = float(np.sum(terms))
    if not rows or total <= 0.0:
        names = ", ".join(s.output_labels[r] for r in rows) or "none"
        raise Rt70Error(f"output(s) {names} have zero variance: nothing to split")
    shares = []
    for group in _pairs(eigenvalues):
        lam = eigenvalues[group[0]]
        variance = float(np.sum(terms[group]))
        shares.append(
            ModeShare(
                frequency_hz=float(abs(lam) / (2.0 * np.pi)),
                damping=float(-lam.real / abs(lam)) if lam != 0 else 0.0,
                variance=variance,
                share=variance / total,
                eigenvalue=complex(lam),
                eigenvector=V[:, group[0]].copy(),
            )
        )
    return sorted(shares, key=lambda m: m.frequency_hz)


def sample_variance_error(
    sys: Any,
    output: str | int | Sequence[str | int],
    T: float,
    dt: float | None = None,
    W: float | np.ndarray = 1.0,
) -> float:
    """Standard deviation of the mean square of one output over a finite record.

    For a zero-mean stationary Gaussian output y with autocovariance
    ``R(τ) = C e^{Aτ} P Cᵀ`` (τ ≥ 0), the mean square ``ŝ² = (1/T) ∫₀ᵀ y² dt`` has
    ``Var ŝ² ≈ (2/T) ∫_{−∞}^{∞} R(τ)² dτ = (4/T) ∫₀^∞ R(τ)² dτ`` for a record much
    longer than the correlation time (relative bias of order τ_c/T). The integral is
    ``c X cᵀ`` with X from a second Lyapunov equation ``A X + X Aᵀ + (P cᵀ)(P cᵀ)ᵀ = 0``
    (c the output's row of C), since ``R(τ)² = c e^{Aτ} P cᵀ c P e^{Aᵀτ} cᵀ``.

    For a record of N = T/dt samples ``y_k = y(k dt)`` and ``ŝ² = (1/N) Σ y_k²``,
    ``Var ŝ² ≈ (2/N) Σ_{k=−∞}^{∞} R(k dt)² = (2/N)(2 c X_d cᵀ − R(0)²)`` with
    ``Φ X_d Φᵀ − X_d + (P cᵀ)(P cᵀ)ᵀ = 0``, ``Φ = e^{A dt}`` (the discrete Lyapunov
    equation); it tends to the continuous formula as dt → 0.

    For several outputs (a vector y, e.g. the components of a pointing error) ŝ² is the
    mean of ``|y|² = Σ_i y_i²``: Isserlis' theorem gives
    ``Var ŝ² ≈ (4/T) Σ_ij ∫₀^∞ R_ij(τ)² dτ = (4/T) tr(C X Cᵀ)`` with
    ``A X + X Aᵀ + G Gᵀ = 0``, ``G = P Cᵀ`` (C the outputs' rows); sampled,
    ``(2/N)(2 tr(C X_d Cᵀ) − ‖C P Cᵀ‖²_F)``. One output is the case above.

    Parameters
    ----------
    sys : control.StateSpace or tuple
        A stable, strictly proper system driven by white noise.
    output : str or int, or a sequence of them
        The output (name or index), or the components of a vector output.
    T : float
        Length of the record (for samples, ``T = N·dt``).
    dt : float, optional
        Sampling interval of a sampled record; None for the continuous mean square.
    W : float or ndarray
        Intensity of the white noise on the inputs.

    Returns
    -------
    float
        The standard deviation of ŝ² (output units squared).
    """
    s = _system(sys)
    _no_feedthrough(s)
    outputs = [output] if isinstance(output, str | int | np.integer) else list(output)
    if not outputs:
        raise Rt70Error("no output named for the sample-variance error")
    rows = [_output_row(s, o)[0] for o in outputs]
    if not (np.isfinite(T) and T > 0):
        raise Rt70Error(f"record length T must be positive and finite, got {T}")
    P = _covariance(s, W)
    C = s.C[rows]
    G = P @ C.T
    if dt is None:
        X = scipy.linalg.solve_continuous_lyapunov(s.A, -G @ G.T)
        return float(np.sqrt(max(4.0 * np.trace(C @ X @ C.T) / T, 0.0)))
    if not (np.isfinite(dt) and 0 < dt <= T):
        raise Rt70Error(f"sampling interval dt must be in (0, T], got {dt}")
    Phi = scipy.linalg.expm(s.A * dt)
    X = scipy.linalg.solve_discrete_lyapunov(Phi, G @ G.T)
    r0 = C @ P @ C.T
    value = 2.0 * dt / T * (2.0 * np.trace(C @ X @ C.T) - float(np.sum(r0 * r0)))
    return float(np.sqrt(max(value, 0.0)))
