"""State-space models of ``M q̈ + D q̇ + K q = B u`` and their frequency and step responses.

What a control engineer builds from a linear model (formalism §2):

- the state space ``ẋ = A x + B u``, ``y = C x + D u`` with ``x = [q; q̇]``
  (:func:`state_space`), a python-control ``StateSpace`` that keeps its second-order
  model (:class:`rt70.linear.state_space.StateSpace`), or in modal coordinates truncated
  to the lowest modes (:func:`modal_state_space`, from the :class:`~rt70.linear.modal.Modes` of
  :func:`rt70.linear.modal.modes`);
- the frequency response (the book's ЛАХ/ЛФХ, i.e. Bode magnitude and phase,
  :func:`frequency_response`) and the step response (:func:`step_response`).

Their figures are drawn by :mod:`rt70.plotting.modal`. python-control's ``StateSpace`` is
the project's one state-space type: every function here and in :mod:`rt70.linear.reduce`
and :mod:`rt70.linear.covariance` takes any python-control system. python-control (and
with it matplotlib) is imported when a system is built or read, not with this module.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import scipy.linalg

from rt70.errors import Rt70Error
from rt70.linear.checks import _columns, _mass, _matrix, _names, _rows, _square
from rt70.linear.modal import Modes
from rt70.linear.second_order import SecondOrder
from rt70.linear.system_matrices import SystemMatrices

if TYPE_CHECKING:
    import control

    from rt70.linear.state_space import StateSpace

# ---------------------------------------------------------------------------- state space


def _assemble(
    M: np.ndarray,
    chol: tuple[np.ndarray, bool],
    K: np.ndarray,
    D: np.ndarray,
    B_in: np.ndarray,
    C_out: np.ndarray,
    C_vel: np.ndarray,
    D_ff: np.ndarray,
    coord_names: tuple[str, ...],
    input_names: tuple[str, ...],
    output_names: tuple[str, ...],
    rate_suffix: str,
) -> SystemMatrices:
    n, m = B_in.shape
    solved = scipy.linalg.cho_solve(chol, np.hstack([K, D, B_in]), check_finite=False)
    A = np.zeros((2 * n, 2 * n))
    A[:n, n:] = np.eye(n)
    A[n:, :n] = -solved[:, :n]
    A[n:, n:] = -solved[:, n : 2 * n]
    B = np.zeros((2 * n, m))
    B[n:] = solved[:, 2 * n :]
    states = coord_names + tuple(f"{s}{rate_suffix}" for s in coord_names)
    return SystemMatrices(
        A,
        B,
        np.hstack([C_out, C_vel]),
        D_ff,
        state_labels=states,
        input_labels=tuple(input_names),
        output_labels=tuple(output_names),
        second_order=SecondOrder(M, K, D, B_in, C_out, C_vel, D_ff),
    )


def _io(
    n: int,
    B_in: np.ndarray,
    C_out: np.ndarray,
    C_vel: np.ndarray | None,
    D_ff: np.ndarray | None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    B_in = _columns("B_in", B_in, n)
    C_out = _rows("C_out", C_out, n)
    p, m = C_out.shape[0], B_in.shape[1]
    C_vel = np.zeros((p, n)) if C_vel is None else _rows("C_vel", C_vel, n)
    if C_vel.shape[0] != p:
        raise Rt70Error(f"C_vel has {C_vel.shape[0]} rows, C_out has {p}")
    D_ff = np.zeros((p, m)) if D_ff is None else _matrix("D_ff", np.atleast_2d(D_ff), (p, m))
    return B_in, C_out, C_vel, D_ff


def system_matrices(
    M: np.ndarray,
    K: np.ndarray,
    D: np.ndarray | None,
    B_in: np.ndarray,
    C_out: np.ndarray,
    C_vel: np.ndarray | None = None,
    D_ff: np.ndarray | None = None,
    *,
    coord_names: Sequence[str] | None = None,
    input_names: Sequence[str] | None = None,
    output_names: Sequence[str] | None = None,
) -> SystemMatrices:
    """The state-space matrices of ``M q̈ + D q̇ + K q = B_in u``, ``y = C_out q + C_vel q̇ + D_ff u``.

    With ``x = [q; q̇]``::

        A = [[0, 1], [−M⁻¹K, −M⁻¹D]],  B = [[0], [M⁻¹B_in]],
        C = [C_out, C_vel],             D = D_ff,

    M⁻¹ applied by a Cholesky solve (:func:`scipy.linalg.cho_solve`), never ``inv(M)``.

    Parameters
    ----------
    M : ndarray, shape (n, n)
        Symmetric positive definite mass matrix.
    K : ndarray, shape (n, n)
        Stiffness matrix (any finite square matrix).
    D : ndarray, shape (n, n), or None
        Damping matrix (None: undamped).
    B_in : ndarray, shape (n, m) or (n,)
        Input matrix (generalised forces per unit input); 1-D means one input.
    C_out : ndarray, shape (p, n) or (n,)
        Position output matrix; 1-D means one output.
    C_vel : ndarray, shape (p, n), optional
        Velocity output matrix (default 0).
    D_ff : ndarray, shape (p, m), optional
        Feedthrough (default 0).
    coord_names, input_names, output_names : sequence of str, optional
        Labels (default ``q1…``, ``u1…``, ``y1…``); states are ``q…`` and ``q…_dot``.

    Returns
    -------
    SystemMatrices
        With the second-order matrices; :meth:`~SystemMatrices.state_space` gives the
        python-control system (:func:`state_space`).
    """
    M, chol = _mass(M)
    n = M.shape[0]
    K = _square("K", K, n)
    D = np.zeros((n, n)) if D is None else _square("D", D, n)
    B_in, C_out, C_vel, D_ff = _io(n, B_in, C_out, C_vel, D_ff)
    return _assemble(
        M,
        chol,
        K,
        D,
        B_in,
        C_out,
        C_vel,
        D_ff,
        _names(coord_names, "q", n, "coordinate"),
        _names(input_names, "u", B_in.shape[1], "input"),
        _names(output_names, "y", C_out.shape[0], "output"),
        "_dot",
    )


def state_space(
    M: np.ndarray,
    K: np.ndarray,
    D: np.ndarray | None,
    B_in: np.ndarray,
    C_out: np.ndarray,
    C_vel: np.ndarray | None = None,
    D_ff: np.ndarray | None = None,
    *,
    coord_names: Sequence[str] | None = None,
    input_names: Sequence[str] | None = None,
    output_names: Sequence[str] | None = None,
) -> StateSpace:
    """The python-control system of :func:`system_matrices` (its formulas and checks).

    Parameters
    ----------
    M, K, D, B_in, C_out, C_vel, D_ff : numpy.ndarray
        As :func:`system_matrices` takes them.
    coord_names, input_names, output_names : sequence of str, optional
        Labels, as :func:`system_matrices`.

    Returns
    -------
    StateSpace
        Also remembers the second-order matrices for :func:`frequency_response`.
    """
    return system_matrices(
        M,
        K,
        D,
        B_in,
        C_out,
        C_vel,
        D_ff,
        coord_names=coord_names,
        input_names=input_names,
        output_names=output_names,
    ).state_space()


def modal_state_space(
    modes: Modes,
    B_in: np.ndarray,
    C_out: np.ndarray,
    C_vel: np.ndarray | None = None,
    D_ff: np.ndarray | None = None,
    n_modes: int | None = None,
    *,
    input_names: Sequence[str] | None = None,
    output_names: Sequence[str] | None = None,
) -> StateSpace:
    """State space in principal coordinates (2.21), truncated to the lowest modes.

    With ``q ≈ V_r z`` (V_r the first ``n_modes`` columns of V) and ``x = [z; ż]``::

        A = [[0, 1], [−Ω_r², −Z_r]],  B = [[0], [V_rᵀ B_in]],
        C = [C_out V_r, C_vel V_r],    D = D_ff,

    with ``Z_r`` the leading block of ``VᵀDV`` (``modes.modal_damping``; 0 if the modes
    were computed without D). Truncation drops the higher modes and, for
    non-proportional damping, their coupling to the kept ones; the static contribution
    of the dropped modes is not added back.

    Parameters
    ----------
    modes : Modes
        From :func:`rt70.linear.modal.modes` (with D for a damped model).
    B_in : ndarray, shape (n, m) or (n,)
        Input matrix in the original coordinates.
    C_out : ndarray, shape (p, n) or (n,)
        Position output matrix in the original coordinates.
    C_vel : ndarray, shape (p, n), optional
        Velocity output matrix (default 0).
    D_ff : ndarray, shape (p, m), optional
        Feedthrough (default 0).
    n_modes : int, optional
        Number of lowest modes kept (default all; rigid modes count).
    input_names, output_names : sequence of str, optional
        Labels; states are ``z1…`` and ``z1_dot…``.

    Returns
    -------
    StateSpace
        Its ``second_order`` is the modal model ``(1, Ω_r², Z_r, V_rᵀB_in, C_out V_r, …)``.
    """
    n = modes.n
    r = n if n_modes is None else int(n_modes)
    if not 1 <= r <= n:
        raise Rt70Error(f"n_modes must be between 1 and {n}, got {n_modes}")
    B_in, C_out, C_vel, D_ff = _io(n, B_in, C_out, C_vel, D_ff)
    Vr = modes.shapes[:, :r]
    Z = np.zeros((r, r)) if modes.modal_damping is None else modes.modal_damping[:r, :r]
    eye = np.eye(r)
    return _assemble(
        eye,
        (eye, True),
        np.diag(modes.omega2[:r]),
        Z.copy(),
        Vr.T @ B_in,
        C_out @ Vr,
        C_vel @ Vr,
        D_ff,
        _names(None, "z", r, "mode"),
        _names(input_names, "u", B_in.shape[1], "input"),
        _names(output_names, "y", C_out.shape[0], "output"),
        "_dot",
    ).state_space()


# ----------------------------------------------------------------------------- responses


@dataclass(frozen=True)
class FrequencyResponse:
    """Complex frequency response ``H(jω)`` of every output/input pair.

    Attributes
    ----------
    freq_hz : ndarray, shape (nf,)
        Frequencies (Hz).
    H : ndarray of complex, shape (nf, p, m)
        ``H[k, i, j]``: output i per unit input j at ``freq_hz[k]``.
    input_names, output_names : tuple of str
        Labels.
    method : str
        ``"second_order"`` or ``"state_space"``.
    """

    freq_hz: np.ndarray
    H: np.ndarray
    input_names: tuple[str, ...]
    output_names: tuple[str, ...]
    method: str

    @property
    def magnitude_db(self) -> np.ndarray:
        """``20 log10 |H|`` (dB) — the ЛАХ (log magnitude)."""
        with np.errstate(divide="ignore"):
            return 20.0 * np.log10(np.abs(self.H))

    @property
    def phase_deg(self) -> np.ndarray:
        """Phase of H in degrees, unwrapped along frequency — the ЛФХ."""
        return np.degrees(np.unwrap(np.angle(self.H), axis=0))


def _pole(f: float) -> Rt70Error:
    return Rt70Error(
        f"frequency response undefined at {f:g} Hz: the system has a pole there "
        "(e.g. a rigid-body mode at 0 Hz)"
    )


#: Bytes of complex matrices the second-order path solves at once (a batch of frequencies).
BATCH_BYTES = 32 * 2**20


def _second_order_response(so: SecondOrder, f: np.ndarray) -> np.ndarray:
    """``(C_out + jω C_vel)(K − ω²M + jωD)⁻¹ B_in + D_ff``, batches of LU solves."""
    n = so.M.shape[0]
    H = np.empty((f.size, so.C_out.shape[0], so.B_in.shape[1]), dtype=complex)
    batch = max(1, min(f.size, BATCH_BYTES // (16 * max(n * n, 1))))
    for start in range(0, f.size, batch):
        fb = f[start : start + batch]
        w = 2.0 * np.pi * fb[:, None, None]
        try:
            X = np.linalg.solve(so.K - w * w * so.M + 1j * w * so.D, so.B_in)
        except np.linalg.LinAlgError:
            for fk in fb:
                wk = 2.0 * np.pi * fk
                if np.linalg.matrix_rank(so.K - wk * wk * so.M + 1j * wk * so.D) < n:
                    raise _pole(fk) from None
            raise
        H[start : start + batch] = (so.C_out + 1j * w * so.C_vel) @ X + so.D_ff
    return H


def _state_space_response(sys: control.StateSpace, f: np.ndarray) -> np.ndarray:
    """``C (jω1 − A)⁻¹ B + D``: python-control's own evaluation of the system.

    Laub's method through slycot where it is installed, otherwise an LU solve at each
    frequency. Measured on the RT-70's balanced 24-state reduction at its 0.036 Hz
    elevation pendulum (ζ = 4e-5) against a 40-digit solve: 4.0e-13 of |H| off, where a
    complex Schur form of A factored once and solved triangularly at each frequency (1.7
    times faster) is 1.1e-9 off.
    """
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # a pole on the grid: refused below
        H = np.asarray(sys(2j * np.pi * f, squeeze=False), dtype=complex)
    H = np.moveaxis(H.reshape(sys.noutputs, sys.ninputs, f.size), -1, 0)
    finite = np.isfinite(H).all(axis=(1, 2))
    if not finite.all():
        raise _pole(float(f[np.argmin(finite)]))
    return H


def frequency_response(
    ss: control.StateSpace, freq_hz: np.ndarray, method: str = "auto"
) -> FrequencyResponse:
    """Frequency response ``H(jω)``, ω = 2π f, of every output/input pair.

    rt70's one evaluation of ``G(jω)``: the loop measures
    (:mod:`rt70.control.loop_measures`) and the reduction error
    (:func:`rt70.linear.reduce.hinf_error`) call it too.

    Parameters
    ----------
    ss : control.StateSpace
        The system: rt70's :class:`StateSpace` or any python-control one.
    freq_hz : array_like, shape (nf,)
        Frequencies (Hz).
    method : {"auto", "second_order", "state_space"}
        ``"second_order"`` solves ``(K − ω²M + jωD) X = B_in`` and forms
        ``H = (C_out + jω C_vel) X + D_ff`` — n × n instead of 2n × 2n, no M⁻¹, and more
        accurate near lightly damped resonances; it needs the system's
        ``second_order``. ``"state_space"`` forms ``H = C (jω1 − A)⁻¹ B + D`` by
        python-control's own evaluation (``sys(s)``). ``"auto"`` takes the second-order
        path when available.

    Returns
    -------
    FrequencyResponse
        With ``magnitude_db`` and ``phase_deg`` (Bode, the book's ЛАХ/ЛФХ).

    Raises
    ------
    Rt70Error
        On non-finite frequencies, an unknown method, or a pole exactly at one of the
        frequencies (a free structure at 0 Hz); evaluate rigid-body systems at f > 0.
    """
    from rt70.linear.state_space import as_state_space, second_order_of

    ss = as_state_space(ss)
    f = np.asarray(freq_hz, dtype=float)
    if f.ndim != 1 or f.size == 0 or not np.all(np.isfinite(f)):
        raise Rt70Error("freq_hz must be a non-empty 1-D array of finite frequencies")
    so = second_order_of(ss)
    if method == "auto":
        method = "second_order" if so is not None else "state_space"
    if method == "second_order":
        if so is None:
            raise Rt70Error("this state space was not built from M, K, D")
        H = _second_order_response(so, f)
    elif method == "state_space":
        H = _state_space_response(ss, f)
    else:
        raise Rt70Error(f"unknown method {method!r} (auto, second_order, state_space)")
    return FrequencyResponse(f, H, tuple(ss.input_labels), tuple(ss.output_labels), method)


def step_response(ss: StateSpace, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Response to a unit step on each input, from rest, by the matrix exponential.

    Over a step h the state obeys ``x(t+h) = Φ x(t) + Γ u`` with ``Φ = e^{Ah}`` and
    ``Γ = ∫₀ʰ e^{Aτ} dτ B``, both read off one :func:`scipy.linalg.expm` of the
    augmented matrix ``[[A, B], [0, 0]] h``. For a constant input this is exact (no
    discretisation error, rigid modes and A singular included); only rounding
    accumulates over the steps. Uniformly spaced ``t`` (to 1e-9 relative) needs one
    exponential, otherwise one per interval.

    Parameters
    ----------
    ss : StateSpace
        The system (x(t[0]) = 0).
    t : array_like, shape (nt,)
        Increasing times (s); the step is applied at ``t[0]``.

    Returns
    -------
    t : ndarray, shape (nt,)
        The times.
    y : ndarray, shape (nt, p, m)
        ``y[k, i, j]``: output i at ``t[k]`` for a unit step on input j.
    """
    from rt70.linear.state_space import as_state_space

    ss = as_state_space(ss)
    t = np.asarray(t, dtype=float)
    if t.ndim != 1 or t.size == 0 or not np.all(np.isfinite(t)):
        raise Rt70Error("t must be a non-empty 1-D array of finite times")
    h = np.diff(t)
    if np.any(h <= 0):
        raise Rt70Error("t must be strictly increasing")
    ns, m = ss.nstates, ss.ninputs
    aug = np.zeros((ns + m, ns + m))
    aug[:ns, :ns], aug[:ns, ns:] = ss.A, ss.B

    def discrete(step: float) -> tuple[np.ndarray, np.ndarray]:
        E = scipy.linalg.expm(aug * step)
        return E[:ns, :ns], E[:ns, ns:]

    X = np.zeros((t.size, ns, m))
    if h.size:
        uniform = np.ptp(h) <= 1e-9 * np.max(h)
        Phi, Gam = discrete(float((t[-1] - t[0]) / h.size)) if uniform else (None, None)
        for k, hk in enumerate(h):
            if not uniform:
                Phi, Gam = discrete(float(hk))
            X[k + 1] = Phi @ X[k] + Gam
    y = np.einsum("pi,kij->kpj", ss.C, X) + ss.D
    return t, y
