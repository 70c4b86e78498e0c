"""`rt70 modes`: the elevation model's printed spectrum, JSON, RT-70 pointing, bad input."""

import json
import re

import pytest

from rt70.cli.main import main
from rt70.model.scene import URDF_DIR
from rt70.testing import assert_close

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
    assert kinds <= {"rigid", "elastic", "overdamped", "unstable"}
    # ζ ≥ 1 is called overdamped, never elastic
    for m in data["modes"]:
        if m["zeta"] is not None:
            assert (m["kind"] == "overdamped") == (m["zeta"] >= 1.0), m
    assert "overdamped" in kinds  # the listing's damping is heavy on its stiff modes
    # mode shapes by coordinate name; the damped system's eigenvalues all accounted for
    assert set(data["modes"][0]["shape"]) == set(data["modes"][1]["shape"])
    assert len(data["modes"][0]["shape"]) == 42
    damped = data["damped"]
    assert 2 * len(damped["oscillatory"]) + len(damped["real_eigenvalues"]) == 84
    assert max(damped["real_eigenvalues"]) > 0  # the unstable mode creeps away
    assert all(0 < o["zeta"] < 1 for o in damped["oscillatory"])
    # the listing's swinging part is not balanced about the free elevation axis
    assert "unstable" in kinds
    assert main(["modes", "rt70", "--elevation", "30", "--lock-axes", "--json"]) == 0
    locked = json.loads(capsys.readouterr().out)
    assert len(locked["modes"]) == 40
    assert all(m["kind"] in ("elastic", "overdamped") and m["freq_hz"] > 0 for m in locked["modes"])


def test_pointing_on_a_scene_without_axes_is_bad_input(capsys):
    assert main(["modes", "rt70_elevation", "--elevation", "10"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("rt70: error:") and "pointing axes" in err


def test_text_explains_unstable_and_rigid_modes(capsys):
    assert main(["modes", "rt70"]) == 0
    out = capsys.readouterr().out
    assert "overdamped" in out
    assert re.search(r"mode 1 is unstable .* about base_rx .* --lock-axes", out)
    assert re.search(r"mode 2 is a rigid-body motion along platform_rz", out)
    assert "the damping is not proportional" in out
    assert main(["modes", "rt70_elevation"]) == 0
    out = capsys.readouterr().out
    assert "rigid-body motion" in out and "--lock-axes" not in out  # no axes to lock


def test_a_large_chain_goes_the_compiled_way(capsys, tmp_path):
    """540 coordinates: the compiled kernels linearise it, the damped system's eigenvalues
    nearest zero are found by shift-invert, and the JSON says how many of them."""
    from rt70.linear import compiled
    from rt70.linear.damped_lowest import DENSE_MAX, LOWEST
    from rt70.scenes.synthetic import elastic_chain

    path = tmp_path / "chain90.urdf"
    path.write_text(elastic_chain(90, seed=0, hanging=True))
    assert 6 * 90 > max(DENSE_MAX, compiled.LARGE_NV)
    assert main(["modes", str(path)]) == 0
    out = capsys.readouterr().out
    assert out.startswith(f"chain90: the {LOWEST} lowest of 540 modes (--count N|all")
    assert f"among its {2 * LOWEST} eigenvalues nearest zero (of 1080)" in out
    assert main(["modes", str(path), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["lowest_of"] == {"modes": 540, "unstable": 0} and len(data["modes"]) == LOWEST
    assert main(["modes", str(path), "--json", "--count", "all"]) == 0
    every = json.loads(capsys.readouterr().out)["modes"]
    assert len(every) == 540
    low, dense = data["modes"], every[:LOWEST]
    assert [m["kind"] for m in low] == [m["kind"] for m in dense]
    freq = [m["freq_hz"] for m in dense]
    assert_close([m["freq_hz"] for m in low], freq, rel=1e-8, scale=freq)
    damped = data["damped"]
    assert (damped["eigenvalues_found"], damped["eigenvalues_total"]) == (2 * LOWEST, 1080)
    assert len(damped["oscillatory"]) == LOWEST
    assert all(0.0 < o["zeta"] < 1.0 for o in damped["oscillatory"])  # 1 % bushing damping


def test_a_bad_count_is_one_line_naming_the_option(capsys):
    for bad in ("0", "al", "-3"):
        with pytest.raises(SystemExit) as exc:
            main(["modes", "rt70_elevation", "--count", bad])
        assert exc.value.code == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "--count" in err and "'all'" in err


def test_count_picks_the_lowest_modes_of_a_small_model(capsys):
    """Lanczos on the book's 6-coordinate elevation model: its rigid mode and the lowest
    elastic ones, as the dense solution has them (the book's 3.2700 and 4.2424 Hz)."""
    assert main(["modes", "rt70_elevation", "--count", "3", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["lowest_of"] == {"modes": 6, "unstable": 0}
    assert [m["kind"] for m in data["modes"]] == ["rigid", "elastic", "elastic"]
    assert_close([m["freq_hz"] for m in data["modes"][1:]], [3.2700, 4.2424], rel=2e-5)
