"""Work–precision report of the integrators of :func:`rt70.simulate.simulate`.

For each test problem and each ``solve_ivp`` method the run is repeated over a ladder
of relative tolerances; every run gives one point (run time, error) of the method's
work–precision curve.

Problems
--------
``rt70``
    ``urdf/rt70.urdf`` from the §4.2.3 listing's initial state over ``T = 2 s`` with the
    listing's damping (mostly 0.1 × stiffness; ξ = 0.105 on the first elastic mode).
``rt70_light``
    The same scene with every damping replaced by ``δ · stiffness``, δ = 0.1/Ω1 (the
    book's rule (2.16), ξ = 0.05 on the first elastic mode; :func:`light_damping_text`),
    same state and span. Ω1 is the first elastic eigenfrequency of the linear model at
    the static equilibrium with the drives holding the listing's pointing
    (``platform_rz = base_rx = 0.8 rad``) and the two axes locked
    (:func:`first_elastic_mode`). The pointing matters (Ω1 = 1.91 rad/s at the zenith,
    2.10 rad/s at the listing's pointing); the run starts at the listing's pointing, so
    Ω1 is taken there. Locking the axes removes the rigid azimuth mode and gravity's
    unstable elevation mode, which are not resonances of the structure.
``double_pendulum``
    ``urdf/double_pendulum.urdf`` (no springs) from ``q = (1.0, −0.5) rad``, ``q̇ = 0``
    over 5 s. q = 0 is the arm stretched horizontally (gravity along −y), so this is a
    large, chaotic swing.
``chain``
    ``serial_chain(50)`` (50 revolute joints, about 40 % of them with springs) from
    ``q`` uniform in ±0.3 rad (seed 1), ``q̇ = 0``, over 1 s: the long, non-stiff chain
    (``elastic_chain(20)`` is as stiff as the RT-70 and would add nothing). Over 2 s the
    chain whips (|q̇| up to 75 rad/s) and is chaotic enough that the errors of all loose
    tolerances saturate at O(1) and the two references part to 2e-9; over 1 s they agree
    to 5e-12.

Both RT-70 problems are stiff (damped eigenvalues down to −4·10⁵ s⁻¹): the explicit
methods need steps of a few µs there and cannot finish within the time cap.

Accuracy
--------
The state is ``x = (q, q̇)`` (the energy-audit states are left out). On the output grid
``t_eval`` (``N_EVAL`` points over the span, the same for every run),
``error = max_t ‖x(t) − x_ref(t)‖∞ / max_t ‖x_ref(t)‖∞``.
The reference is computed at ``rtol = 1e-12`` by a *different* method than the one
measured: each problem has a primary and an alternate reference method
(``Problem.references``); rows of the primary method are measured against the
alternate one. The two references are compared with each other by the same formula:
that is the floor of the measurement (``reference_floor``), below which errors mean
nothing. The non-stiff problems use DOP853 (alternate LSODA) with the default
``atol``; the RT-70 problems use Radau (alternate BDF) with ``atol = 1e-12`` — the
default ``atol = 1e-3·rtol = 1e-15`` is below the rounding level of the stiff forces
and makes BDF take 186 s instead of 3 s for the same result to 5e-10.

Time and the cap
----------------
Time is the best of ``REPEATS`` (3) values of ``SimulationResult.wall_time_s`` (the
``solve_ivp`` call only). Every run happens in a worker process
(:mod:`multiprocessing`, ``spawn``) that keeps its scenes; the parent waits for the
result at most the cap plus a small allowance for the post-processing, then kills the
worker (and starts a new one for the next run). A run over the cap is reported as
``over cap`` after one attempt, and the tighter tolerances of the same method on the
same problem are not run (reported ``over cap (not run)``): a tighter tolerance is
assumed to cost at least as much. The worker runs with BLAS and OpenMP pinned to one
thread (:func:`rt70.threads.single_threaded`; every row records the thread count read back
from the pools and what they would use otherwise): on this 2-core machine a threaded
102 × 102 complex LU (Radau on the 50-body chain) takes 30 times longer than a
single-threaded one.

Targets
-------
:func:`check_targets` judges the targets of issues 5 and 13 that this report measures:
the RT-70 (listing damping) integrated to state error ≤ 1e-6 at ≥ 50× real time, i.e.
in ≤ T/50 of wall time (0.2 s for the 10 s transient). The report's span is T = 2 s,
its error the state error above; the quick run's 0.05 s span measures start-up more than
the transient, so it prints the value but does not judge it. The whole-command time, the
centre-of-mass error in metres and the energy balance are not measured here.
"""

from __future__ import annotations

import csv
import io
import math
import multiprocessing
import multiprocessing.connection
import time
import traceback
import warnings
import xml.etree.ElementTree as ET
from collections.abc import Callable
from dataclasses import asdict, dataclass, fields
from pathlib import Path

import numpy as np

from rt70.atomic import atomic_write, atomic_write_text
from rt70.errors import Rt70Error
from rt70.targets import TargetCheck

#: Methods measured (``solve_ivp`` names).
METHODS = ("RK45", "DOP853", "Radau", "BDF", "LSODA")
#: The tolerance ladder (relative tolerance; ``atol`` is :func:`simulate`'s default).
RTOLS = tuple(10.0**-k for k in range(3, 10))
#: Relative tolerance of the references.
REFERENCE_RTOL = 1e-12
#: Attempts per run; the best wall time is reported.
REPEATS = 3
#: Wall-time cap per run, s.
TIME_CAP_S = 20.0
#: Cap of a reference run, s (a reference over it is an error).
REFERENCE_CAP_S = 240.0
#: Points of the output grid on which runs are compared.
N_EVAL = 201
#: The accuracy at which the summary compares methods (error ≤ this).
TARGET_ERROR = 1e-6

#: The target problem and its targets (issues 5 and 13): error ≤ this, real-time factor ≥ that.
TARGET_PROBLEM = "rt70"
REAL_TIME_TARGET = 50.0
#: Seconds allowed beyond the cap for what follows ``solve_ivp`` (energies, transfer):
#: ``_SLACK_S + _SLACK_FRACTION · cap``.
_SLACK_S = 0.5
_SLACK_FRACTION = 0.1
#: Seconds allowed for a worker to build a problem (load URDF, Pinocchio, Ω1).
_BUILD_TIMEOUT_S = 300.0


@dataclass(frozen=True)
class Problem:
    """One test problem.

    Attributes
    ----------
    name : str
        Key of the problem (``rt70``, ``rt70_light``, ``double_pendulum``, ``chain``).
    t_end : float
        The span is ``(0, t_end)``, s.
    references : (str, str)
        Primary and alternate reference methods: a run of the primary method is
        measured against the alternate one, every other run against the primary.
    reference_atol : float or None
        ``atol`` of the reference runs (None: :func:`simulate`'s default).
    chain_bodies : int
        Bodies of the chain (``chain`` only).
    """

    name: str
    t_end: float
    references: tuple[str, str]
    reference_atol: float | None = None
    chain_bodies: int = 50

    @property
    def t_eval(self) -> np.ndarray:
        """The output grid shared by all runs."""
        return np.linspace(0.0, self.t_end, N_EVAL)

    def reference_for(self, method: str) -> str:
        """The reference method for runs of ``method`` (never ``method`` itself)."""
        primary, alternate = self.references
        return alternate if method == primary else primary


_STIFF_REFS = ("Radau", "BDF")
_SMOOTH_REFS = ("DOP853", "LSODA")

#: The full report's problems.
PROBLEMS = (
    Problem("rt70", 2.0, _STIFF_REFS, 1e-12),
    Problem("rt70_light", 2.0, _STIFF_REFS, 1e-12),
    Problem("double_pendulum", 5.0, _SMOOTH_REFS),
    Problem("chain", 1.0, _SMOOTH_REFS, chain_bodies=50),
)
#: Problems of the quick run (tests): short spans, a 10-body chain.
QUICK_PROBLEMS = (
    Problem("rt70", 0.05, _STIFF_REFS, 1e-12),
    Problem("double_pendulum", 1.0, _SMOOTH_REFS),
    Problem("chain", 0.5, _SMOOTH_REFS, chain_bodies=10),
)
#: Tolerances, cap and repeats of the quick run.
QUICK_RTOLS = (1e-3, 1e-6)
QUICK_CAP_S = 2.0
QUICK_REPEATS = 2


@dataclass(frozen=True)
class Row:
    """One run: a method at one tolerance on one problem.

    ``status`` is ``ok``, ``over cap`` (abandoned at the cap), ``over cap (not run)``
    (a looser tolerance of the same method was over the cap) or ``failed: <message>``.
    ``error`` and ``time_s`` are NaN unless the status is ``ok``; ``times_s`` lists the
    attempts. ``reference`` names the reference of this row and ``reference_floor`` is
    the error of the alternate reference against the primary one (the measurement
    floor). ``notes`` describes the problem. ``threads`` is the largest BLAS/OpenMP thread
    count in the worker (1: pinned), ``threads_unpinned`` what its pools would use
    otherwise (``"openblas 2, openmp 2"``).
    """

    problem: str
    nv: int
    t_end: float
    method: str
    rtol: float
    atol: float
    status: str
    over_cap: bool
    error: float
    time_s: float
    times_s: str
    nfev: int
    njev: int
    nlu: int
    cap_s: float
    reference: str
    reference_floor: float
    notes: str
    threads: int
    threads_unpinned: str


# ---------------------------------------------------------------------------------------
# Problems: scenes and initial states
# ---------------------------------------------------------------------------------------


def listing_pointing(scene) -> dict[str, float]:
    """The RT-70 drive coordinates held at the listing's initial values (rad)."""
    from rt70.linear import linearize as lin
    from rt70.simulate import listing_initial_state

    q0, _ = listing_initial_state(scene)
    names = scene.textbook.coordinate_names
    axes = (lin.AZIMUTH_COORDINATE, lin.ELEVATION_COORDINATE)
    return {c: float(q0[names.index(c)]) for c in axes}


def first_elastic_mode(scene) -> tuple[float, float]:
    """Ω1 (rad/s) and its ξ of the RT-70 linearised at the listing's pointing, axes locked.

    The drives hold ``platform_rz`` and ``base_rx`` at the listing's initial values
    (:func:`listing_pointing`), the static equilibrium of the other coordinates is
    solved (:func:`rt70.linear.linearize.equilibrium`), the linear model is taken there
    with the two axes locked (:func:`rt70.linear.linearize.linearize`) and Ω1 is its
    lowest elastic eigenfrequency (:func:`rt70.linear.modal.modes`).

    Parameters
    ----------
    scene : Scene
        An RT-70 scene (``rt70.urdf`` or an edited copy).

    Returns
    -------
    omega1 : float
        Ω1, rad/s.
    zeta1 : float
        Damping ratio of that mode (``(VᵀDV)₁₁ / 2Ω1``).
    """
    from rt70.linear import linearize as lin
    from rt70.linear import modal

    held = listing_pointing(scene)
    model = lin.linearize(scene, lin.equilibrium(scene, held), locked=tuple(held))
    result = modal.modes(model.M, model.K, model.D)
    first = np.flatnonzero(result.elastic)[0]
    return float(result.omega[first]), float(result.zeta[first])


def light_damping_text(text: str, delta: float) -> str:
    """URDF text with every damping replaced by ``delta · stiffness``.

    Every rt70 element carrying a ``stiffness`` attribute (``<rt70:bushing>``,
    ``<rt70:strut>``, ``<rt70:joint_spring>``) gets ``damping = delta · stiffness``,
    component by component (the book's proportional damping ``D = δ C``, (2.16)).

    Parameters
    ----------
    text : str
        URDF text.
    delta : float
        δ, s (non-negative).

    Returns
    -------
    str
        The edited URDF text (comments dropped).
    """
    from rt70.scenes.generate import fmt_vec
    from rt70.urdf import RT70_NS

    if not (math.isfinite(delta) and delta >= 0.0):
        raise Rt70Error(f"damping factor δ must be finite and non-negative, got {delta}")
    ET.register_namespace("rt70", RT70_NS)
    root = ET.fromstring(text)
    for elem in root.iter():
        if isinstance(elem.tag, str) and elem.tag.startswith("{" + RT70_NS + "}"):
            stiffness = elem.get("stiffness")
            if stiffness is not None:
                k = np.array(stiffness.split(), dtype=float)
                elem.set("damping", fmt_vec(delta * k))
    return '<?xml version="1.0"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


def build_problem(problem: Problem) -> tuple[object, tuple[np.ndarray, np.ndarray], str]:
    """The scene, initial state and a one-line description of a problem.

    Returns
    -------
    scene : Scene
    x0 : (q0, q̇0)
    notes : str
    """
    from rt70.scene import load_scene, scene_from_text
    from rt70.scenes import synthetic
    from rt70.simulate import listing_initial_state

    T = f"T = {problem.t_end:g} s"
    if problem.name == "rt70":
        scene = load_scene("rt70")
        return scene, listing_initial_state(scene), f"listing state and damping, {T}"
    if problem.name == "rt70_light":
        from rt70.linear.topology import book_delta

        base = load_scene("rt70")
        omega1, zeta0 = first_elastic_mode(base)
        delta = book_delta(omega1)
        scene = scene_from_text(light_damping_text(base.text, delta), "rt70_light")
        _, zeta1 = first_elastic_mode(scene)
        notes = (
            f"listing state; damping = δ·stiffness, δ = 0.1/Ω1 = {delta:.4g} s "
            f"(Ω1 = {omega1:.4g} rad/s; ξ1 = {zeta1:.3f}, listing's {zeta0:.3f}), {T}"
        )
        return scene, listing_initial_state(scene), notes
    if problem.name == "double_pendulum":
        scene = load_scene("double_pendulum")
        return scene, (np.array([1.0, -0.5]), np.zeros(2)), f"q = (1, -0.5) rad, q̇ = 0, {T}"
    if problem.name == "chain":
        n = problem.chain_bodies
        scene = scene_from_text(synthetic.serial_chain(n), f"chain_{n}")
        q0 = np.random.default_rng(1).uniform(-0.3, 0.3, scene.textbook.nv)
        notes = f"serial_chain({n}), q uniform in ±0.3 rad (seed 1), q̇ = 0, {T}"
        return scene, (q0, np.zeros(scene.textbook.nv)), notes
    raise Rt70Error(f"unknown work-precision problem '{problem.name}'")


# ---------------------------------------------------------------------------------------
# The worker process
# ---------------------------------------------------------------------------------------

_CACHE: dict[Problem, tuple[object, tuple[np.ndarray, np.ndarray], str]] = {}


def _worker_main(conn: multiprocessing.connection.Connection) -> None:
    """Serve run requests on ``conn`` until told to stop (runs in the worker process)."""
    from rt70.threads import single_threaded

    warnings.simplefilter("ignore")  # solve_ivp warns that `jac` is unused by RK methods
    with single_threaded() as pinning:
        _serve(conn, pinning.unpinned)


def _serve(conn: multiprocessing.connection.Connection, unpinned: str) -> None:
    """The request loop of :func:`_worker_main` (thread pools already pinned)."""
    from rt70.simulate import simulate
    from rt70.threads import max_threads

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
                _ = scene.reference, scene.textbook_data  # built outside the timing
                _CACHE[problem] = scene, x0, notes
            scene, x0, notes = _CACHE[problem]
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
            stats = (res.wall_time_s, res.success, res.message, res.nfev, res.njev, res.nlu)
            conn.send(("result", stats, res.atol, x))
        except Exception:  # reported to the parent, which decides
            conn.send(("error", traceback.format_exc()))


@dataclass
class _Attempt:
    """Outcome of one run in the worker."""

    status: str  # "ok", "over cap", "failed: ..."
    wall_s: float = math.nan
    atol: float = math.nan
    nfev: int = 0
    njev: int = 0
    nlu: int = 0
    x: np.ndarray | None = None


class _Worker:
    """A worker process that runs :func:`simulate` and can be abandoned at a time cap."""

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
        if not self.conn.poll(timeout):
            return None
        try:
            return self.conn.recv()
        except EOFError:
            return ("error", "worker process died")

    def run(self, problem: Problem, method: str, rtol: float, atol: float | None, cap: float):
        """One run; abandoned (worker killed) when not back within ``cap`` + slack."""
        if self.process is None or not self.process.is_alive():
            self.kill()
            self._start()
        assert self.conn is not None
        self.conn.send((problem, method, rtol, atol))
        msg = self._receive(_BUILD_TIMEOUT_S)
        if msg is None:
            self.kill()
            raise Rt70Error(f"{problem.name}: building the problem took over {_BUILD_TIMEOUT_S} s")
        if msg[0] == "error":
            self.kill()
            raise Rt70Error(f"{problem.name}: worker failed:\n{msg[1]}")
        self.nv[problem], self.notes[problem], self.threads[problem] = msg[1], msg[2], msg[3:5]
        msg = self._receive(cap * (1.0 + _SLACK_FRACTION) + _SLACK_S)
        if msg is None:
            self.kill()
            return _Attempt("over cap")
        if msg[0] == "error":
            self.kill()
            return _Attempt("failed: " + msg[1].strip().splitlines()[-1])
        (wall, success, message, nfev, njev, nlu), used_atol, x = msg[1], msg[2], msg[3]
        if wall > cap:
            return _Attempt("over cap", wall, used_atol, nfev, njev, nlu)
        if not success:
            return _Attempt(f"failed: {message}", wall, used_atol, nfev, njev, nlu)
        return _Attempt("ok", wall, used_atol, nfev, njev, nlu, x)


# ---------------------------------------------------------------------------------------
# The report
# ---------------------------------------------------------------------------------------


def relative_error(x: np.ndarray, x_ref: np.ndarray) -> float:
    """``max_t ‖x(t) − x_ref(t)‖∞ / max_t ‖x_ref(t)‖∞`` over a common grid (rows = times)."""
    return float(np.max(np.abs(x - x_ref)) / np.max(np.abs(x_ref)))


def _label(method: str, atol: float | None) -> str:
    a = "default atol" if atol is None else f"atol={atol:g}"
    return f"{method} rtol={REFERENCE_RTOL:g} {a}"


def run(
    quick: bool = False,
    problems: tuple[Problem, ...] | None = None,
    methods: tuple[str, ...] = METHODS,
    rtols: tuple[float, ...] | None = None,
    cap_s: float | None = None,
    repeats: int | None = None,
    progress: Callable[[str], None] | None = None,
) -> list[Row]:
    """Run the work–precision report.

    Parameters
    ----------
    quick : bool
        Small version for tests: :data:`QUICK_PROBLEMS`, :data:`QUICK_RTOLS`,
        :data:`QUICK_CAP_S`, :data:`QUICK_REPEATS` (a few seconds).
    problems, methods, rtols : tuple, optional
        Override the problems, methods and tolerance ladder.
    cap_s : float, optional
        Wall-time cap per run, s (default :data:`TIME_CAP_S`).
    repeats : int, optional
        Attempts per run; the best time is reported (default :data:`REPEATS`).
    progress : callable (str) -> None, optional
        Receives one line per run.

    Returns
    -------
    list of Row
        One row per problem, method and tolerance.

    Raises
    ------
    Rt70Error
        If a problem cannot be built or a reference run fails or exceeds
        :data:`REFERENCE_CAP_S`.

    Notes
    -----
    The runs happen in a ``spawn``-ed worker process, which re-imports the caller's
    ``__main__``: a script calling this must do so under ``if __name__ == "__main__"``.
    """
    problems = problems or (QUICK_PROBLEMS if quick else PROBLEMS)
    rtols = rtols or (QUICK_RTOLS if quick else RTOLS)
    cap = cap_s if cap_s is not None else (QUICK_CAP_S if quick else TIME_CAP_S)
    repeats = repeats or (QUICK_REPEATS if quick else REPEATS)
    say = progress or (lambda _msg: None)
    worker = _Worker()
    rows: list[Row] = []
    try:
        for problem in problems:
            refs = {}
            for method in problem.references:
                start = time.perf_counter()
                got = worker.run(
                    problem, method, REFERENCE_RTOL, problem.reference_atol, REFERENCE_CAP_S
                )
                if got.status != "ok":
                    raise Rt70Error(
                        f"{problem.name}: reference {_label(method, problem.reference_atol)}: "
                        f"{got.status}"
                    )
                refs[method] = got.x
                say(
                    f"{problem.name}: reference {_label(method, problem.reference_atol)} "
                    f"{got.wall_s:.2f} s ({time.perf_counter() - start:.1f} s with set-up)"
                )
            primary, alternate = problem.references
            floor = relative_error(refs[alternate], refs[primary])
            say(f"{problem.name}: references agree to {floor:.2e}")
            for method in methods:
                over = False
                for rtol in rtols:
                    ref_method = problem.reference_for(method)
                    common = dict(
                        problem=problem.name,
                        t_end=problem.t_end,
                        method=method,
                        rtol=rtol,
                        cap_s=cap,
                        reference=_label(ref_method, problem.reference_atol),
                        reference_floor=floor,
                        notes=worker.notes[problem],
                        nv=worker.nv[problem],
                        threads=worker.threads[problem][0],
                        threads_unpinned=worker.threads[problem][1],
                    )
                    if over:
                        rows.append(_row(common, "over cap (not run)", []))
                        continue
                    attempts = []
                    for _ in range(repeats):
                        attempts.append(worker.run(problem, method, rtol, None, cap))
                        if attempts[-1].status != "ok":
                            break
                    done = [a for a in attempts if a.status == "ok"]
                    if done:  # an attempt over the cap after good ones is noise: drop it
                        err = relative_error(done[0].x, refs[ref_method])
                        row = _row(common, "ok", done, err)
                    else:
                        over = attempts[-1].status == "over cap"
                        row = _row(common, attempts[-1].status, attempts)
                    rows.append(row)
                    say(
                        f"{problem.name}: {method} rtol={rtol:g}: {row.status}, "
                        f"error {row.error:.2e}, best {row.time_s:.3f} s"
                    )
    finally:
        worker.close()
    return rows


def _row(common: dict, status: str, attempts: list[_Attempt], error: float = math.nan) -> Row:
    ok = status == "ok"
    walls = [a.wall_s for a in attempts if not math.isnan(a.wall_s)]
    first = attempts[0] if attempts else _Attempt(status)
    rtol = common["rtol"]
    return Row(
        **common,
        atol=first.atol if not math.isnan(first.atol) else 1e-3 * rtol,
        status=status,
        over_cap=status.startswith("over cap"),
        error=error if ok else math.nan,
        time_s=min(walls) if ok else math.nan,
        times_s=";".join(f"{w:.4f}" for w in walls),
        nfev=first.nfev,
        njev=first.njev,
        nlu=first.nlu,
    )


# ---------------------------------------------------------------------------------------
# Summary, table and files
# ---------------------------------------------------------------------------------------


def time_to_reach(rows: list[Row], problem: str, method: str, target: float) -> Row | None:
    """The fastest ``ok`` run of ``method`` on ``problem`` with error ≤ ``target``."""
    ok = [
        r
        for r in rows
        if r.problem == problem and r.method == method and r.status == "ok" and r.error <= target
    ]
    return min(ok, key=lambda r: r.time_s, default=None)


def summary(rows: list[Row], target: float = TARGET_ERROR) -> list[str]:
    """Per problem: the fastest method reaching ``error ≤ target`` and its speed-up over RK45."""
    lines = []
    for problem in dict.fromkeys(r.problem for r in rows):
        methods = dict.fromkeys(r.method for r in rows if r.problem == problem)
        best = [b for m in methods if (b := time_to_reach(rows, problem, m, target))]
        if not best:
            lines.append(f"{problem}: no method reached error ≤ {target:g} within the cap")
            continue
        win = min(best, key=lambda r: r.time_s)
        line = (
            f"{problem}: fastest to error ≤ {target:g}: {win.method} at rtol {win.rtol:g} "
            f"({win.time_s:.3f} s, error {win.error:.1e})"
        )
        rk = time_to_reach(rows, problem, "RK45", target)
        if win.method == "RK45":
            line += "; RK45 itself is the fastest"
        elif rk is not None:
            line += f"; {rk.time_s / win.time_s:.1f}× faster than RK45 ({rk.time_s:.3f} s)"
        elif "RK45" in methods:
            rk_rows = [r for r in rows if r.problem == problem and r.method == "RK45"]
            if any(r.over_cap for r in rk_rows):
                cap = rk_rows[0].cap_s
                line += (
                    f"; RK45 did not reach it within the {cap:g} s cap "
                    f"(speed-up > {cap / win.time_s:.0f}×)"
                )
            else:
                line += f"; RK45 did not reach it down to rtol {min(r.rtol for r in rk_rows):g}"
        lines.append(line)
    return lines


def check_targets(rows: list[Row], target: float = TARGET_ERROR) -> list[TargetCheck]:
    """The targets of issues 5 and 13 that this report measures, against ``rows``.

    The RT-70 (:data:`TARGET_PROBLEM`) must reach state error ≤ ``target`` at
    ≥ :data:`REAL_TIME_TARGET` × real time: the fastest ``ok`` run of any method with
    that error must take at most ``T / REAL_TIME_TARGET`` of integration wall time.
    """
    mine = [r for r in rows if r.problem == TARGET_PROBLEM]
    if not mine:
        goal = f"{TARGET_PROBLEM} at state error ≤ {target:g}, ≥ {REAL_TIME_TARGET:g}× real time"
        return [TargetCheck(goal, "— (not in this run)", None)]
    t_end = mine[0].t_end
    goal = (
        f"{TARGET_PROBLEM} (listing damping, T = {t_end:g} s) to state error ≤ {target:g} in "
        f"≤ {t_end / REAL_TIME_TARGET:.3g} s of integration, i.e. ≥ {REAL_TIME_TARGET:g}× "
        "real time (issues 5, 13)"
    )
    methods = dict.fromkeys(r.method for r in mine)
    best = [b for m in methods if (b := time_to_reach(rows, TARGET_PROBLEM, m, target))]
    if not best:
        reached = f"no method reached it within the {mine[0].cap_s:g} s cap"
        return [TargetCheck(goal, reached, False)]
    win = min(best, key=lambda r: r.time_s)
    factor = t_end / win.time_s
    measured = (
        f"{win.time_s:.3f} s, {factor:.1f}× real time ({win.method}, rtol {win.rtol:g}, "
        f"error {win.error:.1e})"
    )
    full_span = next(p.t_end for p in PROBLEMS if p.name == TARGET_PROBLEM)
    if t_end < full_span:  # a quick run's short span measures start-up, not the transient
        return [TargetCheck(goal, measured + f"; span under the report's {full_span:g} s", None)]
    return [TargetCheck(goal, measured, factor >= REAL_TIME_TARGET)]


def format_table(rows: list[Row]) -> str:
    """The report as text: per problem its description, references, rows and the summary."""
    lines = []
    head = f"{'method':<8} {'rtol':>7} {'error':>10} {'time s':>9} {'nfev':>8}  status"
    for problem in dict.fromkeys(r.problem for r in rows):
        mine = [r for r in rows if r.problem == problem]
        r0 = mine[0]
        refs = sorted({r.reference for r in mine})
        lines += [
            f"{problem} (nv = {r0.nv}): {r0.notes}",
            f"  references: {'; '.join(refs)}; they agree to {r0.reference_floor:.1e}",
            f"  time = best of the attempts' wall times; cap {r0.cap_s:g} s",
            "  " + head,
            "  " + "-" * len(head),
        ]
        for r in mine:
            err = f"{r.error:.2e}" if r.status == "ok" else "—"
            t = f"{r.time_s:.3f}" if r.status == "ok" else f"> {r.cap_s:g}" if r.over_cap else "—"
            nfev = str(r.nfev) if r.status == "ok" else "—"
            lines.append(f"  {r.method:<8} {r.rtol:>7.0e} {err:>10} {t:>9} {nfev:>8}  {r.status}")
        lines.append("")
    lines += summary(rows)
    if rows:
        lines.append(
            f"BLAS/OpenMP threads in the worker: {rows[0].threads} "
            f"(unpinned: {rows[0].threads_unpinned})"
        )
    lines += [c.line() for c in check_targets(rows)]
    lines.append(
        "not measured by this report: the whole command's time, the centre-of-mass error in "
        "metres (issue 13) and the energy balance (issue 5; see `rt70 simulate`)"
    )
    return "\n".join(lines)


def write_results(rows: list[Row], directory: str | Path) -> list[Path]:
    """Write ``work_precision.csv`` and the log–log plot ``work_precision.png`` atomically."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    directory = Path(directory)
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=[f.name for f in fields(Row)], lineterminator="\n")
    writer.writeheader()
    for r in rows:
        writer.writerow({k: (repr(v) if isinstance(v, float) else v) for k, v in asdict(r).items()})
    csv_path = atomic_write_text(directory / "work_precision.csv", buf.getvalue())

    names = list(dict.fromkeys(r.problem for r in rows))
    ncols = 2 if len(names) > 1 else 1
    nrows = math.ceil(len(names) / ncols)
    fig, axes = plt.subplots(
        nrows, ncols, figsize=(6.5 * ncols, 4.8 * nrows), squeeze=False, constrained_layout=True
    )
    style = {
        m: (f"C{i}", marker) for i, (m, marker) in enumerate(zip(METHODS, "osD^v", strict=True))
    }
    for ax, problem in zip(axes.flat, names, strict=False):
        mine = [r for r in rows if r.problem == problem]
        cap = mine[0].cap_s
        for method in dict.fromkeys(r.method for r in mine):
            color, marker = style.get(method, ("k", "x"))
            runs = [r for r in mine if r.method == method]
            pts = [(r.time_s, r.error) for r in runs if r.status == "ok"]
            over = [r.rtol for r in runs if r.over_cap]
            label = method
            if over:
                label += f" (over the cap from rtol {max(over):.0e})"
            if pts:
                t, e = zip(*pts, strict=True)
                ax.loglog(t, e, "-", color=color, marker=marker, label=label)
            else:
                ax.plot([], [], "none", color=color, marker=marker, label=label)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.axvline(cap, color="0.5", ls="--", lw=1, label=f"time cap {cap:g} s")
        floor = mine[0].reference_floor
        if floor > 0:
            ax.axhline(floor, color="0.5", ls=":", lw=1, label="references' agreement")
        title = f"{problem} (nv = {mine[0].nv}, T = {mine[0].t_end:g} s)"
        ax.set_title(title, fontsize=10)
        ax.set_xlabel("run time, s (best of repeats)")
        ax.set_ylabel("max relative state error")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7, loc="best")
    for ax in list(axes.flat)[len(names) :]:
        ax.set_visible(False)
    ladder = sorted({r.rtol for r in rows}, reverse=True)
    fig.suptitle(
        f"Work–precision: error against run time, rtol {ladder[0]:.0e} … {ladder[-1]:.0e} "
        f"(references: another method at rtol {REFERENCE_RTOL:g})",
        fontsize=11,
    )
    png_path = atomic_write(directory / "work_precision.png", lambda tmp: fig.savefig(tmp, dpi=110))
    plt.close(fig)
    return [csv_path, png_path]
