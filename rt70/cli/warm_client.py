"""Hand a command to the warm process, if one runs: the ``rt70`` command's first step.

Standard library only. When a warm process (``rt70 warm start``,
:mod:`rt70.cli.warm_server`) listens at :func:`~rt70.cli.warm_protocol.socket_path`,
:func:`run` passes it this process's standard streams, words, working directory and
environment; a worker forked from the warm process runs the command on them and sends
back its exit code, and Ctrl-C or SIGTERM here is passed on to the worker. When none
listens, or it cannot serve this request as this process would (rt70 changed since it
started, other start-up variables), :func:`run` returns None and the command runs here.
"""

from __future__ import annotations

import os
import signal
import socket
import struct
import sys

from rt70.cli import warm_protocol as protocol

#: What a command served warm exits with when its worker died without an exit code.
EXIT_WORKER_LOST = 1

FORWARDED_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


def run(argv: list[str]) -> int | None:
    """Run ``rt70 ARGV`` in a worker of the warm process; None: run it here instead.

    Parameters
    ----------
    argv : list of str
        The command's words (``sys.argv[1:]``).

    Returns
    -------
    int or None
        The worker's exit code; None when no warm process serves this request.
    """
    if os.environ.get(protocol.SWITCH_VARIABLE) == "0" or (argv[:1] == ["warm"]):
        return None
    path = protocol.socket_path()
    if not path.exists() or not _streams_open():
        return None
    sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    relay = _Relay()
    try:
        sock.connect(str(path))
        with relay:
            protocol.send(sock, b"R", protocol.request_body(argv), [0, 1, 2])
            kind, payload, _ = protocol.receive(sock)
            if kind == protocol.ANSWERS["pid"]:
                worker = struct.unpack("!i", payload)[0]
                relay.hand_over(worker)
                return _exit_code(sock, worker)
    except OSError:
        pass
    finally:
        sock.close()
    return None  # "cold" (another rt70, other start-up variables), or no warm process


def _streams_open() -> bool:
    """Whether standard input, output and error are open file descriptors."""
    try:
        for fd in (0, 1, 2):
            os.fstat(fd)
    except OSError:
        return False
    return True


class _Relay:
    """Inside the block SIGINT, SIGTERM and SIGHUP go to the worker once it is known.

    A signal that comes before the worker's process id is kept and passed on then; if no
    worker takes the command, it is raised here again when the block ends, as if it had
    come now.
    """

    def __init__(self) -> None:
        self.pending: list[int] = []
        self._worker: int | None = None
        self._previous: dict = {}

    def hand_over(self, pid: int) -> None:
        """From now on relay to the worker ``pid``, the signals kept so far first."""
        self._worker = pid
        for signum in self.pending:
            self._send(signum)
        self.pending.clear()

    def _send(self, signum: int) -> None:
        try:
            os.kill(self._worker, signum)
        except ProcessLookupError:
            pass

    def _handle(self, signum: int, _frame) -> None:
        if self._worker is None:
            self.pending.append(signum)
        else:
            self._send(signum)

    def __enter__(self) -> _Relay:
        self._previous = {s: signal.signal(s, self._handle) for s in FORWARDED_SIGNALS}
        return self

    def __exit__(self, *_exc) -> None:
        for s, handler in self._previous.items():
            signal.signal(s, handler)
        for signum in self.pending:  # nobody took them: as if they came now
            signal.raise_signal(signum)


def _exit_code(sock: socket.socket, worker: int) -> int:
    """The worker's exit code (its answer), or :data:`EXIT_WORKER_LOST`.

    A relayed signal does not break the wait: the socket calls resume after a handler
    that returns (PEP 475).
    """
    kind, payload, _ = protocol.receive(sock)
    if kind != protocol.ANSWERS["exit"]:
        print(f"rt70: error: the warm process's worker {worker} ended without an exit code",
              file=sys.stderr)  # fmt: skip
        return EXIT_WORKER_LOST
    return struct.unpack("!i", payload)[0]
