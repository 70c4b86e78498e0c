"""Outputs on a failing disk, messages that name the option, loops that cannot close (issue 21).

- a file system that refuses an output (full, over quota, failing, read-only) at the
  temporary file, the write, the ``fsync`` or a rename: one line
  ``rt70: error: <path>: cannot write (<reason>)``, exit 2, the previous files intact and
  no temporary file left — for the writer itself and for every command that writes
  (``simulate --out``, ``plant --out``, ``reactions --output``, ``bench``) and standard
  output redirected to a full disk;
- every error a command-line value can trigger names the option (or the file) at fault;
- closed loops that cannot close are a model error (exit 2) naming the file, the loop and
  the residual, on both sides, before any comparison.

The disk failures are simulated by making the writing functions raise ``OSError`` (no
root needed); the real behaviour on a full tmpfs was checked by hand (issue 21 notes).
"""

from __future__ import annotations

import errno
import io
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from matplotlib.figure import Figure

import rt70.guards.atomic as atomic
from rt70.cli.main import main
from rt70.errors import OutputError
from rt70.guards.atomic import atomic_write_all, atomic_write_text

#: The errors of a file system that refuses data, and the reasons the message gives.
DISK_ERRORS = (errno.ENOSPC, errno.EDQUOT, errno.EIO, errno.EROFS)


def disk_error(code: int = errno.ENOSPC) -> OSError:
    """The ``OSError`` a full (or failing, or read-only) file system raises."""
    return OSError(code, os.strerror(code))


def one_error_line(err: str) -> str:
    """The single ``rt70: error:`` line of stderr (nothing else: no traceback, no warning)."""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("rt70: error: "), err
    return lines[0]


def old_set(directory: Path, *names: str) -> dict[str, str]:
    """Write ``old <name>`` into each file; return the expected directory listing."""
    for name in names:
        (directory / name).write_text(f"old {name}")
    return {name: f"old {name}" for name in names}


def listing(directory: Path) -> dict[str, str]:
    """Every file in ``directory`` (hidden ones included) → its text."""
    return {p.name: p.read_text(errors="replace") for p in sorted(directory.iterdir())}


def fail_on_call(monkeypatch, owner, name: str, call: int, code: int = errno.ENOSPC) -> list:
    """Make ``owner.name`` raise ``disk_error(code)`` on its ``call``-th call (1-based).

    Returns the list of calls seen (their count tells that the stage was reached).
    """
    real = getattr(owner, name)
    calls: list = []

    def failing(*args, **kwargs):
        calls.append(args)
        if len(calls) == call:
            raise disk_error(code)
        return real(*args, **kwargs)

    monkeypatch.setattr(owner, name, failing)
    return calls


# --- 1. the writer: every stage, every errno -------------------------------------------------


def _write(text: str):
    return lambda tmp: tmp.write_text(text)


def _full_disk_write(code: int):
    def write(tmp: Path) -> None:
        tmp.write_text("partial")  # a part reached the disk before it filled up
        raise disk_error(code)

    return write


@pytest.mark.parametrize("code", DISK_ERRORS)
@pytest.mark.parametrize("which", [0, 1])
def test_a_failed_write_keeps_the_old_set_and_leaves_no_temporary(tmp_path, code, which):
    expected = old_set(tmp_path, "run.csv", "run.png")
    writers = {tmp_path / "run.csv": _write("new csv"), tmp_path / "run.png": _write("new png")}
    target = list(writers)[which]
    writers[target] = _full_disk_write(code)
    with pytest.raises(OutputError) as info:
        atomic_write_all(writers)
    assert str(info.value) == f"{target}: cannot write ({os.strerror(code)})"
    assert listing(tmp_path) == expected


@pytest.mark.parametrize(
    ("owner", "name", "call"),
    [
        (atomic.tempfile, "mkstemp", 1),  # no room for the first temporary file
        (atomic.tempfile, "mkstemp", 2),  # … or for the second
        (atomic.os, "fsync", 1),
        (atomic.os, "fsync", 2),
        (atomic.os, "chmod", 2),
        (atomic.os, "link", 1),  # keeping an old file under a second name
        (atomic.os, "link", 2),
        (atomic.os, "replace", 1),  # the first rename
        (atomic.os, "replace", 2),  # the second: the first is put back
    ],
)
@pytest.mark.parametrize("code", DISK_ERRORS)
def test_every_stage_of_a_set_fails_cleanly(tmp_path, monkeypatch, owner, name, call, code):
    expected = old_set(tmp_path, "run.csv", "run.png")
    calls = fail_on_call(monkeypatch, owner, name, call, code)
    with pytest.raises(OutputError, match=r"/run\.(csv|png): cannot write \(") as info:
        atomic_write_all(
            {tmp_path / "run.csv": _write("new csv"), tmp_path / "run.png": _write("new png")}
        )
    assert len(calls) >= call  # the stage was reached (a rename failing: then the put-back)
    assert os.strerror(code) in str(info.value)
    assert listing(tmp_path) == expected


def test_a_failed_second_rename_removes_a_first_file_that_did_not_exist(tmp_path, monkeypatch):
    expected = old_set(tmp_path, "run.png")  # run.csv is new
    fail_on_call(monkeypatch, atomic.os, "replace", 2)
    with pytest.raises(OutputError, match="run.png: cannot write"):
        atomic_write_all(
            {tmp_path / "run.csv": _write("new csv"), tmp_path / "run.png": _write("new png")}
        )
    assert listing(tmp_path) == expected


def test_directories_created_for_a_failed_set_are_removed(tmp_path, monkeypatch):
    fail_on_call(monkeypatch, atomic.os, "fsync", 1)
    with pytest.raises(OutputError, match="cannot write"):
        atomic_write_text(tmp_path / "a" / "b" / "table.csv", "x")
    assert list(tmp_path.iterdir()) == []


def test_a_single_file_failing_at_rename_keeps_the_old_one(tmp_path, monkeypatch):
    expected = old_set(tmp_path, "table.csv")
    fail_on_call(monkeypatch, atomic.os, "replace", 1, errno.EDQUOT)
    with pytest.raises(OutputError, match=r"table\.csv: cannot write \(Disk quota exceeded\)"):
        atomic_write_text(tmp_path / "table.csv", "new")
    assert listing(tmp_path) == expected


def test_without_hard_links_a_set_is_still_written(tmp_path, monkeypatch):
    old_set(tmp_path, "run.csv", "run.png")

    def no_links(*args, **kwargs):
        raise OSError(errno.EPERM, os.strerror(errno.EPERM))

    monkeypatch.setattr(atomic.os, "link", no_links)
    atomic_write_all({tmp_path / "run.csv": _write("A"), tmp_path / "run.png": _write("B")})
    assert listing(tmp_path) == {"run.csv": "A", "run.png": "B"}


def test_a_successful_set_leaves_only_its_files(tmp_path):
    old_set(tmp_path, "run.csv", "run.png")
    paths = atomic_write_all({tmp_path / "run.csv": _write("A"), tmp_path / "run.png": _write("B")})
    assert paths == [tmp_path / "run.csv", tmp_path / "run.png"]
    assert listing(tmp_path) == {"run.csv": "A", "run.png": "B"}


def test_other_errors_of_a_writer_pass_through(tmp_path):
    def bug(tmp: Path) -> None:
        raise KeyError("not a disk problem")

    with pytest.raises(KeyError):
        atomic_write_all({tmp_path / "y.csv": bug})
    assert listing(tmp_path) == {}


# --- 2. the commands that write files -----------------------------------------------------


def _cli_fails_cleanly(argv, capsys, path: Path) -> None:
    assert main(argv) == 2
    err = one_error_line(capsys.readouterr().err)
    assert err == f"rt70: error: {path}: cannot write (No space left on device)"


@pytest.mark.parametrize(
    ("suffix", "owner", "name", "failing"),
    [
        (".csv", Figure, "savefig", ".png"),  # the plot fills the disk
        (".npz", np, "savez_compressed", ".npz"),  # the trajectory does
        (".csv", Path, "write_text", ".csv"),
        (".csv", atomic.os, "fsync", ".csv"),
    ],
)
def test_simulate_out_on_a_full_disk(tmp_path, monkeypatch, capsys, suffix, owner, name, failing):
    expected = old_set(tmp_path, f"run{suffix}", "run.png")
    fail_on_call(monkeypatch, owner, name, 1)
    out = tmp_path / f"run{suffix}"
    argv = ["simulate", "double_pendulum", "--t-end", "0.05", "--out", str(out)]
    _cli_fails_cleanly(argv, capsys, out.with_suffix(failing))
    assert listing(tmp_path) == expected


def test_simulate_out_second_rename_fails(tmp_path, monkeypatch, capsys):
    expected = old_set(tmp_path, "run.csv", "run.png")
    fail_on_call(monkeypatch, atomic.os, "replace", 2)
    out = tmp_path / "run.csv"
    _cli_fails_cleanly(
        ["simulate", "double_pendulum", "--t-end", "0.05", "--out", str(out)],
        capsys,
        tmp_path / "run.png",
    )
    assert listing(tmp_path) == expected


def test_plant_out_on_a_full_disk(tmp_path, monkeypatch, capsys):
    expected = old_set(tmp_path, "plant.npz")
    fail_on_call(monkeypatch, np, "savez", 1)
    out = tmp_path / "plant.npz"
    _cli_fails_cleanly(["plant", "three_masses", "--out", str(out)], capsys, out)
    assert listing(tmp_path) == expected


@pytest.mark.parametrize("suffix", [".csv", ".json"])
def test_reactions_output_on_a_full_disk(tmp_path, monkeypatch, capsys, suffix):
    import rt70.telescope.bearing_loads as bl

    expected = old_set(tmp_path, f"loads{suffix}")
    monkeypatch.setattr(bl, "load_table", lambda *a, **k: [])  # the loads are not the point
    fail_on_call(monkeypatch, Path, "write_text", 1)
    out = tmp_path / f"loads{suffix}"
    _cli_fails_cleanly(
        ["reactions", "rt70_servo", "--elevation", "45", "--output", str(out)], capsys, out
    )
    assert listing(tmp_path) == expected


def _bench_rows():
    from rt70.reports.bench import Row

    return [
        Row("per_call", "rt70", 42, 1, 2e-5, 1e-5, 2.0, 1, "openblas 2"),
        Row("scaling_chain", "chain_100", 100, 1, 1e-4, 5e-5, 2.0, 1, "openblas 2"),
        Row("scaling_chain", "chain_200", 200, 1, 3e-4, 1e-4, 3.0, 1, "openblas 2"),
    ]


@pytest.mark.parametrize(
    ("owner", "name", "call", "failing"),
    [
        (Path, "write_text", 1, "mass_matrix_bench.csv"),
        (Figure, "savefig", 1, "mass_matrix_bench.png"),
        (atomic.os, "replace", 2, "mass_matrix_bench.png"),
    ],
)
def test_bench_on_a_full_disk_keeps_the_old_table_and_plot(
    tmp_path, monkeypatch, capsys, owner, name, call, failing
):
    import rt70.reports.bench as bench

    expected = old_set(tmp_path, "mass_matrix_bench.csv", "mass_matrix_bench.png")
    monkeypatch.setattr(bench, "run", lambda **kwargs: _bench_rows())
    fail_on_call(monkeypatch, owner, name, call)
    _cli_fails_cleanly(["bench", "--quick", "--out", str(tmp_path)], capsys, tmp_path / failing)
    assert listing(tmp_path) == expected


def test_bench_writes_table_and_plot_as_a_set(tmp_path, monkeypatch, capsys):
    import rt70.reports.bench as bench

    monkeypatch.setattr(bench, "run", lambda **kwargs: _bench_rows())
    assert main(["bench", "--quick", "--out", str(tmp_path / "new")]) == 0
    names = sorted(p.name for p in (tmp_path / "new").iterdir())
    assert names == ["mass_matrix_bench.csv", "mass_matrix_bench.png"]


def test_bench_simulate_results_are_a_set(tmp_path, monkeypatch):
    from rt70.reports import work_precision as wp
    from rt70.reports import work_precision_results as wpr

    row = wp.Row(
        "double_pendulum", 2, 1.0, "BDF", 1e-6, 1e-9, "ok", False, 1e-7, 0.1, "0.1", 10, 1, 1,
        30.0, "Radau", 1e-10, "", 1, "openblas 2", com_error=1e-7, com_floor=1e-11,
    )  # fmt: skip
    expected = old_set(tmp_path, "work_precision.csv", "work_precision.png")
    fail_on_call(monkeypatch, Figure, "savefig", 1)
    with pytest.raises(OutputError, match=r"work_precision\.png: cannot write"):
        wpr.write_results([row], tmp_path)
    assert listing(tmp_path) == expected


# --- 3. standard output on a full disk -------------------------------------------------------


class _FullDisk:
    """A text stream on a full disk."""

    def write(self, text: str) -> int:
        raise disk_error()

    def flush(self) -> None:
        raise disk_error()

    def fileno(self) -> int:
        raise io.UnsupportedOperation("fileno")


def test_standard_output_on_a_full_disk_is_one_line(monkeypatch, capsys):
    monkeypatch.setattr(sys, "stdout", _FullDisk())
    assert main(["modes", "three_masses"]) == 2
    err = one_error_line(capsys.readouterr().err)
    assert err == "rt70: error: standard output: cannot write (No space left on device)"


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="no /dev/full on this system")
def test_standard_output_redirected_to_dev_full():
    with open("/dev/full", "w") as full:
        proc = subprocess.run(
            [sys.executable, "-m", "rt70", "modes", "three_masses", "--json"],
            stdout=full,
            stderr=subprocess.PIPE,
            text=True,
            timeout=120,
            env={**os.environ, "MPLBACKEND": "Agg"},
        )
    assert proc.returncode == 2
    assert one_error_line(proc.stderr) == (
        "rt70: error: standard output: cannot write (No space left on device)"
    )


# --- 4. messages name the option or file at fault -------------------------------------------


def test_option_at_fault_keeps_the_class_and_prefixes_the_option():
    from rt70.cli.options import option_at_fault
    from rt70.linear.topology import LinearModelError

    with pytest.raises(LinearModelError) as info, option_at_fault("--reduce 7"):
        raise LinearModelError("order must be between 1 and 6")
    assert str(info.value) == "--reduce 7: order must be between 1 and 6"
    with pytest.raises(LinearModelError) as info, option_at_fault("--reduce 7"):
        raise LinearModelError("--reduce 7: order must be between 1 and 6")
    assert str(info.value) == "--reduce 7: order must be between 1 and 6"  # named once
    with option_at_fault("--x 1"):  # nothing raised: nothing changes
        pass


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (
            ["plant", "three_masses", "--reduce", "10000"],
            "rt70: error: three_masses: --reduce 10000: order must be between 1 and 6 (the "
            "plant has 6 states, 0 of them rigid or unstable and always kept), got 10000",
        ),
        (
            ["plant", "three_masses", "--reduce", "100", "--method", "modal"],
            "rt70: error: three_masses: --reduce 100: n_modes must be between 1 and 3 (the "
            "plant has 3 modes of 2 states each, 0 of them rigid or unstable and always "
            "kept), got 50",
        ),
        (
            ["cart", "--start", "0", "0"],
            "rt70: error: --start 0 0: start (0, 0) is an equilibrium of the programmed "
            "field (4.6): no heading is programmed there",
        ),
        (
            ["impact", "three_masses", "--pin", "x1:1,2"],
            "rt70: error: --pin x1:1,2: stow pin 'x1:1,2': the point must be three numbers x,y,z",
        ),
    ],
)
def test_a_refused_value_names_its_option(argv, expected, capsys):
    assert main(argv) == 2
    assert one_error_line(capsys.readouterr().err) == expected


@pytest.mark.parametrize(
    ("option", "value", "fault"),
    [
        ("--brake", "nope", "brake on joint 'nope': no such joint"),
        ("--brake", "x1", None),  # a good lock beside a bad one: the bad one is named
        ("--pin", "nope:0,0,0", "stow pin on link 'nope': not a moving link"),
    ],
)
def test_impact_names_the_lock_option_and_the_file(option, value, fault, capsys):
    argv = ["impact", "three_masses", option, value]
    if fault is None:
        argv += ["--brake", "x9"]
        option, value, fault = "--brake", "x9", "brake on joint 'x9': no such joint"
    assert main(argv) == 2
    err = one_error_line(capsys.readouterr().err)
    assert err.startswith(f"rt70: error: {option} {value}: ")
    assert f"three_masses.urdf: {fault}" in err


# --- 5. loops that cannot close ---------------------------------------------------------------

FOUR_BAR = (Path(__file__).resolve().parents[1] / "urdf" / "four_bar.urdf").read_text()
LOOP = """  <rt70:loop name="coupler_rocker" type="point">
    <rt70:frame1 link="coupler" xyz="0.5 0 0" rpy="0 0 0"/>
    <rt70:frame2 link="rocker" xyz="0.45 0 0" rpy="0 0 0"/>
  </rt70:loop>
"""
assert LOOP in FOUR_BAR


def four_bar_with(loops: str) -> str:
    """urdf/four_bar.urdf with its loop replaced by ``loops``."""
    return FOUR_BAR.replace(LOOP, loops)


#: Four-bars whose loops cannot close, and what the error says of them.
CANNOT_CLOSE = {
    # the rocker's end 5 m from its pivot: crank + coupler reach 0.7 m, the pivots are
    # 0.4 m apart, so the two ends stay at least 5 − 0.4 − 0.7 = 3.9 m apart
    "too_far": (
        LOOP.replace('xyz="0.45 0 0"', 'xyz="5 0 0"'),
        "loop 'coupler_rocker' cannot close; the closest configuration found (13 starts, "
        "the textbook and Pinocchio) leaves loop 'coupler_rocker' 3.9 m apart",
    ),
    # the coupler's end on the rocker at 0.45 m and at 0.2 m: each closes, not both
    "contradictory": (
        LOOP + LOOP.replace("coupler_rocker", "second").replace("0.45 0 0", "0.2 0 0"),
        "loops 'coupler_rocker', 'second' contradict each other: each closes alone",
    ),
    # a planar loop's z row is redundant (identically zero) — here identically 0.1 m
    "out_of_plane": (
        LOOP.replace('xyz="0.45 0 0"', 'xyz="0.45 0 0.1"'),
        "loop 'coupler_rocker' cannot close; the closest configuration found (13 starts, "
        "the textbook and Pinocchio) leaves loop 'coupler_rocker' 0.1 m apart",
    ),
    # a weld whose frames differ by a turn about x that no z-axis joint can take up
    "weld_turned": (
        LOOP.replace('type="point"', 'type="frame"').replace(
            'xyz="0.45 0 0" rpy="0 0 0"', 'xyz="0.45 0 0" rpy="0.3 0 0"'
        ),
        "rad turned",
    ),
}


@pytest.fixture(scope="module")
def loop_files(tmp_path_factory) -> dict[str, Path]:
    directory = tmp_path_factory.mktemp("loops")
    files = {}
    for name, (loops, _) in CANNOT_CLOSE.items():
        files[name] = directory / f"{name}.urdf"
        files[name].write_text(four_bar_with(loops))
    files["duplicate"] = directory / "duplicate.urdf"  # redundant, consistent
    files["duplicate"].write_text(four_bar_with(LOOP + LOOP.replace("coupler_rocker", "again")))
    return files


@pytest.mark.slow
@pytest.mark.parametrize("name", list(CANNOT_CLOSE))
def test_validate_refuses_loops_that_cannot_close_before_comparing(
    name, loop_files, monkeypatch, capsys
):
    import rt70.crosscheck.validate as validate

    def no_comparison(*args):
        raise AssertionError("compared a model whose loops cannot close")

    monkeypatch.setattr(validate, "loop_pairs", no_comparison)
    assert main(["validate", "--samples", "2", str(loop_files[name])]) == 2
    err = one_error_line(capsys.readouterr().err)
    assert err.startswith(f"rt70: error: {loop_files[name]}: ")
    assert CANNOT_CLOSE[name][1] in err
    assert err.endswith(
        "the model contradicts itself (check the link lengths and the loops' xyz/rpy)"
    )


@pytest.mark.slow
@pytest.mark.parametrize("command", [["simulate", "--t-end", "0.01"], ["modes"]])
def test_every_command_gives_the_same_loop_error(command, loop_files, capsys):
    assert main(["validate", "--samples", "1", str(loop_files["too_far"])]) == 2
    expected = one_error_line(capsys.readouterr().err)
    assert main([command[0], str(loop_files["too_far"]), *command[1:]]) == 2
    assert one_error_line(capsys.readouterr().err) == expected


def test_both_sides_find_the_same_closest_configuration(loop_files):
    from rt70.model.scene import load_scene
    from rt70.simulation.closure import closure_search
    from rt70.testing import assert_close

    scene = load_scene(str(loop_files["too_far"]))
    for side in ("textbook", "reference"):
        found = closure_search(scene, side)
        assert not found.closed
        # the least-squares descent stops at a relative change of ½|Φ|² below 1e-8
        assert_close(np.linalg.norm(found.phi), 3.9, rel=1e-6)


def test_redundant_consistent_loops_keep_working(loop_files, capsys):
    path = str(loop_files["duplicate"])
    assert main(["validate", "--samples", "2", path]) == 0
    assert main(["simulate", path, "--t-end", "0.05"]) == 0  # closed from rest elsewhere than q = 0
    assert "constraints: max |Φ|" in capsys.readouterr().out


def test_newton_does_not_call_a_diverged_iteration_closed(loop_files):
    """The contradictory loops once 'converged' at q ~ 1e13 rad, |Φ| ~ 1 m (tol · |q|)."""
    from rt70.errors import LoopClosureError
    from rt70.model.scene import load_scene
    from rt70.simulation.closed_chains import assemble

    scene = load_scene(str(loop_files["contradictory"]))
    with pytest.raises(LoopClosureError, match="contradict each other"):
        assemble(scene, np.zeros(3))
