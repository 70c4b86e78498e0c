"""The warm process (``rt70 warm``): a command served by it is the command run cold.

One warm process for the module, on a socket of its own (``RT70_WARM_SOCKET``): the same
output, exit code and files as in a fresh interpreter, the error lines of bad input, the
client's working directory, Ctrl-C passed on to the worker; a request it cannot serve as
the client would run it (other start-up variables, other rt70 files) runs cold.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from rt70.cli import warm_protocol, warm_server

pytestmark = pytest.mark.skipif(not hasattr(os, "fork"), reason="the warm process needs fork")

RT70 = [sys.executable, "-m", "rt70"]


def _env(socket_path: Path, **extra: str) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k != "RT70_WARM"}
    return {**env, "RT70_WARM_SOCKET": str(socket_path), "MPLBACKEND": "Agg", **extra}


def _rt70(env, *words, cwd=None, check_code=None) -> subprocess.CompletedProcess:
    done = subprocess.run([*RT70, *words], env=env, cwd=cwd, capture_output=True, text=True,
                          timeout=300)  # fmt: skip
    if check_code is not None:
        assert done.returncode == check_code, done.stderr
    return done


def _served(env) -> int:
    line = _rt70(env, "warm", "status", check_code=0).stdout
    return int(line.split(" command(s) served")[0].rsplit(" ", 1)[1])


@pytest.fixture(scope="module")
def warm(tmp_path_factory):
    """A warm process on a socket of its own; stopped after the module."""
    env = _env(tmp_path_factory.mktemp("warm") / "w.sock")
    started = _rt70(env, "warm", "start", "--idle", "10", check_code=0)
    assert "warm process ready: pid" in started.stdout
    yield env
    _rt70(env, "warm", "stop", check_code=0)


def test_a_command_served_warm_prints_what_it_prints_cold(warm, tmp_path):
    before = _served(warm)
    words = ("simulate", "double_pendulum", "--t-end", "0.5", "--out", "run.csv", "--no-plot")
    hot = _rt70(warm, *words, cwd=tmp_path, check_code=0)
    assert _served(warm) == before + 1  # it was the warm process's worker
    cold_dir = tmp_path / "cold"
    cold_dir.mkdir()
    cold = _rt70({**warm, "RT70_WARM": "0"}, *words, cwd=cold_dir, check_code=0)
    assert _served(warm) == before + 1  # RT70_WARM=0: not served
    strip = lambda text: [ln for ln in text.splitlines() if "wall" not in ln and "split" not in ln]  # noqa: E731
    assert strip(hot.stdout) == strip(cold.stdout) and hot.stdout
    assert (tmp_path / "run.csv").read_text() == (cold_dir / "run.csv").read_text()


def test_bad_input_is_one_line_and_exit_2_through_the_warm_process(warm):
    before = _served(warm)
    done = _rt70(warm, "simulate", "no_such_scene", check_code=2)
    assert _served(warm) == before + 1
    assert done.stderr.count("\n") == 1 and done.stderr.startswith("rt70: error: no_such_scene")
    typo = _rt70(warm, "simulate", "rt70", "--t-ned", "1", check_code=2)
    assert "--t-ned" in typo.stderr and "Traceback" not in typo.stderr


def test_other_start_up_variables_run_cold(warm):
    before = _served(warm)
    other = "3" if os.environ.get("OMP_NUM_THREADS") != "3" else "5"  # not the warm one's
    done = _rt70({**warm, "OMP_NUM_THREADS": other}, "--version", check_code=0)
    assert done.stdout.startswith("rt70 ")
    assert _served(warm) == before


def test_ctrl_c_reaches_the_worker(warm):
    """SIGINT to the client interrupts the worker: exit 130, 'rt70: interrupted'."""
    before = _served(warm)
    client = subprocess.Popen(
        [*RT70, "simulate", "rt70", "--t-end", "500", "--no-plot"], env=warm,
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    deadline = time.monotonic() + 120.0
    while _served(warm) == before and time.monotonic() < deadline:
        time.sleep(0.2)  # until the client has handed its command over (then it relays)
    client.send_signal(signal.SIGINT)
    _, err = client.communicate(timeout=120)
    assert client.returncode == 130, err
    assert "rt70: interrupted" in err
    assert _served(warm) == before + 1


def test_a_server_whose_files_changed_stops_and_another_rt70_runs_cold(monkeypatch, tmp_path):
    server = warm_server.Server(tmp_path / "s.sock", idle_s=1.0)
    env = dict(os.environ)
    same = {"fingerprint": server.fingerprint, "env": env}
    assert server.refusal(same) is None
    assert server.refusal({**same, "env": {**env, "NUMBA_DISABLE_JIT": "1"}}) == (
        "other start-up variables"
    )
    assert server.refusal({**same, "fingerprint": "another"}) == "another rt70"
    monkeypatch.setattr(warm_protocol, "fingerprint", lambda: "edited since")
    assert server.refusal({**same, "fingerprint": "edited since"}) == warm_server.STALE


def test_start_status_stop_without_a_process(tmp_path):
    env = _env(tmp_path / "none.sock")
    assert "no warm process at" in _rt70(env, "warm", "status", check_code=0).stdout
    assert "no warm process at" in _rt70(env, "warm", "stop", check_code=0).stdout
    long = _env(tmp_path / ("x" * 120) / "w.sock")
    done = _rt70(long, "warm", "start", check_code=2)
    assert done.stderr.startswith("rt70: error: rt70 warm: the socket path")


def test_the_bench_times_commands_served_by_a_warm_process_of_its_own():
    """``rt70.reports.targets.warm_process``: its commands are served, then it stops."""
    from rt70.reports.targets import wall_times, warm_process

    with warm_process() as env:
        assert len(wall_times(["--version"], 2, env)) == 2
        assert _served(env) == 2
    assert "no warm process at" in _rt70(env, "warm", "status", check_code=0).stdout


def test_the_large_model_bench_times_a_command_served_warm(warm, tmp_path):
    """``rt70 bench large``'s warm row: a served command's wall time judged, a failure not met."""
    from rt70.reports import large_targets as lt

    before = _served(warm)
    ok = lt._judged_warm(["modes", "three_masses"], 1e9, tmp_path, warm)
    assert _served(warm) == before + 1
    failed = lt._judged_warm(["modes", "missing.urdf"], 1e9, tmp_path, warm)
    assert failed.met is False and "exit 2" in failed.measured
    assert ok.target.endswith("warm process") and "served by the warm process" in ok.measured


def test_a_signal_before_the_worker_is_known_reaches_it_then():
    """The client relays a signal that came during the hand-over once the worker's pid
    arrives (the worker then ends as the signal says)."""
    from rt70.cli.warm_client import _Relay

    worker = subprocess.Popen(["sleep", "60"])
    with _Relay() as relay:
        os.kill(os.getpid(), signal.SIGTERM)
        deadline = time.monotonic() + 10.0
        while not relay.pending and time.monotonic() < deadline:
            time.sleep(0.01)
        assert relay.pending == [signal.SIGTERM]
        relay.hand_over(worker.pid)
        assert relay.pending == []
    assert worker.wait(timeout=30) == -signal.SIGTERM


def test_a_client_that_sends_nonsense_or_goes_away_does_not_stop_it(warm):
    """Each connection is answered on its own: a truncated or malformed request, or a
    client gone before its answer, leaves the warm process serving."""
    import socket
    import struct

    path = warm["RT70_WARM_SOCKET"]
    bad = b"{not json"
    for junk, fds in ((b"", None), (b"R\x00\x00", None), (b"Z", None),
                      (b"R" + struct.pack("!I", len(bad)) + bad, [0, 1, 2])):  # fmt: skip
        sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        sock.connect(path)
        if fds:
            socket.send_fds(sock, [junk], fds)
        else:
            sock.sendall(junk)
        sock.close()
    before = _served(warm)
    _rt70(warm, "--version", check_code=0)
    assert _served(warm) == before + 1
    assert "JSONDecodeError" in Path(path + ".log").read_text()  # the bad one was read, logged


def _later_ends(server, timeout_s: float = 240.0) -> None:
    """Wait until the later warm-up's child has ended, then let the server finish it."""
    import select

    assert select.select([server.later], [], [], timeout_s)[0], "the child did not end"
    server.finish_later()
    os.waitpid(server.later_pid, 0)  # this test process does not ignore SIGCHLD


def test_the_later_warm_up_runs_in_a_child_then_in_the_warm_process(monkeypatch, tmp_path):
    """:data:`LATER` (here a short command) runs in a child while the process serves, then
    in the process itself; a command that fails in the child is not run again."""
    import gc

    server = warm_server.Server(tmp_path / "w.sock", 10.0)
    server.listen()
    try:
        monkeypatch.setattr(warm_server, "LATER", (("modes", "three_masses"),))
        server.start_later()
        assert server.status()["later"] == "compiling"
        _later_ends(server)
        assert server.later is None and server.status()["later"].startswith("loaded in")
        monkeypatch.setattr(warm_server, "LATER", (("modes", "missing.urdf"),))
        server.start_later()
        _later_ends(server)
        assert server.status()["later"] == "failed"
    finally:
        server.stop_later()
        server.listener.close()
        gc.unfreeze()


def test_start_settle_waits_for_the_later_warm_up(tmp_path):
    """``rt70 warm start --settle`` prints how the later warm-up ended (here: left out)."""
    env = _env(tmp_path / "w.sock")
    started = _rt70(env, "warm", "start", "--idle", "1", "--settle", check_code=0)
    try:
        assert "compiled BDF off (RT70_WARM_LATER=0)" in started.stdout
    finally:
        _rt70(env, "warm", "stop", check_code=0)


def test_every_warm_up_command_succeeds(warm):
    """A warm-up command that fails loads less than it should: the log names it."""
    log = Path(warm["RT70_WARM_SOCKET"] + ".log").read_text()
    assert "ready at" in log and "warm-up: " not in log, log
