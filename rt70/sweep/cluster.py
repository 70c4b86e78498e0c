"""The Dask side of :mod:`rt70.sweep.run`: a cluster to run on and the executor that uses it.

- :func:`local_cluster`: a ``LocalCluster`` of single-threaded worker *processes* (one
  per core by default) on the loopback interface, no dashboard;
- :func:`connect`: a client of an existing cluster (``dask scheduler`` + ``dask worker
  tcp://…``), refused with :class:`~rt70.sweep.run.SweepError` when it cannot be reached
  within a timeout;
- :func:`on_dask`: the executor of :func:`rt70.sweep.run.run` that submits one task per
  chunk and yields the results as they finish; a cluster that cannot finish (scheduler
  gone, no worker left, a chunk whose workers keep dying) ends it with one
  :class:`~rt70.sweep.run.ClusterError` (docs/sweeps.md, "Faults of the cluster").

Every worker pins its BLAS to one thread (:class:`PinBlasThreads`, threadpoolctl) and
builds each scene once (:func:`rt70.sweep.run.build_scene` caches it in the worker process).
"""

from __future__ import annotations

import itertools
import logging
import os
import queue
import time
from collections.abc import Generator, Iterator
from concurrent.futures import CancelledError
from contextlib import ExitStack, contextmanager

from distributed import Client, LocalCluster
from distributed.client import FutureCancelledError
from distributed.diagnostics.plugin import WorkerPlugin
from distributed.scheduler import KilledWorker

from rt70.guards.resources import check_memory
from rt70.sweep.quantities import Quantity
from rt70.sweep.run import (
    Chunk,
    ChunkResult,
    ClusterError,
    Executor,
    Grid,
    SceneSource,
    Sweep,
    SweepError,
    compute_chunk,
)

#: Seconds :func:`connect` waits for a scheduler by default.
CONNECT_TIMEOUT = 10.0


#: Seconds :func:`on_dask` lets a cluster have no worker before it stops the sweep.
WORKER_TIMEOUT = 10.0

#: Most chunks :func:`on_dask` keeps submitted at once.
WINDOW = 256

#: Seconds between :func:`on_dask`'s checks of the cluster while no chunk finishes.
POLL = 0.2


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
PRELOAD = ("rt70.sweep.run", "rt70.reference", "rt70.linear.linearize", "rt70.linear.modal")


#: Memory of one local worker process, bytes: its resident set after a chunk of
#: ``rt70_servo`` (numpy, scipy, Pinocchio, rt70, the scene on both sides) is 185 MB
#: (``python validation/sweep_memory.py``), rounded up for larger scenes and the
#: scaled scenes a worker keeps (:data:`rt70.sweep.run.SCENES_KEPT`).
WORKER_BYTES = 300_000_000


def default_workers() -> int:
    """Local workers by default: one per core."""
    return os.cpu_count() or 1


def check_workers(workers: int) -> None:
    """Refuse more local worker processes than this machine's memory holds.

    Raises
    ------
    ResourceError
        ``--workers N``: ``N × WORKER_BYTES`` beyond the share of memory a run may use.
    """
    check_memory(
        workers * WORKER_BYTES,
        f"{workers} worker processes (about {WORKER_BYTES / 1e6:.0f} MB each)",
        f"--workers {workers}",
    )


def local_cluster(workers: int | None = None, **options) -> LocalCluster:
    """A local cluster of ``workers`` single-threaded processes (default: one per core).

    The workers listen on 127.0.0.1 only, serve no dashboard, log nothing below
    CRITICAL (a worker restarted, a task failed: what stops the sweep is one
    :class:`~rt70.sweep.run.ClusterError`), and import :data:`PRELOAD` as they start;
    ``options`` go to ``LocalCluster`` as well (e.g. ``memory_limit``).

    Raises
    ------
    ResourceError
        More workers than this machine's memory holds (:func:`check_workers`).
    """
    n = workers or default_workers()
    check_workers(n)
    return LocalCluster(
        n_workers=n,
        threads_per_worker=1,
        processes=True,
        host="127.0.0.1",
        dashboard_address=None,
        silence_logs=logging.CRITICAL,  # a fault that stops the sweep is a ClusterError
        preload=list(PRELOAD),
        **options,
    )


def start_local(stack: ExitStack, workers: int | None = None) -> Client:
    """Start a :func:`local_cluster` and a client of it, both closed by ``stack``.

    Raises
    ------
    ClusterError
        The cluster did not start (a worker process that cannot start, no free port).
    ResourceError
        More workers than this machine's memory holds (:func:`check_workers`).
    """
    try:
        cluster = stack.enter_context(local_cluster(workers))
        return stack.enter_context(Client(cluster))
    except (OSError, RuntimeError, TimeoutError) as exc:
        reason = " ".join(str(exc).split()) or type(exc).__name__
        raise ClusterError(f"could not start a local Dask cluster ({reason})") from None


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


def on_dask(
    client: Client, worker_timeout: float = WORKER_TIMEOUT, window: int = WINDOW
) -> Executor:
    """An executor submitting one task per chunk to ``client``.

    The scene, grid and quantities go to the cluster as one task (not scattered data):
    when every worker holding them dies the scheduler recomputes them, so a cluster
    whose workers are restarted (a nanny, an autoscaler) carries on. At most ``window``
    chunks are submitted at a time; results come back as they finish. When the
    consumer stops early (Ctrl-C, an error) the unfinished tasks are cancelled.

    Parameters
    ----------
    client : distributed.Client
        Of the cluster to run on.
    worker_timeout : float
        Seconds the cluster may have no worker at all before the sweep stops.
    window : int
        Most chunks submitted and not yet returned.

    Raises
    ------
    ClusterError
        (From the generator.) The scheduler is gone, the cluster has had no worker for
        ``worker_timeout`` seconds, or a chunk's worker died
        ``distributed.scheduler.allowed-failures`` + 1 times (a worker memory limit, a
        crash, killed workers): the sweep cannot finish on this cluster.
    """

    def run(sweep: Sweep, chunks: list[Chunk]) -> Generator[ChunkResult, None, None]:
        if not chunks:
            return
        finished: queue.SimpleQueue = queue.SimpleQueue()
        running: dict = {}
        todo = iter(chunks)
        watch = _WorkerWatch(client, worker_timeout)
        try:
            with _cluster_faults():
                client.register_plugin(PinBlasThreads(), name="rt70-pin-blas")
                inputs = client.submit(
                    _inputs, sweep.source, sweep.grid, sweep.quantities, pure=False
                )
                for chunk in itertools.islice(todo, window):
                    _submit(client, inputs, chunk, running, finished)
            while running:
                future = _next_finished(finished, watch)
                yield _result(future, running.pop(future))
                with _cluster_faults():
                    for chunk in itertools.islice(todo, 1):
                        _submit(client, inputs, chunk, running, finished)
        finally:
            _cancel(client, list(running))

    return run


def _inputs(source: SceneSource, grid: Grid, quantities: tuple[Quantity, ...]):
    """The task holding a sweep's inputs (recomputed by the scheduler if they are lost)."""
    return source, grid, quantities


def _compute(inputs, chunk: Chunk) -> ChunkResult:
    """One chunk's task: :func:`rt70.sweep.run.compute_chunk` on the inputs' task result."""
    source, grid, quantities = inputs
    return compute_chunk(source, grid, chunk, quantities)


def _submit(client: Client, inputs, chunk: Chunk, running: dict, finished) -> None:
    future = client.submit(_compute, inputs, chunk, pure=False)
    running[future] = chunk
    future.add_done_callback(finished.put)


def _result(future, chunk: Chunk) -> ChunkResult:
    """The chunk's result; a fault of the cluster as :class:`ClusterError`.

    An exception the task itself raised (a bug in a quantity) is raised as it is.
    """
    try:
        return future.result()
    except KilledWorker as exc:
        deaths = exc.allowed_failures + 1
        raise ClusterError(
            f"chunk {chunk.number}: the worker it was given to died {deaths} time(s) (a "
            "worker memory limit, a crash or killed workers)"
        ) from None
    except Exception as exc:
        if future.status == "error":
            raise  # raised by compute_chunk on the worker
        raise ClusterError(f"chunk {chunk.number}: {_fault(exc)}") from None


def _next_finished(finished: queue.SimpleQueue, watch: _WorkerWatch):
    """The next future to finish; checks the cluster while none does."""
    while True:
        try:
            return finished.get(timeout=POLL)
        except queue.Empty:
            pass
        watch.check()


def _cancel(client: Client, futures: list) -> None:
    """Cancel unfinished tasks if the scheduler can still be told (a stop, an error)."""
    if futures and client.status == "running":
        try:
            client.cancel(futures)
        except (OSError, TimeoutError):
            pass  # the scheduler went away meanwhile: nothing left to cancel


class _WorkerWatch:
    """Stops a sweep whose cluster has had no worker for ``timeout`` seconds."""

    def __init__(self, client: Client, timeout: float):
        self.client = client
        self.timeout = timeout
        self.since: float | None = None

    def check(self) -> None:
        """Raise :class:`ClusterError` if the scheduler is gone or has been without workers."""
        if self.client.status != "running":
            raise ClusterError("lost the connection to the Dask scheduler")
        with _cluster_faults():
            workers = workers_of(self.client)
        if workers > 0:
            self.since = None
            return
        now = time.monotonic()
        self.since = now if self.since is None else self.since
        if now - self.since > self.timeout:
            raise ClusterError(
                f"the Dask cluster has had no worker for {self.timeout:g} s "
                "(every worker died or left)"
            )


@contextmanager
def _cluster_faults() -> Iterator[None]:
    """Turn the client's connection failures into :class:`ClusterError`."""
    try:
        yield
    except (OSError, TimeoutError, CancelledError) as exc:
        raise ClusterError(_fault(exc)) from None


def _fault(exc: BaseException) -> str:
    """One line for a fault of the cluster."""
    if isinstance(exc, FutureCancelledError) and exc.reason == "scheduler-connection-lost":
        return "lost the connection to the Dask scheduler"
    if isinstance(exc, CancelledError):
        reason = getattr(exc, "reason", "") or "no reason given"
        if reason == "lost dependencies":  # the inputs' task could not be loaded or kept
            reason += ": the sweep's inputs; can the scheduler and workers import rt70 and "
            reason += "the quantities' modules?"
        return f"cancelled by the Dask cluster ({reason})"
    text = " ".join(str(exc).split())
    return f"lost the Dask scheduler ({type(exc).__name__}{': ' + text if text else ''})"
