"""Speed of ``rt70 sweep`` (issue 11 targets: 91 points ≤ 10 s; 2 workers ≥ 1.7× 1 worker).

The sweep: ``first_frequency`` of ``rt70_servo`` at 91 elevations (0…90° step 1°,
azimuth 0), chunks of ``--chunk`` consecutive elevations. For 1 and then 2 workers a
fresh ``LocalCluster`` of single-threaded worker processes (BLAS pinned to one thread,
:mod:`rt70.sweep.cluster`) is started, the sweep run and the cluster closed; printed:
the start-up, the sweep's wall time (workers importing rt70 and building the scene
included: they start empty), the CPU seconds the workers spent on it (a measure of the
work that the other users of a shared machine do not change much) and the total, the
load average, and the ratio of the sweep times — and, as the wall-time ratio depends on
whether another job holds a core, the ratio of one worker's CPU time to the busier of
two workers' (the speed-up free cores would give: how evenly the work splits). Every
run's numbers are checked bit-identical to the first. Before that, in this process
(BLAS pinned): the per-point cost of the static equilibrium from a cold start (q = 0,
what the sweep does) and from the previous elevation's (a warm start), and of the
whole point. The machine is shared: ``--repeat`` runs each measurement several times.

Run: ``python validation/sweep_speed.py [--repeat 2] [--chunk 8]``; writes
validation/results/sweep_speed.json.
"""

from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path

import numpy as np
from distributed import Client
from threadpoolctl import threadpool_limits

from rt70.linear.linearize import equilibrium
from rt70.scenes.rt70_state import rt70_pointing
from rt70.sweep import run as sw
from rt70.sweep.cluster import local_cluster, on_dask, workers_of

RESULTS = Path(__file__).resolve().parent / "results" / "sweep_speed.json"
ELEVATIONS = tuple(float(e) for e in range(91))


def in_process(sweep: sw.Sweep) -> dict[str, float]:
    """Seconds per point in this process: cold and warm equilibria, the whole point."""
    scene = sw.build_scene(sweep.source)
    out = {}
    with threadpool_limits(limits=1):
        for warm in (False, True):
            q, start = None, time.perf_counter()
            for e in ELEVATIONS:
                q = equilibrium(scene, rt70_pointing(e), q_start=q if warm else None)
            out["equilibrium_warm" if warm else "equilibrium_cold"] = (
                time.perf_counter() - start
            ) / len(ELEVATIONS)
        start = time.perf_counter()
        sw.run(sweep, sw.serial)
        out["point_serial"] = (time.perf_counter() - start) / len(ELEVATIONS)
    return out


def on_cluster(sweep: sw.Sweep, workers: int) -> tuple[dict[str, float], dict]:
    """Start a cluster of ``workers`` processes, run the sweep, close it: the times."""
    start = time.perf_counter()
    with local_cluster(workers) as cluster, Client(cluster) as client:
        assert workers_of(client) == workers
        cpu0 = client.run(time.process_time)
        started = time.perf_counter()
        result = sw.run(sweep, on_dask(client), workers=workers)
        swept = time.perf_counter()
        cpu1 = client.run(time.process_time)
    done = time.perf_counter()
    each = sorted(cpu1[w] - cpu0[w] for w in cpu0)  # CPU seconds each worker spent on it
    times = {"startup": started - start, "sweep": swept - started, "total": done - start}
    times["workers_cpu"], times["workers_cpu_each"] = sum(each), each
    times["load_average_1min"] = os.getloadavg()[0]  # after the run: others' work too
    return times, result.arrays


def main() -> None:
    """Print and write the timings."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=2)
    parser.add_argument("--chunk", type=int, default=sw.DEFAULT_CHUNK)
    args = parser.parse_args()
    grid = sw.make_grid({"elevation": ELEVATIONS})
    sweep = sw.plan("rt70_servo", grid, ["first_frequency"], chunk=args.chunk)
    record: dict = {"points": grid.size, "chunk": args.chunk, "runs": []}
    reference = None
    for r in range(args.repeat):
        serial = in_process(sweep)
        print(
            f"run {r + 1}: in this process, per point: equilibrium cold "
            f"{serial['equilibrium_cold'] * 1e3:.1f} ms, warm "
            f"{serial['equilibrium_warm'] * 1e3:.1f} ms; whole point "
            f"{serial['point_serial'] * 1e3:.1f} ms"
        )
        run = {"in_process": serial}
        for workers in (1, 2):
            times, arrays = on_cluster(sweep, workers)
            if reference is None:
                reference = arrays
            for name, values in reference.items():
                assert np.array_equal(arrays[name], values, equal_nan=True), name
            run[f"workers_{workers}"] = times
            print(
                f"run {r + 1}: {workers} worker(s): start-up {times['startup']:.2f} s, "
                f"{grid.size} points {times['sweep']:.2f} s (workers' CPU "
                f"{times['workers_cpu']:.2f} s), total {times['total']:.2f} s; load average "
                f"{times['load_average_1min']:.2f}"
            )
        run["speedup"] = run["workers_1"]["sweep"] / run["workers_2"]["sweep"]
        run["speedup_total"] = run["workers_1"]["total"] / run["workers_2"]["total"]
        # what free cores would give: one worker's CPU time over the busiest of two's
        run["speedup_cpu"] = run["workers_1"]["workers_cpu"] / max(
            run["workers_2"]["workers_cpu_each"]
        )
        print(
            f"run {r + 1}: 2 workers vs 1: {run['speedup']:.2f}× on the sweep, "
            f"{run['speedup_total']:.2f}× start-up included; work split: the busier of "
            f"2 workers {max(run['workers_2']['workers_cpu_each']):.2f} CPU s, "
            f"{run['speedup_cpu']:.2f}× less than 1 worker's"
        )
        record["runs"].append(run)
    RESULTS.parent.mkdir(parents=True, exist_ok=True)
    RESULTS.write_text(json.dumps(record, indent=2) + "\n", encoding="utf-8")
    print(f"wrote {RESULTS}")


if __name__ == "__main__":
    main()
