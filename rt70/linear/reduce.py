"""Reduced plants: modal truncation with static correction, balanced truncation, H∞ error.

A controller (LQG, an observer, a notch set) is designed on a plant of a few states, not
on the 84 of the RT-70's linearisation (:func:`rt70.linear.plant.plant`). This module
reduces a :class:`~rt70.linear.state_space.StateSpace` and measures what the reduction
costs:

- :func:`modal_truncation` keeps the r lowest modes of the second-order model
  ``M q̈ + D q̇ + K q = B u`` in principal coordinates (formalism §2, (2.17)–(2.21))
  and adds the **static correction** of the dropped modes — their residual flexibility
  ``C V_d Ω_d⁻² V_dᵀ B`` as a feedthrough — so that the reduced plant's static gain
  equals the full one's (structural dynamics' "modal truncation with static
  correction", the mode-acceleration method). Rigid and unstable modes are always kept.
- :func:`balanced_truncation` keeps the states of the largest Hankel singular values
  (the square-root method: Cholesky-like factors of the two Gramians, one SVD, no
  inversion of an ill-conditioned balancing transformation). python-control's
  ``balred`` needs slycot, which is not installed, so this is scipy only. A plant with
  rigid or unstable modes (the RT-70 with its axes free) has no Gramians: it is split
  additively ``G = G_u + G_s`` (ordered real Schur form and one Sylvester equation);
  ``G_u`` is kept whole and only the stable part ``G_s`` is balanced and truncated.
  The error then obeys ``σ_{k+1} ≤ ‖G − G_r‖∞ ≤ 2 Σ_{i>k} σ_i`` (Glover 1984; Enns 1984)
  over the stable part's Hankel singular values σ_i.
- :func:`hinf_error` measures ``‖G − G_r‖∞ = max_ω σ_max(G(jω) − G_r(jω))`` on a dense
  logarithmic grid made denser at every lightly damped pole of both plants, its peak
  then refined by a bounded scalar search.

Every function here takes any python-control ``StateSpace``; rt70's plants
(:class:`~rt70.linear.state_space.StateSpace`) also carry their second-order model. A
system without one (built by python-control) is split on its physical ``A``: on the
RT-70 with its axes free the truncation to 12 states is then 3.3e-8 of ‖G‖∞ from the
plant, against 6.2e-9 with the second-order model (tests/test_control_interop.py);
modal truncation needs that model and says so.

Balanced truncation weighs the outputs in their units: give the outputs comparable units
first (:func:`rescaled`: angles in arc seconds and points in mm, say), or the radians
of an axis angle count for nothing against the arc seconds of a pointing correction.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
import scipy.linalg
import scipy.optimize

from rt70.errors import Rt70Error
from rt70.linear import modal
from rt70.linear.responses import frequency_response, state_space
from rt70.linear.state_space import StateSpace, as_state_space, second_order_of

#: A pole λ of a plant without a second-order model is marginal (rigid, kept with the
#: unstable part) when ``|λ|² ≤ MARGINAL_RTOL · max|λ|²``; with one, when
#: ``|λ|² ≤`` the rigid tolerance of :func:`rt70.linear.modal.modes` (``1e-10 max|ω²|``).
MARGINAL_RTOL = modal.RIGID_RTOL


@dataclass(frozen=True)
class Reduction:
    """A reduced plant and what it was reduced from.

    Attributes
    ----------
    ss : StateSpace
        The reduced plant, with the full plant's input and output names.
    method : str
        ``"modal"`` or ``"balanced"``.
    order : int
        Number of states of ``ss``.
    n_unstable : int
        States kept whole because their poles are rigid or unstable (modal: 2 per rigid
        or unstable mode; balanced: the order of ``G_u``).
    hsv : ndarray or None
        Hankel singular values of the stable part, descending (balanced only).
    bound : float or None
        ``2 Σ`` of the discarded Hankel singular values, the upper bound on
        ``‖G − G_r‖∞`` (balanced only).
    """

    ss: StateSpace
    method: str
    order: int
    n_unstable: int
    hsv: np.ndarray | None = None
    bound: float | None = None


# ------------------------------------------------------------------------------ helpers


def rescaled(
    ss: StateSpace, output_scale: Sequence[float] | float = 1.0, input_scale=1.0
) -> StateSpace:
    """The plant with outputs multiplied by ``output_scale`` and inputs by ``input_scale``.

    ``y_new = S_y y`` and ``u = S_u u_new``: e.g. ``output_scale = 206264.8`` turns
    radians into arc seconds, ``input_scale = 1e6`` makes the input MN·m. The
    second-order model is scaled with it, so :func:`modal_truncation` still applies.

    Parameters
    ----------
    ss : StateSpace
        The plant (p outputs, m inputs).
    output_scale : float or sequence of float
        ``S_y``: one factor for all outputs or p of them (finite, non-zero).
    input_scale : float or sequence of float
        ``S_u``: one factor for all inputs or m of them (finite, non-zero).
    """
    ss = as_state_space(ss)
    sy = np.broadcast_to(np.asarray(output_scale, dtype=float), (ss.noutputs,))
    su = np.broadcast_to(np.asarray(input_scale, dtype=float), (ss.ninputs,))
    if not (np.all(np.isfinite(sy)) and np.all(np.isfinite(su)) and np.all(sy) and np.all(su)):
        raise Rt70Error("scales must be finite and non-zero")
    so = second_order_of(ss)
    if so is not None:
        so = replace(
            so,
            B_in=so.B_in * su,
            C_out=sy[:, None] * so.C_out,
            C_vel=sy[:, None] * so.C_vel,
            D_ff=sy[:, None] * so.D_ff * su,
        )
    return StateSpace(
        ss.A,
        ss.B * su,
        sy[:, None] * ss.C,
        sy[:, None] * ss.D * su,
        states=ss.state_labels,
        inputs=ss.input_labels,
        outputs=ss.output_labels,
        second_order=so,
    )


def _sym(X: np.ndarray) -> np.ndarray:
    return 0.5 * (X + X.T)


def _named(ss: StateSpace, A, B, C, D, prefix: str) -> StateSpace:
    return StateSpace(
        A,
        B,
        C,
        D,
        states=[f"{prefix}{i + 1}" for i in range(A.shape[0])],
        inputs=ss.input_labels,
        outputs=ss.output_labels,
    )


# ---------------------------------------------------------------------- modal truncation


def modal_truncation(ss: StateSpace, n_modes: int) -> Reduction:
    """Keep the ``n_modes`` lowest modes and add the dropped modes' static flexibility.

    With ``K V = M V Ω²``, ``VᵀMV = 1`` (:func:`rt70.linear.modal.modes`) and the modes
    split into kept (r) and dropped (d), ``q ≈ V_r z``: the reduced plant is the
    principal-coordinate model (2.21) of the kept modes, ``V_rᵀ M V_r z̈ + V_rᵀ D V_r ż
    + V_rᵀ K V_r z = V_rᵀ B_in u`` (the projection itself, not ``diag(Ω_r²)``: eigh's
    ω² carry an absolute error ``ε max ω²``, which a 0.04 Hz mode with ζ = 4e-5 feels
    at its peak), with the feedthrough ::

        D_r = D + C_out V_d Ω_d⁻² V_dᵀ B_in,

    the static response of the dropped modes (their residual flexibility). Its static
    gain ``C_out (V_r Ω_r⁻² V_rᵀ + V_d Ω_d⁻² V_dᵀ) B_in = C_out K⁻¹ B_in`` is the full
    plant's. The damping coupling ``V_rᵀ D V_d`` between kept and dropped modes is
    dropped (small for light, near-proportional damping; the H∞ error shows what it
    costs); velocity outputs get no correction (their static response is zero).

    Parameters
    ----------
    ss : StateSpace
        A plant built from M, K, D (:func:`rt70.linear.plant.plant`).
    n_modes : int
        Modes kept (states ``2 n_modes``); at least the rigid and unstable ones, which
        come first in ascending ω².

    Raises
    ------
    Rt70Error
        If ``ss`` has no second-order model, or ``n_modes`` is out of range or would drop
        a rigid or unstable mode.
    """
    ss = as_state_space(ss)
    so = second_order_of(ss)
    if so is None:
        raise Rt70Error("modal truncation needs a plant built from M, K, D (second_order)")
    md = modal.modes(so.M, so.K, so.D)
    n_marginal = int(np.sum(md.rigid | md.negative))
    if not max(1, n_marginal) <= n_modes <= md.n:
        raise Rt70Error(
            f"n_modes must be between {max(1, n_marginal)} and {md.n} (the plant has {md.n} "
            f"modes of 2 states each, {n_marginal} of them rigid or unstable and always "
            f"kept), got {n_modes}"
        )
    Vr, Vd = md.shapes[:, :n_modes], md.shapes[:, n_modes:]
    flexibility = (Vd / md.omega2[n_modes:]) @ Vd.T
    reduced = state_space(
        _sym(Vr.T @ so.M @ Vr),
        _sym(Vr.T @ so.K @ Vr),
        _sym(Vr.T @ so.D @ Vr),
        Vr.T @ so.B_in,
        so.C_out @ Vr,
        so.C_vel @ Vr,
        so.D_ff + so.C_out @ flexibility @ so.B_in,
        coord_names=[f"z{i + 1}" for i in range(n_modes)],
        input_names=ss.input_labels,
        output_names=ss.output_labels,
    )
    return Reduction(reduced, "modal", reduced.nstates, 2 * n_marginal)


# ------------------------------------------------------------------- balanced truncation


@dataclass(frozen=True)
class AdditiveSplit:
    """``G = G_s + G_u``: the stable part ``(A_s, B_s, C_s)``, the rest ``(A_u, B_u, C_u, D)``."""

    A_s: np.ndarray
    B_s: np.ndarray
    C_s: np.ndarray
    A_u: np.ndarray
    B_u: np.ndarray
    C_u: np.ndarray
    D: np.ndarray


def _marginal_limit(ss: StateSpace) -> float:
    """``|λ|²`` below which a pole counts as rigid: the modes' rigid tolerance on ω²."""
    so = second_order_of(ss)
    if so is not None:  # the stiffness scale, not the (larger) overdamped real poles
        return modal.modes(so.M, so.K).rigid_tol
    lam = np.linalg.eigvals(ss.A)
    return MARGINAL_RTOL * float(np.max(np.abs(lam) ** 2, initial=0.0))


def _conditioned(ss: StateSpace) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(A, B, C)`` of the same plant in coordinates where its poles are accurate.

    A plant with a second-order model goes to principal coordinates first (all modes,
    :func:`modal_truncation`: a change of coordinates), then every plant is scaled by
    :func:`scipy.linalg.matrix_balance`. On the RT-70 with its axes free this takes the
    additive split's error at the 0.036 Hz elevation pendulum (ζ = 4e-5) from 1e-7 to
    2e-10 of ‖G‖∞: the physical ``A`` (‖A‖ ≈ 9e7) places that pole only to about
    1e-12 rad/s, a tenth of a millionth of its half-power bandwidth ζω ≈ 9e-6 rad/s.
    """
    so = second_order_of(ss)
    if so is not None:
        ss = modal_truncation(ss, so.M.shape[0]).ss
    _, (s, _) = scipy.linalg.matrix_balance(ss.A, permute=False, separate=True)
    return (ss.A * s) / s[:, None], ss.B / s[:, None], ss.C * s


def additive_split(ss: StateSpace, offset: float = 0.0) -> AdditiveSplit:
    """Split ``G`` into a stable part and a rigid-or-unstable part, ``G = G_s + G_u``.

    In the coordinates of :func:`_conditioned` (principal coordinates, balanced), the
    real Schur form ``Uᵀ A U = [[A_s, A_12], [0, A_u]]`` is ordered with the stable
    poles first; the Sylvester equation ``A_s X − X A_u + A_12 = 0``
    (:func:`scipy.linalg.solve_sylvester`) block-diagonalises it. A pole is rigid or
    unstable when ``Re λ ≥ 0`` or ``|λ|²`` is below the rigid-mode tolerance of
    :func:`rt70.linear.modal.modes` on ω² (``1e-10 max ω²``; :data:`MARGINAL_RTOL` of
    ``max|λ|²`` without a second-order model): a rigid mode's double pole at 0 is split
    by the stiffness matrix's rounding into ``±√δ``-sized poles, one of them "stable".
    With ``offset > 0`` a pole also joins ``G_u`` when ``Re λ ≥ −offset · max(1, |Im λ|)``
    (MATLAB's ``balred`` has the same option): a mode with ζ below about ``offset`` is
    then kept whole instead of balanced (its Gramians are of order 1/ζ and their
    rounding sets a floor on the error of the rest).
    """
    ss = as_state_space(ss)
    if not (np.isfinite(offset) and offset >= 0.0):
        raise Rt70Error(f"offset must be a finite non-negative number, got {offset!r}")
    limit = _marginal_limit(ss)
    A, B, C = _conditioned(ss)

    def stable(re: float, im: float) -> bool:
        return re < -offset * max(1.0, abs(im)) and re * re + im * im > limit

    T, U, n_s = scipy.linalg.schur(A, output="real", sort=stable)
    Bt, Ct = U.T @ B, C @ U
    A_s, A_12, A_u = T[:n_s, :n_s], T[:n_s, n_s:], T[n_s:, n_s:]
    X = scipy.linalg.solve_sylvester(A_s, -A_u, -A_12) if 0 < n_s < A.shape[0] else None
    B_s, B_u = Bt[:n_s], Bt[n_s:]
    C_s, C_u = Ct[:, :n_s], Ct[:, n_s:]
    if X is not None:  # S = [[1, X], [0, 1]]: B ← S⁻¹ B, C ← C S
        B_s = B_s - X @ B_u
        C_u = C_u + C_s @ X
    return AdditiveSplit(A_s, B_s, C_s, A_u, B_u, C_u, ss.D)


def _factor(P: np.ndarray) -> np.ndarray:
    """L with ``L Lᵀ = P`` for a symmetric positive semidefinite Gramian P.

    By :func:`scipy.linalg.eigh`, rounding's tiny negative eigenvalues set to 0 (a
    Cholesky factorisation fails on a Gramian whose smallest eigenvalues are below
    rounding, as the stiff modes' are).
    """
    w, V = scipy.linalg.eigh(0.5 * (P + P.T))
    return V * np.sqrt(np.clip(w, 0.0, None))


def _gramian_factors(A: np.ndarray, B: np.ndarray, C: np.ndarray):
    P = scipy.linalg.solve_continuous_lyapunov(A, -B @ B.T)
    Q = scipy.linalg.solve_continuous_lyapunov(A.T, -C.T @ C)
    return _factor(P), _factor(Q)


def hankel_singular_values(ss: StateSpace, offset: float = 0.0) -> tuple[np.ndarray, int]:
    """Hankel singular values of the stable part (descending) and the order of the rest.

    ``σ_i = sqrt(λ_i(P Q))`` with the Gramians ``A P + P Aᵀ + B Bᵀ = 0`` and
    ``Aᵀ Q + Q A + Cᵀ C = 0`` of the stable part (:func:`additive_split`).
    """
    ss = as_state_space(ss)
    split = additive_split(ss, offset)
    if split.A_s.shape[0] == 0:
        return np.zeros(0), split.A_u.shape[0]
    Lp, Lq = _gramian_factors(split.A_s, split.B_s, split.C_s)
    return scipy.linalg.svd(Lq.T @ Lp, compute_uv=False), split.A_u.shape[0]


def balanced_truncation(ss: StateSpace, order: int, offset: float = 0.0) -> Reduction:
    """Balanced truncation (square-root method) to ``order`` states.

    The rigid or unstable part ``G_u`` of :func:`additive_split` is kept whole
    (``n_u`` states); the stable part is reduced to ``k = order − n_u`` states: with
    ``P = L_p L_pᵀ``, ``Q = L_q L_qᵀ`` and ``L_qᵀ L_p = U Σ Wᵀ``, the projections
    ``T_r = L_p W_k Σ_k^{-1/2}`` and ``T_l = L_q U_k Σ_k^{-1/2}`` give
    ``A_k = T_lᵀ A T_r``, ``B_k = T_lᵀ B``, ``C_k = C T_r`` (Laub et al. 1987;
    Antoulas 2005 §7.2). The bound ``2 Σ_{i>k} σ_i`` is returned with it.

    Parameters
    ----------
    ss : StateSpace
        The plant.
    order : int
        Number of states kept, ``n_u`` of them those of ``G_u``.
    offset : float
        Moves nearly undamped modes into ``G_u`` (ζ below about ``offset``,
        :func:`additive_split`); 0 keeps only the rigid and unstable ones there.

    Raises
    ------
    Rt70Error
        If ``order`` is below ``n_u`` or above the plant's order, or the kept Hankel
        singular values include zeros (an unobservable or uncontrollable part: choose a
        smaller order).
    """
    ss = as_state_space(ss)
    split = additive_split(ss, offset)
    n_u, n_s = split.A_u.shape[0], split.A_s.shape[0]
    if not max(1, n_u) <= order <= n_u + n_s:
        raise Rt70Error(
            f"order must be between {max(1, n_u)} and {n_u + n_s} (the plant has "
            f"{n_u + n_s} states, {n_u} of them rigid or unstable and always kept), "
            f"got {order}"
        )
    k = order - n_u
    if n_s:
        Lp, Lq = _gramian_factors(split.A_s, split.B_s, split.C_s)
        U, hsv, Wt = scipy.linalg.svd(Lq.T @ Lp)
    else:
        hsv = np.zeros(0)
    if k and hsv[k - 1] <= np.finfo(float).eps * hsv[0]:
        raise Rt70Error(
            f"order {order}: Hankel singular value {k} is zero to rounding; the stable part "
            f"has only {int(np.sum(hsv > np.finfo(float).eps * hsv[0]))} that count"
        )
    scale = 1.0 / np.sqrt(hsv[:k]) if k else np.zeros(0)
    Tr = Lp @ Wt[:k].T * scale if k else np.zeros((n_s, 0))
    Tl = Lq @ U[:, :k] * scale if k else np.zeros((n_s, 0))
    A = scipy.linalg.block_diag(Tl.T @ split.A_s @ Tr, split.A_u)
    B = np.vstack([Tl.T @ split.B_s, split.B_u])
    C = np.hstack([split.C_s @ Tr, split.C_u])
    reduced = _named(ss, A, B, C, split.D.copy(), "x")
    bound = 2.0 * float(np.sum(hsv[k:]))
    return Reduction(reduced, "balanced", order, n_u, hsv=hsv, bound=bound)


# --------------------------------------------------------------------------- H∞ error


@dataclass(frozen=True)
class HinfError:
    """``‖G − G_r‖∞`` and where it peaks.

    Attributes
    ----------
    peak : float
        ``max_ω σ_max(G(jω) − G_r(jω))``, in the plant's output/input units.
    freq_hz : float
        Frequency of the peak (Hz).
    relative : float
        ``peak / ‖G‖`` over the same grid (``‖G‖`` the largest σ_max of the full plant).
    """

    peak: float
    freq_hz: float
    relative: float


def _poles_grid(ss_list: Sequence[StateSpace], f_min: float, f_max: float) -> np.ndarray:
    """Extra frequencies around every lightly damped pole: ``f_d (1 + c ζ)``."""
    extra = []
    offsets = np.array([-3.0, -1.5, -0.7, -0.3, 0.0, 0.3, 0.7, 1.5, 3.0])
    for ss in ss_list:
        lam = np.linalg.eigvals(ss.A)
        lam = lam[lam.imag > 0]
        f_d = lam.imag / (2.0 * np.pi)
        zeta = np.clip(-lam.real / np.abs(lam), 1e-9, 1.0)
        extra.append((f_d[:, None] * (1.0 + np.outer(zeta, offsets))).ravel())
    f = np.concatenate(extra) if extra else np.zeros(0)
    return f[(f >= f_min) & (f <= f_max)]


def _sigma_max(full: StateSpace, reduced: StateSpace, f: np.ndarray) -> tuple:
    H = frequency_response(full, f).H
    E = H - frequency_response(reduced, f).H
    return np.linalg.norm(E, ord=2, axis=(1, 2)), np.linalg.norm(H, ord=2, axis=(1, 2))


def hinf_error(
    full: StateSpace,
    reduced: StateSpace,
    f_min: float = 1e-3,
    f_max: float | None = None,
    n_grid: int = 2000,
) -> HinfError:
    """``‖G − G_r‖∞`` over ``[f_min, f_max]`` Hz: dense grid, poles, then a local search.

    The grid is ``n_grid`` log-spaced points plus nine points across the half-power band
    of every lightly damped pole of both plants (``f_d (1 + c ζ)``, ``|c| ≤ 3``); the
    largest value is then refined by :func:`scipy.optimize.minimize_scalar` between
    its grid neighbours. ``f_max`` defaults to twice the plant's highest pole frequency.
    The full plant is evaluated by its second-order model when it has one (accurate at
    lightly damped resonances), the reduced by its state space. Rigid or unstable modes
    make ``G`` unbounded at 0, so ``f_min > 0`` is required; their parts cancel in the
    error when both methods keep them whole.

    Parameters
    ----------
    full, reduced : StateSpace
        The plant G and its reduction G_r (the same inputs and outputs).
    f_min : float
        The lowest frequency, Hz (positive).
    f_max : float, optional
        The highest frequency, Hz (default twice the highest pole frequency of ``full``).
    n_grid : int
        Number of log-spaced grid points.
    """
    full, reduced = as_state_space(full), as_state_space(reduced)
    if not (np.isfinite(f_min) and f_min > 0):
        raise Rt70Error(f"f_min must be a positive frequency, got {f_min!r}")
    if f_max is None:
        f_max = 2.0 * float(np.max(np.abs(np.linalg.eigvals(full.A)))) / (2.0 * np.pi)
    if not (np.isfinite(f_max) and f_max > f_min):
        raise Rt70Error(f"f_max must exceed f_min = {f_min:g} Hz, got {f_max!r}")
    f = np.unique(
        np.concatenate(
            [np.geomspace(f_min, f_max, n_grid), _poles_grid((full, reduced), f_min, f_max)]
        )
    )
    err, gain = _sigma_max(full, reduced, f)
    i = int(np.argmax(err))
    lo, hi = f[max(i - 1, 0)], f[min(i + 1, f.size - 1)]
    peak, f_peak = float(err[i]), float(f[i])
    if hi > lo:
        res = scipy.optimize.minimize_scalar(
            lambda x: -_sigma_max(full, reduced, np.array([np.exp(x)]))[0][0],
            bounds=(np.log(lo), np.log(hi)),
            method="bounded",
            options={"xatol": 1e-9},
        )
        if -res.fun > peak:
            peak, f_peak = float(-res.fun), float(np.exp(res.x))
    return HinfError(peak, f_peak, peak / float(np.max(gain)))
