"""The warm process's address, fingerprint and messages, in the standard library alone.

The client (:mod:`rt70.cli.warm_client`) imports this before anything heavy, so that a
command served warm never pays for numpy. A request is one message carrying the caller's
standard streams (their file descriptors, passed over the Unix socket as
``SCM_RIGHTS``) and a JSON body: the command's words, the working directory, the
environment, the streams' encoding and the client's fingerprint of rt70. The answers are
one letter and a payload (:data:`ANSWERS`).
"""

from __future__ import annotations

import hashlib
import json
import os
import socket
import struct
import sys
from pathlib import Path

#: The socket's path, if set; else ``$XDG_RUNTIME_DIR`` (or ``$TMPDIR``, ``/tmp``)
#: ``/rt70-warm-<uid>.sock``.
SOCKET_VARIABLE = "RT70_WARM_SOCKET"

#: ``RT70_WARM=0``: every command runs in its own interpreter, a warm process or not.
SWITCH_VARIABLE = "RT70_WARM"

#: Environment variables read when numpy, the BLAS, numba or Python start: a request whose
#: values differ from the warm process's runs in its own interpreter.
STARTUP_PREFIXES = (
    "PYTHON", "OMP_", "OPENBLAS_", "MKL_", "BLIS_", "VECLIB_", "NUMEXPR_", "NUMBA_",
    "RT70_WARM",
)  # fmt: skip

#: One-letter answers: the worker's process id, its exit code, "run it yourself" (with the
#: reason), the status (JSON), and "stopping".
ANSWERS = {"pid": b"P", "exit": b"X", "cold": b"C", "status": b"S", "stopping": b"Q"}

_LENGTH = struct.Struct("!I")


def socket_path() -> Path:
    """The warm process's socket (:data:`SOCKET_VARIABLE`)."""
    explicit = os.environ.get(SOCKET_VARIABLE)
    if explicit:
        return Path(explicit)
    base = os.environ.get("XDG_RUNTIME_DIR") or os.environ.get("TMPDIR") or "/tmp"
    return Path(base) / f"rt70-warm-{os.getuid()}.sock"


def startup_environment(environ: dict[str, str] | os._Environ) -> dict[str, str]:
    """The variables of ``environ`` that act at start-up (:data:`STARTUP_PREFIXES`)."""
    return {k: v for k, v in environ.items() if k.startswith(STARTUP_PREFIXES)}


def fingerprint() -> str:
    """A digest of this environment (its prefix and interpreter) and of rt70's files.

    Each source or data file of the package counts by its path, size and modification time.

    A warm process whose fingerprint differs from its client's runs code that is not
    the client's (rt70 edited or reinstalled since it started): it does not serve it.
    """
    package = Path(__file__).resolve().parents[1]
    digest = hashlib.sha1(f"{sys.prefix}|{os.path.realpath(sys.executable)}".encode())
    stack = [str(package)]
    while stack:
        with os.scandir(stack.pop()) as entries:
            for entry in sorted(entries, key=lambda e: e.name):
                if entry.is_dir(follow_symlinks=False) and entry.name != "__pycache__":
                    stack.append(entry.path)
                elif entry.name.endswith((".py", ".urdf", ".csv", ".json")):
                    info = entry.stat()
                    digest.update(f"{entry.path}|{info.st_size}|{info.st_mtime_ns}".encode())
    return digest.hexdigest()


def send(sock: socket.socket, kind: bytes, payload: bytes = b"", fds: list[int] | None = None):
    """One message: its kind, its payload's length, the payload; ``fds`` passed with it.

    Parameters
    ----------
    sock : socket.socket
        A connected Unix stream socket.
    kind : bytes
        One letter: of :data:`ANSWERS`, or ``R`` (a request), ``T`` (status), ``Q`` (stop).
    payload : bytes
        The body (JSON, a packed integer, or nothing).
    fds : list of int, optional
        File descriptors passed with it (``SCM_RIGHTS``): a request's standard streams.
    """
    data = kind + _LENGTH.pack(len(payload)) + payload
    if fds:
        socket.send_fds(sock, [data], fds)
    else:
        sock.sendall(data)


def receive(sock: socket.socket, max_fds: int = 0) -> tuple[bytes, bytes, list[int]]:
    """The next message: ``(kind, payload, fds)``; ``(b"", b"", [])`` when the peer closed."""
    if max_fds:
        head, fds, _, _ = socket.recv_fds(sock, 1 + _LENGTH.size, max_fds)
    else:
        head, fds = sock.recv(1 + _LENGTH.size), []
    while head and len(head) < 1 + _LENGTH.size:
        more = sock.recv(1 + _LENGTH.size - len(head))
        if not more:
            return b"", b"", list(fds)
        head += more
    if not head:
        return b"", b"", list(fds)
    (length,) = _LENGTH.unpack(head[1:])
    payload = b""
    while len(payload) < length:
        more = sock.recv(min(length - len(payload), 1 << 16))
        if not more:
            return b"", b"", list(fds)
        payload += more
    return head[:1], payload, list(fds)


def request_body(argv: list[str]) -> bytes:
    """The JSON body of a request to run ``rt70 ARGV`` as this process would."""
    return json.dumps(
        {
            "argv": argv,
            "cwd": os.getcwd(),
            "env": dict(os.environ),
            "encoding": [sys.stdout.encoding, sys.stderr.encoding, sys.stdin.encoding]
            if sys.stdin is not None and sys.stdout is not None and sys.stderr is not None
            else None,
            "fingerprint": fingerprint(),
        }
    ).encode()
