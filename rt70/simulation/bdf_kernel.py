"""A compiled variable-order BDF (NDF) loop on the book's equations of motion.

The method is scipy's ``BDF`` (Shampine and Reichelt, "The MATLAB ODE Suite", SIAM J.
Sci. Comput. 18, 1997, §2: the numerical differentiation formulas of orders 1–5 with
Klopfenstein's κ, quasi-constant step size in the backward differences ``D``, a
simplified Newton iteration and Jacobians taken again only when it fails to converge),
written as plain loops compiled with numba so that a step never returns to Python. Its
step-size and order rules, tolerances and dense output are scipy's, so a run takes the
steps scipy's BDF takes on the same equations, up to rounding: the tests compare the two
(``tests/test_compiled_bdf.py``).

The state is ``y = [q; q̇; E_ψ]`` of (1.73), (4.79) with the dissipated energy of the
energy audit (:class:`rt70.simulation.states.EnergyAudit`), its derivative the dampers'
power. Each Newton iterate evaluates scipy's ``G = c f(y) − ψ − d`` with its q̇ rows
multiplied by A: those rows ask for the accelerations ``q̈* = (ψ + d)/c``, and
``A (c q̈ − ψ − d) = −c r(q, q̇, q̈*)`` with r the residual of the equations
(:mod:`rt70.textbook.forward_kernel`), so an iterate costs one Newton–Euler pass and no
forward dynamics. The Jacobian ``[[0, 1, 0], [J_q, J_q̇, 0], [0, 0, 0]]`` (the energy's
row zero, as the other methods') makes Newton's matrix ``1 − c J`` of size 2nv + 1
reducible to nv: with ``G = [G_q; G_q̇; G_E]`` and ``J_x = −A⁻¹ R_x``,

    (A + c R_q̇ + c² R_q) Δq̇ = A G_q̇ − c R_q G_q,   Δq = G_q + c Δq̇,   ΔE = G_E,

which :mod:`rt70.simulation.bdf_newton` factors (pair-local: the articulated-body
algorithm in O(nv); otherwise LU).

The loop runs in chunks (:func:`advance`): between two the caller checks the evaluation
budget, a stop (Ctrl-C) and the progress bar, and empties the output buffer.
"""

from __future__ import annotations

import numba
import numpy as np

from rt70.guards.kernel_cache import stamp_kernel_caches
from rt70.simulation.bdf_newton import factor, jacobian_at, solve
from rt70.textbook.forward_kernel import DONE, K_R, K_ZERO, NOT_FINITE, _forward, _residual

stamp_kernel_caches()  # before the first numba.njit

MAX_ORDER = 5
NEWTON_MAXITER = 4
MIN_FACTOR = 0.2
MAX_FACTOR = 10.0
#: Klopfenstein's κ of the NDF of each order (Shampine and Reichelt, Table 1).
KAPPA = np.array([0.0, -0.1850, -1.0 / 9.0, -0.0823, -0.0415, 0.0])
GAMMA = np.concatenate(([0.0], np.cumsum(1.0 / np.arange(1, MAX_ORDER + 1))))
ALPHA = (1.0 - KAPPA) * GAMMA
ERROR_CONST = KAPPA * GAMMA + 1.0 / np.arange(1, MAX_ORDER + 2)

#: The scalars of a run, in ``s``: time, step, order, equal steps, Newton's matrix
#: factored, safety factor of the last step, evaluations, Jacobians, factorisations,
#: steps, samples written, next output time's index, kernel status, Newton's matrix
#: pair-local (1) or dense (0) (:mod:`rt70.simulation.bdf_newton`), run started.
T, H, ORDER, EQUAL, LU_OK, SAFETY, NFEV, NJEV, NLU, NSTEP, NOUT, NEXT, KSTATUS, LOCAL, STARTED = (
    range(15)
)
#: Length of ``s``.
SCALARS = 15
#: What :func:`advance` returns.
CHUNK_DONE, FINISHED, FULL, TOO_SMALL, KERNEL_ERROR = range(5)


@numba.njit(cache=True)
def _rhs(y, K, n, f, sums) -> int:
    """``f = [q̇; q̈; P_d]`` at ``y = [q; q̇; E_ψ]``; the status of the forward dynamics."""
    status = _forward(y[:n], y[n : 2 * n], K, f[n : 2 * n], sums)
    f[:n] = y[n : 2 * n]
    f[2 * n] = sums[3]
    return status


@numba.njit(cache=True)
def _norm(x, scale) -> float:
    """The root mean square of ``x / scale``."""
    total = 0.0
    for i in range(x.shape[0]):
        total += (x[i] / scale[i]) ** 2
    return np.sqrt(total / x.shape[0])


@numba.njit(cache=True)
def _compute_R(order, factor):
    """The matrix that changes the differences' step by ``factor`` (Shampine–Reichelt §2.2)."""
    M = np.zeros((order + 1, order + 1))
    M[0, :] = 1.0
    for i in range(1, order + 1):
        for j in range(1, order + 1):
            M[i, j] = (i - 1 - factor * j) / i
    for i in range(1, order + 1):
        for j in range(order + 1):
            M[i, j] *= M[i - 1, j]
    return M


@numba.njit(cache=True)
def _change_D(D, order, factor) -> None:
    """Rescale the backward differences ``D[:order + 1]`` to a step ``factor`` times as long."""
    R, U = _compute_R(order, factor), _compute_R(order, 1.0)
    RU = np.zeros((order + 1, order + 1))
    for i in range(order + 1):  # loops: numba's @ calls BLAS, slow at this size
        for j in range(order + 1):
            for k in range(order + 1):
                RU[i, j] += R[i, k] * U[k, j]
    old = D[: order + 1].copy()
    for i in range(order + 1):
        for k in range(D.shape[1]):
            x = 0.0
            for j in range(order + 1):
                x += RU[j, i] * old[j, k]
            D[i, k] = x


@numba.njit(cache=True)
def _newton_residual(K, n, y, c, psi, d, acc, b, sums) -> int:
    """The Newton residual ``c f(y) − ψ − d`` with its q̇ rows multiplied by A, into ``b``.

    Returns the kernel's status.

    The q̇ rows ask ``c q̈ = ψ + d``, i.e. the accelerations ``q̈* = (ψ + d) / c``; with r
    linear in q̈, ``A (c q̈(q, q̇) − ψ − d) = −c r(q, q̇, q̈*)``: one residual, no solve.
    """
    for i in range(n):
        acc[i] = (psi[n + i] + d[n + i]) / c
    status = _residual(y[:n], y[n : 2 * n], acc, K, b[n : 2 * n], sums)
    for i in range(n):
        b[i] = c * y[n + i] - psi[i] - d[i]
        b[n + i] *= -c
        if not np.isfinite(b[n + i]):
            return NOT_FINITE
    for i in range(2 * n, y.shape[0]):
        b[i] = c * sums[3] - psi[i] - d[i]
    return status


@numba.njit(cache=True)
def _solve_system(K, n, y_predict, c, psi, newton, work, s, scale, tol):
    """Newton's iteration of one step: ``(converged, iterations, status)``.

    ``work = (y, d, acc, dy, rhs, sums)``: ``y`` the solution, ``d`` its correction from
    the prediction.
    """
    y, d, acc, dy, b, sums = work
    local = s[LOCAL] == 1
    y[:] = y_predict
    d[:] = 0.0
    old = -1.0
    for k in range(NEWTON_MAXITER):
        status = _newton_residual(K, n, y, c, psi, d, acc, b, sums)
        s[NFEV] += 1
        if status == NOT_FINITE:
            return False, k + 1, DONE
        if status != DONE:
            return False, k + 1, status
        solve(K, newton, c, b, n, dy, local)
        dy_norm = _norm(dy, scale)
        rate = -1.0 if old < 0.0 else dy_norm / old
        if rate >= 0.0 and (
            rate >= 1.0 or rate ** (NEWTON_MAXITER - k) / (1 - rate) * dy_norm > tol
        ):
            return False, k + 1, DONE
        y += dy
        d += dy
        if dy_norm == 0.0 or (rate >= 0.0 and rate / (1 - rate) * dy_norm < tol):
            return True, k + 1, DONE
        old = dy_norm
    return False, NEWTON_MAXITER, DONE


@numba.njit(cache=True)
def initial_step(K, n, y0, f0, t_span, rtol, atol, s) -> float:
    """The first step, as scipy's ``select_initial_step`` for order 1; −1 if the kernel fails.

    Hairer, Nørsett and Wanner, *Solving Ordinary Differential Equations I*, §II.4.

    Parameters
    ----------
    K : tuple
        The forward kernel's arrays (:class:`rt70.textbook.forward_kernel.ForwardData`).
    n : int
        Coordinates, nv.
    y0, f0 : numpy.ndarray, shape (2 nv + 1,)
        The initial state and its derivative.
    t_span : numpy.ndarray, shape (2,)
        ``[t0, t1]``, s.
    rtol : float
        Relative tolerance.
    atol : numpy.ndarray, shape (2 nv + 1,)
        Absolute tolerances.
    s : numpy.ndarray, shape (SCALARS,)
        The run's scalars (the evaluation counted, a kernel failure's status).
    """
    span = abs(t_span[1] - t_span[0])
    if span == 0.0:
        return 0.0
    scale = atol + np.abs(y0) * rtol
    d0, d1 = _norm(y0, scale), _norm(f0, scale)
    h0 = 1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1
    h0 = min(h0, span)
    f1, sums = np.empty_like(f0), np.empty(4)
    s[NFEV] += 1
    status = _rhs(y0 + h0 * f0, K, n, f1, sums)
    if status != DONE:
        s[KSTATUS] = status
        return -1.0
    d2 = _norm(f1 - f0, scale) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** 0.5
    return min(100 * h0, h1, span)


@numba.njit(cache=True)
def _converge(K, n, y_predict, c, psi, newton, work, s, scale, tol):
    """Newton's iteration, the Jacobian taken again once if it fails.

    Returns ``(converged, iterations, status)`` (scipy's inner loop of ``BDF._step_impl``).
    """
    current, local = False, s[LOCAL] == 1
    while True:
        if s[LU_OK] == 0:
            status = factor(K, newton, c, local)
            if status != DONE:
                return False, 0, status
            s[NLU] += 1
            s[LU_OK] = 1
        converged, n_iter, status = _solve_system(K, n, y_predict, c, psi, newton, work, s,
                                                  scale, tol)  # fmt: skip
        if status != DONE or converged or current:
            return converged, n_iter, status
        s[NJEV] += 1
        status = jacobian_at(K, n, y_predict, newton, s, local)
        if status != DONE:
            return False, n_iter, status
        s[LU_OK], current = 0, True


@numba.njit(cache=True)
def _prediction(D, order):
    """``(y_predict, ψ)``: ``Σ_{j ≤ k} D_j`` and ``Σ_{1 ≤ j ≤ k} γ_j D_j / α_k`` at order k."""
    y, psi = D[0].copy(), np.zeros(D.shape[1])
    for j in range(1, order + 1):
        w = GAMMA[j] / ALPHA[order]
        for i in range(D.shape[1]):
            y[i] += D[j, i]
            psi[i] += w * D[j, i]
    return y, psi


@numba.njit(cache=True)
def _start(K, n, y0, t_span, tolerances, D, newton, s) -> int:
    """A run's start (scipy's ``BDF.__init__``); :data:`DONE` or the kernel's status.

    The first step, the differences ``D[0] = y0``, ``D[1] = h f(y0)`` and the first
    Jacobian; :func:`advance` calls it at a run's first call (one compiled entry point:
    numba compiles each entry with all it calls).
    """
    f0, sums = np.empty_like(y0), np.empty(4)
    status = _rhs(y0, K, n, f0, sums)
    if status != DONE:
        return status
    s[NFEV] += 1
    h0 = initial_step(K, n, y0, f0, t_span, tolerances[0], tolerances[1], s)
    if h0 < 0.0:
        return int(s[KSTATUS])
    s[H] = h0
    D[0] = y0
    D[1] = f0 * h0
    s[NJEV] += 1
    return jacobian_at(K, n, y0, newton, s, s[LOCAL] == 1)


@numba.njit(cache=True)
def _attempt(K, n, t_bound, tolerances, D, newton, s, work) -> int:
    """Steps tried until one is accepted: scipy's ``BDF._step_impl`` up to the update of D.

    Returns :data:`CHUNK_DONE` with ``s[T]``, ``s[H]`` the new time and the step taken
    (``work`` holding y and d), or :data:`TOO_SMALL` or :data:`KERNEL_ERROR`.
    """
    rtol, atol, newton_tol = tolerances
    y_new, d = work[0], work[1]
    t, order = s[T], int(s[ORDER])
    min_step = 10 * abs(np.nextafter(t, np.inf) - t)
    h_abs = s[H]
    if h_abs < min_step:
        _change_D(D, order, min_step / h_abs)
        h_abs, s[EQUAL] = min_step, 0
    while True:
        if h_abs < min_step:
            return TOO_SMALL
        t_new = t + h_abs
        if t_new - t_bound > 0:
            t_new = t_bound
            _change_D(D, order, abs(t_new - t) / h_abs)
            s[EQUAL], s[LU_OK] = 0, 0
        h_abs = abs(t_new - t)
        y_predict, psi = _prediction(D, order)
        scale = atol + rtol * np.abs(y_predict)
        c = h_abs / ALPHA[order]
        converged, n_iter, status = _converge(K, n, y_predict, c, psi, newton, work, s, scale,
                                              newton_tol)  # fmt: skip
        if status != DONE:
            s[KSTATUS] = status
            return KERNEL_ERROR
        if not converged:
            h_abs *= 0.5
            _change_D(D, order, 0.5)
            s[EQUAL], s[LU_OK] = 0, 0
            continue
        safety = 0.9 * (2 * NEWTON_MAXITER + 1) / (2 * NEWTON_MAXITER + n_iter)
        scale = atol + rtol * np.abs(y_new)
        error_norm = _norm(ERROR_CONST[order] * d, scale)
        if error_norm <= 1:
            s[T], s[H], s[EQUAL], s[SAFETY] = t_new, h_abs, s[EQUAL] + 1, safety
            return CHUNK_DONE
        factor = max(MIN_FACTOR, safety * error_norm ** (-1 / (order + 1)))
        h_abs *= factor
        _change_D(D, order, factor)
        s[EQUAL] = 0


@numba.njit(cache=True)
def _power(norm, order) -> float:
    """``norm ** (−1 / order)``, infinite for a zero norm."""
    return np.inf if norm == 0.0 else norm ** (-1.0 / order)


@numba.njit(cache=True)
def _accept(D, s, work, tolerances) -> None:
    """Update the differences with the accepted step; change the order and the step.

    scipy's ``BDF._step_impl`` after the step is accepted.
    """
    rtol, atol = tolerances[0], tolerances[1]
    y_new, d = work[0], work[1]
    order = int(s[ORDER])
    D[order + 2] = d - D[order + 1]
    D[order + 1] = d
    for i in range(order, -1, -1):
        D[i] += D[i + 1]
    if s[EQUAL] < order + 1:
        return
    scale = atol + rtol * np.abs(y_new)
    error_norm = _norm(ERROR_CONST[order] * d, scale)
    m_norm = _norm(ERROR_CONST[order - 1] * D[order], scale) if order > 1 else np.inf
    p_norm = _norm(ERROR_CONST[order + 1] * D[order + 2], scale) if order < MAX_ORDER else np.inf
    factors = np.array([_power(m_norm, order), _power(error_norm, order + 1),
                        _power(p_norm, order + 2)])  # fmt: skip
    order += int(np.argmax(factors)) - 1
    factor = min(MAX_FACTOR, s[SAFETY] * factors.max())
    s[ORDER], s[H] = order, s[H] * factor
    _change_D(D, order, factor)
    s[EQUAL], s[LU_OK] = 0, 0


@numba.njit(cache=True)
def _dense(D, s, t, out) -> None:
    """``out = y(t)`` by the step's interpolating polynomial (scipy's ``BdfDenseOutput``)."""
    order, h, t_now = int(s[ORDER]), s[H], s[T]
    out[:] = D[0]
    p = 1.0
    for j in range(order):
        p *= (t - (t_now - h * j)) / (h * (1 + j))
        out += D[j + 1] * p


@numba.njit(cache=True)
def _emit(t, y, samples, s) -> bool:
    """Write the sample ``(t, y)``; False when the buffer is full."""
    times, states = samples
    i = int(s[NOUT])
    if i >= times.shape[0]:
        return False
    times[i], states[i] = t, y
    s[NOUT] = i + 1
    return True


@numba.njit(cache=True)
def energies(K, n, states, out) -> int:
    """``out[i] = [T, U_g, U_c, P_d]`` of each sample ``states[i] = [q; q̇; E_ψ]``.

    Returns :data:`DONE` or the bushing at gimbal lock.

    Parameters
    ----------
    K : tuple
        The forward kernel's arrays (:class:`rt70.textbook.forward_kernel.ForwardData`).
    n : int
        Coordinates, nv.
    states : numpy.ndarray, shape (m, 2 nv + 1)
        The samples.
    out : numpy.ndarray, shape (m, 4)
        The energies, J, and the dampers' power, W.
    """
    for i in range(states.shape[0]):
        q, v = states[i, :n].copy(), states[i, n : 2 * n].copy()
        status = _residual(q, v, K[K_ZERO], K, K[K_R], out[i])
        if status != DONE:
            return status
    return DONE


@numba.njit(cache=True)
def advance(K, n, t_bound, tolerances, D, newton, s, work, t_eval, samples, max_steps) -> int:
    """At most ``max_steps`` steps towards ``t_bound``, their samples into ``samples``.

    With ``t_eval`` empty every step is a sample, else the samples are at the times of
    ``t_eval`` from ``s[NEXT]`` on, by the dense output. Returns :data:`CHUNK_DONE`,
    :data:`FINISHED`, :data:`FULL` (buffer full: empty it and call again; no sample is
    lost), :data:`TOO_SMALL` or :data:`KERNEL_ERROR` (the kernel's status in
    ``s[KSTATUS]``). The first call of a run (``s[STARTED] == 0``, ``D[0]`` the initial
    state, ``s[T]`` its time) starts it: the first step, ``D[1]`` and the first Jacobian.

    Parameters
    ----------
    K : tuple
        The forward kernel's arrays (:class:`rt70.textbook.forward_kernel.ForwardData`).
    n : int
        Coordinates, nv.
    t_bound : float
        The end of the run, s.
    tolerances : tuple
        ``(rtol, atol, newton_tol)``: scipy's BDF's, atol per state.
    D : numpy.ndarray, shape (MAX_ORDER + 3, 2 nv + 1)
        The backward differences.
    newton : tuple
        Newton's matrix: the Jacobian's parts and their factor
        (:func:`rt70.simulation.bdf_newton.buffers`).
    s : numpy.ndarray, shape (SCALARS,)
        The run's scalars (:data:`T` … :data:`KSTATUS`).
    work : tuple
        Newton's buffers (:func:`_solve_system`).
    t_eval : numpy.ndarray
        Output times, s, or empty for every step.
    samples : tuple
        ``(times, states)`` buffers; ``s[NOUT]`` of them written.
    max_steps : int
        The most steps of this call.
    """
    if s[STARTED] == 0:  # the run's first call: D[0] holds y0
        status = _start(K, n, D[0].copy(), np.array([s[T], t_bound]), tolerances, D, newton, s)
        if status != DONE:
            s[KSTATUS] = status
            return KERNEL_ERROR
        s[STARTED] = 1
    y = np.empty(D.shape[1])
    every_step = t_eval.shape[0] == 0
    for _ in range(max_steps):
        while s[NEXT] < t_eval.shape[0] and t_eval[int(s[NEXT])] <= s[T]:
            _dense(D, s, t_eval[int(s[NEXT])], y)
            if not _emit(t_eval[int(s[NEXT])], y, samples, s):
                return FULL
            s[NEXT] += 1
        if s[T] >= t_bound:
            return FINISHED
        if every_step and s[NOUT] >= samples[0].shape[0]:
            return FULL
        status = _attempt(K, n, t_bound, tolerances, D, newton, s, work)
        if status != CHUNK_DONE:
            return status
        s[NSTEP] += 1
        _accept(D, s, work, tolerances)
        if every_step:
            _emit(s[T], D[0], samples, s)
    return CHUNK_DONE
