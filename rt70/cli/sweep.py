"""``rt70 sweep``: quantities over a grid of pointings, winds and scene parameters.

The command's options and its handler (:mod:`rt70.sweep.run` does the work,
:mod:`rt70.sweep.cluster` the Dask side); :mod:`rt70.cli.main` adds it to the ``rt70`` parser.
Every option is checked before any work starts (one ``rt70: error:`` line, exit 2).
"""

from __future__ import annotations

import argparse
import json
import sys

from rt70.cli import options
from rt70.cli.surface_options import add_frequency_argument
from rt70.errors import Rt70Error


def add_parser(sub) -> argparse.ArgumentParser:
    """Add ``sweep`` to the ``rt70`` sub-parsers ``sub``; return its parser."""
    swp = sub.add_parser(
        "sweep",
        help="compute quantities over a grid of pointings, winds and scene parameters (Dask)",
        description="Compute registered quantities (the locked-rotor first frequency, the "
        "gravity sag of the main mirror, ...) at every point of the Cartesian grid "
        "elevation × azimuth × wind × direction × --scale factors, on a local Dask cluster "
        "(one single-threaded worker process per core) or an existing one (--scheduler). "
        "Axis values: A:B:N (N values, ends included), A,B,... or A. Writes FILE (.npz: "
        "the axes and one array per quantity field) and FILE's .json sidecar (metadata, "
        "failed points); finished chunks are kept in FILE.partial/ so the same command "
        "resumes an interrupted sweep (docs: 'Sweeps', docs/sweeps.md).",
    )
    swp.add_argument("scene", metavar="SCENE", help="scene name or URDF path (RT-70 axes)")
    for name, unit, default in (
        ("elevation", "degrees, 0 … 90", "90"),
        ("azimuth", "degrees", "0"),
        ("wind", "wind speed, m/s", "0"),
        ("direction", "wind direction, degrees", "0"),
    ):
        swp.add_argument(
            f"--{name}",
            type=_sweep_values,
            metavar="A:B:N",
            help=f"{name} values, {unit} (default {default})",
        )
    swp.add_argument(
        "--scale",
        type=_sweep_scale,
        action="append",
        metavar="NAME=A:B:N",
        help="scale a scene parameter by these factors (stiffness, damping, "
        "reducer_stiffness); repeatable",
    )
    swp.add_argument(
        "--quantity",
        type=_sweep_quantities,
        metavar="Q1,Q2",
        help="quantities to compute (default first_frequency,sag; also pointing, surface)",
    )
    add_frequency_argument(swp, "the surface quantity adds Ruze's efficiency there")
    swp.add_argument("--out", required=True, metavar="FILE", help="output file, .npz")
    swp.add_argument(
        "--scheduler", metavar="ADDRESS", help="an existing Dask scheduler, tcp://host:port"
    )
    swp.add_argument(
        "--timeout",
        type=_timeout,
        default=10.0,
        help="seconds to wait for --scheduler, and for a worker when the cluster has none "
        "left (default 10)",
    )
    swp.add_argument(
        "--workers",
        type=_non_negative_int,
        help="local worker processes (default one per core; 0: compute in this process)",
    )
    swp.add_argument(
        "--chunk",
        type=options.positive_int,
        default=8,  # rt70.sweep.run.DEFAULT_CHUNK
        help="grid points per task, consecutive elevations (default 8)",
    )
    swp.add_argument("--no-progress", action="store_true", help="no progress bar")
    swp.add_argument("--json", action="store_true", help="print the metadata as JSON")
    swp.set_defaults(func=run)
    return swp


def run(args: argparse.Namespace) -> int:
    """Plan the sweep (options, scene, partial results checked), run it, print a summary."""
    from pathlib import Path

    import numpy as np

    from rt70.sweep import run as sw

    if args.scheduler is not None and args.workers is not None:
        raise Rt70Error("--workers starts a local cluster: not with --scheduler")
    scaled = [name for name, _ in args.scale or []]
    if len(set(scaled)) != len(scaled):
        raise Rt70Error("--scale: a scene parameter is named twice")
    values = {k: getattr(args, k) for k in ("elevation", "azimuth", "wind", "direction")}
    grid = sw.make_grid({k: v for k, v in values.items() if v is not None}, dict(args.scale or []))
    quantities = args.quantity or sw.DEFAULT_QUANTITIES
    if args.frequency:
        from rt70.sweep.quantities import register_quantity
        from rt70.sweep.surface_quantity import surface_quantity

        if "surface" not in quantities:
            raise Rt70Error("--frequency: only the surface quantity uses it (--quantity surface)")
        register_quantity(surface_quantity(args.frequency))
    out = Path(args.out)
    sw.check_output(out)
    if args.scheduler is None and args.workers != 0:
        from rt70.sweep.cluster import check_workers, default_workers

        check_workers(args.workers or default_workers())
    plan = sw.plan(args.scene, grid, quantities, chunk=args.chunk)
    store = sw.PartialResults(out, plan)
    store.check()  # a foreign partial directory: refused up front
    progress = not args.no_progress
    with store.locked():  # a second sweep on this --out: refused here, before a cluster starts
        try:
            if args.scheduler is None and args.workers == 0:
                result = sw.run(plan, sw.serial, out, workers=0, progress=progress)
                where = "in this process"
            else:
                result, where = _sweep_on_dask(args, plan, out, progress)
        except KeyboardInterrupt:
            print(
                f"rt70: finished chunks kept in {store.directory}; rerun to resume", file=sys.stderr
            )
            raise
    meta = result.metadata
    if args.json:
        print(json.dumps(meta, indent=2))
        return 0
    axes = " × ".join(f"{len(a.values)} {a.name}" for a in grid.axes)
    chunks = meta["chunks"]
    print(f"{plan.source.name}: sweep of {grid.size} point(s) ({axes})")
    again = f" ({chunks['recomputed']} of them untrusted files)" if chunks["recomputed"] else ""
    print(
        f"  {chunks['total']} chunk(s) of ≤ {plan.chunk}: {chunks['computed']} computed "
        f"{where}{again}, {chunks['resumed']} resumed; {meta['wall_time_s']:.2f} s wall"
    )
    for q in plan.quantities:
        for f in q.fields:
            if f.shape:
                continue
            a = result.arrays[f.name]
            span = (
                f"{np.nanmin(a):.6g} … {np.nanmax(a):.6g} {f.unit}"
                if np.isfinite(a).any()
                else "no value"
            )
            print(f"  {f.name}: {span} ({f.description})")
    for e in result.errors:
        point = ", ".join(f"{k} {v:g}" for k, v in e["point"].items())
        print(f"  failed: {e['quantity']} at {point}: {e['error']}")
    print(f"wrote {out} and {sw.sidecar(out)}")
    return 0


def _sweep_on_dask(args: argparse.Namespace, plan, out, progress: bool):
    """Run the sweep on the scheduler asked for, or on a local cluster started here.

    Dask's own log lines (a worker restarted, a connection lost) are silenced: a fault
    that stops the sweep is one :class:`rt70.sweep.run.ClusterError` line.
    """
    import logging
    from contextlib import ExitStack

    from distributed.utils import silence_logging_cmgr

    from rt70.sweep import cluster as sweep_dask
    from rt70.sweep import run as sw

    with ExitStack() as stack:
        stack.enter_context(silence_logging_cmgr(logging.CRITICAL))
        if args.scheduler is not None:
            client = stack.enter_context(sweep_dask.connect(args.scheduler, args.timeout))
            where = f"on the cluster at {args.scheduler}"
        else:
            client = sweep_dask.start_local(stack, args.workers)
            where = "on a local Dask cluster"
        n = sweep_dask.workers_of(client)
        where += f" ({n} worker{'s' if n != 1 else ''})"
        executor = sweep_dask.on_dask(client, worker_timeout=args.timeout)
        result = sw.run(plan, executor, out, workers=n, progress=progress)
    return result, where


def _sweep_values(text: str) -> tuple[float, ...]:
    """The argparse type of a sweep axis (:func:`rt70.sweep.run.parse_values`)."""
    from rt70.sweep.run import parse_values

    try:
        return parse_values(text)
    except Rt70Error as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def _sweep_scale(text: str) -> tuple[str, tuple[float, ...]]:
    """The argparse type of ``--scale NAME=VALUES`` (a known scene parameter)."""
    from rt70.sweep.quantities import PARAMETERS

    name, sep, values = text.partition("=")
    if not sep:
        raise argparse.ArgumentTypeError(f"'{text}' is not NAME=VALUES (e.g. stiffness=0.8:1.2:5)")
    if name not in PARAMETERS:
        raise argparse.ArgumentTypeError(
            f"unknown scene parameter '{name}' (known: {', '.join(PARAMETERS)})"
        )
    return name, _sweep_values(values)


def _sweep_quantities(text: str) -> tuple[str, ...]:
    """The argparse type of ``--quantity a,b`` (registered quantities)."""
    import rt70.sweep.surface_quantity  # noqa: F401  (registers 'surface')
    from rt70.sweep.quantities import quantity_names

    try:
        return quantity_names(text)
    except Rt70Error as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


#: Longest ``--timeout``, seconds: a scheduler or a worker not there within an hour is
#: not coming (a larger number only turns a dead cluster into a hang).
MAX_TIMEOUT = 3600.0


def _timeout(text: str) -> float:
    """Seconds to wait for a scheduler or a worker: 0 < T ≤ :data:`MAX_TIMEOUT`."""
    value = options.positive_float(text)
    if value > MAX_TIMEOUT:
        raise argparse.ArgumentTypeError(f"must be at most {MAX_TIMEOUT:g} s (an hour), got {text}")
    return value


def _non_negative_int(text: str) -> int:
    """An integer ≥ 0 (``--workers 0``: in this process)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not an integer") from None
    if value < 0:
        raise argparse.ArgumentTypeError(f"must be at least 0, got {text}")
    return value
