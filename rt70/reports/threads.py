"""Single-threaded BLAS and OpenMP while a benchmark times, and a record of it.

On a small shared machine a threaded BLAS makes small matrix products slower, not
faster, and its timings swing with the load of the other cores: with OpenBLAS's default
threading the textbook mass matrix of a 400-body chain took 39.9 ms instead of 1.70 ms
and the fitted growth exponent came out 3.5 instead of 1.2. The benchmarks time
inside :func:`single_threaded`, which pins every thread pool that ``threadpoolctl`` sees
(OpenBLAS, MKL, BLIS, OpenMP) to one thread and records what the pools would use
otherwise, so that the output says under which conditions it was measured.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass


@dataclass
class ThreadPinning:
    """The thread pools during a timing.

    Attributes
    ----------
    unpinned : str
        The pools and their thread counts without the pinning, e.g.
        ``"openblas 2, openmp 2"`` (``"none"`` when no pool was loaded).
    pinned : int
        Largest thread count of any pool while pinned, as read back from the pools on
        entering and again on leaving the ``with`` block (1 when the pinning held,
        also for every library loaded inside the block).
    """

    unpinned: str
    pinned: int = 1

    def describe(self) -> str:
        """One line for a report: ``BLAS/OpenMP threads pinned to 1 (unpinned: …)``."""
        return f"BLAS/OpenMP threads pinned to {self.pinned} (unpinned: {self.unpinned})"


def pools() -> str:
    """The thread pools loaded in this process and their thread counts, sorted, in one line."""
    from threadpoolctl import threadpool_info

    return (
        ", ".join(sorted(f"{p['internal_api']} {p['num_threads']}" for p in threadpool_info()))
        or "none"
    )


def max_threads() -> int:
    """The largest thread count of any pool loaded in this process (1 if none)."""
    from threadpoolctl import threadpool_info

    return max((p["num_threads"] for p in threadpool_info()), default=1)


@contextmanager
def single_threaded() -> Iterator[ThreadPinning]:
    """Pin every BLAS and OpenMP thread pool to one thread for the ``with`` block.

    ``threadpoolctl`` can only limit libraries already loaded, so numpy's and scipy's
    OpenBLAS, Pinocchio's OpenMP runtime and scikit-sundae's own OpenBLAS and OpenMP
    are loaded first; the pools are read back
    when the block ends, so a library loaded inside it and left threaded shows in
    ``pinned``.

    Yields
    ------
    ThreadPinning
        What the pools would use without pinning; ``pinned`` is final after the block.
    """
    import numpy  # noqa: F401  (load the thread pools: only loaded ones can be limited)
    import pinocchio  # noqa: F401
    import scipy.linalg  # noqa: F401
    import sksundae  # noqa: F401  (CVODE: its wheel brings its own OpenBLAS and OpenMP)
    from threadpoolctl import threadpool_limits

    pinning = ThreadPinning(unpinned=pools())
    with threadpool_limits(limits=1):
        pinning.pinned = max_threads()
        try:
            yield pinning
        finally:
            pinning.pinned = max(pinning.pinned, max_threads())
