"""``rt70 warm start|stop|status``: the warm process that serves the next commands.

``start`` launches :mod:`rt70.cli.warm_server` in a session of its own and waits until it
answers (its warm-up takes a few seconds); while it runs, every ``rt70`` command of this
user (the same socket, :func:`rt70.cli.warm_protocol.socket_path`) runs in a worker
forked from it, without the start-up (docs/performance.md, "The warm process").
``RT70_WARM=0`` runs a command in its own interpreter regardless.
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import socket
import subprocess
import sys
import time
from pathlib import Path

from rt70.cli import options
from rt70.cli import warm_protocol as protocol
from rt70.errors import Rt70Error

#: How long ``start`` waits for the warm-up, s.
START_TIMEOUT_S = 180.0
#: How long :func:`settled` waits for the later warm-up (a compile after an install), s.
LATER_TIMEOUT_S = 600.0

#: Idle time after which the warm process stops, minutes (``--idle``).
DEFAULT_IDLE_MIN = 60.0


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """The ``warm`` subcommand (run by :func:`run`)."""
    warm = sub.add_parser(
        "warm",
        help="start, stop or show the warm process that runs commands without start-up",
        description="A warm process imports rt70 and loads its compiled kernels once; "
        "while it runs, each rt70 command of this user runs in a worker forked from it "
        "(the same output and exit code, without the 0.7–1.5 s start-up). RT70_WARM=0 "
        "runs a command in its own interpreter; RT70_WARM_SOCKET sets the socket; "
        "RT70_WARM_LATER=0 leaves the compiled BDF's kernels out of the warm process.",
    )
    warm.add_argument("action", choices=("start", "stop", "status"), help="what to do")
    warm.add_argument(
        "--idle", type=options.positive_float, default=DEFAULT_IDLE_MIN, metavar="MIN",
        help="start: stop after this many minutes without a command "
        f"(default {DEFAULT_IDLE_MIN:g})",
    )  # fmt: skip
    warm.add_argument(
        "--settle", action="store_true",
        help="start: also wait until the compiled BDF's kernels are loaded (their first "
        f"compile after an install takes a minute or more; at most {LATER_TIMEOUT_S:g} s)",
    )  # fmt: skip
    warm.set_defaults(func=run)
    return warm


def run(args: argparse.Namespace) -> int:
    """Do ``args.action``; print one line (status: its fields)."""
    if not hasattr(socket, "AF_UNIX") or not hasattr(os, "fork"):
        raise Rt70Error("rt70 warm: the warm process needs fork and Unix sockets (POSIX)")
    path = protocol.socket_path()
    status = _ask(path, b"T")
    if args.action == "status":
        print(_describe(status) if status else f"rt70: no warm process at {path}")
        return 0
    if args.action == "stop":
        if status is None:
            print(f"rt70: no warm process at {path}")
            return 0
        _ask(path, b"Q")
        print(f"rt70: warm process {status['pid']} stopped")
        return 0
    if status is not None:
        print(f"rt70: already running: {_describe(status)}")
        return 0
    status = _start(path, args.idle * 60.0)
    if args.settle:
        status = settled(path) or status
    print(f"rt70: warm process ready: {_describe(status)}")
    return 0


def _start(path: Path, idle_s: float) -> dict:
    """Launch the warm process and wait for its first answer; its status."""
    if len(os.fsencode(path)) >= 100:  # sockaddr_un holds 104–108 bytes
        raise Rt70Error(f"rt70 warm: the socket path '{path}' is too long for a Unix socket")
    if not path.parent.is_dir():
        raise Rt70Error(f"rt70 warm: no directory '{path.parent}' for the socket")
    log = path.with_name(path.name + ".log")
    with open(log, "w") as stderr:
        process = subprocess.Popen(
            [sys.executable, "-m", "rt70.cli.warm_server", "--idle", repr(idle_s)],
            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=stderr,
            start_new_session=True,
        )  # fmt: skip
    deadline = time.monotonic() + START_TIMEOUT_S
    while time.monotonic() < deadline:
        status = _ask(path, b"T")
        if status is not None and status.get("pid") == process.pid:
            return status
        if process.poll() is not None:
            last = log.read_text(errors="replace").strip().splitlines()[-1:] or ["no message"]
            raise Rt70Error(f"rt70 warm: the warm process stopped while warming up: {last[0]}")
        time.sleep(0.1)
    process.terminate()
    raise Rt70Error(f"rt70 warm: the warm process did not answer in {START_TIMEOUT_S:g} s")


def _ask(path: Path, kind: bytes) -> dict | None:
    """Send ``kind`` (T: status, Q: stop) to the warm process; its JSON answer or None."""
    if not path.exists():
        return None
    sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    sock.settimeout(10.0)
    try:
        sock.connect(str(path))
        protocol.send(sock, kind)
        answer, payload, _ = protocol.receive(sock)
    except OSError:
        return None
    finally:
        sock.close()
    if answer == protocol.ANSWERS["status"]:
        return json.loads(payload)
    return {} if answer == protocol.ANSWERS["stopping"] else None


def settled(path: Path, timeout_s: float = LATER_TIMEOUT_S) -> dict | None:
    """The warm process's status once its later warm-up has ended (or ``timeout_s`` passed).

    Parameters
    ----------
    path : Path
        Its socket.
    timeout_s : float
        The longest wait, s.

    Returns
    -------
    dict or None
        Its status (``later``: how the later warm-up ended, or ``compiling`` at the
        timeout); None when no warm process answers there.
    """
    deadline = time.monotonic() + timeout_s
    status = _ask(path, b"T")
    while status and status.get("later") == "compiling" and time.monotonic() < deadline:
        time.sleep(0.2)
        status = _ask(path, b"T")
    return status


def _describe(status: dict) -> str:
    """One line: pid, socket, age, warm-up time and later warm-up, commands served, memory."""
    started = datetime.datetime.fromtimestamp(status["started"]).strftime("%Y-%m-%d %H:%M:%S")
    memory = f", {status['rss_mb']:g} MB resident" if status.get("rss_mb") else ""
    return (
        f"pid {status['pid']} at {status['socket']}, started {started} (warm-up "
        f"{status['warm_up_s']:g} s; compiled BDF {status.get('later', 'not started')}), "
        f"{status['served']} command(s) served, stops after "
        f"{status['idle_s'] / 60.0:g} min idle{memory}"
    )
