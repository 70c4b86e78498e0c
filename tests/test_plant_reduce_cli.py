"""``rt70 plant SCENE --reduce N --method modal|balanced``: the reduced plant and its H∞
error on the command line."""

from __future__ import annotations

import json

import numpy as np
import pytest

from rt70.cli.main import main
from rt70.testing import assert_close

ARGV = ["plant", "rt70_servo", "--elevation", "45", "--reduce", "12"]


def _run(argv: list[str]) -> int:
    try:
        return main(argv)
    except SystemExit as exc:  # argparse's own checks (options.Parser)
        return int(exc.code)


@pytest.mark.parametrize("method", ["modal", "balanced"])
def test_plant_reduce_json_and_npz(capsys, tmp_path, method):
    out = tmp_path / "reduced.npz"
    assert main([*ARGV, "--method", method, "--json", "--out", str(out)]) == 0
    info = json.loads(capsys.readouterr().out)
    reduced = info["reduced"]
    assert reduced["method"] == method and reduced["order"] == 12
    assert reduced["full_order"] == 84 and len(info["states"]) == 12
    error = reduced["hinf_error_relative"]  # measured 2.2e-2 modal, 1.3e-7 balanced
    assert error > 0.0
    assert_close(error, 0.0, rel=0.05, scale=1.0)  # a relative error: its own scale is 1
    assert (reduced["bound_2sum_hsv"] is None) == (method == "modal")
    with np.load(out) as arrays:
        assert arrays["A"].shape == (12, 12) and arrays["B"].shape == (12, 2)


def test_plant_reduce_prints_the_hinf_error(capsys):
    assert main(ARGV) == 0
    text = capsys.readouterr().out
    assert "12 states, 2 inputs, 19 outputs" in text
    assert "reduced by balanced truncation to 12 states: H∞ error" in text


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--reduce", "7", "--method", "modal"], "modal truncation keeps whole modes"),
        (["--method", "modal"], "--method needs --reduce"),
        (["--reduce", "0"], "--reduce"),
        (["--reduce", "1"], "order must be between 2 and 84"),
    ],
)
def test_bad_reduce_options_exit_2_with_one_line(capsys, argv, message):
    code = _run(["plant", "rt70_servo", *argv])
    err = capsys.readouterr().err
    assert code == 2 and message in err and len(err.strip().splitlines()) == 1


def test_long_signal_lists_are_cut_in_the_text_summary():
    """Thousands of forces and coordinates are named in --json and --out, counted in text."""
    from rt70.cli.plant import LISTED, _listed

    few = [f"s{i}" for i in range(LISTED)]
    assert _listed(few) == ", ".join(few)
    many = [f"s{i}" for i in range(LISTED + 5)]
    text = _listed(many)
    assert text.startswith(", ".join(few) + ", … and 5 more")
    assert f"s{LISTED}" not in text.split("…")[0]
