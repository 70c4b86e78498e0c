"""Memory of ``rt70 sweep``: the constants of :func:`rt70.sweep.run.peak_bytes` and of
:data:`rt70.sweep.cluster.WORKER_BYTES`, measured.

1. The sweep's own memory in the client, by tracemalloc (Python objects and numpy
   arrays), over a grid of ``--points`` points of a quantity with the fields of
   ``first_frequency`` and ``sag`` (11 numbers per point, two quantities) that costs
   nothing to compute, written to ``--out`` (a tmpfs by default, so that fsync is
   cheap): once with every point computed, once with every point failed (an error
   record per point and quantity), with chunks of 1 and of 8 points. The fit: bytes per
   number (the results), per error record and per chunk.
2. One local Dask worker process after a chunk of ``rt70_servo`` (both quantities):
   its resident set (psutil), the number :data:`rt70.sweep.cluster.WORKER_BYTES` rounds up.

Run: ``python validation/sweep_memory.py [--points 9000]`` (5 min on a loaded 2-core
machine); prints the numbers and writes validation/results/sweep_memory.json.
"""

from __future__ import annotations

import argparse
import gc
import json
import os
import tempfile
import tracemalloc
from pathlib import Path

from rt70.errors import Rt70Error
from rt70.sweep import run as sw
from rt70.sweep.quantities import Field, Quantity

RESULTS = Path(__file__).resolve().parent / "results" / "sweep_memory.json"


def _ok(scene, point):
    return {"a": 1.0, "b": [1.0] * 6, "c": 2.0, "d": [0.0] * 3}


def _fail(scene, point):
    raise Rt70Error("rt70_servo: no static equilibrium: the free coordinates have no stiffness")


def quantities(compute) -> tuple[Quantity, ...]:
    """Two quantities with the shapes of first_frequency (1 + 6) and sag (1 + 3)."""
    f1 = (Field("a", (), "Hz", "a"), Field("b", (6,), "Hz", "b"))
    f2 = (Field("c", (), "arcsec", "c"), Field("d", (3,), "arcsec", "d"))
    return (Quantity("q1", f1, compute), Quantity("q2", f2, compute))


def measure(points: int, chunk: int, compute, directory: Path) -> dict[str, float]:
    """Peak traced bytes of one sweep (its output written), and its sizes."""
    n_el = 90
    n_az = points // n_el
    grid = sw.make_grid(
        {"elevation": [i * 90 / (n_el - 1) for i in range(n_el)], "azimuth": range(n_az)}
    )
    sweep = sw.Sweep(sw.SceneSource.read("rt70_servo"), grid, quantities(compute), chunk)
    sw.build_scene(sweep.source)  # the scene is not the sweep's memory
    out = directory / f"m{chunk}.npz"
    gc.collect()
    tracemalloc.start()
    base = tracemalloc.get_traced_memory()[0]
    sw.run(sweep, sw.serial, out)
    peak = tracemalloc.get_traced_memory()[1] - base
    tracemalloc.stop()
    chunks = len(sweep.chunks())
    return {"points": grid.size, "chunks": chunks, "peak_bytes": peak}


def worker_bytes() -> int:
    """Resident set of one local worker after a chunk of rt70_servo, bytes."""
    from distributed import Client

    from rt70.sweep.cluster import local_cluster, on_dask

    grid = sw.make_grid({"elevation": (30.0, 60.0)})
    sweep = sw.plan("rt70_servo", grid, ["first_frequency", "sag"], chunk=2)
    with local_cluster(1) as cluster, Client(cluster) as client:
        sw.run(sweep, on_dask(client))
        rss = client.run(lambda: __import__("psutil").Process().memory_info().rss)
    return max(rss.values())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=9_000)
    parser.add_argument("--out", default="/dev/shm" if os.path.isdir("/dev/shm") else None)
    args = parser.parse_args()
    rows = []
    with tempfile.TemporaryDirectory(dir=args.out) as tmp:
        for chunk in (1, 8):
            for name, compute in (("computed", _ok), ("failed", _fail)):
                row = measure(args.points, chunk, compute, Path(tmp)) | {
                    "chunk": chunk,
                    "points_are": name,
                }
                rows.append(row)
                print(
                    f"chunk {chunk}, every point {name}: {row['points']} points, "
                    f"{row['chunks']} chunks, peak {row['peak_bytes'] / 1e6:.1f} MB "
                    f"({row['peak_bytes'] / row['points']:.0f} B per point)"
                )
    # per chunk: chunks of 1 against chunks of 8, every point computed
    c1, f1, c8, f8 = rows
    per_chunk = (c1["peak_bytes"] - c8["peak_bytes"]) / (c1["chunks"] - c8["chunks"])
    per_number = (c8["peak_bytes"] - per_chunk * c8["chunks"]) / (11 * c8["points"])
    per_error = max(
        (f["peak_bytes"] - c["peak_bytes"]) / (2 * c["points"]) for c, f in ((c1, f1), (c8, f8))
    )
    rss = worker_bytes()
    fit = {
        "bytes_per_chunk": per_chunk,
        "bytes_per_number": per_number,
        "bytes_per_error": per_error,
        "worker_rss_bytes": rss,
    }
    print(
        f"fit: {per_number:.1f} B per number, {per_error:.0f} B per error record, "
        f"{per_chunk:.0f} B per chunk; one worker after a chunk: {rss / 1e6:.0f} MB"
    )
    RESULTS.parent.mkdir(exist_ok=True)
    RESULTS.write_text(json.dumps({"runs": rows, "fit": fit}, indent=2) + "\n")


if __name__ == "__main__":
    main()
