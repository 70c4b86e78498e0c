"""rt70 sweep against hostile input: sizes, paths, untrusted chunks, a second sweep on the
same --out, a full disk, NaN, and a Dask cluster whose workers or scheduler die.

Faults are made deterministically: chunks past the first wait for a gate file before
they finish (so a fault always lands mid-sweep), workers are killed with SIGKILL by pid
or told not to come back (``Nanny.close_gracefully``), the cluster is closed from a
second thread, a worker memory limit is a ``LocalCluster(memory_limit=...)`` and a task
that holds more, and a full disk is a writer that raises ``OSError(ENOSPC)``.
"""

from __future__ import annotations

import errno
import functools
import json
import logging
import os
import signal
import subprocess
import sys
import time
import zipfile
from pathlib import Path

import numpy as np
import pytest

from rt70.cli.main import main
from rt70.errors import OutputError, ResourceError, Rt70Warning
from rt70.sweep import plan as sweep_plan
from rt70.sweep import run as sw
from rt70.sweep import store as sweep_store
from rt70.sweep.quantities import QUANTITIES, Field, Quantity

SCENE = "rt70_servo"
URDF = Path(__file__).resolve().parents[1] / "urdf" / "rt70_servo.urdf"


def one_error_line(err: str) -> str:
    lines = [line for line in err.splitlines() if line.strip()]
    assert len(lines) == 1, err
    assert lines[0].startswith("rt70: error: "), err
    return lines[0]


def cli(argv: list[str]) -> int:
    """``main(argv)``; argparse's own exits returned as their code."""
    try:
        return main(argv)
    except SystemExit as exc:
        return exc.code


# --- cheap test quantities (no equilibrium: milliseconds per chunk) --------------------


def _cheap(scene, point):
    return {"cheap": point.elevation + 1000.0 * point.azimuth, "pair": [point.elevation, 1.0]}


CHEAP = Quantity(
    "cheap", (Field("cheap", (), "1", "test"), Field("pair", (2,), "1", "test")), _cheap
)


def _wait_for(gate: str) -> None:
    """Block until the file ``gate`` exists (a safety cap of 10 min, not a verdict)."""
    for _ in range(12_000):
        if os.path.exists(gate):
            return
        time.sleep(0.05)


def _gated(gate: str, scene, point):
    try:  # the first chunk to start goes through; the others wait for the gate
        os.close(os.open(gate + ".first", os.O_CREAT | os.O_EXCL))
    except FileExistsError:
        _wait_for(gate)
    return {"gated": point.elevation}


def gated(gate: Path) -> Quantity:
    """Exactly one chunk finishes before ``gate`` exists, whichever a worker starts first:
    a fault made once it is saved lands mid-sweep, with the others running or queued."""
    return Quantity(
        "gated", (Field("gated", (), "deg", "test"),), functools.partial(_gated, str(gate))
    )


def _hog(scene, point):
    if point.elevation > 15.0:
        block = np.ones(HOG_BYTES // 8)  # touched: resident
        _wait_for("/nonexistent/rt70-test-gate")  # held until the nanny kills the process
        return {"hog": float(block[0])}
    return {"hog": point.elevation}


HOG_BYTES = 600_000_000
HOG = Quantity("hog", (Field("hog", (), "1", "test"),), _hog)


def cheap_sweep(elevations=(10.0, 30.0, 50.0, 70.0), chunk=1) -> sw.Sweep:
    grid = sw.make_grid({"elevation": elevations})
    return sw.Sweep(sw.SceneSource.read(SCENE), grid, (CHEAP,), chunk)


def stop_after(n: int, seen: list[int] | None = None):
    """An on_chunk hook: Ctrl-C once ``n`` chunks were saved."""
    seen = [] if seen is None else seen

    def hook(result):
        seen.append(result.number)
        if len(seen) == n:
            raise KeyboardInterrupt

    return hook


@pytest.fixture
def no_work(monkeypatch):
    """Reading a scene or starting a cluster fails the test."""

    def forbidden(*args, **kwargs):
        raise AssertionError("work started before the options were checked")

    monkeypatch.setattr("rt70.sweep.run.SceneSource.read", forbidden)
    monkeypatch.setattr("rt70.sweep.cluster.local_cluster", forbidden)


@pytest.fixture
def memory_8gb(monkeypatch):
    """This 'machine' has 8 GB available (the checks' verdicts do not depend on the host)."""
    monkeypatch.setattr("rt70.guards.resources.available_memory", lambda: 8_000_000_000)


# --- sizes, checked before any work ------------------------------------------------------------


@pytest.mark.parametrize(
    ("extra", "expected"),
    [
        (["--elevation", "0:90:1000000000"], "argument --elevation: '0:90:1000000000': "),
        (
            ["--elevation", "0:90:100000", "--azimuth", "0:90:100000"],
            "--elevation × --azimuth: a grid of 10000000000 points (100000 × 100000)",
        ),
        (
            ["--elevation", "0:90:1000", "--scale", "stiffness=0.5:2:1000"],
            "--elevation × --scale stiffness: a grid of 1000000 points",
        ),
        (["--workers", "1000"], "--workers 1000: 1000 worker processes"),
    ],
)
def test_a_sweep_too_large_for_memory_is_refused_before_work(
    extra, expected, no_work, memory_8gb, tmp_path, capsys
):
    """10⁹ values of one axis, a 10¹⁰ product, 10⁶ points, 1000 workers: one line naming
    the options and the estimate against the memory available, nothing created."""
    code = cli(["sweep", SCENE, "--out", str(tmp_path / "s.npz"), *extra])
    line = one_error_line(capsys.readouterr().err)
    assert code == 2
    assert expected in line and "GB of memory; this run may use 4 GB" in line, line
    assert list(tmp_path.iterdir()) == []


def test_the_estimate_counts_results_errors_and_chunks(monkeypatch):
    grid = sw.make_grid({"elevation": tuple(range(10)), "azimuth": (0.0, 1.0, 2.0)})
    q = (CHEAP,)  # 3 numbers per point, one quantity
    per_point = 3 * sweep_plan.BYTES_PER_NUMBER + sweep_plan.BYTES_PER_ERROR
    expected = 30 * per_point + 3 * 3 * sweep_plan.BYTES_PER_CHUNK
    assert sw.peak_bytes(grid, q, chunk=4) == expected  # ceil(10 / 4) = 3 chunks per azimuth
    monkeypatch.setattr("rt70.guards.resources.available_memory", lambda: 2 * expected)
    sw.check_size(grid, q, 4)  # exactly the share a run may use: accepted
    monkeypatch.setattr("rt70.guards.resources.available_memory", lambda: 2 * expected - 2)
    with pytest.raises(ResourceError, match="--elevation × --azimuth: a grid of 30 points"):
        sw.check_size(grid, q, 4)


def test_run_checks_the_size_itself(monkeypatch, tmp_path):
    """The library's run() refuses before computing a chunk, as plan() does."""
    monkeypatch.setattr("rt70.guards.resources.available_memory", lambda: 1_000)
    computed = []
    with pytest.raises(ResourceError, match="a grid of 4 points"):
        sw.run(cheap_sweep(), sw.serial, tmp_path / "s.npz", on_chunk=computed.append)
    assert computed == [] and list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    ("extra", "expected"),
    [
        (["--azimuth", "1e300"], "--azimuth: angles from -360° to 360°"),
        (["--direction", "-400"], "--direction: angles from -360° to 360°"),
        (["--timeout", "1e300"], "argument --timeout: must be at most 3600 s (an hour)"),
    ],
)
def test_options_out_of_range_are_refused(extra, expected, no_work, tmp_path, capsys):
    """--azimuth 1e300 gave a first frequency 'at' an angle no float can place; --timeout
    1e300 waited for an unreachable scheduler for ever."""
    assert cli(["sweep", SCENE, "--out", str(tmp_path / "s.npz"), *extra]) == 2
    assert expected in one_error_line(capsys.readouterr().err)


def test_a_scale_factor_beyond_the_model_numbers_is_refused(tmp_path, capsys):
    argv = ["sweep", SCENE, "--workers", "0", "--out", str(tmp_path / "s.npz")]
    assert cli([*argv, "--scale", "stiffness=1,1e300"]) == 2
    line = one_error_line(capsys.readouterr().err)
    assert "--scale stiffness: factor 1e+300 times the largest stiffness" in line
    assert "beyond 1e+30" in line and list(tmp_path.iterdir()) == []


# --- output paths of the wrong kind, checked before any work --------------------------------


@pytest.mark.parametrize(
    ("make", "expected"),
    [
        (
            lambda d: (d / "s.npz.partial").write_text("x"),
            "s.npz.partial: exists and is not a directory",
        ),
        (lambda d: (d / "s.json").mkdir(), "s.json: exists and is not a regular file"),
        (
            lambda d: (d / "s.npz.partial" / "key.json").mkdir(parents=True),
            "key.json: exists and is not",
        ),
        (lambda d: (d / "s.npz.partial" / "lock").mkdir(parents=True), "lock: exists and is not"),
        (lambda d: os.mkfifo(d / "s.json"), "s.json: exists and is not a regular file"),
    ],
)
def test_output_paths_of_the_wrong_kind_are_refused_before_work(
    make, expected, no_work, tmp_path, capsys
):
    """A .partial that is a file, a sidecar that is a directory or a FIFO: refused before
    the scene is read (it used to fail with a traceback after the work, or hang)."""
    make(tmp_path)
    before = sorted(p.relative_to(tmp_path) for p in tmp_path.rglob("*"))
    assert cli(["sweep", SCENE, "--out", str(tmp_path / "s.npz")]) == 2
    assert expected in one_error_line(capsys.readouterr().err)
    assert sorted(p.relative_to(tmp_path) for p in tmp_path.rglob("*")) == before


# --- resume: every chunk verified, the untrusted ones recomputed ---------------------------


def _truncate(path: Path, _other: Path) -> str:
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])
    return "unreadable (BadZipFile"


def _random_bytes(path: Path, _other: Path) -> str:
    path.write_bytes(np.random.default_rng(0).bytes(3000))
    return "unreadable (BadZipFile"


def _empty(path: Path, _other: Path) -> str:
    path.write_bytes(b"")
    return "unreadable (BadZipFile"


def _foreign(path: Path, other: Path) -> str:
    """A chunk file of another grid, with the right fields and a valid checksum."""
    path.write_bytes(other.read_bytes())
    return "from another sweep (its key differs)"


def _old_layout(path: Path, _other: Path) -> str:
    """What rt70 wrote before: np.savez of the right fields, no key, no checksum."""
    np.savez(path, errors=np.array("[]"), cheap=np.ones(1), pair=np.ones((1, 2)))
    return "not this sweep's fields"


def _neighbour(path: Path, _other: Path) -> str:
    """Chunk 1's file under chunk 2's name: this sweep's, but another chunk."""
    path.write_bytes((path.parent / "chunk-00001.npz").read_bytes())
    return "holds another chunk"


def _edited(path: Path, _other: Path) -> str:
    """One bit of a field flipped, the ZIP rewritten (its CRCs right): the checksum differs."""
    members = _members(path)
    data = bytearray(members["cheap.npy"])
    data[-1] ^= 1
    members["cheap.npy"] = bytes(data)
    _rewrite(path, members)
    return "checksum mismatch"


def _wrong_shape(path: Path, _other: Path) -> str:
    """A field of another shape, the checksum recomputed to match (a consistent forgery)."""
    meta = json.loads(_members(path)["meta.json"])
    del meta["format"], meta["sha256"]
    sweep_store.write_chunk(path, meta, {"cheap": np.ones(3), "pair": np.ones((3, 2))}, [])
    return "cheap is (3,) float64, not the chunk's (1,) float64"


def _nan_without_record(path: Path, _other: Path) -> str:
    """A NaN value with no error record, checksum valid: NaN never passes silently."""
    meta = json.loads(_members(path)["meta.json"])
    del meta["format"], meta["sha256"]
    arrays = {"cheap": np.array([np.nan]), "pair": np.ones((1, 2))}
    sweep_store.write_chunk(path, meta, arrays, [])
    return "cheap at grid index [2, 0, 0, 0] is not finite and has no error record"


def _huge_header(path: Path, _other: Path) -> str:
    """A .npy header claiming 10¹² values: refused from the member's size, not allocated."""
    members = _members(path)
    header = np.lib.format.header_data_from_array_1_0(np.ones(1))
    header["shape"] = (10**12,)
    import io

    buf = io.BytesIO()
    np.lib.format.write_array_header_1_0(buf, header)
    members["cheap.npy"] = buf.getvalue() + b"\0" * 8
    _rewrite(path, members)
    return "cheap is (1000000000000,) float64, not the chunk's (1,)"


def _fifo(path: Path, _other: Path) -> str:
    path.unlink()
    os.mkfifo(path)
    return "not a regular file"


def _dev_zero(path: Path, _other: Path) -> str:
    path.unlink()
    path.symlink_to("/dev/zero")
    return "not a regular file"


def _members(path: Path) -> dict[str, bytes]:
    with zipfile.ZipFile(path) as z:
        return {n: z.read(n) for n in z.namelist()}


def _rewrite(path: Path, members: dict[str, bytes]) -> None:
    with zipfile.ZipFile(path, "w") as z:
        for name, data in members.items():
            z.writestr(name, data)


@pytest.fixture(scope="module")
def fresh_cheap():
    return sw.run(cheap_sweep(), sw.serial)


@pytest.mark.parametrize(
    "spoil",
    [
        _truncate,
        _random_bytes,
        _empty,
        _foreign,
        _old_layout,
        _neighbour,
        _edited,
        _wrong_shape,
        _nan_without_record,
        _huge_header,
        _fifo,
        _dev_zero,
    ],
)
def test_resume_recomputes_a_chunk_it_cannot_trust_and_says_why(spoil, tmp_path, fresh_cheap):
    """Chunk 2 of 4 spoiled: the resumed sweep keeps chunks 0, 1, 3, recomputes 2 with
    one warning naming the file and the reason, and equals a fresh sweep."""
    out = tmp_path / "s.npz"
    sweep = cheap_sweep()
    with pytest.raises(KeyboardInterrupt):
        sw.run(sweep, sw.serial, out, on_chunk=stop_after(4))
    other_out = tmp_path / "o.npz"  # another grid, same fields: its chunk 2
    other = cheap_sweep(elevations=(10.0, 30.0, 60.0, 70.0))
    with pytest.raises(KeyboardInterrupt):
        sw.run(other, sw.serial, other_out, on_chunk=stop_after(3))
    target = tmp_path / "s.npz.partial" / "chunk-00002.npz"
    reason = spoil(target, tmp_path / "o.npz.partial" / "chunk-00002.npz")

    computed: list[int] = []
    with pytest.warns(Rt70Warning) as warned:
        result = sw.run(sweep, sw.serial, out, on_chunk=lambda r: computed.append(r.number))
    messages = [str(w.message) for w in warned]
    assert (
        len(messages) == 1 and "1 chunk file(s) cannot be trusted and are recomputed" in messages[0]
    )
    assert f"chunk-00002.npz: {reason}" in messages[0], messages[0]
    assert computed == [2]
    assert result.metadata["chunks"] == {"total": 4, "resumed": 3, "computed": 1, "recomputed": 1}
    for name, expected in fresh_cheap.arrays.items():
        np.testing.assert_array_equal(result.arrays[name], expected, err_msg=name)
    assert out.exists() and not (tmp_path / "s.npz.partial").exists()


def test_the_cli_says_on_stderr_how_many_chunks_were_recomputed(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(QUANTITIES, "cheap", CHEAP)
    out = tmp_path / "s.npz"
    argv = ["sweep", SCENE, "--elevation", "10,30,50,70", "--chunk", "1", "--quantity", "cheap"]
    argv += ["--workers", "0", "--out", str(out), "--no-progress"]
    with pytest.raises(KeyboardInterrupt):
        sw.run(
            sw.plan(SCENE, sw.make_grid({"elevation": (10.0, 30.0, 50.0, 70.0)}), ["cheap"], 1),
            sw.serial,
            out,
            on_chunk=stop_after(4),
        )
    for name in ("chunk-00000.npz", "chunk-00003.npz"):
        (tmp_path / "s.npz.partial" / name).write_bytes(b"garbage")
    assert cli(argv) == 0
    captured = capsys.readouterr()
    lines = [line for line in captured.err.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("rt70: warning: "), captured.err
    assert (
        "2 chunk file(s) cannot be trusted and are recomputed: chunk-00000.npz: unreadable"
        in lines[0]
    )
    assert "chunk-00003.npz: unreadable (BadZipFile: File is not a zip file)" in lines[0]
    assert (
        "4 chunk(s) of ≤ 1: 2 computed in this process (2 of them untrusted files), 2 resumed"
        in captured.out
    )


def test_a_directory_in_place_of_a_chunk_file_is_refused_before_work(tmp_path):
    out = tmp_path / "s.npz"
    with pytest.raises(KeyboardInterrupt):
        sw.run(cheap_sweep(), sw.serial, out, on_chunk=stop_after(1))
    (tmp_path / "s.npz.partial" / "chunk-00001.npz").mkdir()
    computed: list[int] = []
    with pytest.raises(
        OutputError, match="chunk-00001.npz: a directory where a chunk file belongs"
    ):
        sw.run(cheap_sweep(), sw.serial, out, on_chunk=computed.append)
    assert computed == []


@pytest.mark.parametrize(("content", "reason"), [(None, "missing"), ("{not json", "unreadable")])
def test_chunks_without_a_readable_key_file_are_refused(content, reason, tmp_path):
    """Whose chunks these are cannot be told: refused, nothing deleted."""
    out = tmp_path / "s.npz"
    with pytest.raises(KeyboardInterrupt):
        sw.run(cheap_sweep(), sw.serial, out, on_chunk=stop_after(2))
    key = tmp_path / "s.npz.partial" / "key.json"
    key.unlink()
    if content is not None:
        key.write_text(content)
    with pytest.raises(sw.SweepError, match=f"key.json: {reason}, so the 2 chunk file"):
        sw.run(cheap_sweep(), sw.serial, out)
    assert len(list((tmp_path / "s.npz.partial").glob("chunk-*.npz"))) == 2


def test_a_result_from_the_executor_is_checked_too(tmp_path):
    """A worker running other code (NaN without a record, wrong shapes) stops the sweep."""

    def lying(sweep, chunks):
        for c in chunks:
            yield sw.ChunkResult(c.number, {"cheap": np.array([np.nan]), "pair": np.ones((1, 2))})

    with pytest.raises(
        sw.SweepError,
        match="chunk 0 as computed: cheap at grid index .* is not finite and has no error",
    ):
        sw.run(cheap_sweep(), lying, tmp_path / "s.npz")

    def misshapen(sweep, chunks):
        for c in chunks:
            yield sw.ChunkResult(c.number, {"cheap": np.ones(3)})

    with pytest.raises(sw.SweepError, match="chunk 0 as computed: fields"):
        sw.run(cheap_sweep(), misshapen, tmp_path / "t.npz")


# --- one writer per partial directory ---------------------------------------------------------

HOLD_LOCK = """
import sys
from pathlib import Path
from rt70.sweep.store import DirectoryLock
DirectoryLock(Path(sys.argv[1])).acquire()
print("held", flush=True)
sys.stdin.read()
"""


@pytest.fixture
def lock_holder(tmp_path):
    """A second process holding the lock of tmp_path/s.npz.partial until it ends."""
    env = dict(os.environ, PYTHONPATH=str(Path(__file__).resolve().parents[1]))
    proc = subprocess.Popen(
        [sys.executable, "-c", HOLD_LOCK, str(tmp_path / "s.npz.partial")],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        env=env,
        text=True,
    )
    assert proc.stdout.readline().strip() == "held"
    yield proc
    proc.kill()
    proc.wait()


def test_a_second_sweep_on_the_same_out_is_refused(lock_holder, tmp_path, capsys):
    """Two sweeps started together on one --out both passed the key check and wrote into
    one .partial/: now the second is refused at once, naming the first's pid."""
    argv = ["sweep", SCENE, "--workers", "0", "--out", str(tmp_path / "s.npz"), "--no-progress"]
    assert cli(argv) == 2
    line = one_error_line(capsys.readouterr().err)
    assert f"s.npz.partial: another rt70 sweep (pid {lock_holder.pid} on " in line
    assert "wait for it to finish, or write to another --out" in line
    assert sorted(p.name for p in (tmp_path / "s.npz.partial").iterdir()) == ["lock"]
    assert not (tmp_path / "s.npz").exists()


def test_the_lock_is_checked_again_inside_run(lock_holder, tmp_path):
    computed: list[int] = []
    with pytest.raises(sweep_store.LockedError, match="another rt70 sweep"):
        sw.run(cheap_sweep(), sw.serial, tmp_path / "s.npz", on_chunk=computed.append)
    assert computed == []


def test_a_killed_sweep_leaves_no_stale_lock(lock_holder, tmp_path, fresh_cheap):
    """SIGKILL: the kernel drops the flock; the next sweep takes it (its lock file stays)."""
    lock_holder.send_signal(signal.SIGKILL)
    lock_holder.wait()
    assert (tmp_path / "s.npz.partial" / "lock").read_text().startswith(f"pid {lock_holder.pid} ")
    result = sw.run(cheap_sweep(), sw.serial, tmp_path / "s.npz")
    np.testing.assert_array_equal(result.arrays["cheap"], fresh_cheap.arrays["cheap"])
    assert not (tmp_path / "s.npz.partial").exists()


def test_the_lock_is_reentrant_in_a_process_and_released(tmp_path):
    lock = sweep_store.DirectoryLock(tmp_path / "d")
    lock.acquire()
    lock.acquire()
    lock.release()
    assert (tmp_path / "d" / "lock").exists()
    lock.release()
    assert not (tmp_path / "d").exists()  # nothing else was in it


# --- a full disk -----------------------------------------------------------------------------


def _no_space(*args, **kwargs):
    raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))


def test_a_full_disk_while_saving_chunks_is_one_line_and_resumable(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(QUANTITIES, "cheap", CHEAP)
    out = tmp_path / "s.npz"
    argv = ["sweep", SCENE, "--elevation", "10,30,50,70", "--chunk", "1", "--quantity", "cheap"]
    argv += ["--workers", "0", "--out", str(out), "--no-progress"]
    real = sweep_store.write_chunk
    calls = []

    def fills_up(*args, **kwargs):
        calls.append(1)
        if len(calls) == 3:
            _no_space()
        real(*args, **kwargs)

    monkeypatch.setattr(sweep_store, "write_chunk", fills_up)
    assert cli(argv) == 2
    line = one_error_line(capsys.readouterr().err)
    assert "chunk-00002.npz: cannot write (No space left on device)" in line
    assert "2 finished chunk(s) kept in" in line and "rerun to resume" in line
    partial = tmp_path / "s.npz.partial"
    assert sorted(p.name for p in partial.iterdir()) == [
        "chunk-00000.npz",
        "chunk-00001.npz",
        "key.json",
    ]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.npz.partial"]

    monkeypatch.setattr(sweep_store, "write_chunk", real)
    assert cli([*argv, "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["chunks"]["resumed"] == 2


def test_a_full_disk_at_the_end_keeps_the_previous_files_and_the_chunks(
    tmp_path, capsys, monkeypatch
):
    monkeypatch.setitem(QUANTITIES, "cheap", CHEAP)
    out = tmp_path / "s.npz"
    out.write_bytes(b"previous npz")
    (tmp_path / "s.json").write_text("previous json")
    argv = ["sweep", SCENE, "--elevation", "10,30,50,70", "--chunk", "1", "--quantity", "cheap"]
    argv += ["--workers", "0", "--out", str(out), "--no-progress"]
    monkeypatch.setattr("rt70.sweep.run.np.savez", _no_space)
    assert cli(argv) == 2
    line = one_error_line(capsys.readouterr().err)
    assert "s.npz: cannot write (No space left on device)" in line
    assert "the previous s.npz and s.json are unchanged, 4 finished chunk(s) kept in" in line
    assert (
        out.read_bytes() == b"previous npz" and (tmp_path / "s.json").read_text() == "previous json"
    )
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.json", "s.npz", "s.npz.partial"]
    assert len(list((tmp_path / "s.npz.partial").iterdir())) == 5  # 4 chunks and the key

    monkeypatch.undo()
    monkeypatch.setitem(QUANTITIES, "cheap", CHEAP)
    assert cli([*argv, "--json"]) == 0
    chunks = json.loads(capsys.readouterr().out)["chunks"]
    assert chunks["resumed"] == 4 and chunks["computed"] == 0


# --- NaN never reaches an output without its error record ------------------------------------


def _nan_or_inf(scene, point):
    bad = {10.0: np.nan, 30.0: np.inf}.get(point.elevation, point.elevation)
    return {"shaky": bad, "padded": [point.elevation, np.nan]}


SHAKY = Quantity(
    "shaky",
    (
        Field("shaky", (), "1", "test"),
        Field("padded", (2,), "1", "test", nan="fewer than two: the missing ones"),
    ),
    _nan_or_inf,
)


def test_a_non_finite_value_is_an_error_record(tmp_path):
    """NaN and inf from a quantity: NaN in every field of it at that point, with a record;
    a NaN a field declares (padding) passes."""
    grid = sw.make_grid({"elevation": (10.0, 30.0, 50.0)})
    sweep = sw.Sweep(sw.SceneSource.read(SCENE), grid, (SHAKY,), 1)
    out = tmp_path / "s.npz"
    result = sw.run(sweep, sw.serial, out)
    np.testing.assert_array_equal(result.arrays["shaky"][:, 0, 0, 0], [np.nan, np.nan, 50.0])
    np.testing.assert_array_equal(result.arrays["padded"][2, 0, 0, 0], [50.0, np.nan])
    assert np.isnan(result.arrays["padded"][:2]).all()
    assert [(e["index"][0], e["error"]) for e in result.errors] == [
        (0, "shaky: shaky is not finite at this point (nan)"),
        (1, "shaky: shaky is not finite at this point (inf)"),
    ]
    meta = json.loads(sw.sidecar(out).read_text())
    assert (
        meta["quantities"]["shaky"]["fields"]["padded"]["nan"] == "fewer than two: the missing ones"
    )
    assert meta["quantities"]["shaky"]["fields"]["shaky"]["nan"] == "a failed point (see errors)"


def _moved_point(name: str, xyz: str, tmp_path: Path, duplicate: bool = False) -> Path:
    text = URDF.read_text()
    line = next(x for x in text.splitlines() if f'name="{name}"' in x and "optical_point" in x)
    new = line.split(' xyz="')[0] + f' xyz="{xyz}"/>'
    text = text.replace(line, (line + "\n" + new) if duplicate else new)
    path = tmp_path / "scene.urdf"
    path.write_text(text)
    return path


def test_sag_with_the_focus_on_the_vertex_is_refused(tmp_path, capsys):
    """The main mirror's focus moved onto its vertex: sag was NaN at every point with no
    error; now the scene is refused before any work, naming the points."""
    scene = _moved_point("main_mirror_focus", "0 0 8", tmp_path)
    argv = ["sweep", str(scene), "--workers", "0", "--out", str(tmp_path / "s.npz")]
    assert cli([*argv, "--quantity", "sag"]) == 2
    line = one_error_line(capsys.readouterr().err)
    assert "the main mirror's focus and vertex are the same point (main_mirror 0 0 8)" in line
    assert not (tmp_path / "s.npz").exists()


def test_sag_with_the_focus_on_the_vertex_is_an_error_record_past_the_check(tmp_path):
    """Past plan()'s check (a Sweep built by hand) the NaN rule still holds."""
    scene = _moved_point("main_mirror_focus", "0 0 8", tmp_path)
    grid = sw.make_grid({"elevation": (45.0,)})
    sweep = sw.Sweep(sw.SceneSource.read(scene), grid, (QUANTITIES["sag"],), 1)
    result = sw.run(sweep, sw.serial)
    assert np.isnan(result.arrays["sag"]).all() and np.isnan(result.arrays["sag_error"]).all()
    [error] = [e["error"] for e in result.errors]
    assert "focus and vertex are at one place" in error and "no focal axis" in error


def test_a_repeated_optical_point_is_refused(tmp_path, capsys):
    scene = _moved_point("main_mirror_focus", "0 0 14", tmp_path, duplicate=True)
    argv = ["sweep", str(scene), "--workers", "0", "--out", str(tmp_path / "s.npz")]
    assert cli(argv) == 2
    line = one_error_line(capsys.readouterr().err)
    assert f"{scene}: two <rt70:optical_point> elements named 'main_mirror_focus'" in line


# --- faults of the cluster ---------------------------------------------------------------------


def _cluster(**kwargs):
    from distributed import LocalCluster

    options = dict(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1")
    options |= dict(dashboard_address=None, silence_logs=logging.CRITICAL)
    return LocalCluster(**(options | kwargs))


def gated_sweep(gate: Path, elevations=(10.0, 20.0, 30.0, 40.0)) -> sw.Sweep:
    grid = sw.make_grid({"elevation": elevations})
    return sw.Sweep(sw.SceneSource.read(SCENE), grid, (gated(gate),), 1)


def kill_workers(client) -> None:
    """SIGKILL every worker process (their nannies restart them)."""
    for pid in client.run(os.getpid).values():
        os.kill(pid, signal.SIGKILL)


@pytest.mark.slow
def test_killing_every_worker_is_survived(tmp_path):
    """Every worker killed once the first chunk is saved: the nannies restart them, the
    sweep's inputs (a task, not scattered data) are recomputed, and every chunk is
    computed once."""
    from distributed import Client

    from rt70.sweep.cluster import on_dask

    gate = tmp_path / "gate"
    sweep = gated_sweep(gate)
    seen: list[int] = []
    with _cluster() as cluster, Client(cluster) as client:

        def hook(result):
            seen.append(result.number)
            if len(seen) == 1:
                kill_workers(client)
                gate.touch()

        result = sw.run(sweep, on_dask(client), tmp_path / "s.npz", on_chunk=hook)
    assert sorted(seen) == [0, 1, 2, 3]
    np.testing.assert_array_equal(result.arrays["gated"][:, 0, 0, 0], [10.0, 20.0, 30.0, 40.0])
    assert result.metadata["chunks"]["computed"] == 4 and result.errors == []


@pytest.mark.slow
def test_no_worker_left_stops_with_one_error_and_the_rerun_resumes(tmp_path):
    """Every worker gone for good (its nanny told not to restart it): after the timeout a
    ClusterError naming the kept chunks; the rerun computes only the other three."""
    from distributed import Client

    from rt70.sweep.cluster import on_dask

    gate = tmp_path / "gate"
    sweep = gated_sweep(gate)
    out = tmp_path / "s.npz"
    with _cluster() as cluster, Client(cluster) as client:

        def hook(result):
            for nanny in cluster.workers.values():
                nanny.close_gracefully()
            kill_workers(client)

        with pytest.raises(sw.ClusterError) as exc:
            sw.run(sweep, on_dask(client, worker_timeout=1.0), out, on_chunk=hook)
    message = str(exc.value)
    assert message.startswith("the Dask cluster has had no worker for 1 s (every worker died")
    assert message.endswith(f"1 finished chunk(s) kept in {out}.partial: rerun to resume")
    kept = [int(p.stem[-5:]) for p in Path(f"{out}.partial").glob("chunk-*.npz")]
    assert len(kept) == 1
    gate.touch()
    computed: list[int] = []
    resumed = sw.run(sweep, sw.serial, out, on_chunk=lambda r: computed.append(r.number))
    assert sorted(computed + kept) == [0, 1, 2, 3] and resumed.metadata["chunks"]["resumed"] == 1
    np.testing.assert_array_equal(resumed.arrays["gated"][:, 0, 0, 0], [10.0, 20.0, 30.0, 40.0])


@pytest.fixture
def external_cluster():
    """``dask scheduler`` and ``dask worker --nworkers 2`` as processes of their own (their
    output to /dev/null, as a cluster's is not the command's); killed at the end."""
    import socket

    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    address = f"tcp://127.0.0.1:{port}"
    here = Path(__file__).resolve().parent  # the scheduler unpickles this file's quantities
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(here.parent), str(here)]))
    quiet = dict(stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env)
    dask = [sys.executable, "-m", "dask"]
    scheduler = subprocess.Popen(
        [*dask, "scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard"],
        start_new_session=True,
        **quiet,
    )
    worker = subprocess.Popen(
        [*dask, "worker", address, "--nworkers", "2", "--nthreads", "1", "--no-dashboard"],
        start_new_session=True,
        **quiet,
    )
    yield address, scheduler
    for proc in (worker, scheduler):  # each in its own process group, with its children
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        proc.wait()


@pytest.mark.slow
def test_the_scheduler_killed_mid_sweep_is_one_line_of_the_cli(
    external_cluster, tmp_path, capfd, monkeypatch
):
    """`rt70 sweep --scheduler`: the scheduler process killed (SIGKILL) once the first
    chunk is saved: exit 2, one line on stderr (no traceback, no Dask log line), the
    chunk kept for the rerun, which finishes in this process."""
    address, scheduler = external_cluster
    gate = tmp_path / "gate"
    monkeypatch.setitem(QUANTITIES, "gated", gated(gate))
    out = tmp_path / "s.npz"
    real_save = sw.PartialResults.save

    def save(self, result):
        real_save(self, result)
        scheduler.kill()

    monkeypatch.setattr(sw.PartialResults, "save", save)
    base = ["sweep", SCENE, "--elevation", "10,20,30", "--chunk", "1", "--quantity", "gated"]
    base += ["--out", str(out), "--no-progress"]
    code = cli([*base, "--scheduler", address, "--timeout", "60"])
    err = capfd.readouterr().err
    assert code == 2
    line = one_error_line(err)
    assert ": lost the connection to the Dask scheduler; 1 finished chunk(s) kept in " in line
    assert line.endswith(f"{out}.partial: rerun to resume")

    monkeypatch.setattr(sw.PartialResults, "save", real_save)
    gate.touch()
    assert cli([*base, "--workers", "0", "--json"]) == 0
    chunks = json.loads(capfd.readouterr().out)["chunks"]
    assert chunks["resumed"] == 1 and chunks["computed"] == 2


@pytest.mark.slow
def test_a_worker_memory_limit_is_one_line_of_the_cli(tmp_path, capfd, monkeypatch):
    """A chunk that needs more than the workers' memory limit: the nanny kills its worker
    (once allowed here); exit 2 with one line, no traceback ('FutureCancelledError …
    already forgotten' before)."""
    import dask

    from rt70.sweep import cluster as sweep_dask

    monkeypatch.setitem(QUANTITIES, "hog", HOG)
    real = sweep_dask.local_cluster
    monkeypatch.setattr(sweep_dask, "local_cluster", functools.partial(real, memory_limit="400MB"))
    out = tmp_path / "s.npz"
    argv = ["sweep", SCENE, "--elevation", "10,30", "--chunk", "1", "--quantity", "hog"]
    with dask.config.set({"distributed.scheduler.allowed-failures": 0}):
        code = cli([*argv, "--workers", "1", "--out", str(out), "--no-progress"])
    err = capfd.readouterr().err
    assert code == 2
    line = one_error_line(err)
    # the worker held both chunks (one running, one queued): either may be reported
    assert ": the worker it was given to died 1 time(s) (a worker memory limit" in line
    assert line.endswith(f"finished chunk(s) kept in {out}.partial: rerun to resume")
