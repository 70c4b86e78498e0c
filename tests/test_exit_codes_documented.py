"""Every exit code that README.md, docs/*.md and ``rt70 --help`` state is what rt70 does.

The statements (``grep -n -i exit README.md docs/*.md``, rt70/cli/main.py's docstring and
``rt70 --help``), and where each is run:

- docs/validation.md, "``rt70 validate``": ``validate`` exits 0 when every row is within the
  tolerance, 1 when one is not (a NaN or infinity fails its row), 2 on bad input, on a
  model with no degree of freedom and on a run that would check nothing — here.
- docs/commands.md, "Exit codes", and ``rt70 --help``: 0 success, 1 a check
  disagreed / a robot failed unexpectedly / ``simulate``'s integration stopped early,
  2 bad input, 130 Ctrl-C, 141 a closed standard output, 143 SIGTERM; ``bench`` exits 0
  whether or not its targets are met — here, one case of each for every command but
  ``sweep`` (its 2 and 130, docs/sweeps.md: tests/test_sweep.py). A full disk (2):
  tests/test_outputs_and_messages.py; a model too large (2): tests/test_cli_robustness.py.
- docs/robots.md: a robot that cannot be loaded is no error by itself; one that fails
  with an unexpected exception makes the exit code 1 — here.
- docs/impacts.md, docs/urdf-reader.md, docs/wind.md, docs/loops.md: refused input and
  models exit 2 with one line — here for ``impact``; the models in their own tests
  (tests/test_urdf_reading.py, tests/test_wind.py, tests/test_outputs_and_messages.py).
- ``pointing`` succeeding (0): tests/test_pointing.py (12 s; not repeated here).
"""

from __future__ import annotations

import dataclasses
import os
import re
import signal
import subprocess
import sys
import threading

import numpy as np
import pytest

from rt70.cli.main import main
from rt70.cli.session import EXIT_BROKEN_PIPE, EXIT_CODES, EXIT_INTERRUPTED, EXIT_TERMINATED

NO_DOF = """<robot name="still">
  <link name="world"/>
  <link name="box"><inertial><mass value="1"/>
    <inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="weld" type="fixed"><parent link="world"/><child link="box"/></joint>
</robot>
"""


def exit_code(argv: list[str]) -> int:
    """What ``rt70 ARGV`` exits with, in this process (argparse's refusals included)."""
    try:
        return main(argv)
    except SystemExit as exc:
        return int(exc.code)


def test_help_lists_every_exit_code(capsys):
    assert exit_code(["--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())
    for code, meaning in EXIT_CODES.items():
        assert f"{code} {' '.join(meaning.split())}" in text
    assert sorted(EXIT_CODES) == [0, 1, 2, 130, 141, 143]


@pytest.mark.parametrize(
    "argv",
    [
        ["validate", "three_masses", "--samples", "1"],
        ["modes", "three_masses"],
        ["plant", "three_masses"],
        ["simulate", "double_pendulum", "--t-end", "0.01"],
        ["reactions", "rt70_servo", "--elevation", "90"],
        ["impact", "three_masses", "--brake", "x1"],
        ["cart", "--duration", "0.2", "--step", "0.1"],
    ],
    ids=lambda argv: argv[0],
)
def test_success_is_0(argv, capsys):
    assert exit_code(argv) == 0
    assert capsys.readouterr().err == ""


@pytest.mark.parametrize(
    "argv",
    [
        ["validate", "no_such_scene"],
        ["validate", "robot:no_such_robot"],  # a run that would check nothing
        ["validate", "three_masses", "--samples", "0"],
        ["modes", "double_pendulum", "--elevation", "45"],
        ["plant", "three_masses", "--reduce", "100"],
        ["simulate", "double_pendulum", "--rtol", "2"],
        ["pointing", "three_masses", "--wind", "10"],
        ["reactions", "three_masses"],
        ["impact", "three_masses", "--brake", "nope"],
        ["cart", "--start", "0", "0"],
        ["bench", "--K", "0"],
    ],
    ids=lambda argv: f"{argv[0]} {argv[-1]}",
)
def test_bad_input_is_2_with_one_line(argv, capsys):
    assert exit_code(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("rt70: error: ")


def test_validate_of_a_model_with_no_degree_of_freedom_is_2(tmp_path, capsys):
    path = tmp_path / "still.urdf"
    path.write_text(NO_DOF)
    assert exit_code(["validate", str(path)]) == 2
    assert "no degree of freedom" in capsys.readouterr().err


# --- 1: a check disagreed, a robot failed unexpectedly, an integration stopped -----------------


@pytest.mark.parametrize("error", [1e-6, np.nan], ids=["off", "nan"])
def test_validate_disagreeing_is_1(error, monkeypatch, capsys):
    from rt70.textbook import dynamics

    real = dynamics.gravity_force
    monkeypatch.setattr(dynamics, "gravity_force", lambda *a: real(*a) * (1.0 + error))
    assert exit_code(["validate", "double_pendulum", "--samples", "1"]) == 1
    out = capsys.readouterr().out
    assert re.search(r"^double_pendulum +2 gravity .* NO\b", out, re.M), out


def _survey_with(failed: dict[str, str]):
    def survey(names=None, balance_inertia=False):
        from rt70.model.scene import load_scene

        return [load_scene("three_masses")], failed

    return survey


@pytest.mark.parametrize(
    ("reason", "expected"),
    [("no degree of freedom", 0), ("unexpected KeyError: 'x'", 1)],
    ids=["not-loaded", "bug"],
)
def test_robots_not_loaded_are_no_error_but_a_bug_is_1(reason, expected, monkeypatch, capsys):
    import rt70.crosscheck.robots as robots

    monkeypatch.setattr(robots, "survey", _survey_with({"some_robot": reason}))
    assert exit_code(["validate", "robots", "--samples", "1"]) == expected
    assert f"not loaded: some_robot: {reason}" in capsys.readouterr().out


def test_simulate_stopped_before_the_end_is_1(monkeypatch, capsys):
    import rt70.simulation.simulate as simulate

    real = simulate.simulate

    def stopped(*args, **kwargs):
        return dataclasses.replace(real(*args, **kwargs), success=False, message="step too small")

    monkeypatch.setattr(simulate, "simulate", stopped)
    assert exit_code(["simulate", "double_pendulum", "--t-end", "0.01"]) == 1
    assert "FAILED: step too small" in capsys.readouterr().out


@pytest.mark.parametrize("met", [True, False])
def test_bench_exits_0_whether_or_not_the_targets_are_met(met, tmp_path, monkeypatch, capsys):
    import rt70.reports.bench as bench

    ratio = 2.0 if met else 50.0  # the per-call target is a ratio ≤ 10
    rows = [bench.Row("per_call", "rt70", 42, 1, ratio * 1e-5, 1e-5, ratio, 1, "")]
    monkeypatch.setattr(bench, "run", lambda **kwargs: rows)
    assert exit_code(["bench", "--quick", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    verdict = "measured 2.00 — met" if met else "measured 50.00 — NOT met"
    assert f"target per-call ratio ≤ 10 on rt70 — {verdict}" in out


# --- signals and a closed pipe: real processes ------------------------------------------------


def _signalled(signum: int) -> tuple[int, str]:
    """Run a long ``rt70 simulate`` and send ``signum`` once its progress bar shows."""
    proc = subprocess.Popen(
        [sys.executable, "-m", "rt70", "simulate", "double_pendulum", "--t-end", "1e6"]
        + ["--progress"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        env={**os.environ, "MPLBACKEND": "Agg"},
        # as from a terminal, even when the tests run in the background (SIGINT ignored,
        # which rt70 then keeps ignoring: tests/test_hostile_guards.py)
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    watchdog = threading.Timer(300, proc.kill)  # only if it never starts
    watchdog.start()
    try:
        seen = b""
        while b"%" not in seen:  # the bar: the command is running, its handlers are in
            chunk = proc.stderr.read1(256)
            assert chunk, "rt70 ended before its progress bar"
            seen += chunk
        proc.send_signal(signum)
        _, err = proc.communicate(timeout=120)
    finally:
        watchdog.cancel()
        proc.kill()
    return proc.returncode, (seen + err).decode(errors="replace")


@pytest.mark.slow
@pytest.mark.parametrize(
    ("signum", "expected"),
    [(signal.SIGTERM, EXIT_TERMINATED), (signal.SIGINT, EXIT_INTERRUPTED)],
    ids=["SIGTERM", "SIGINT"],
)
def test_a_stopped_command_exits_128_plus_the_signal(signum, expected):
    code, err = _signalled(signum)
    assert code == expected == 128 + signum
    assert "Traceback" not in err


def test_a_closed_standard_output_is_141():
    proc = subprocess.Popen(
        [sys.executable, "-m", "rt70", "plant", "three_masses", "--json"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env={**os.environ, "MPLBACKEND": "Agg"},
    )
    proc.stdout.close()  # the reader is gone before rt70 prints (``| head -0``)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == EXIT_BROKEN_PIPE == 141
    assert err == b""
