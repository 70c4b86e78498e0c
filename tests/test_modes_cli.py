"""`rt70 modes`: the elevation model's printed spectrum, JSON, RT-70 pointing, bad input."""

import json
import re

from rt70.cli import main
from rt70.scene import URDF_DIR

PRINTED_ELEVATION_HZ = ["0.0000", "3.2700", "4.2424", "6.3041", "7.2579", "19.6420"]


def test_elevation_scene_prints_the_book_spectrum(capsys):
    assert main(["modes", str(URDF_DIR / "rt70_elevation.urdf")]) == 0
    out = capsys.readouterr().out
    freqs = re.findall(r"^\s+\d+\s+(\d+\.\d{4})", out, flags=re.M)
    assert freqs == PRINTED_ELEVATION_HZ


def test_modes_json_and_rt70_pointing(capsys):
    assert main(["modes", "rt70", "--elevation", "30", "--azimuth", "10", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["scene"] == "rt70" and len(data["modes"]) == 42
    kinds = {m["kind"] for m in data["modes"]}
    assert kinds <= {"rigid", "elastic", "unstable"}
    # the listing's swinging part is not balanced about the free elevation axis
    assert "unstable" in kinds
    assert main(["modes", "rt70", "--elevation", "30", "--lock-axes", "--json"]) == 0
    locked = json.loads(capsys.readouterr().out)
    assert len(locked["modes"]) == 40
    assert all(m["kind"] == "elastic" and m["freq_hz"] > 0 for m in locked["modes"])


def test_pointing_on_a_scene_without_axes_is_bad_input(capsys):
    assert main(["modes", "rt70_elevation", "--elevation", "10"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("rt70: error:") and "pointing axes" in err
