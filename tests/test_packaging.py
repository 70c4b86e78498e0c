"""A normal install works from any directory (issue 8, item 1).

The wheel is built from this tree, installed into a fresh virtual environment (no
editable install, no source tree on the path) and ``rt70 validate`` is run from a
temporary directory: the scenes must ship with the package. The install has no extras,
so the robots of example-robot-data are absent and asking for them names the extra.
About a minute: the fresh environment installs rt70's dependencies from the package
index.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

from rt70.model.scene import scene_names

ROOT = Path(__file__).resolve().parents[1]


def test_every_package_is_listed_in_pyproject():
    """pyproject.toml lists the packages explicitly (to map urdf/ in): keep it complete."""
    config = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    listed = set(config["tool"]["setuptools"]["packages"])
    found = {
        ".".join(p.parent.relative_to(ROOT).parts) for p in (ROOT / "rt70").rglob("__init__.py")
    }
    assert found | {"rt70.scene_files"} == listed
    assert config["tool"]["setuptools"]["package-dir"]["rt70.scene_files"] == "urdf"


#: A guard against a hang only: the slowest command, the wheel's install into a fresh
#: venv, took 96 s on a loaded 2-core machine (load average 5).
HANG_GUARD_S = 1800.0


def _run(cmd: list[str], cwd: Path, timeout: float = HANG_GUARD_S) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}  # the wheel, not a tree
    proc = subprocess.run(
        cmd, cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout, check=False
    )
    assert proc.returncode == 0, f"{' '.join(cmd)}\n{proc.stdout[-2000:]}\n{proc.stderr[-2000:]}"
    return proc


#: What the wheel is not built from (the copy of the tree leaves them out).
NOT_SOURCE = (".git", ".venv", "build", "*.egg-info", "__pycache__", ".*_cache")


@pytest.fixture(scope="module")
def installed(tmp_path_factory) -> Path:
    """``bin/`` of a fresh venv with the wheel of this tree installed."""
    tmp = tmp_path_factory.mktemp("wheel")
    pip = [sys.executable, "-m", "pip"]
    # a copy: pip builds in the source tree (its build/), and two test workers at once
    # would collide there ("File exists: build/bdist…")
    source = tmp / "source"
    shutil.copytree(ROOT, source, ignore=shutil.ignore_patterns(*NOT_SOURCE))
    _run([*pip, "wheel", "-q", "--no-deps", "-w", str(tmp / "dist"), str(source)], tmp)
    wheels = list((tmp / "dist").glob("rt70-*.whl"))
    assert len(wheels) == 1
    _run([sys.executable, "-m", "venv", str(tmp / "venv")], tmp)
    # --no-compile: pip's byte-compilation of every installed module is half the install
    # (58 s against 29 s measured); the few commands below compile what they import
    _run([str(tmp / "venv/bin/pip"), "install", "-q", "--no-compile", str(wheels[0])], tmp)
    return tmp / "venv" / "bin"


@pytest.mark.slow
def test_installed_wheel_validates_from_any_directory(installed, tmp_path):
    proc = _run([str(installed / "rt70"), "validate", "--samples", "1"], tmp_path)
    assert f"{len(scene_names())} target(s)" in proc.stdout  # every scene in urdf/
    scenes = {line.split()[0] for line in proc.stdout.splitlines()[2:] if line.strip()}
    assert {"rt70", "rt70_elevation", "double_pendulum"} <= scenes
    proc = _run([str(installed / "rt70"), "validate", "rt70", "--samples", "1"], tmp_path)
    assert "1 target(s)" in proc.stdout
    proc = _run([str(installed / "rt70"), "modes", "rt70_elevation"], tmp_path)
    assert "3.2700" in proc.stdout


def test_installed_package_is_not_the_source_tree(installed, tmp_path):
    code = "import rt70.model.scene as s; print(s.__file__); print(s.URDF_DIR)"
    proc = _run([str(installed / "python"), "-c", code], tmp_path)
    module, scenes = proc.stdout.split()
    assert not module.startswith(str(ROOT)) and not scenes.startswith(str(ROOT))
    assert scenes.endswith("scene_files")


def test_installed_package_ships_the_wind_tables(installed, tmp_path):
    """The built-in coefficient tables are package data (rt70/wind_tables/*.csv)."""
    code = (
        "from rt70.physics.coefficient_tables import builtin_table as b\n"
        "print(b('dish').axial[0], b('cylinder').normal[18], b('dish').source)\n"
    )
    proc = _run([str(installed / "python"), "-c", code], tmp_path)
    assert proc.stdout.split()[:2] == ["1.42", "1.2"]


def test_installed_package_is_typed_and_knows_its_version(installed, tmp_path):
    """The PEP 561 marker ships in the wheel; --version and the wheel's metadata agree."""
    code = "from importlib.resources import files; print(files('rt70').joinpath('py.typed'))"
    proc = _run([str(installed / "python"), "-c", code], tmp_path)
    marker = Path(proc.stdout.strip())
    assert marker.is_file() and marker.stat().st_size == 0
    assert not str(marker).startswith(str(ROOT))
    proc = _run([str(installed / "rt70"), "--version"], tmp_path)
    from rt70._version import __version__

    assert proc.stdout == f"rt70 {__version__}\n"
    proc = _run([str(installed / "python"), "-c", "import importlib.metadata as m; "
                 "print(m.version('rt70'))"], tmp_path)  # fmt: skip
    assert proc.stdout == f"{__version__}\n"


def test_core_install_without_robots_says_which_extra(installed, tmp_path):
    """The wheel without extras has no example-robot-data: 'robots' names the extra."""
    code = (
        "import importlib.metadata as m\n"
        "try:\n    m.version('example-robot-data')\n"
        "except m.PackageNotFoundError:\n    print('absent')\n"
    )
    assert _run([str(installed / "python"), "-c", code], tmp_path).stdout == "absent\n"
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    proc = subprocess.run(
        [str(installed / "rt70"), "validate", "robots"],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        timeout=HANG_GUARD_S,
        check=False,
    )
    assert (proc.returncode, proc.stdout) == (2, "")
    assert proc.stderr == (
        "rt70: error: the robots of example-robot-data are not installed: "
        "pip install 'rt70[robots]'\n"
    )
