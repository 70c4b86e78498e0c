"""The warm process: rt70 imported and its compiled kernels loaded once, a fork per command.

A command started cold spends about 1.5 s before any work on rt70_servo (numpy, scipy,
SUNDIALS' bindings, Pinocchio, numba and its cached kernels: docs/performance.md). The
warm process pays that once: it imports the modules the commands use and runs a few
short commands (:data:`WARM_UP`) so that numba's kernels are loaded, then listens on a
Unix socket (:func:`rt70.cli.warm_protocol.socket_path`, the owner alone may connect).
Each request forks a worker, which takes the client's standard streams, working
directory and environment and runs :func:`rt70.cli.main.run_here` on its words: the
command sees what it would see in its own process, and nothing it changes reaches the
warm process or the next command. Commands whose first run after an install compiles
kernels for a minute or more (:data:`LATER`) are run once it serves: by a child first,
which compiles what numba's cache lacks, then by the warm process itself, which loads
the cache; until then a worker loads or compiles them as a cold command would.

The warm process serves a request only as the client's own process would run it: the
client's rt70 must be the same files (:func:`~rt70.cli.warm_protocol.fingerprint`; when
the files changed under it, it stops), and the start-up variables the same
(:data:`~rt70.cli.warm_protocol.STARTUP_PREFIXES`); otherwise it answers "cold" and the
client runs the command itself. It stops after ``idle`` seconds without a request, on
``rt70 warm stop``, or when its socket was removed or taken by another.

Run as ``python -m rt70.cli.warm_server --idle SECONDS`` by ``rt70 warm start``.
"""

from __future__ import annotations

import argparse
import contextlib
import gc
import io
import json
import os
import select
import signal
import socket
import struct
import sys
import time
import traceback
from pathlib import Path

from rt70.cli import warm_protocol as protocol

#: Commands run once at start (output discarded): they load the modules and numba kernels
#: the simulations, the servo scenarios and the linear models use.
WARM_UP = (
    ("simulate", "rt70_servo", "--scenario", "hold", "--t-end", "0.2", "--no-plot"),
    ("simulate", "rt70", "--t-end", "0.01", "--no-plot"),
    ("modes", "three_masses"),
)

#: Commands whose first run after an install compiles kernels for a minute or more (the
#: compiled BDF's). A child forked once the warm process serves runs them, compiling what
#: numba's cache lacks; then the warm process runs them itself, loading the cache (a
#: fraction of a second), so that its workers inherit the kernels
#: (:meth:`Server.start_later`, :meth:`Server.finish_later`). ``RT70_WARM_LATER=0`` leaves
#: them out.
LATER = (("simulate", "rt70", "--t-end", "0.01", "--method", "compiled-BDF", "--no-plot"),)

#: Modules imported at start besides what :data:`WARM_UP` loads (python-control: the
#: plant and servo commands; matplotlib with its file backend: the plots).
MODULES = ("control", "matplotlib.pyplot", "scipy.signal")

#: How often an idle warm process checks that its socket is still its own, s.
TICK_S = 30.0


class Server:
    """The warm process's state: its socket, start fingerprint, counters."""

    def __init__(self, path: Path, idle_s: float) -> None:
        self.path, self.idle_s = path, idle_s
        self.fingerprint = protocol.fingerprint()
        self.startup = protocol.startup_environment(os.environ)
        self.started, self.served, self.warm_up_s = time.time(), 0, 0.0
        self.listener: socket.socket | None = None
        self.inode = 0
        self.later: int | None = None  # the read end of the LATER child's pipe
        self.later_pid, self.later_state = 0, "not started"

    def warm_up(self) -> None:
        """Import :data:`MODULES` and run :data:`WARM_UP` (output to the null device)."""
        start = time.perf_counter()
        os.environ.setdefault("MPLBACKEND", "Agg")
        for name in MODULES:
            with contextlib.suppress(ImportError):
                __import__(name)
        _quietly(WARM_UP)
        gc.collect()
        gc.freeze()  # the workers' collections skip what is here: fewer pages copied on write
        self.warm_up_s = time.perf_counter() - start

    def start_later(self) -> None:
        """Fork the child that runs :data:`LATER`; it writes one byte when all succeeded."""
        read, write = os.pipe()
        pid = os.fork()
        if pid == 0:
            os.close(read)
            self.listener.close()
            code = 1
            try:
                if _quietly(LATER):
                    os.write(write, b"1")
                    code = 0
            finally:
                os._exit(code)
        os.close(write)
        self.later, self.later_pid, self.later_state = read, pid, "compiling"

    def finish_later(self) -> None:
        """The child has ended: run :data:`LATER` here if it succeeded (the cache loads)."""
        ok = os.read(self.later, 1) == b"1"
        os.close(self.later)
        self.later = None
        if not ok:
            self.later_state = "failed"
            _log("the later warm-up failed in its child: not loaded")
            return
        start = time.perf_counter()
        ok = _quietly(LATER)
        gc.collect()
        gc.freeze()
        self.later_state = f"loaded in {time.perf_counter() - start:.2f} s" if ok else "failed"
        _log(f"later warm-up: {self.later_state}")

    def stop_later(self) -> None:
        """Stop the :data:`LATER` child if it still runs."""
        if self.later is not None:
            with contextlib.suppress(OSError):
                os.kill(self.later_pid, signal.SIGTERM)
            os.close(self.later)
            self.later = None

    def listen(self) -> None:
        """Bind the socket, readable and writable by its owner alone."""
        with contextlib.suppress(FileNotFoundError):
            self.path.unlink()
        self.listener = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        old = os.umask(0o177)
        try:
            self.listener.bind(str(self.path))
        finally:
            os.umask(old)
        self.listener.listen(16)
        self.listener.settimeout(TICK_S)
        self.inode = os.stat(self.path).st_ino

    def owns_socket(self) -> bool:
        """Whether the socket file is still the one this process bound."""
        try:
            return os.stat(self.path).st_ino == self.inode
        except OSError:
            return False

    def loop(self) -> None:
        """Serve requests until idle, stopped, or the socket is no longer ours."""
        last = time.monotonic()
        while self.owns_socket() and time.monotonic() - last < self.idle_s:
            waiting = [self.listener] + ([] if self.later is None else [self.later])
            ready = select.select(waiting, [], [], TICK_S)[0]
            if self.later is not None and self.later in ready:
                self.finish_later()
            if self.listener not in ready:
                continue
            try:
                conn, _ = self.listener.accept()
            except TimeoutError:
                continue
            last = time.monotonic()
            with conn:
                conn.settimeout(None)
                try:
                    keep = self.answer(conn)
                except Exception:  # one connection's trouble (a client gone) is not ours
                    _log(traceback.format_exc().rstrip())
                    keep = True
                if not keep:
                    return
        _log("idle: stopping" if self.owns_socket() else "the socket is not ours: stopping")

    def answer(self, conn: socket.socket) -> bool:
        """Answer one connection; False: stop serving."""
        kind, payload, fds = protocol.receive(conn, max_fds=3)
        try:
            if kind == b"T":
                protocol.send(conn, protocol.ANSWERS["status"], json.dumps(self.status()).encode())
                return True
            if kind == b"Q":
                protocol.send(conn, protocol.ANSWERS["stopping"])
                _log("asked to stop: stopping")
                return False
            if kind != b"R" or len(fds) != 3 or not _same_user(conn):
                return True
            request = json.loads(payload)
            reason = self.refusal(request)
            if reason is not None:
                protocol.send(conn, protocol.ANSWERS["cold"], reason.encode())
                _log(f"not served ({reason})" + (": stopping" if reason == STALE else ""))
                return reason != STALE
            self.served += 1
            if os.fork() == 0:
                _work(conn, self.listener, request, fds)  # never returns
            return True
        finally:
            for fd in fds:
                os.close(fd)

    def refusal(self, request: dict) -> str | None:
        """Why this request must run in its own interpreter, or None."""
        if request.get("fingerprint") != self.fingerprint:
            return STALE if protocol.fingerprint() != self.fingerprint else "another rt70"
        if protocol.startup_environment(request.get("env", {})) != self.startup:
            return "other start-up variables"
        return None

    def status(self) -> dict:
        """What ``rt70 warm status`` prints."""
        return {
            "pid": os.getpid(),
            "socket": str(self.path),
            "started": self.started,
            "idle_s": self.idle_s,
            "served": self.served,
            "warm_up_s": round(self.warm_up_s, 3),
            "later": self.later_state,
            "rss_mb": _rss_mb(),
            "fingerprint": self.fingerprint,
        }


#: The refusal that stops the warm process: its rt70 files changed since it started.
STALE = "rt70 changed since the warm process started"


def _quietly(commands) -> bool:
    """Run each command here, its output to the null device; whether all exited 0.

    A command that did not is logged (:func:`_log`).
    """
    from rt70.cli.main import run_here

    failed = []
    with open(os.devnull, "w") as null:
        with contextlib.redirect_stdout(null), contextlib.redirect_stderr(null):
            for words in commands:
                code = run_here(list(words))
                if code != 0:
                    failed.append(f"'rt70 {' '.join(words)}' exited {code}")
    for line in failed:
        _log(f"warm-up: {line}")
    return not failed


def _log(line: str) -> None:
    """One line (or a traceback) on the warm process's log (``<socket>.log``), timed."""
    print(f"{time.strftime('%Y-%m-%d %H:%M:%S')} {line}", file=sys.stderr, flush=True)


def _same_user(conn: socket.socket) -> bool:
    """Whether the peer runs as this user: Linux's SO_PEERCRED, elsewhere the socket's mode."""
    option = getattr(socket, "SO_PEERCRED", None)
    if option is None:
        return True
    _, uid, _ = struct.unpack("3i", conn.getsockopt(socket.SOL_SOCKET, option, 12))
    return uid == os.getuid()


def _rss_mb() -> float | None:
    """Resident memory of the warm process, MB (Linux), else None."""
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                return round(int(line.split()[1]) / 1024.0, 1)
    except OSError:
        return None
    return None


def _work(conn: socket.socket, listener: socket.socket, request: dict, fds: list[int]):
    """The forked worker: take the client's streams and run its command; never returns."""
    code = 1
    try:
        listener.close()
        signal.signal(signal.SIGCHLD, signal.SIG_DFL)
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
        signal.signal(signal.SIGINT, signal.default_int_handler)
        for target, fd in zip((0, 1, 2), fds, strict=True):
            os.dup2(fd, target)
        os.chdir(request["cwd"])
        os.environ.clear()
        os.environ.update(request["env"])
        _reopen_streams(request.get("encoding"))
        _reseed()
        sys.argv = ["rt70", *request["argv"]]
        protocol.send(conn, protocol.ANSWERS["pid"], struct.pack("!i", os.getpid()))
        code = _run(request["argv"])
    finally:
        with contextlib.suppress(BaseException):
            protocol.send(conn, protocol.ANSWERS["exit"], struct.pack("!i", code))
        os._exit(0)


def _run(argv: list[str]) -> int:
    """:func:`rt70.cli.main.run_here` on ``argv``, as the ``rt70`` script would exit."""
    from rt70.cli.main import run_here

    try:
        code = run_here(argv)
    except SystemExit as exc:
        code = exc.code
    except BaseException:  # a bug: the traceback, as the script would print it
        traceback.print_exc()
        code = 1
    if code is None or isinstance(code, str):
        if isinstance(code, str):
            print(code, file=sys.stderr)
        code = 0 if code is None else 1
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):
            stream.flush()
    return int(code)


def _reopen_streams(encodings: list[str] | None) -> None:
    """``sys.stdin``, ``stdout``, ``stderr`` on descriptors 0–2, as Python opens them."""
    encodings = encodings or [None, None, None]
    sys.stdout = _text(1, "w", encodings[0], line=os.isatty(1))
    sys.stderr = _text(2, "w", encodings[1], line=True)
    sys.stdin = _text(0, "r", encodings[2], line=False)


def _text(fd: int, mode: str, encoding: str | None, line: bool) -> io.TextIOWrapper:
    """A text stream on ``fd`` (not closing it), line-buffered if ``line``."""
    errors = "backslashreplace" if fd == 2 else None
    buffering = 1 if line else -1
    return open(fd, mode, buffering, encoding or "utf-8", errors, closefd=False)


def _reseed() -> None:
    """Fresh seeds for the global random generators (a fork shares the warm process's)."""
    import random

    random.seed()
    numpy = sys.modules.get("numpy")
    if numpy is not None:
        numpy.random.seed()


def main(argv: list[str] | None = None) -> int:
    """``python -m rt70.cli.warm_server --idle SECONDS``: warm up, then serve."""
    parser = argparse.ArgumentParser(prog="python -m rt70.cli.warm_server")
    parser.add_argument("--idle", type=float, required=True, help="idle time to stop, s")
    args = parser.parse_args(argv)
    server = Server(protocol.socket_path(), args.idle)
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(0))  # SIGTERM removes the socket too
    server.warm_up()
    signal.signal(signal.SIGCHLD, signal.SIG_IGN)  # the workers are reaped by the system
    server.listen()
    _log(f"pid {os.getpid()} ready at {server.path} (warm-up {server.warm_up_s:.2f} s)")
    if os.environ.get("RT70_WARM_LATER", "1") != "0":
        server.start_later()
    else:
        server.later_state = "off (RT70_WARM_LATER=0)"
    try:
        server.loop()
    finally:
        server.stop_later()
        if server.owns_socket():
            server.path.unlink()
    return 0


if __name__ == "__main__":
    sys.exit(main())
