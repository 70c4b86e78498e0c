"""The Dask side of :mod:`rt70.sweep`: a cluster to run on and the executor that uses it.

- :func:`local_cluster`: a ``LocalCluster`` of single-threaded worker *processes* (one
  per core by default) on the loopback interface, no dashboard;
- :func:`connect`: a client of an existing cluster (``dask scheduler`` + ``dask worker
  tcp://…``), refused with :class:`~rt70.sweep.SweepError` when it cannot be reached
  within a timeout;
- :func:`on_dask`: the executor of :func:`rt70.sweep.run` that submits one task per
  chunk and yields the results as they finish (``distributed.as_completed``).

Every worker pins its BLAS to one thread (:class:`PinBlasThreads`, threadpoolctl) and
builds each scene once (:func:`rt70.sweep.build_scene` caches it in the worker process).
"""

from __future__ import annotations

import logging
import os
from collections.abc import Generator

from distributed import Client, LocalCluster, as_completed
from distributed.diagnostics.plugin import WorkerPlugin

from rt70.sweep import Chunk, ChunkResult, Executor, Sweep, SweepError, compute_chunk

#: Seconds :func:`connect` waits for a scheduler by default.
CONNECT_TIMEOUT = 10.0


class PinBlasThreads(WorkerPlugin):
    """One BLAS thread per worker process (threadpoolctl), set when a worker starts.

    Each worker runs one task at a time; several BLAS threads per worker would compete
    for the same cores. Registered by :func:`on_dask`, so workers that join an existing
    cluster later get it too.
    """

    idempotent = True

    def setup(self, worker) -> None:
        """Limit the worker process's BLAS and OpenMP pools to one thread (for good)."""
        from threadpoolctl import threadpool_limits

        threadpool_limits(limits=1)


#: Modules a local worker imports when it starts (numpy, scipy, Pinocchio, rt70's
#: analyses: ~0.4 s), so its first task does not pay for them.
PRELOAD = ("rt70.sweep", "rt70.reference", "rt70.linear.linearize", "rt70.linear.modal")


def local_cluster(workers: int | None = None) -> LocalCluster:
    """A local cluster of ``workers`` single-threaded processes (default: one per core).

    The workers listen on 127.0.0.1 only, serve no dashboard, and import
    :data:`PRELOAD` as they start.
    """
    n = workers or os.cpu_count() or 1
    return LocalCluster(
        n_workers=n,
        threads_per_worker=1,
        processes=True,
        host="127.0.0.1",
        dashboard_address=None,
        silence_logs=logging.ERROR,
        preload=list(PRELOAD),
    )


def connect(address: str, timeout: float = CONNECT_TIMEOUT) -> Client:
    """A client of the scheduler at ``address`` (``tcp://host:port``).

    Raises
    ------
    SweepError
        If the scheduler does not answer within ``timeout`` seconds.
    """
    try:
        return Client(address, timeout=timeout)
    except (OSError, TimeoutError, ValueError) as exc:
        reason = " ".join(str(exc).split()) or type(exc).__name__
        raise SweepError(
            f"--scheduler {address}: no Dask scheduler reachable within {timeout:g} s ({reason})"
        ) from None


def workers_of(client: Client) -> int:
    """Number of workers the client's cluster has now."""
    return len(client.scheduler_info(n_workers=-1)["workers"])


def on_dask(client: Client) -> Executor:
    """An executor submitting one task per chunk to ``client``.

    The scene, grid and quantities are scattered to every worker once; results come
    back as they finish. When the consumer stops early (Ctrl-C) the unfinished tasks
    are cancelled.
    """

    def run(sweep: Sweep, chunks: list[Chunk]) -> Generator[ChunkResult, None, None]:
        if not chunks:
            return
        client.register_plugin(PinBlasThreads(), name="rt70-pin-blas")
        # hash=False: keys of this run only. Content-hashed keys are shared with an earlier
        # run on the same client, whose futures release them as it ends, and the new
        # run's tasks then lose their inputs ("lost dependencies": measured on two sweeps
        # with the same scene in one client, validation/pointing_budget.py)
        source, grid, quantities = client.scatter(
            [sweep.source, sweep.grid, sweep.quantities], broadcast=True, hash=False
        )
        futures = [
            client.submit(compute_chunk, source, grid, c, quantities, pure=False) for c in chunks
        ]
        try:
            for future in as_completed(futures):
                yield future.result()
        finally:
            client.cancel(futures)

    return run
