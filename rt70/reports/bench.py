"""Benchmarks of the textbook algorithm against Pinocchio, as ratios taken in one run.

The textbook side is timed in its compiled form (:mod:`rt70.textbook.mass_kernel`, the
rows ``per_call``, ``batched``, ``scaling_*``) and in its readable numpy form
(:mod:`rt70.textbook.structured`, the rows ``*_numpy``), and the dense form of the book
(``scaling_*_dense``); the targets judge the compiled form. ``first_call`` is the kernel's
first call in the process: compilation, or loading it from numba's on-disk cache.

This machine is shared and noisy, so every comparison interleaves the two sides:
each round times the textbook call and the Pinocchio call back to back, the ratio is
taken per round, and the median ratio is reported (with the best time of each side).
All timing happens with BLAS and OpenMP pinned to one thread
(:mod:`rt70.reports.threads`); the CSV records the pinned thread count and what the pools
would use otherwise.
"""

from __future__ import annotations

import csv
import io
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, fields, replace
from pathlib import Path

import numpy as np

from rt70.guards.atomic import atomic_write_all
from rt70.model.scene import Scene, load_scene, scene_from_text
from rt70.reports.targets import TargetCheck
from rt70.reports.threads import single_threaded
from rt70.textbook import dynamics, mass_kernel, structured


@dataclass(frozen=True)
class Row:
    """One benchmark result: seconds per configuration on each side and their ratio.

    ``threads`` is the largest BLAS/OpenMP thread count during the timing (1: pinned),
    ``threads_unpinned`` what the pools would have used (``"openblas 2, openmp 2"``).
    """

    benchmark: str
    target: str
    nv: int
    K: int
    t_textbook_s: float
    t_pinocchio_s: float
    ratio: float
    threads: int = 0
    threads_unpinned: str = ""


def _per_call(fn: Callable[[], object], budget_s: float) -> float:
    """Seconds per call of ``fn``, timing enough calls to fill about ``budget_s``."""
    start = time.perf_counter()
    fn()
    once = max(time.perf_counter() - start, 1e-7)
    number = max(1, int(budget_s / once))
    start = time.perf_counter()
    for _ in range(number):
        fn()
    return (time.perf_counter() - start) / number


def compare(
    textbook: Callable[[], object],
    pinocchio: Callable[[], object],
    rounds: int = 7,
    budget_s: float = 0.02,
) -> tuple[float, float, float]:
    """Interleaved timing: (best textbook s/call, best Pinocchio s/call, median ratio).

    Parameters
    ----------
    textbook, pinocchio : callable () -> object
        The two calls to time, each with its arguments bound; their results are dropped.
    rounds : int, optional
        Rounds; each times the textbook call, then the Pinocchio call, back to back.
    budget_s : float, optional
        Wall time each side fills per round, s (as many calls as fit, at least one).

    Returns
    -------
    tuple of float
        The best seconds per call of each side over the rounds, and the median over
        the rounds of the per-round ratio textbook / Pinocchio.
    """
    t_tb, t_pin = [], []
    for _ in range(rounds):
        t_tb.append(_per_call(textbook, budget_s))
        t_pin.append(_per_call(pinocchio, budget_s))
    ratios = np.array(t_tb) / np.array(t_pin)
    return min(t_tb), min(t_pin), float(np.median(ratios))


def _pin_crba(scene: Scene, q: np.ndarray) -> Callable[[], object]:
    import pinocchio as pin

    from rt70 import reference

    ref = scene.reference
    qp = reference.to_pinocchio(ref, q)[0]
    model = ref.pin_model
    data = model.createData()  # its own buffers, apart from the scene's
    return lambda: pin.crba(model, data, qp)


def first_call(scene: Scene) -> Row:
    """The kernel's first call in this process (compile or cache load) against ``pin.crba``'s."""
    model = scene.textbook
    q = np.zeros(model.nv)
    kdata = mass_kernel.KernelData(model, 1)
    start = time.perf_counter()
    mass_kernel.mass_matrix(model, kdata, q)
    t_tb = time.perf_counter() - start
    crba = _pin_crba(scene, q)
    start = time.perf_counter()
    crba()
    t_pin = time.perf_counter() - start
    return Row("first_call", scene.name, model.nv, 1, t_tb, t_pin, t_tb / t_pin)


def per_call(scene: Scene, rounds: int, budget_s: float, numpy_form: bool = False) -> Row:
    """Textbook A(q) (the kernel, or the structured numpy form) against one ``pin.crba``.

    Parameters
    ----------
    scene : Scene
        The scene timed, at one random configuration (seed 0, q within ±0.5).
    rounds : int
        Interleaved rounds of :func:`compare`.
    budget_s : float
        Wall time per side and round, s.
    numpy_form : bool, optional
        Time :func:`rt70.textbook.structured.mass_matrix` instead of the compiled
        :func:`rt70.textbook.mass_kernel.mass_matrix` (row ``per_call_numpy``).

    Returns
    -------
    Row
        Row ``per_call`` (or ``per_call_numpy``) with K = 1.
    """
    model = scene.textbook
    q = np.random.default_rng(0).uniform(-0.5, 0.5, model.nv)
    if numpy_form:
        bdata = structured.BatchData(model, 1)
        textbook = lambda: structured.mass_matrix(model, bdata, q)  # noqa: E731
    else:
        kdata = mass_kernel.KernelData(model, 1)
        textbook = lambda: mass_kernel.mass_matrix(model, kdata, q)  # noqa: E731
    textbook()  # compiled (or loaded from the cache) before the timing
    t_tb, t_pin, ratio = compare(textbook, _pin_crba(scene, q), rounds, budget_s)
    name = "per_call_numpy" if numpy_form else "per_call"
    return Row(name, scene.name, model.nv, 1, t_tb, t_pin, ratio)


def batched(scene: Scene, K: int, rounds: int, budget_s: float, numpy_form: bool = False) -> Row:
    """Textbook batched A for K configurations against K calls of ``pin.crba``.

    Parameters
    ----------
    scene : Scene
        The scene timed, at K random configurations (seed 1, q within ±0.5).
    K : int
        Number of configurations of the batch.
    rounds : int
        Interleaved rounds of :func:`compare`.
    budget_s : float
        Wall time per side and round, s.
    numpy_form : bool, optional
        Time :func:`rt70.textbook.structured.mass_matrix_batch` instead of the compiled
        :func:`rt70.textbook.mass_kernel.mass_matrix_batch` (row ``batched_numpy``).

    Returns
    -------
    Row
        Row ``batched`` (or ``batched_numpy``): seconds per configuration on each side.
    """
    import pinocchio as pin

    from rt70 import reference

    model = scene.textbook
    Q = np.random.default_rng(1).uniform(-0.5, 0.5, (K, model.nv))
    if numpy_form:
        bdata = structured.BatchData(model, K)
        textbook = lambda: structured.mass_matrix_batch(model, bdata, Q)  # noqa: E731
    else:
        kdata = mass_kernel.KernelData(model, K)
        textbook = lambda: mass_kernel.mass_matrix_batch(model, kdata, Q)  # noqa: E731
    textbook()
    ref = scene.reference
    QP = [reference.to_pinocchio(ref, q)[0] for q in Q]
    pm = ref.pin_model
    pd = pm.createData()

    def pin_loop() -> None:
        for qp in QP:
            pin.crba(pm, pd, qp)

    t_tb, t_pin, ratio = compare(textbook, pin_loop, rounds, budget_s)
    name = "batched_numpy" if numpy_form else "batched"
    return Row(name, scene.name, model.nv, K, t_tb / K, t_pin / K, ratio)


def scaling(kind: str, sizes: list[int], rounds: int, budget_s: float, dense_max: int) -> list[Row]:
    """Cost of A(q) on generated serial chains or balanced trees of the given sizes.

    The dense form (full L and S) is timed as well up to ``dense_max`` bodies.

    Parameters
    ----------
    kind : {"chain", "tree"}
        :func:`rt70.scenes.synthetic.serial_chain` or, for any other value,
        :func:`rt70.scenes.synthetic.balanced_tree`.
    sizes : list of int
        Numbers of bodies of the generated scenes.
    rounds : int
        Interleaved rounds of the kernel's timing (half as many, at least 3, for the
        numpy and dense forms).
    budget_s : float
        Wall time per side and round, s.
    dense_max : int
        Largest number of bodies at which the dense form is timed.

    Returns
    -------
    list of Row
        Per size the rows ``scaling_<kind>``, ``scaling_<kind>_numpy`` and, up to
        ``dense_max``, ``scaling_<kind>_dense``.
    """
    from rt70.scenes import synthetic

    make = synthetic.serial_chain if kind == "chain" else synthetic.balanced_tree
    rows = []
    for n in sizes:
        scene = scene_from_text(make(n), f"{kind}_{n}")
        rows.append(replace(per_call(scene, rounds, budget_s), benchmark=f"scaling_{kind}"))
        numpy_row = per_call(scene, max(3, rounds // 2), budget_s, numpy_form=True)
        rows.append(replace(numpy_row, benchmark=f"scaling_{kind}_numpy"))
        if n <= dense_max:
            model, data = scene.textbook, scene.textbook_data
            q = np.zeros(model.nv)
            t_dense, t_pin, ratio = compare(
                lambda m=model, d=data, q=q: dynamics.mass_matrix(m, d, q),
                _pin_crba(scene, q),
                max(3, rounds // 2),
                budget_s,
            )
            rows.append(
                Row(f"scaling_{kind}_dense", scene.name, model.nv, 1, t_dense, t_pin, ratio)
            )
    return rows


def fit_exponent(rows: list[Row], benchmark: str, min_nv: int = 0) -> float:
    """Slope of log(time) against log(nv) over the rows of one benchmark.

    Parameters
    ----------
    rows : list of Row
        Benchmark rows; the textbook time ``t_textbook_s`` is fitted.
    benchmark : str
        The benchmark whose rows are fitted, e.g. ``"scaling_chain"``.
    min_nv : int, optional
        Only rows with at least this many coordinates are fitted.

    Returns
    -------
    float
        The least-squares slope; NaN with fewer than two rows.
    """
    pts = [(r.nv, r.t_textbook_s) for r in rows if r.benchmark == benchmark and r.nv >= min_nv]
    if len(pts) < 2:
        return float("nan")
    nv, t = np.log([p[0] for p in pts]), np.log([p[1] for p in pts])
    return float(np.polyfit(nv, t, 1)[0])


#: The kernel's targets: per-call ratio ≤ 10 on these scenes, batched ratio ≤ 1 at
#: K = 1000 on the RT-70, growth exponent of the chain ≤ 2.2.
PER_CALL_TARGET = 10.0
PER_CALL_SCENES = ("rt70", "talos_full")
BATCHED_TARGET = 1.0
BATCHED_K = 1000
BATCHED_SCENE = "rt70"
EXPONENT_TARGET = 2.2
#: The exponent is judged on the sizes from here up (the growth, not the per-call
#: overhead); a run with fewer than two of them does not judge it.
EXPONENT_MIN_NV = 100


def check_targets(rows: list[Row]) -> list[TargetCheck]:
    """Every target of the mass-matrix benchmark against this run's rows."""
    checks = []
    for name in PER_CALL_SCENES:
        row = next((r for r in rows if r.benchmark == "per_call" and r.target == name), None)
        checks.append(
            TargetCheck(
                f"per-call ratio ≤ {PER_CALL_TARGET:g} on {name}",
                "—" if row is None else f"{row.ratio:.2f}",
                None if row is None else row.ratio <= PER_CALL_TARGET,
            )
        )
    row = next((r for r in rows if r.benchmark == "batched" and r.target == BATCHED_SCENE), None)
    goal = f"batched ratio ≤ {BATCHED_TARGET:g} at K = {BATCHED_K} on {BATCHED_SCENE}"
    if row is None:
        checks.append(TargetCheck(goal, "—", None))
    elif row.K != BATCHED_K:
        checks.append(TargetCheck(goal, f"{row.ratio:.2f} at K = {row.K}", None))
    else:
        checks.append(TargetCheck(goal, f"{row.ratio:.2f}", row.ratio <= BATCHED_TARGET))
    goal = f"chain exponent ≤ {EXPONENT_TARGET:g} (fitted on nv ≥ {EXPONENT_MIN_NV})"
    large = [r for r in rows if r.benchmark == "scaling_chain" and r.nv >= EXPONENT_MIN_NV]
    if len(large) >= 2:
        exponent = fit_exponent(rows, "scaling_chain", min_nv=EXPONENT_MIN_NV)
        span = f"nv {min(r.nv for r in large)}–{max(r.nv for r in large)}"
        checks.append(TargetCheck(goal, f"{exponent:.2f} ({span})", exponent <= EXPONENT_TARGET))
    else:  # small sizes measure the per-call overhead, not the growth
        nv = [r.nv for r in rows if r.benchmark == "scaling_chain"]
        measured = (
            "—"
            if not nv
            else f"{fit_exponent(rows, 'scaling_chain'):.2f} (nv {min(nv)}–{max(nv)} only)"
        )
        checks.append(TargetCheck(goal, measured, None))
    return checks


def run(
    robots: tuple[str, ...] = ("ur5", "panda", "talos_full"),
    sizes: tuple[int, ...] = (10, 20, 50, 100, 200, 400),
    K: int = 1000,
    rounds: int = 7,
    budget_s: float = 0.02,
    dense_max: int = 100,
    progress: Callable[[str], None] | None = None,
) -> list[Row]:
    """All mass-matrix benchmarks: per call, batched, and growth with size.

    Parameters
    ----------
    robots : tuple of str, optional
        Robots of example-robot-data timed beside the RT-70
        (:func:`rt70.crosscheck.robots.load_robot`).
    sizes : tuple of int, optional
        Numbers of bodies of the generated chains and trees (:func:`scaling`).
    K : int, optional
        Batch size of :func:`batched`, on the RT-70 and the first robot.
    rounds : int, optional
        Interleaved rounds per comparison (half, at least 3, for the numpy forms).
    budget_s : float, optional
        Wall time per side and round, s.
    dense_max : int, optional
        Largest number of bodies at which the dense form is timed.
    progress : callable (str) -> None, optional
        Receives one line per stage.

    Returns
    -------
    list of Row
        Every row, with the pinned and unpinned thread counts of the timing.
    """
    from rt70.crosscheck.robots import load_robot

    say = progress or (lambda _msg: None)
    scenes = [load_scene("rt70")] + [load_robot(name) for name in robots]
    rows = []
    with single_threaded() as pinning:
        say(pinning.describe())
        rows.append(first_call(scenes[0]))
        for scene in scenes:
            say(f"per call: {scene.name}")
            rows.append(per_call(scene, rounds, budget_s))
            rows.append(per_call(scene, max(3, rounds // 2), budget_s, numpy_form=True))
        for scene in scenes[:2]:
            say(f"batched K={K}: {scene.name}")
            rows.append(batched(scene, K, max(3, rounds // 2), budget_s))
            rows.append(batched(scene, K, max(3, rounds // 2), budget_s, numpy_form=True))
        for kind in ("chain", "tree"):
            say(f"scaling: {kind}s of {', '.join(map(str, sizes))} bodies")
            rows.extend(scaling(kind, list(sizes), rounds, budget_s, dense_max))
    return [replace(r, threads=pinning.pinned, threads_unpinned=pinning.unpinned) for r in rows]


def format_report(rows: list[Row]) -> str:
    """The benchmark table, the fitted exponents and the targets."""
    head = f"{'benchmark':<22} {'target':<14} {'nv':>4} {'K':>5} {'textbook µs':>12} "
    head += f"{'pinocchio µs':>12} {'ratio':>8}"
    lines = [head, "-" * len(head)]
    for r in rows:
        lines.append(
            f"{r.benchmark:<22} {r.target:<14} {r.nv:>4} {r.K:>5} {r.t_textbook_s * 1e6:>12.2f} "
            f"{r.t_pinocchio_s * 1e6:>12.2f} {r.ratio:>8.2f}"
        )
    lines.append("")
    for kind in ("chain", "tree"):
        bench = f"scaling_{kind}"
        if any(r.benchmark == bench for r in rows):
            lines.append(
                f"exponent of textbook A(q) time vs nv, {kind}s: "
                f"{fit_exponent(rows, bench):.2f} (all sizes), "
                f"{fit_exponent(rows, bench, min_nv=100):.2f} (nv ≥ 100); numpy form "
                f"{fit_exponent(rows, bench + '_numpy', min_nv=100):.2f} (nv ≥ 100); dense "
                f"form {fit_exponent(rows, bench + '_dense'):.2f}"
            )
    if rows:
        lines.append(
            f"BLAS/OpenMP threads during timing: {rows[0].threads} "
            f"(unpinned: {rows[0].threads_unpinned})"
        )
    lines += [c.line() for c in check_targets(rows)]
    return "\n".join(lines)


def write_results(rows: list[Row], directory: Path) -> list[Path]:
    """Write ``mass_matrix_bench.csv`` and the log–log plot ``mass_matrix_bench.png`` together.

    Raises
    ------
    OutputError
        The directory cannot take them (:func:`rt70.guards.atomic.atomic_write_all`); neither
        file is changed.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=[f.name for f in fields(Row)])
    writer.writeheader()
    for r in rows:
        writer.writerow(asdict(r))
    text = buf.getvalue()

    fig, ax = plt.subplots(figsize=(7, 5), constrained_layout=True)
    styles = {"chain": "o", "tree": "s"}
    for kind, marker in styles.items():
        for bench, label, ls in (
            (f"scaling_{kind}", "textbook kernel", "-"),
            (f"scaling_{kind}_numpy", "textbook structured numpy", "-."),
            (f"scaling_{kind}_dense", "textbook dense", ":"),
        ):
            pts = sorted((r.nv, r.t_textbook_s) for r in rows if r.benchmark == bench)
            if pts:
                nv, t = zip(*pts, strict=True)
                ax.loglog(nv, np.array(t) * 1e6, ls, marker=marker, label=f"{label}, {kind}")
        pts = sorted((r.nv, r.t_pinocchio_s) for r in rows if r.benchmark == f"scaling_{kind}")
        if pts:
            nv, t = zip(*pts, strict=True)
            ax.loglog(nv, np.array(t) * 1e6, "--", marker=marker, label=f"pin.crba, {kind}")
    ax.set_xlabel("nv (generalised coordinates)")
    ax.set_ylabel("time per A(q), µs")
    threads = f", BLAS threads {rows[0].threads}" if rows else ""
    ax.set_title(f"Mass matrix cost against size (one run, interleaved{threads})")
    ax.grid(True, which="both", alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=8)
    try:  # the table and its plot appear together, or neither changes
        return atomic_write_all(
            {
                directory / "mass_matrix_bench.csv": lambda tmp: tmp.write_text(
                    text, encoding="utf-8", newline="\n"
                ),
                directory / "mass_matrix_bench.png": lambda tmp: fig.savefig(tmp, dpi=120),
            }
        )
    finally:
        plt.close(fig)
