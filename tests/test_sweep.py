"""rt70 sweep: grids, quantities, a real local Dask cluster against the serial path, resume.

The Dask result must be bit-identical to the serial one: both run the same function
(:func:`rt70.sweep.run.compute_chunk`) on the same chunks from the same scene text, with one
BLAS thread (threadpoolctl) on both sides, and every point starts its Newton
equilibrium from q = 0 — nothing depends on which process computed a chunk, or when.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from rt70.cli.main import main
from rt70.errors import Rt70Error
from rt70.sweep import run as sw
from rt70.sweep.quantities import Field, Quantity, scaled_scene
from rt70.testing import assert_close

SCENE = "rt70_servo"


def one_error_line(err: str) -> str:
    lines = [line for line in err.splitlines() if line.strip()]
    assert len(lines) == 1, err
    assert lines[0].startswith("rt70: error: "), err
    return lines[0]


@pytest.fixture(scope="module")
def small():
    """3 elevations × 2 azimuths of rt70_servo, chunks of 2 (4 chunks), both quantities."""
    grid = sw.make_grid({"elevation": (15.0, 45.0, 75.0), "azimuth": (0.0, 90.0)})
    return sw.plan(SCENE, grid, ["first_frequency", "sag"], chunk=2)


@pytest.fixture(scope="module")
def serial_result(small):
    return sw.run(small, sw.serial)


# --- the grid ----------------------------------------------------------------------------


def test_axis_values():
    assert sw.parse_values("45") == (45.0,)
    assert sw.parse_values("0:90:4") == (0.0, 30.0, 60.0, 90.0)
    assert sw.parse_values("10,20.5") == (10.0, 20.5)
    assert sw.parse_values("5:5:1") == (5.0,)
    for bad in ("1:2", "0:90:1", "0:90:x", "a", "0:90:0", "nan", "1:2:3:4"):
        with pytest.raises(sw.SweepError):
            sw.parse_values(bad)


def test_chunks_run_along_elevation_and_cover_the_grid():
    grid = sw.make_grid({"elevation": tuple(range(7)), "wind": (0.0, 5.0)})
    chunks = grid.chunks(3)
    assert [(c.rest, c.start, c.stop) for c in chunks[:4]] == [
        ((0, 0, 0), 0, 3),
        ((0, 0, 0), 3, 6),
        ((0, 0, 0), 6, 7),
        ((0, 1, 0), 0, 3),
    ]
    seen = [i for c in chunks for i in c.indices()]
    assert sorted(seen) == sorted(np.ndindex(*grid.shape)) and len(seen) == grid.size
    assert grid.point((2, 0, 1, 0)).wind == 5.0


# --- the quantities ----------------------------------------------------------------------


def test_serial_values_are_those_of_rt70_modes_and_the_mirror_outputs(serial_result, capsys):
    """first_frequency is `rt70 modes`' first locked-rotor frequency; sag ≥ 0, arcsec."""
    f = serial_result.arrays["first_frequency"]
    assert f.shape == (3, 2, 1, 1) and serial_result.arrays["frequencies"].shape == (3, 2, 1, 1, 6)
    assert main(["modes", SCENE, "--elevation", "45", "--azimuth", "90", "--json"]) == 0
    modes = json.loads(capsys.readouterr().out)["modes"]
    expected = [m["freq_hz"] for m in modes[:6]]
    np.testing.assert_array_equal(serial_result.arrays["frequencies"][1, 1, 0, 0], expected)
    assert f[1, 1, 0, 0] == expected[0]
    sag = serial_result.arrays["sag"]
    assert np.isfinite(sag).all() and (sag > 1.0).all()  # the dish sags by arc seconds
    err = serial_result.arrays["sag_error"]  # |s − n5| small: its norm is the angle
    assert_close(np.linalg.norm(err, axis=-1), sag, rel=1e-6, scale=sag)  # point by point
    assert serial_result.errors == []


def test_stiffness_scale_reaches_both_sides():
    """The scaled description is what the textbook and Pinocchio both build from."""
    from rt70.reference import forces as ref_forces
    from rt70.textbook import forces

    scene = sw.build_scene(sw.SceneSource.read(SCENE))
    stiff = scaled_scene(scene, {"stiffness": 2.0})
    assert scaled_scene(scene, {"stiffness": 1.0}) is scene
    q = np.random.default_rng(0).normal(scale=1e-3, size=scene.textbook.nv)
    zero = np.zeros_like(q)
    for s, factor in ((scene, 1.0), (stiff, 2.0)):
        tb, _ = forces.spring_damper_force(s.textbook, s.textbook_data, q, zero)
        ref, _ = ref_forces.spring_damper_force(s.reference, s.reference_data, q, zero)
        base, _ = forces.spring_damper_force(scene.textbook, scene.textbook_data, q, zero)
        assert_close(ref, tb, rel=1e-10, what="Pinocchio's spring force")
        assert_close(tb, factor * base, rel=1e-12, what="scaled spring force")


def test_a_failed_point_is_nan_with_its_message(tmp_path):
    """A quantity that raises is NaN at that point, its message in the JSON sidecar."""

    def picky(scene, point):
        if point.elevation > 50:
            raise Rt70Error("no answer above 50°")
        return {"picky": point.elevation + point.wind}

    quantity = Quantity("picky", (Field("picky", (), "1", "test"),), picky)
    grid = sw.make_grid({"elevation": (30.0, 60.0), "wind": (0.0, 5.0)})
    sweep = sw.Sweep(sw.SceneSource.read(SCENE), grid, (quantity,), chunk=1)
    out = tmp_path / "picky.npz"
    sw.run(sweep, sw.serial, out)
    with np.load(out) as data:
        np.testing.assert_array_equal(data["picky"][:, 0, :, 0], [[30.0, 35.0], [np.nan, np.nan]])
        np.testing.assert_array_equal(data["wind"], [0.0, 5.0])
    meta = json.loads(sw.sidecar(out).read_text())
    assert [(e["index"], e["error"]) for e in meta["errors"]] == [
        ([1, 0, 0, 0], "no answer above 50°"),
        ([1, 0, 1, 0], "no answer above 50°"),
    ]
    assert meta["errors"][1]["point"]["wind"] == 5.0
    assert not (tmp_path / "picky.npz.partial").exists()


# --- Dask ----------------------------------------------------------------------------------


@pytest.mark.slow
def test_dask_cluster_equals_serial_bit_for_bit(small, serial_result, tmp_path):
    """A real LocalCluster: 2 worker processes over loopback, the same numbers."""
    from distributed import Client, LocalCluster

    from rt70.sweep.cluster import on_dask, workers_of

    with (
        LocalCluster(
            n_workers=2,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            dashboard_address=None,
        ) as cluster,
        Client(cluster) as client,
    ):
        assert workers_of(client) == 2
        out = tmp_path / "dask.npz"
        result = sw.run(small, on_dask(client), out, workers=2)
        # a second sweep of the same scene on the same client: its inputs' task is its
        # own (content-hashed keys were released by the first run as it ended, and the
        # second run's tasks were cancelled for "lost dependencies")
        again = sw.run(small, on_dask(client), workers=2)
        # each worker process built the scene once and computed some chunks
        pids = client.run(lambda: __import__("os").getpid())
    for name, expected in result.arrays.items():
        np.testing.assert_array_equal(again.arrays[name], expected, err_msg=name)
    assert len(set(pids.values())) == 2
    for name, expected in serial_result.arrays.items():
        np.testing.assert_array_equal(result.arrays[name], expected, err_msg=name)
    with np.load(out) as data:
        assert set(data.files) == set(serial_result.arrays)
        expected = serial_result.arrays["first_frequency"]
        np.testing.assert_array_equal(data["first_frequency"], expected)
    meta = json.loads(sw.sidecar(out).read_text())
    assert meta["workers"] == 2 and meta["chunks"] == {
        "total": 4,
        "resumed": 0,
        "computed": 4,
        "recomputed": 0,
    }


@pytest.mark.slow
def test_cli_sweep_on_a_local_cluster(tmp_path, capsys, serial_result):
    """`rt70 sweep` starts its own 2-worker cluster, closes it, writes NPZ + JSON."""
    out = tmp_path / "cli.npz"
    argv = ["sweep", SCENE, "--elevation", "15:75:3", "--azimuth", "0,90", "--chunk", "2"]
    argv += ["--workers", "2", "--out", str(out), "--no-progress", "--json"]
    assert main(argv) == 0
    meta = json.loads(capsys.readouterr().out)
    assert meta["workers"] == 2 and meta["shape"] == [3, 2, 1, 1]
    assert meta["quantities"]["sag"]["fields"]["sag"]["unit"] == "arcsec"
    with np.load(out) as data:
        np.testing.assert_array_equal(data["sag"], serial_result.arrays["sag"])
    assert json.loads(sw.sidecar(out).read_text()) == meta


# --- resume ------------------------------------------------------------------------------


def test_resume_computes_only_the_missing_chunks(tmp_path):
    grid = sw.make_grid({"elevation": (10.0, 30.0, 50.0, 70.0, 90.0)})
    sweep = sw.plan(SCENE, grid, ["first_frequency"], chunk=1)  # 5 chunks
    out = tmp_path / "resume.npz"
    computed: list[int] = []

    def interrupt_after_two(result):
        computed.append(result.number)
        if len(computed) == 2:
            raise KeyboardInterrupt  # Ctrl-C after the second chunk was saved

    with pytest.raises(KeyboardInterrupt):
        sw.run(sweep, sw.serial, out, on_chunk=interrupt_after_two)
    partial = tmp_path / "resume.npz.partial"
    assert sorted(p.name for p in partial.glob("chunk-*.npz")) == [
        "chunk-00000.npz",
        "chunk-00001.npz",
    ]
    assert not out.exists()

    # another grid does not mix with these chunks: refused, nothing deleted
    other = sw.plan(SCENE, sw.make_grid({"elevation": (10.0, 20.0)}), ["first_frequency"], 1)
    with pytest.raises(sw.SweepError, match="different sweep"):
        sw.run(other, sw.serial, out)
    assert len(list(partial.glob("chunk-*.npz"))) == 2

    again: list[int] = []
    resumed = sw.run(sweep, sw.serial, out, on_chunk=lambda r: again.append(r.number))
    assert sorted(again) == [2, 3, 4]
    assert resumed.metadata["chunks"] == {"total": 5, "resumed": 2, "computed": 3, "recomputed": 0}
    assert out.exists() and not partial.exists()
    fresh = sw.run(sweep, sw.serial)
    np.testing.assert_array_equal(resumed.arrays["frequencies"], fresh.arrays["frequencies"])


def test_an_empty_partial_directory_is_a_fresh_start(tmp_path):
    """A stop between creating FILE.partial/ and writing its key leaves it empty."""
    out = tmp_path / "s.npz"
    (tmp_path / "s.npz.partial").mkdir()
    sweep = sw.plan(SCENE, sw.make_grid({"elevation": (45.0,)}), ["first_frequency"], 1)
    assert sw.run(sweep, sw.serial, out).metadata["chunks"]["computed"] == 1
    assert out.exists() and not (tmp_path / "s.npz.partial").exists()


def test_cli_refuses_a_foreign_partial_directory(tmp_path, capsys):
    out = tmp_path / "s.npz"
    (tmp_path / "s.npz.partial").mkdir()
    (tmp_path / "s.npz.partial" / "key.json").write_text('{"key": "something else"}')
    argv = ["sweep", SCENE, "--workers", "0", "--out", str(out), "--no-progress"]
    assert main(argv) == 2
    assert "different sweep" in one_error_line(capsys.readouterr().err)


# --- options checked before any work ----------------------------------------------------------


@pytest.fixture
def no_work(monkeypatch):
    """Reading a scene or starting a cluster fails the test."""

    def forbidden(*args, **kwargs):
        raise AssertionError("work started before the options were checked")

    monkeypatch.setattr("rt70.sweep.run.SceneSource.read", forbidden)
    monkeypatch.setattr("rt70.sweep.cluster.local_cluster", forbidden)


@pytest.mark.parametrize(
    ("extra", "expected"),
    [
        (["--elevation", "1:2"], "argument --elevation: '1:2': a range is START:STOP:COUNT"),
        (["--elevation", "0:90:1"], "COUNT must be at least 2"),
        (["--azimuth", "x"], "argument --azimuth: 'x' is not a number"),
        (["--quantity", "first_frequency,nope"], "unknown quantity nope"),
        (["--scale", "stifness=1:2:3"], "unknown scene parameter 'stifness'"),
        (["--scale", "stiffness"], "is not NAME=VALUES"),
        (["--workers", "-1"], "argument --workers"),
        (["--chunk", "0"], "argument --chunk"),
        (["--elevation", "181"], "--elevation: elevations lie between -90° and 180°"),
        (["--wind", "-5"], "--wind: speeds must be at least 0"),
        (["--scale", "stiffness=0,1"], "factors must be greater than 0"),
        (["--scale", "damping=1", "--scale", "damping=2"], "named twice"),
        (["--scheduler", "tcp://127.0.0.1:9", "--workers", "2"], "not with --scheduler"),
    ],
)
def test_bad_option_exits_2_with_one_line_before_any_work(
    extra, expected, no_work, tmp_path, capsys
):
    out = tmp_path / "s.npz"
    try:
        code = main(["sweep", SCENE, "--out", str(out), *extra])
    except SystemExit as exc:  # argparse's own errors
        code = exc.code
    assert code == 2
    assert expected in one_error_line(capsys.readouterr().err)
    assert list(tmp_path.iterdir()) == []


def test_bad_output_path_exits_2(no_work, tmp_path, capsys):
    assert main(["sweep", SCENE, "--out", str(tmp_path / "s.csv")]) == 2
    assert "--out must be a .npz file" in one_error_line(capsys.readouterr().err)


def test_scene_without_pointing_axes_exits_2(tmp_path, capsys):
    assert main(["sweep", "three_masses", "--out", str(tmp_path / "s.npz")]) == 2
    err = one_error_line(capsys.readouterr().err)
    assert "no pointing axes to sweep" in err and "<rt70:mount>" in err


def test_an_elevation_outside_the_scene_s_range_exits_2_before_the_cluster(
    monkeypatch, tmp_path, capsys
):
    def forbidden(*args, **kwargs):
        raise AssertionError("the cluster started before the grid was checked")

    monkeypatch.setattr("rt70.sweep.cluster.local_cluster", forbidden)
    out = tmp_path / "s.npz"
    assert main(["sweep", SCENE, "--out", str(out), "--elevation", "91"]) == 2
    err = one_error_line(capsys.readouterr().err)
    assert "--elevation 91" in err and "from 0° to 90°" in err and "<rt70:axis" in err
    assert list(tmp_path.iterdir()) == []


def test_unreachable_scheduler_exits_2_quickly(tmp_path, capsys):
    """Nothing listens on the discard port: refused after the short timeout, no files."""
    argv = ["sweep", SCENE, "--scheduler", "tcp://127.0.0.1:9", "--timeout", "0.5"]
    assert main([*argv, "--out", str(tmp_path / "s.npz"), "--no-progress"]) == 2
    line = one_error_line(capsys.readouterr().err)
    assert "--scheduler tcp://127.0.0.1:9: no Dask scheduler reachable within 0.5 s" in line
    assert list(tmp_path.iterdir()) == []
