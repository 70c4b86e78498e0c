"""The worker process of the work–precision report: runs that can be abandoned at a cap.

Every run happens in a worker process (:mod:`multiprocessing`, ``spawn``) that keeps its
scenes and runs with BLAS and OpenMP pinned to one thread
(:func:`rt70.reports.threads.single_threaded`); the parent waits for the result at most
the cap plus a small allowance for the post-processing, then kills the worker (and
starts a new one for the next run). Besides the state it sends back the positions of
the bodies' centres of mass on the output grid (:func:`com_positions`), the engineering
metric of the simulation-speed targets.
"""

from __future__ import annotations

import contextlib
import math
import multiprocessing
import multiprocessing.connection
import traceback
import warnings
from dataclasses import dataclass

import numpy as np

from rt70.errors import Rt70Error
from rt70.reports.work_precision_problems import Problem, build_problem

#: Seconds allowed beyond the cap for what follows ``solve_ivp`` (energies, transfer):
#: ``_SLACK_S + _SLACK_FRACTION · cap``.
_SLACK_S = 0.5
_SLACK_FRACTION = 0.1
#: Seconds allowed for a worker to build a problem (load URDF, Pinocchio, Ω1) and load a
#: method's code (:func:`_load`).
_BUILD_TIMEOUT_S = 300.0

#: The scenes built in this (worker) process, by problem.
_CACHE: dict[Problem, tuple[object, tuple[np.ndarray, np.ndarray], str]] = {}
#: The (problem, method) pairs whose code this worker has loaded (:func:`_load`).
_LOADED: set[tuple[Problem, str]] = set()
#: The span of :func:`_load`'s run, as a fraction of the problem's.
_LOAD_FRACTION = 1e-6


def com_positions(scene, q: np.ndarray) -> np.ndarray:
    """World positions of the centres of mass of the bodies with mass, m, at each row of q.

    Computed on the reference side: for each Pinocchio joint ``i`` carrying mass (the
    bodies rigidly attached to it merged into one inertia), ``c_i = oMi[i] · lever_i``
    after ``forwardKinematics``.

    Parameters
    ----------
    scene : Scene
        The scene the trajectory belongs to (its Pinocchio model computes the positions).
    q : (n_t, nv) array
        Book coordinates along a trajectory.

    Returns
    -------
    (n_t, n_bodies, 3) array
    """
    import pinocchio as pin

    from rt70.reference.coordinates import to_pinocchio

    ref, rd = scene.reference, scene.reference_data
    model, data = ref.pin_model, rd.pin_data
    massive = [i for i in range(1, model.njoints) if model.inertias[i].mass > 0.0]
    levers = [model.inertias[i].lever for i in massive]
    out = np.empty((len(q), len(massive), 3))
    for k, qk in enumerate(q):
        qp = to_pinocchio(ref, qk)[0]
        pin.forwardKinematics(model, data, qp)
        for j, (i, lever) in enumerate(zip(massive, levers, strict=True)):
            out[k, j] = data.oMi[i].act(lever)
    return out


def _worker_main(conn: multiprocessing.connection.Connection) -> None:
    """Serve run requests on ``conn`` until told to stop (runs in the worker process)."""
    from rt70.reports.threads import single_threaded

    warnings.simplefilter("ignore")  # solve_ivp warns that `jac` is unused by RK methods
    with single_threaded() as pinning:
        _serve(conn, pinning.unpinned)


def _serve(conn: multiprocessing.connection.Connection, unpinned: str) -> None:
    """The request loop of :func:`_worker_main` (thread pools already pinned)."""
    from rt70.reports.threads import max_threads
    from rt70.simulation.simulate import simulate

    while True:
        try:
            request = conn.recv()
        except EOFError:
            return
        if request is None:
            return
        problem, method, rtol, atol = request
        try:
            if problem not in _CACHE:
                scene, x0, notes = build_problem(problem)
                _ = scene.reference_data, scene.textbook_data  # built outside the timing
                _CACHE[problem] = scene, x0, notes
            scene, x0, notes = _CACHE[problem]
            if (problem, method) not in _LOADED:
                _load(simulate, scene, problem, method, x0)
                _LOADED.add((problem, method))
            conn.send(("ready", scene.textbook.nv, notes, max_threads(), unpinned))
            res = simulate(
                scene,
                (0.0, problem.t_end),
                x0=x0,
                method=method,
                rtol=rtol,
                atol=atol,
                t_eval=problem.t_eval,
            )
            x = np.hstack([res.q, res.qd]) if res.success else None
            com = com_positions(scene, res.q) if res.success else None
            timing = dict(getattr(res, "timing", None) or {})  # CVODE's split, once merged
            stats = (res.wall_time_s, res.success, res.message, res.nfev, res.njev, res.nlu)
            conn.send(("result", stats, res.atol, x, com, res.n_steps, timing))
        except Exception:  # reported to the parent, which decides
            conn.send(("error", traceback.format_exc()))


def _load(simulate, scene, problem: Problem, method: str, x0) -> None:
    """A run of the method over a short span, before any timed run, under the build timeout.

    A compiled method's kernels are compiled on their first call after an install (for
    ``compiled-BDF`` about a minute, longer on a loaded machine) and loaded from numba's
    cache in every later process; neither belongs to a run's time, nor should the first
    tolerance of the ladder be over the cap for it. A failure is left to the timed run,
    which reports it.
    """
    with contextlib.suppress(Exception):
        simulate(scene, (0.0, _LOAD_FRACTION * problem.t_end), x0=x0, method=method, rtol=1e-3)


@dataclass
class Attempt:
    """Outcome of one run in the worker."""

    status: str  # "ok", "over cap", "failed: ..."
    wall_s: float = math.nan
    atol: float = math.nan
    nfev: int = 0
    njev: int = 0
    nlu: int = 0
    x: np.ndarray | None = None
    com: np.ndarray | None = None  # (n_t, n_bodies, 3) centres of mass, m
    n_steps: int = -1  # -1: not known (scipy with t_eval)
    timing: dict | None = None  # {"rhs", "jacobian", "integrator"} s, when measured


class Worker:
    """A worker process that runs a simulation, abandoned at a time cap.

    The simulation is :func:`~rt70.simulation.simulate.simulate`.
    """

    def __init__(self) -> None:
        self.process: multiprocessing.process.BaseProcess | None = None
        self.conn: multiprocessing.connection.Connection | None = None
        self.nv: dict[Problem, int] = {}
        self.notes: dict[Problem, str] = {}
        self.threads: dict[Problem, tuple[int, str]] = {}  # (pinned, unpinned)

    def _start(self) -> None:
        ctx = multiprocessing.get_context("spawn")
        parent, child = ctx.Pipe()
        process = ctx.Process(target=_worker_main, args=(child,), daemon=True)
        process.start()
        child.close()
        self.process, self.conn = process, parent

    def kill(self) -> None:
        """End the worker process (the one this object started) now."""
        if self.process is not None:
            if self.process.is_alive():
                self.process.kill()
            self.process.join()
        if self.conn is not None:
            self.conn.close()
        self.process = self.conn = None

    def close(self) -> None:
        """Ask the worker to stop, then make sure it has."""
        if self.process is not None and self.process.is_alive() and self.conn is not None:
            try:
                self.conn.send(None)
                self.process.join(5.0)
            except (BrokenPipeError, OSError):
                pass
        self.kill()

    def _receive(self, timeout: float):
        assert self.conn is not None
        if not self.conn.poll(None if math.isinf(timeout) else timeout):  # inf: no cap
            return None
        try:
            return self.conn.recv()
        except EOFError:
            return ("error", "worker process died")

    def run(self, problem: Problem, method: str, rtol: float, atol: float | None, cap: float):
        """One run; abandoned (worker killed) when not back within ``cap`` + slack.

        Parameters
        ----------
        problem : Problem
            The test problem; the worker builds its scene once and keeps it.
        method : str
            Integrator of :func:`~rt70.simulation.simulate.simulate`.
        rtol : float
            Relative tolerance.
        atol : float or None
            Absolute tolerance; None: the default of
            :func:`~rt70.simulation.simulate.simulate`.
        cap : float
            Wall-time cap of the integration, s (``inf``: none).

        Returns
        -------
        Attempt
            ``ok``, ``over cap`` or ``failed: <message>``, with the run's statistics.

        Raises
        ------
        Rt70Error
            If the problem cannot be built in the worker.
        """
        if self.process is None or not self.process.is_alive():
            self.kill()
            self._start()
        assert self.conn is not None
        self.conn.send((problem, method, rtol, atol))
        msg = self._receive(_BUILD_TIMEOUT_S)
        if msg is None:
            self.kill()
            raise Rt70Error(
                f"{problem.name}: building the problem and loading {method}'s code took over "
                f"{_BUILD_TIMEOUT_S} s"
            )
        if msg[0] == "error":
            self.kill()
            raise Rt70Error(f"{problem.name}: worker failed:\n{msg[1]}")
        self.nv[problem], self.notes[problem], self.threads[problem] = msg[1], msg[2], msg[3:5]
        msg = self._receive(cap * (1.0 + _SLACK_FRACTION) + _SLACK_S)
        if msg is None:
            self.kill()
            return Attempt("over cap")
        if msg[0] == "error":
            self.kill()
            return Attempt("failed: " + msg[1].strip().splitlines()[-1])
        (wall, success, message, nfev, njev, nlu), used_atol, x, com, steps, timing = msg[1:]
        if wall > cap:
            return Attempt("over cap", wall, used_atol, nfev, njev, nlu, n_steps=steps)
        if not success:
            return Attempt(f"failed: {message}", wall, used_atol, nfev, njev, nlu, n_steps=steps)
        return Attempt("ok", wall, used_atol, nfev, njev, nlu, x, com, steps, timing)
