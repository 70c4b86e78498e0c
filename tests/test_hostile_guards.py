"""Hostile input to every command but ``sweep`` ends in one line, exit 2 (issue 21 §3).

One test per class of the issue's battery (``validation/hostile_guards.py`` runs ~140
cases in subprocesses and counts them):

- coefficient tables that are special files, too large, or hold numbers above 1e30;
- physical options beyond a stated bound (wind speed: Mach 0.3; rates, positions: 1e30;
  a heading error: π);
- sizes and durations beyond the memory (rt70.guards.resources' time-series estimate);
- runs an integrator cannot finish: the evaluation budget, a solver failing before its
  first output time;
- loads beyond any equilibrium (Newton's forces not finite);
- NaN never printed: a settling time never reached says so; results are checked;
- numpy/scipy RuntimeWarnings become the one error line, never a stray warning.

Each checks exit 2, exactly one stderr line starting ``rt70: error:`` that names the
option, file or element, and no traceback; in-process (``rt70.cli.main.main``) unless a
process of its own is needed.
"""

from __future__ import annotations

import math
import os
import warnings
from pathlib import Path

import numpy as np
import pytest

import rt70.guards.resources as resources
import rt70.simulation.integrators as integrators
from rt70.cli import options
from rt70.cli.main import main
from rt70.errors import Rt70Error, SimulationError
from rt70.model.scene import URDF_DIR
from rt70.physics.coefficient_tables import MAX_COEFFICIENT, MAX_TABLE_BYTES, MAX_TABLE_ROWS
from rt70.testing import assert_close
from rt70.urdf import elements

SERVO = URDF_DIR / "rt70_servo.urdf"
HEADER = "theta_deg,axial,normal,moment\n"


def one_error(capsys, argv: list[str]) -> str:
    """Run ``rt70 ARGV`` in-process; assert exit 2 and one error line; return the line.

    A bad option ends in argparse's ``SystemExit(2)`` (rt70.cli.options.Parser), any other
    failure in main's return value.
    """
    try:
        code = main(argv)
    except SystemExit as exc:
        code = exc.code
    err = capsys.readouterr().err
    lines = [line for line in err.splitlines() if line.strip()]
    assert code == 2, err
    assert len(lines) == 1, err
    assert lines[0].startswith("rt70: error: "), err
    assert "Traceback" not in err
    return lines[0]


def table_scene(tmp_path: Path, table: str) -> Path:
    """rt70_servo with its main-mirror wind element reading ``coefficients=table``."""
    text = SERVO.read_text().replace(
        'name="main_mirror" link="main_mirror" shape="dish"',
        f'name="main_mirror" link="main_mirror" coefficients="{table}"',
    )
    path = tmp_path / "scene.urdf"
    path.write_text(text)
    return path


# --- coefficient tables --------------------------------------------------------------------
@pytest.mark.parametrize("kind", ["fifo", "/dev/zero", "/dev/urandom", "directory"])
def test_a_special_file_as_coefficient_table_is_refused(tmp_path, capsys, kind):
    if kind == "fifo":
        table = tmp_path / "table.csv"
        os.mkfifo(table)  # opening it would block for ever
    elif kind == "directory":
        table = tmp_path / "table.csv"
        table.mkdir()
    else:
        table = Path(kind)
    line = one_error(capsys, ["validate", str(table_scene(tmp_path, str(table)))])
    assert f"{table}: is not a regular file" in line
    assert "<rt70:wind name='main_mirror'>" in line


@pytest.mark.parametrize("value", ["1e31", "1e300", "-2e30"])
def test_coefficients_above_the_urdf_bound_are_refused(tmp_path, capsys, value):
    (tmp_path / "t.csv").write_text(HEADER + f"0,1,0,0\n90,{value},1,1\n180,1,0,0\n")
    line = one_error(capsys, ["validate", str(table_scene(tmp_path, "t.csv"))])
    assert "t.csv: axial coefficient" in line and "magnitude above 1e+30" in line


def test_the_table_bound_is_the_urdf_readers():
    assert MAX_COEFFICIENT == elements.MAX_MAGNITUDE == options.MAX_MAGNITUDE


def test_a_table_with_too_many_rows_or_bytes_is_refused(tmp_path, capsys):
    n = MAX_TABLE_ROWS + 1
    rows = "".join(f"{180 * i / (n - 1)!r},1,0,0\n" for i in range(n))
    (tmp_path / "rows.csv").write_text(HEADER + rows)
    line = one_error(capsys, ["validate", str(table_scene(tmp_path, "rows.csv"))])
    assert f"rows.csv: {n} rows" in line
    comment = "# " + "x" * 78 + "\n"
    padding = comment * (MAX_TABLE_BYTES // len(comment) + 1)
    (tmp_path / "big.csv").write_text(padding + HEADER + "0,1,0,0\n90,1,1,1\n180,1,0,0\n")
    line = one_error(capsys, ["validate", str(table_scene(tmp_path, "big.csv"))])
    assert "big.csv: larger than 1 MiB" in line


# --- physical options ----------------------------------------------------------------------
@pytest.mark.parametrize(
    ("argv", "named"),
    [
        (["pointing", "rt70_servo", "--wind", "1e10"], "--wind"),
        (["pointing", "rt70_servo", "--wind", "103"], "--wind"),
        (["reactions", "rt70_servo", "--wind", "1e300"], "--wind"),
        (["impact", "rt70", "--brake", "base_rx", "--rate", "base_rx=1e300"], "--rate"),
        (["impact", "rt70", "--brake", "base_rx", "--rate", "base_rx=2e30"], "--rate"),
        (["cart", "--start", "1e300", "0"], "--start"),
        (["cart", "--heading-error", "1e300"], "--heading-error"),
        (["cart", "--heading-error", "3.2"], "--heading-error"),
        (["impact", "rt70", "--pin", "main_mirror:1e300,0,0"], "--pin"),
        (["pointing", "rt70_servo", "--azimuth", "1e300"], "--azimuth"),
        (["pointing", "rt70_servo", "--direction", "-361"], "--direction"),
        (["simulate", "rt70_servo", "--azimuth", "400"], "--azimuth"),
        (["reactions", "rt70_servo", "--direction", "0,1e300"], "--direction"),
    ],
)
def test_physical_options_beyond_their_bound_are_refused(capsys, argv, named):
    line = one_error(capsys, argv)
    assert named in line


def test_the_wind_bound_is_mach_0_3(capsys):
    assert_close(options.MAX_WIND_SPEED, 102.09, rel=1e-12)  # 0.3 × 340.3 m/s, to the digit
    assert options.wind_speed("102") == 102.0


# --- sizes and durations against the memory -------------------------------------------------
def test_time_series_estimate():
    assert resources.time_series_bytes(1000, 10) == 8 * 1000 * 10 * resources.TIME_SERIES_COPIES
    assert resources.time_series_samples(10, available=8 * 10 * 4 * 2 * 100) == 100
    with pytest.raises(resources.ResourceError, match="--step 1e-09"):
        resources.check_time_series(1e10, 10, "samples", "--step 1e-09", available=2**30)


@pytest.mark.parametrize(
    ("argv", "named"),
    [
        (["pointing", "rt70_servo", "--wind", "10", "--duration", "1e12"], "--duration 1e+12"),
        (["cart", "--step", "1e-9"], "--step 1e-09"),
        (["cart", "--step", "1e-6", "--duration", "100"], "--step 1e-06"),
        (["simulate", "rt70_servo", "--t-end", "1e12"], "--t-end 1e+12"),
    ],
)
def test_runs_beyond_the_memory_are_refused_before_the_work(capsys, argv, named):
    line = one_error(capsys, argv)
    assert named in line and "of memory" in line


def test_a_run_without_output_times_stops_at_the_samples_memory_holds(monkeypatch, capsys):
    # one sample per step: the most evaluations are the samples memory holds (here 200)
    import rt70.simulation.simulate

    monkeypatch.setattr(rt70.simulation.simulate, "time_series_samples", lambda channels: 200)
    line = one_error(capsys, ["simulate", "rt70", "--t-end", "10"])
    assert "right-hand-side evaluations" in line and "memory" in line


# --- runs an integrator cannot finish -------------------------------------------------------
def test_the_evaluation_budget_stops_a_run_with_one_line(monkeypatch, capsys):
    monkeypatch.setattr(integrators, "COMMAND_BUDGET", integrators.EvaluationBudget(300, 0.0))
    line = one_error(capsys, ["simulate", "rt70", "--method", "RK23", "--t-end", "10"])
    assert "rt70: integration stopped at t = " in line
    assert "stopped after 300 right-hand-side evaluations" in line


def test_the_budget_counts_evaluations():
    calls = []
    with integrators.evaluation_budget(integrators.EvaluationBudget(10, 1.0)):
        rhs = integrators.budgeted(lambda t, x: calls.append(t) or -x, 5.0)
        for _ in range(15):
            rhs(0.0, np.ones(1))
        with pytest.raises(SimulationError, match="stopped after 15 right-hand"):
            rhs(0.0, np.ones(1))
    assert len(calls) == 15
    unlimited = integrators.budgeted(lambda t, x: -x, 5.0)  # no budget outside: no count
    assert all(unlimited(0.0, np.ones(1)) == -1.0 for _ in range(10**4))


@pytest.mark.parametrize("limited", [True, False])
def test_a_lost_stop_is_raised_again_at_the_next_evaluation(limited):
    """A Ctrl-C swallowed where it was raised (a finaliser, a library's broad except) is
    not lost: the right-hand side raises the recorded stop until the command is over."""
    from rt70.guards import stop

    budget = integrators.EvaluationBudget(10**6, 1.0) if limited else None
    with integrators.evaluation_budget(budget):
        rhs = integrators.budgeted(lambda t, x: -x, 5.0)
        assert rhs(0.0, np.ones(1))[0] == -1.0
        try:
            stop.request(KeyboardInterrupt)
        except KeyboardInterrupt:
            pass  # swallowed, as a library might
        try:
            for _ in range(2):
                with pytest.raises(KeyboardInterrupt):
                    rhs(0.0, np.ones(1))
        finally:
            stop.clear()
        assert rhs(0.0, np.ones(1))[0] == -1.0 and not stop.requested()


def test_stop_signals_record_and_raise_and_clear():
    """The command line's SIGINT and SIGTERM handlers raise, record, and forget on exit."""
    import signal

    from rt70.cli.session import stop_signals
    from rt70.guards import stop

    before = signal.signal(signal.SIGINT, signal.default_int_handler)  # as in a terminal
    try:
        _raise_record_and_clear(stop_signals, stop)
        assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    finally:
        signal.signal(signal.SIGINT, before)


def test_a_sigint_ignored_from_the_start_stays_ignored():
    """A job started in the background ignores SIGINT; the command line leaves it so."""
    import signal

    from rt70.cli.session import stop_signals
    from rt70.guards import stop

    before = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        with stop_signals(143):
            assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN
            signal.raise_signal(signal.SIGINT)  # ignored: nothing raised, nothing recorded
            assert not stop.requested()
        assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN
    finally:
        signal.signal(signal.SIGINT, before)


def _raise_record_and_clear(stop_signals, stop) -> None:
    import signal

    with stop_signals(143):
        with pytest.raises(KeyboardInterrupt):
            signal.raise_signal(signal.SIGINT)
        assert stop.requested()
        with pytest.raises(KeyboardInterrupt):
            stop.check()
    assert not stop.requested()
    with stop_signals(143):
        with pytest.raises(SystemExit) as exc:
            signal.raise_signal(signal.SIGTERM)
        assert exc.value.code == 143
        with pytest.raises(SystemExit):
            stop.check()
    assert not stop.requested()


def test_a_run_kept_step_by_step_checks_its_pace_against_memory():
    """One sample per step: a run whose start extrapolates to far more samples than
    memory holds stops at the pace check, not after minutes at the memory limit."""
    check = integrators.PACE_CHECK
    dt = 1e-3  # simulated seconds per evaluation
    fits = integrators.budgeted(np.negative, span=check * dt * 5, limit=check, t0=2.0)
    for k in range(1, check + 1):  # 5 × the pace check's work over the span: within the margin
        fits(2.0 + k * dt, np.ones(1))
    huge = integrators.budgeted(np.negative, span=1e12, limit=10**6, t0=2.0)
    for k in range(1, check):
        huge(2.0 + k * dt, np.ones(1))
    with pytest.raises(SimulationError, match=r"about 1e\+15 evaluations .* 1000000 samples"):
        huge(2.0 + check * dt, np.ones(1))


def test_an_endless_structural_run_is_one_line_within_its_first_evaluations(capsys):
    line = one_error(capsys, ["simulate", "double_pendulum", "--t-end", "1e12"])
    assert "double_pendulum: integration stopped at t = " in line
    assert "at the pace of its first 2000 evaluations" in line and "memory holds" in line


def test_a_solver_failing_before_its_first_output_time_leaves_an_empty_record():
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a solver's warning would go into the message
        sol = integrators.integrate(
            "RK45",
            lambda t, y: y * y,  # blows up at t = 1: the step shrinks to nothing there
            None,
            (0.0, 10.0),
            np.ones(1),
            1e-8,
            np.full(1, 1e-10),
            t_eval=np.array([5.0, 10.0]),
            max_evaluations=100_000,
        )
    assert not sol.success and "step size" in sol.message
    assert sol.y.shape == (1, 0) and sol.t.shape == (0,)


def drive_scene(tmp_path: Path, key: str, value: str) -> Path:
    text = SERVO.read_text()
    line = next(x for x in text.splitlines() if '<rt70:drive name="elevation"' in x)
    start = line.index(f' {key}="')
    end = line.index('"', start + len(key) + 3)
    path = tmp_path / f"drive_{key}.urdf"
    path.write_text(text.replace(line, line[:start] + f' {key}="{value}"' + line[end + 1 :]))
    return path


def test_a_drive_at_the_extremes_fails_with_one_line(tmp_path, capsys):
    line = one_error(
        capsys, ["simulate", str(drive_scene(tmp_path, "L_a", "1e-30")), "--t-end", "1"]
    )
    assert "drive_L_a: drive 'elevation' is too stiff for this run: its rate R_a/L_a" in line


# --- loads beyond any equilibrium -----------------------------------------------------------
def test_a_load_beyond_any_equilibrium_is_one_line(tmp_path, capsys):
    (tmp_path / "t.csv").write_text(HEADER + "0,1e29,0,0\n90,1e29,1e29,1e29\n180,1e29,0,0\n")
    line = one_error(
        capsys,
        ["reactions", str(table_scene(tmp_path, "t.csv")), "--wind", "30", "--elevation", "45"],
    )
    assert "scene: " in line and "not finite" in line


# --- NaN never printed ------------------------------------------------------------------------
@pytest.mark.slow
def test_a_step_that_does_not_settle_says_so(capsys):
    code = main(
        [
            "simulate",
            "rt70_servo",
            "--scenario",
            "step-elevation",
            "--elevation",
            "90",
            "--t-end",
            "2",
        ]
    )
    out = capsys.readouterr().out
    assert code == 0
    assert "axis not inside 1″ by the end of the run (t = 2 s)" in out
    assert "nan" not in out.lower()


def test_results_with_nan_are_refused():
    options.check_finite({"a": [1.0, {"b": 2.0}], "c": None, "d": np.ones(2)}, "x")
    with pytest.raises(Rt70Error, match=r"x: a\[1\]\.b is NaN"):
        options.check_finite({"a": [1.0, {"b": math.nan}]}, "x")
    with pytest.raises(Rt70Error, match=r"x: d is NaN or infinite"):
        options.check_finite({"d": np.array([1.0, np.inf])}, "x")
    # long lists and dicts of numbers (mode shapes) are checked at once, and still named
    shape = {f"q{i}": float(i) for i in range(40)}
    options.check_finite({"modes": [{"shape": shape, "kind": "elastic"}] * 20}, "x")
    with pytest.raises(Rt70Error, match=r"x: modes\[0\]\.shape\.q39 is NaN"):
        options.check_finite({"modes": [{"shape": {**shape, "q39": math.nan}}]}, "x")
    with pytest.raises(Rt70Error, match=r"x: \[17\] is NaN"):
        options.check_finite([1] * 17 + [math.inf], "x")
    options.check_finite(["nan"] * 20 + [None], "x")  # text and None are not numbers


def test_settling_metrics_nan_is_text_other_nan_is_an_error():
    from types import SimpleNamespace

    from rt70.telescope.servo_metrics import summary_lines

    m = {
        "pointing_drift_arcsec": 3.0,
        "final_pointing_arcsec": 2.0,
        "settle_s": math.nan,
        "static_misalignment_arcsec": 1.0,
        "wall_s": 1.0,
        "energy_drift": 1e-9,
        "tracking_rms_arcsec": math.nan,
        "tracking_max_after_settle_arcsec": math.nan,
    }
    result = SimpleNamespace(
        t=np.array([0.0, 3.0]), relative_drift=1e-9, balance_scale=1.0, input_work=np.zeros(2)
    )
    run = SimpleNamespace(
        metrics=m, scenario=SimpleNamespace(rate_arcsec_s=15.0), result=result, axis_torque={}
    )
    text = "\n".join(summary_lines(run))
    assert "not inside 1″ by the end of the run (t = 3 s)" in text and "nan" not in text
    m["final_pointing_arcsec"] = math.nan
    with pytest.raises(Rt70Error, match="final_pointing_arcsec is not finite"):
        summary_lines(run)


# --- RuntimeWarnings ------------------------------------------------------------------------
def test_a_runtime_warning_is_the_one_error_line(monkeypatch, capsys):
    import rt70.model.scene

    real = rt70.model.scene.load_scene

    def overflowing(*args, **kwargs):
        np.float64(1e308) * np.float64(10.0)  # numpy: "overflow encountered"
        return real(*args, **kwargs)

    monkeypatch.setattr(rt70.model.scene, "load_scene", overflowing)
    line = one_error(capsys, ["modes", "two_body_gravity"])
    assert line.startswith(
        "rt70: error: rt70 modes two_body_gravity: numerical failure (RuntimeWarning: overflow"
    )


def test_a_floating_point_failure_names_the_option_at_fault(capsys):
    """cart's start speed enters the torques squared: 1e300 overflows in the servo."""
    line = one_error(capsys, ["cart", "--speed-error", "1e300"])
    assert line.startswith(
        "rt70: error: the start state (--start, --heading-error, --speed-error): numerical "
        "failure (RuntimeWarning: overflow"
    )
