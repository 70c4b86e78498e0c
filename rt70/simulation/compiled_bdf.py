"""``simulate(..., method="compiled-BDF")``: scipy's BDF with the whole loop compiled.

For a passive scene the kernels cover (no modal bodies, mimic joints, closed loops,
drives, servos, input forces or events) the integration loop of scipy's BDF, the right-
hand side and its Jacobian run as one compiled program (:mod:`rt70.simulation.bdf_kernel`
on :mod:`rt70.textbook.forward_kernel`). The result is the BDF run's to within the
integration tolerance (``tests/test_compiled_bdf.py`` compares the two), without
scipy's step overhead and Python's call overhead per evaluation.

The loop returns to Python every :data:`CHUNK_STEPS` steps: there the evaluation
budget and memory limit of the other methods are applied
(:class:`rt70.simulation.integrators.EvaluationCounter`), a Ctrl-C is raised, the progress
bar moves and the samples are collected. The energy audit is the other methods': T,
U_g and U_c of each sample and the dissipated energy integrated as a state.
"""

from __future__ import annotations

import sys
import threading
import time

import numpy as np

from rt70.errors import Rt70Error
from rt70.guards.arrays import check_vector
from rt70.guards.resources import time_series_samples
from rt70.model.scene import Scene
from rt70.simulation import bdf_kernel as bk
from rt70.simulation import bdf_newton
from rt70.simulation.integrators import COMPILED_BDF, EvaluationCounter
from rt70.simulation.request import run_compiled, uncovered
from rt70.simulation.result import (
    DRIFT_FACTOR,
    SimulationResult,
    coordinate_units,
    energy_balance,
    initial_energy_scale,
)
from rt70.textbook import forward_kernel
from rt70.textbook.spatial import check_euler_pairs

#: The method's name in :func:`rt70.simulation.simulate.simulate` and ``rt70 simulate``.
METHOD = COMPILED_BDF
#: Steps between two returns to Python.
CHUNK_STEPS = 64
#: Samples collected per return when every step is a sample.
BUFFER_ROWS = 4096
#: Seconds of loading the kernels after which a line on stderr says they compile.
COMPILE_NOTICE_S = 3.0


def run(
    scene: Scene,
    t_span: tuple[float, float],
    x0: tuple[np.ndarray, np.ndarray] | None,
    tolerances: tuple[float, float | None],
    inputs,
    progress: bool,
    t_eval: np.ndarray | None,
    extras: dict,
) -> SimulationResult:
    """:func:`simulate_bdf` for :func:`rt70.simulation.simulate.simulate`'s arguments.

    Parameters
    ----------
    scene, t_span, x0, progress, t_eval
        As :func:`simulate_bdf` (checked by :func:`rt70.simulation.request.checked_request`).
    tolerances : (rtol, atol or None)
        ``atol`` defaults to ``1e-3 rtol`` (as the other methods').
    inputs : None
        Refused unless None: the compiled loop takes no input forces.
    extras : dict
        ``components`` and ``events`` (refused unless empty) and ``outputs``:
        ``(outputs, side)``, the quantities evaluated on the trajectory by ``side``.
    """
    refused = {"inputs": inputs, "components": extras["components"], "events": extras["events"]}
    return run_compiled(
        METHOD, scene, x0, tolerances, refused, extras["outputs"],
        lambda tol: simulate_bdf(scene, t_span, x0, tol, progress, t_eval),
    )  # fmt: skip


def _data(scene: Scene) -> forward_kernel.ForwardData:
    """The scene's kernel data, refused for what the kernels do not cover."""
    data = forward_kernel.ForwardData.of(scene.textbook)
    if data is None or scene.description.loops:
        raise uncovered(scene, METHOD)
    return data


def pair_local(data: forward_kernel.ForwardData) -> bool:
    """Newton's matrix in the pair-local form (:mod:`rt70.simulation.bdf_newton`).

    Parameters
    ----------
    data : ForwardData
        The scene's kernel data: the form is pair-local when every bushing acts across
        one pair.
    """
    return data.motion.local


def _work(size: int, n: int) -> tuple[np.ndarray, ...]:
    """Newton's buffers (:func:`bk._solve_system`): y, d, q̈*, Δy, the residual, sums."""
    return (np.empty(size), np.empty(size), np.empty(n), np.empty(size), np.empty(size),
            np.empty(4))  # fmt: skip


class _Run:
    """The compiled loop's state for one run: the arrays :func:`bk.advance` takes."""

    def __init__(self, scene, data, y0, t_span, tolerances, cap) -> None:
        model, n = scene.textbook, scene.textbook.nv
        size = y0.size
        self.n, self.t_span, self.tolerances = n, t_span, tolerances
        self.K = data.arrays
        self.s = np.zeros(bk.SCALARS)
        local = pair_local(data)
        self.s[bk.T], self.s[bk.ORDER], self.s[bk.LOCAL] = t_span[0], 1, local
        self.D = np.zeros((bk.MAX_ORDER + 3, size))
        self.newton = bdf_newton.buffers(n, model.nb, local)
        self.work = _work(size, n)
        self.samples = (np.empty(cap), np.empty((cap, size)))
        self.D[0] = y0  # the loop's first call starts the run from it

    def advance(self, t_eval: np.ndarray, max_steps: int = CHUNK_STEPS) -> int:
        """:func:`bk.advance` for at most ``max_steps`` steps."""
        return bk.advance(self.K, self.n, self.t_span[1], self.tolerances, self.D, self.newton,
                          self.s, self.work, t_eval, self.samples, max_steps)  # fmt: skip

    def collect(self) -> tuple[np.ndarray, np.ndarray]:
        """The samples written since the last call, copied; the buffer emptied."""
        m = int(self.s[bk.NOUT])
        self.s[bk.NOUT] = 0
        return tuple(x[:m].copy() for x in self.samples)


def _energies(model, data: forward_kernel.ForwardData, y: np.ndarray) -> np.ndarray:
    """``[T, U_g, U_c, P_d]`` of each state ``y[i] = [q; q̇; E_ψ]`` (:func:`bk.energies`)."""
    out = np.empty((y.shape[0], 4))
    forward_kernel.raise_status(model, data, bk.energies(data.arrays, model.nv, y, out))
    data.motion.placed[:] = np.nan
    return out


def _load(scene: Scene, data: forward_kernel.ForwardData, y0: np.ndarray, tolerances) -> None:
    """Call the loop for no step and no start, before the clock starts.

    numba loads every kernel's cached code then, or compiles it: after an install or a
    change to a kernel's source (:mod:`rt70.guards.kernel_cache`), which takes about a
    minute. A load still going after :data:`COMPILE_NOTICE_S` says so on stderr.
    """
    run = _Run(scene, data, y0, (0.0, 1.0), tolerances, 1)
    run.s[bk.STARTED] = 1
    notice = threading.Timer(COMPILE_NOTICE_S, _say_compiling)
    notice.daemon = True
    notice.start()
    try:
        run.advance(np.empty(0), max_steps=0)
    finally:
        notice.cancel()


def _say_compiling() -> None:
    print(
        f"rt70: compiling the {METHOD} kernels (once after an install or a change to a "
        "kernel: about a minute)",
        file=sys.stderr,
        flush=True,
    )


def simulate_bdf(
    scene: Scene,
    t_span: tuple[float, float],
    x0: tuple[np.ndarray, np.ndarray] | None,
    tolerances: tuple[float, float],
    progress: bool = False,
    t_eval: np.ndarray | None = None,
) -> SimulationResult:
    """Integrate the passive ``scene`` by scipy's BDF compiled with its equations.

    Parameters
    ----------
    scene : Scene
        A scene the kernels cover (no modal bodies, mimic joints or loops).
    t_span : (t0, t1)
        Time interval, s.
    x0 : (q0, q̇0) or None
        Initial state (default rest at q = 0), in the file's coordinate order.
    tolerances : (rtol, atol)
        scipy's BDF tolerances; atol of q and q̇ (the dissipated energy's is rtol times
        the initial energy scale, as the other methods').
    progress : bool
        Show a progress bar (tqdm) on stderr.
    t_eval : numpy.ndarray, optional
        Output times, s, increasing within ``t_span`` (the dense output there); default
        every step.
    """
    from tqdm import tqdm

    model, data = scene.textbook, _data(scene)
    n = model.nv
    q0, v0 = (np.zeros(n), np.zeros(n)) if x0 is None else x0
    q0, v0 = check_vector("initial state q0", q0, n), check_vector("initial state qd0", v0, n)
    check_euler_pairs(model, model.expand(q0))
    t0, t1 = map(float, t_span)
    try:
        scale = initial_energy_scale(*_energies(model, data, np.r_[q0, v0, 0.0][None])[0, :3])
    except Rt70Error as exc:
        raise type(exc)(f"{scene.name}: at the initial state: {exc}") from None
    rtol, atol = tolerances
    atol_vec = np.r_[np.full(2 * n, atol), rtol * scale]
    newton_tol = max(10 * np.finfo(float).eps / rtol, min(0.03, rtol**0.5))
    y0 = np.r_[q0, v0, 0.0]
    limit = None if t_eval is not None else time_series_samples(2 * n + 5)
    counter = EvaluationCounter(t1 - t0, limit, t0)
    t_eval = np.empty(0) if t_eval is None else np.asarray(t_eval, dtype=float)
    cap = t_eval.size + 1 if t_eval.size else BUFFER_ROWS
    shape = "{l_bar}{bar}| {n:.3f}/{total:.3f} s [{elapsed}<{remaining}]"
    bar = tqdm(total=t1 - t0, disable=not progress, bar_format=shape)
    try:
        _load(scene, data, y0, (rtol, atol_vec, newton_tol))  # not timed
        start = time.perf_counter()
        state = _Run(scene, data, y0, (t0, t1), (rtol, atol_vec, newton_tol), cap)
        chunks, status = [], bk.CHUNK_DONE
        if not t_eval.size:  # the start is a sample, as solve_ivp's
            bk._emit(t0, y0, state.samples, state.s)
        while status in (bk.CHUNK_DONE, bk.FULL):
            evaluations = state.s[bk.NFEV]
            status = state.advance(t_eval)
            counter.add(int(state.s[bk.NFEV] - evaluations), state.s[bk.T])
            bar.update(state.s[bk.T] - t0 - bar.n)
            if status != bk.CHUNK_DONE:
                chunks.append(state.collect())
        wall = time.perf_counter() - start
    except Rt70Error as exc:
        raise type(exc)(f"{scene.name}: {exc}") from None
    finally:
        bar.close()
    data.motion.placed[:] = np.nan
    if status == bk.KERNEL_ERROR:
        try:
            forward_kernel.raise_status(model, data, int(state.s[bk.KSTATUS]))
        except Rt70Error as exc:
            reached = state.s[bk.T]
            raise type(exc)(
                f"{scene.name}: integration stopped at t = {reached:.6g} s: {exc}"
            ) from None
    t, y = (np.concatenate(c) for c in zip(*chunks, strict=True))
    return _result(scene, state, (t, y, _energies(model, data, y)), (rtol, atol), (wall, status))


def _result(scene: Scene, state: _Run, samples, tolerances, clock) -> SimulationResult:
    """The run as a :class:`SimulationResult` with its energy audit."""
    t, y, (T, U_g, U_c, _) = samples[0], samples[1], samples[2].T
    n, s = state.n, state.s
    wall, status = clock
    E_psi, W_u = y[:, 2 * n], np.zeros(t.size)
    balance, exchanged = energy_balance(T, U_g, U_c, E_psi, W_u)
    rtol, atol = tolerances
    success = status == bk.FINISHED
    message = (
        "The solver successfully reached the end of the integration interval."
        if success
        else "Required step size is less than spacing between numbers."
    )
    result = SimulationResult(
        scene=scene.name,
        side="compiled",
        method=METHOD,
        rtol=rtol,
        atol=atol,
        t=t,
        q=y[:, :n],
        qd=y[:, n : 2 * n],
        kinetic=T,
        gravity=U_g,
        elastic=U_c,
        dissipated=E_psi,
        input_work=W_u,
        balance=balance,
        balance_scale=max(exchanged, initial_energy_scale(T[0], U_g[0], U_c[0])),
        nfev=int(s[bk.NFEV]),
        njev=int(s[bk.NJEV]),
        nlu=int(s[bk.NLU]),
        n_steps=int(s[bk.NSTEP]),
        wall_time_s=wall,
        success=success,
        message=message,
        coordinates=list(scene.textbook.coordinate_names),
        states={"dissipated": E_psi, "input_work": W_u},
        timing={"integrator": wall},
        coordinate_units=coordinate_units(scene),
    )
    result.drift_flagged = result.relative_drift > DRIFT_FACTOR * rtol
    return result
