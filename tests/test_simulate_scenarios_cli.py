"""``rt70 simulate`` with the servo scenarios: defaults, options, refusals (issue 10 item 6)."""

from __future__ import annotations

from pathlib import Path

import pytest

from rt70.cli.main import main

ALL_JOINTS = Path(__file__).resolve().parent / "data" / "all_joint_types.urdf"


def one_error_line(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("rt70: error: "), err
    return lines[0]


def test_servo_scene_runs_a_scenario_and_writes_its_figure(tmp_path, capsys):
    out = tmp_path / "step.csv"
    code = main(
        [
            "simulate",
            "rt70_servo",
            "--scenario",
            "step-elevation",
            "--t-end",
            "0.5",
            "--elevation",
            "30",
            "--out",
            str(out),
        ]
    )
    text = capsys.readouterr().out
    assert code == 0
    assert "step-elevation at elevation 30°" in text and "pointing error" in text
    assert "step 3600″" in text and "predicted from the bandwidth" in text
    assert out.is_file() and out.with_suffix(".png").stat().st_size > 10_000
    header = out.read_text().splitlines()[0]
    assert "state:elevation:current" in header and "output:main_mirror_direction" not in header


def test_listing_as_printed_runs_the_structural_benchmark_with_a_hint(capsys):
    assert main(["simulate", "rt70", "--t-end", "0.01"]) == 0
    text = capsys.readouterr().out
    assert "declare no <rt70:servo>" in text and "could not hold it" in text
    assert "rt70 simulate rt70_servo" in text
    assert "balance drift" in text  # today's benchmark output


def test_free_axes_runs_the_structural_benchmark(capsys):
    assert main(["simulate", "rt70_servo", "--free-axes", "--t-end", "0.01"]) == 0
    text = capsys.readouterr().out
    assert "cannot hold" not in text and "pointing error" not in text


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["rt70_servo", "--free-axes", "--scenario", "hold"], "--free-axes"),
        (["rt70_servo", "--free-axes", "--elevation", "30"], "--free-axes"),
        (["rt70_servo", "--scenario", "wobble"], "invalid choice"),
        (["rt70_servo", "--elevation", "95"], "elevation 95° lies outside its axis's range 0…90°"),
        ([str(ALL_JOINTS), "--scenario", "hold"], "pointing axes"),
        (["rt70", "--scenario", "hold"], "declares no servo: add an <rt70:servo>"),
    ],
)
def test_bad_options_are_refused_in_one_line(args, message, capsys):
    try:
        code = main(["simulate", *args])
    except SystemExit as exc:  # argparse's own refusals (options.Parser: one line, exit 2)
        code = exc.code
    assert code == 2
    captured = capsys.readouterr()
    assert message in one_error_line(captured.err)
    assert captured.out == ""  # refused before any work


def test_a_pointing_error_that_has_not_settled_is_not_reported_settled(capsys):
    """5 s into a 1° elevation step the RT-70 is still slewing (final error 413″): the
    cross-elevation error settled at t = 0 must not make the pointing error 'inside 1″'."""
    assert main(["simulate", "rt70_servo", "--scenario", "step-elevation", "--t-end", "5"]) == 0
    line = next(s for s in capsys.readouterr().out.splitlines() if "pointing error" in s)
    assert "not inside 1″ by the end of the run" in line, line
