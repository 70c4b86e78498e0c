"""The robots of example-robot-data: names, survey, agreement with Pinocchio, CLI."""

import json

import pytest

import rt70.crosscheck.robots
from rt70.cli.main import main
from rt70.crosscheck.robots import (
    NOT_INSTALLED,
    ROBOTS,
    UNEXPECTED,
    load_robot,
    robots_dir,
    survey,
)
from rt70.crosscheck.validate import cross_check
from rt70.errors import Rt70Error, SceneError
from rt70.testing import assert_close

TOL = 1e-10
CHECKED = ("mass_matrix", "bias", "gravity", "forward_dynamics")

#: Robots whose URDF cannot be modelled, with the rt70 error class (docs/robots.md gives
#: each reason): impossible inertias of moving links, a mimic of a joint that does not
#: exist, a robot whose hand joints move no mass (singular mass matrix), an empty robot.
NOT_LOADED = {
    "alex_psyonic_hands": "TopologyError",
    "allegro_left_hand": "InertiaError",
    "allegro_right_hand": "InertiaError",
    "finger_edu": "InertiaError",
    "hector": "SceneError",
    "hyq": "InertiaError",
    "iris": "SceneError",
    "pr2": "InertiaError",
    "romeo": "MasslessCoordinateError",
    "romeo_small": "InertiaError",
    "romeo_laas_small": "InertiaError",
    "ur3_empty": "UrdfError",
}


@pytest.fixture(scope="module")
def surveyed():
    """``({name: scene}, {name: reason})`` of every robot, surveyed once."""
    loaded, failed = survey()
    return {s.name: s for s in loaded}, failed


def test_loader_names_are_present():
    assert {"ur5", "panda", "talos_full", "solo12"} <= set(ROBOTS)
    assert ROBOTS["ur5"] == "ur_description/urdf/ur5_robot.urdf"
    assert ROBOTS["panda"] == "panda_description/urdf/panda.urdf"
    assert ROBOTS["talos_full"] == "talos_data/robots/talos_full_v2.urdf"
    assert ROBOTS["solo12"] == "solo_description/robots/solo12.urdf"


def test_every_urdf_file_has_one_name():
    root = robots_dir()
    files = {p.relative_to(root).as_posix() for p in root.rglob("*.urdf")}
    assert len(set(ROBOTS.values())) == len(ROBOTS)
    assert set(ROBOTS.values()) == files


@pytest.mark.slow
def test_survey_accounts_for_every_robot(surveyed):
    loaded, failed = surveyed
    assert set(loaded) | set(failed) == set(ROBOTS)
    assert not set(loaded) & set(failed)
    for reason in failed.values():
        assert reason and "\n" not in reason


def test_no_unexpected_exception(surveyed):
    """A failure that is not an Rt70Error is a bug in rt70, never a robot's fault."""
    _, failed = surveyed
    bugs = {n: r for n, r in failed.items() if r.startswith(UNEXPECTED)}
    assert not bugs, bugs


def test_robots_not_loaded_are_exactly_the_known_ones(surveyed):
    _, failed = surveyed
    assert {name: reason.split(":")[0] for name, reason in failed.items()} == NOT_LOADED


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(set(ROBOTS) - set(NOT_LOADED)))
def test_robot_agrees_with_pinocchio(surveyed, name):
    loaded, failed = surveyed
    assert name in loaded, f"{name} does not load: {failed.get(name)}"
    records = {r.quantity: r for r in cross_check(loaded[name], samples=2, seed=7, repeat=1)}
    for quantity in CHECKED:
        r = records[quantity]
        # cross_check's error is relative to the natural scale already: its scale is 1
        assert_close(r.max_rel_err, 0.0, rel=TOL, scale=1.0, what=f"{name} {quantity}")


@pytest.mark.parametrize("name", ["ur5", "solo12", "panda", "talos_full"])
def test_robot_loads(surveyed, name):
    _, failed = surveyed
    if name in failed:
        pytest.fail(f"{name} does not load: {failed[name]}")


def test_load_robot_names_the_scene():
    scene = load_robot("ur5")
    assert scene.name == "ur5"
    assert scene.path == robots_dir() / ROBOTS["ur5"]
    assert scene.textbook.nv == 6


def test_unknown_robot_is_bad_input():
    with pytest.raises(SceneError, match="no such robot"):
        survey(["no_such_robot"])
    assert main(["validate", "robot:no_such_robot"]) == 2


def test_missing_package_is_a_clear_error(monkeypatch, tmp_path):
    monkeypatch.setattr(rt70.crosscheck.robots, "_candidates", lambda: [tmp_path])
    with pytest.raises(Rt70Error) as exc:
        robots_dir()
    assert str(exc.value) == NOT_INSTALLED


@pytest.mark.parametrize(
    "argv",
    [["validate", "robots"], ["validate", "rt70", "robot:ur5"], ["bench", "--quick"]],
    ids=["validate-robots", "validate-robot-name", "bench"],
)
def test_commands_without_the_robots_extra_exit_2(argv, monkeypatch, tmp_path, capsys):
    """Without example-robot-data (a core install): one line naming the extra, exit 2.

    The finder sees an environment without the package: no prefix holds the robots.
    """
    monkeypatch.setattr(rt70.crosscheck.robots, "_candidates", lambda: [tmp_path])
    out = ["--out", str(tmp_path / "out")] if argv[0] == "bench" else []
    assert main([*argv, *out]) == 2
    captured = capsys.readouterr()
    assert captured.err == (
        "rt70: error: the robots of example-robot-data are not installed: "
        "pip install 'rt70[robots]'\n"
    )
    assert captured.out == ""
    assert not (tmp_path / "out").exists()


def test_unexpected_exception_is_recorded(monkeypatch):
    def broken(name, *args, **kwargs):
        raise KeyError("boom")

    monkeypatch.setattr(rt70.crosscheck.robots, "load_robot", broken)
    loaded, failed = survey(["ur5"])
    assert loaded == []
    assert failed == {"ur5": "unexpected KeyError: 'boom'"}


def test_cli_lists_robots_not_loaded(capsys):
    # ur3.urdf of example-robot-data 6.0.0 is an empty <robot>: never loads
    assert main(["validate", "robot:ur5", "robot:ur3_empty", "--samples", "1"]) == 0
    out = capsys.readouterr().out
    assert "ur5 " in out
    assert "not loaded: ur3_empty: UrdfError: no <link> elements" in out


def test_cli_json_stays_a_list(capsys):
    assert main(["validate", "robot:ur5", "robot:ur3_empty", "--samples", "1", "--json"]) == 0
    captured = capsys.readouterr()
    records = json.loads(captured.out)
    assert isinstance(records, list) and {r["target"] for r in records} == {"ur5"}
    assert "not loaded: ur3_empty: " in captured.err
