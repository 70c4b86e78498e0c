"""Stop requests that cannot be lost: a signal is recorded as well as raised.

Python turns SIGINT into a ``KeyboardInterrupt`` raised wherever the main thread happens
to be. Raised inside a finaliser, a weak-reference callback, or library code that catches
broadly, it is lost and the work goes on: ``rt70 simulate double_pendulum --t-end 1e6
--progress`` once ignored a Ctrl-C under heavy load and integrated on. The command line's
handlers therefore :func:`request` the stop (which records it and raises), and code that
calls back into rt70 on every step — the integrators' right-hand side
(:func:`rt70.simulation.integrators.budgeted`) — calls :func:`check`, which raises it again
until the command is over. The cost is one list test per call.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import NoReturn

_REQUESTED: list[Callable[[], BaseException]] = []


def request(make: Callable[[], BaseException]) -> NoReturn:
    """Record a stop and raise it: ``make()`` builds the exception, here and at every check.

    Parameters
    ----------
    make : callable
        Returns the exception that stops the work, e.g. ``KeyboardInterrupt`` or
        ``lambda: SystemExit(143)``.
    """
    _REQUESTED.append(make)
    raise make()


def check() -> None:
    """Raise the first recorded stop again, if there is one; else return at once."""
    if _REQUESTED:
        raise _REQUESTED[0]()


def requested() -> bool:
    """Whether a stop was requested since the last :func:`clear`."""
    return bool(_REQUESTED)


def clear() -> None:
    """Forget every recorded stop (the command that received them is over)."""
    _REQUESTED.clear()
