"""Nothing reachable from the command line crashes or eats the machine (issue 8, part 3).

- memory and parser guards (rt70.guards.resources): the estimates, the refusals (with a
  monkeypatched available memory: nothing large is allocated), one small measurement,
  a tree deeper than Pinocchio's main-thread limit parsed on the big-stack thread;
- the linear-time lookups behind many bushings and joint springs (results, not timings:
  ``validation/bushing_scaling.py`` measures the cost);
- options checked before any work: one line on stderr, exit 2;
- atomic output sets: SIGTERM during a write, a failure between two files, SIGTERM
  during the renames;
- a closed standard output (``| head``);
- models that ``simulate`` and ``modes`` must refuse cleanly;
- wrong shapes and non-finite states from Python, on both sides.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest

import rt70.guards.resources as resources
import rt70.reference.limits as limits
from rt70 import reference
from rt70.cli.main import EXIT_BROKEN_PIPE, EXIT_TERMINATED, main
from rt70.errors import (
    NonFiniteError,
    OutputError,
    ResourceError,
    Rt70Error,
    ShapeError,
    SimulationError,
)
from rt70.guards.atomic import atomic_write_all
from rt70.model.scene import load_scene, scene_from_text
from rt70.scenes.synthetic import serial_chain
from rt70.simulation.simulate import simulate
from rt70.textbook import dynamics, forces, structured

ROOT = Path(__file__).resolve().parents[1]
ALL_JOINTS = ROOT / "tests" / "data" / "all_joint_types.urdf"
INERTIAL = (
    '<inertial><mass value="1"/>'
    '<inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial>'
)
LIMIT = '<limit lower="-1" upper="1" effort="1" velocity="1"/>'


def run(*args: str, **kwargs) -> subprocess.CompletedProcess:
    """``python -m rt70 ARGS`` in a subprocess (text output, 120 s at most)."""
    return subprocess.run(
        [sys.executable, "-m", "rt70", *args],
        capture_output=True,
        text=True,
        timeout=120,
        env={**os.environ, "MPLBACKEND": "Agg"},
        **kwargs,
    )


def one_error_line(err: str) -> str:
    """The single ``rt70: error:`` line of stderr (and nothing else: no traceback)."""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("rt70: error: "), err
    return lines[0]


def chain_urdf(joint_types: list[str], massless: tuple[int, ...] = ()) -> str:
    """A chain world → l1 → l2 … with the given joint types (links in ``massless``: none)."""
    parts = ['<robot name="c" xmlns:rt70="urn:rt70:urdf-extensions:1">', '<link name="world"/>']
    for i, jtype in enumerate(joint_types, start=1):
        parts.append(f'<link name="l{i}">{"" if i in massless else INERTIAL}</link>')
        parent = "world" if i == 1 else f"l{i - 1}"
        parts.append(
            f'<joint name="j{i}" type="{jtype}"><parent link="{parent}"/>'
            f'<child link="l{i}"/><origin xyz="0 0 -1"/><axis xyz="1 0 0"/>{LIMIT}</joint>'
        )
    parts.append("</robot>")
    return "\n".join(parts)


# --- 1. memory and parser guards ---------------------------------------------------------


def test_available_memory_reads_meminfo():
    available = resources.available_memory()
    if Path("/proc/meminfo").exists():
        assert available is not None and available > 0
    else:
        assert available is None


def test_reference_estimate_is_cubic_and_refuses_beyond_the_budget():
    est = resources.reference_peak_bytes
    assert est(1000, 1001) > 100e9  # the 1000-link chain of the issue: ~100 GB
    assert 7.5 < est(1000, 1001) / est(500, 501) < 8.0  # cubic
    resources.check_memory(10**9, "x", "f.urdf", available=3 * 10**9)  # fits: no error
    with pytest.raises(ResourceError, match=r"^f\.urdf: x would need about 2 GB"):
        resources.check_memory(2 * 10**9, "x", "f.urdf", available=3 * 10**9)


def test_unknown_available_memory_checks_nothing(monkeypatch):
    monkeypatch.setattr(resources, "available_memory", lambda: None)  # not Linux
    resources.check_memory(10**15, "x", "f.urdf")


def test_reference_model_refused_before_pinocchio_allocates(monkeypatch):
    """A 300-coordinate chain needs ~2.8 GB on the reference side: refused on a 1 GB machine."""
    monkeypatch.setattr(resources, "available_memory", lambda: 10**9)
    scene = scene_from_text(serial_chain(300), "chain300.urdf")
    with pytest.raises(
        ResourceError, match=r"^chain300\.urdf: .* 300 coordinates .* about 2\.8\d* GB"
    ):
        scene.reference  # noqa: B018
    scene.textbook_data  # noqa: B018  (the textbook side needs ~50 MB: fine)


def test_textbook_side_refused_beyond_the_budget(monkeypatch):
    monkeypatch.setattr(resources, "available_memory", lambda: 10**7)
    scene = scene_from_text(serial_chain(100), "chain100.urdf")
    with pytest.raises(ResourceError, match=r"^chain100\.urdf: the textbook side.*100 bodies"):
        scene.textbook_data  # noqa: B018


def test_cli_refuses_a_model_too_large(monkeypatch, tmp_path, capsys):
    monkeypatch.setattr(resources, "available_memory", lambda: 10**8)
    path = tmp_path / "chain.urdf"
    path.write_text(serial_chain(150), encoding="utf-8")
    for argv in (["validate", str(path)], ["simulate", str(path)]):
        assert main(argv) == 2
        assert str(path) in one_error_line(capsys.readouterr().err)
    assert main(["simulate", str(path)]) == 2
    line = one_error_line(capsys.readouterr().err)
    assert "--method generalized-alpha" in line  # the compiled kernels cover the chain


def test_a_refused_simulation_names_what_can_run_it():
    """The compiled kernels where they cover the model, the textbook side otherwise."""
    from rt70.cli.simulate import _refusal_hint

    chain = scene_from_text(serial_chain(3), "chain.urdf")
    assert "--method generalized-alpha" in _refusal_hint(chain)
    closed = load_scene("four_bar")  # a closed loop: not covered
    assert _refusal_hint(closed).startswith("'--side textbook'")


_MEASURE = r"""
import json
from rt70.reference import ReferenceData, ReferenceModel
from rt70.model.scene import scene_from_text
from rt70.scenes.synthetic import serial_chain

def status():  # resident memory: peak (VmHWM), anonymous, file-backed (libraries), shared
    with open("/proc/self/status") as f:
        keys = ("VmHWM", "Rss")
        return {l.split(":")[0]: int(l.split()[1]) * 1024 for l in f if l.startswith(keys)}

scene = scene_from_text(serial_chain(100), "chain")
base = status()
ReferenceData(ReferenceModel(scene.description, scene.text))
end = status()
# peak growth of anonymous memory: library pages evicted and read back in (a loaded
# machine) must not count; VmHWM, not ru_maxrss, which keeps the parent's peak (fork)
print(json.dumps(end["VmHWM"] - end["RssFile"] - end["RssShmem"] - base["RssAnon"]))
"""


@pytest.mark.skipif(not Path("/proc/self/status").exists(), reason="needs Linux /proc")
def test_reference_estimate_bounds_a_measured_peak():
    """One real measurement (nv = 100, ~110 MB): the estimate is above it, and not far."""
    out = subprocess.run(
        [sys.executable, "-c", _MEASURE], capture_output=True, text=True, check=True, timeout=120
    )
    peak = json.loads(out.stdout)
    estimate = resources.reference_peak_bytes(100, 101)
    assert peak <= estimate <= 1.3 * peak, (peak, estimate)


def test_tree_depth_and_parser_guard(monkeypatch):
    desc = scene_from_text(chain_urdf(["revolute", "fixed", "revolute"])).description
    assert limits.tree_depth(desc) == 4
    monkeypatch.setattr(resources, "PARSER_MAX_DEPTH", 3)
    scene = scene_from_text(chain_urdf(["revolute", "fixed", "revolute"]), "deep.urdf")
    with pytest.raises(ResourceError, match=r"^deep\.urdf: kinematic tree 4 links deep"):
        scene.reference  # noqa: B018


def test_run_with_stack_returns_and_raises():
    assert resources.run_with_stack(lambda: 42) == 42
    with pytest.raises(KeyError, match="x"):
        resources.run_with_stack(lambda: {}["x"])


_DEEP = r"""
import sys
from rt70.model.scene import scene_from_text
n = 5000  # the main thread's 8 MiB stack segfaults Pinocchio's parser near 3770 levels
inertial = sys.argv[1]
parts = ['<robot name="deep">', '<link name="l0"/>']
for i in range(1, n):
    jtype = "revolute" if i == n - 1 else "fixed"
    parts += [f'<link name="l{i}">{inertial}</link>',
              f'<joint name="j{i}" type="{jtype}"><parent link="l{i-1}"/><child link="l{i}"/>'
              '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>']
scene = scene_from_text("\n".join(parts + ["</robot>"]), "deep")
print(scene.reference.nv)
"""


@pytest.mark.slow
def test_deep_tree_parses_on_the_big_stack_thread():
    """5000 levels: beyond the main thread's limit, well within the parser thread's."""
    proc = subprocess.run(
        [sys.executable, "-c", _DEEP, INERTIAL], capture_output=True, text=True, timeout=120
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout.strip() == "1"


# --- 2. many bushings and joint springs: linear-time lookups, same results ----------------


def test_bushings_are_attached_without_adding_pinocchio_frames():
    """Model.addFrame scans all frames (quadratic in bushings): none are added."""
    import pinocchio as pin

    scene = load_scene("rt70")
    assert scene.description.bushings
    plain = pin.buildModelFromXML(scene.text)
    assert scene.reference.pin_model.nframes == plain.nframes


def test_child_joints_keep_file_order_and_springs_resolve():
    """The one-pass child map and spring lookup give what the linear scans gave."""
    from rt70.textbook.model import _child_joints

    desc = load_scene(ALL_JOINTS).description
    children = _child_joints(desc)
    for link in desc.links:
        assert children.get(link, []) == desc.child_joints(link)
    for spring in desc.joint_springs:
        assert desc.joint(spring.joint).name == spring.joint


# --- 3. options checked before any work ---------------------------------------------------


@pytest.fixture
def no_work(monkeypatch):
    """Any scene loaded or simulation started fails the test."""

    def forbidden(*args, **kwargs):
        raise AssertionError("work started before the options were checked")

    monkeypatch.setattr("rt70.model.scene.load_scene", forbidden)
    monkeypatch.setattr("rt70.simulation.simulate.simulate", forbidden)


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (["simulate", "rt70", "--rtol", "0"], "--rtol"),
        (["simulate", "rt70", "--rtol", "-1"], "--rtol"),
        (["simulate", "rt70", "--rtol", "1"], "--rtol"),
        (["simulate", "rt70", "--rtol", "nan"], "--rtol"),
        (["simulate", "rt70", "--t-end", "0"], "--t-end"),
        (["simulate", "rt70", "--t-end", "inf"], "--t-end"),
        (["simulate", "rt70", "--method", "Euler"], "--method"),
        (["simulate", "rt70", "--side", "mujoco"], "--side"),
        (["modes", "rt70", "--elevation", "200"], "--elevation"),
        (["modes", "rt70", "--elevation", "-91"], "--elevation"),
        (["modes", "rt70", "--azimuth", "nan"], "--azimuth"),
        (["validate", "rt70", "--samples", "0"], "--samples"),
        (["validate", "rt70", "--samples", "two"], "--samples"),
        (["validate", "rt70", "--seed", "-1"], "--seed"),
        (["validate", "rt70", "--tolerance", "-1e-10"], "--tolerance"),
        (["validate", "rt70", "--tolerance", "inf"], "--tolerance"),
        (["bench", "--K", "0"], "--K"),
        (["bench", "--K", "100000000"], "--K"),
    ],
)
def test_bad_option_exits_2_before_any_work(argv, expected, no_work, capsys):
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    assert f"argument {expected}" in one_error_line(capsys.readouterr().err)


def test_good_edge_options_are_accepted():
    from rt70.cli.main import build_parser

    args = build_parser().parse_args(["modes", "rt70", "--elevation", "0", "--azimuth", "-360"])
    assert (args.elevation, args.azimuth) == (0.0, -360.0)
    args = build_parser().parse_args(["validate", "--tolerance", "0", "--seed", "0"])
    assert args.tolerance == 0.0


def _read_only_directory(tmp_path: Path) -> Path:
    """A directory no file can be created in (root ignores permissions: use /proc)."""
    if os.geteuid() == 0:
        return Path("/proc")
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o555)
    return ro


def test_bad_outputs_fail_before_the_simulation(tmp_path, no_work, capsys):
    (tmp_path / "dir.csv").mkdir()
    (tmp_path / "plot.png").mkdir()
    (tmp_path / "file").write_text("x")
    cases = {
        str(tmp_path / "run.txt"): "must end in .csv or .npz",
        str(tmp_path / "dir.csv"): "is a directory",
        str(tmp_path / "plot.csv"): "plot.png: is a directory",
        str(_read_only_directory(tmp_path) / "run.csv"): "cannot create files",
        str(tmp_path / "file" / "run.csv"): "is not a directory",
        "": "empty path",
    }
    for out, message in cases.items():
        assert main(["simulate", "double_pendulum", "--out", out]) == 2, out
        assert message in one_error_line(capsys.readouterr().err), out
    assert main(["bench", "--out", str(tmp_path / "file")]) == 2
    assert "is not a directory" in one_error_line(capsys.readouterr().err)


def test_bad_option_subprocess_one_line_no_traceback():
    for args in (["simulate", "rt70", "--rtol", "0"], ["modes", "rt70", "--elevation", "200"]):
        proc = run(*args)
        assert proc.returncode == 2
        one_error_line(proc.stderr)
        assert proc.stdout == ""


# --- 4. atomic output sets ------------------------------------------------------------------

_SIGTERM_WHILE_WRITING = r"""
import sys, time
from pathlib import Path
from matplotlib.figure import Figure

def slow_savefig(self, fname, *args, **kwargs):  # a plot that takes forever to write
    Path(fname).write_bytes(b"x" * 2_000_000)  # a 2 MB partial file
    print("WRITING", flush=True)
    for _ in range(1200):  # short sleeps: the kernel may hand SIGTERM to another thread
        time.sleep(0.1)  # (BLAS's), and Python runs the handler at the main thread's next step

Figure.savefig = slow_savefig
from rt70.cli.main import main
sys.exit(main(["simulate", "double_pendulum", "--t-end", "0.05", "--out", sys.argv[1]]))
"""


@pytest.mark.slow
def test_sigterm_while_writing_leaves_the_old_files_and_no_temporaries(tmp_path):
    out = tmp_path / "run.csv"
    out.write_text("old csv")
    (tmp_path / "run.png").write_text("old png")
    proc = subprocess.Popen(
        [sys.executable, "-c", _SIGTERM_WHILE_WRITING, str(out)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env={**os.environ, "MPLBACKEND": "Agg"},
    )
    watchdog = threading.Timer(300, proc.kill)  # only if the child hangs before writing
    watchdog.start()
    try:
        for line in proc.stdout:  # wait, however loaded the machine, until the write is on
            if line.strip() == "WRITING":
                break
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=120)
    finally:
        watchdog.cancel()
        proc.kill()
    assert proc.returncode == EXIT_TERMINATED, err
    assert "Traceback" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.csv", "run.png"]  # no .tmp
    assert out.read_text() == "old csv" and (tmp_path / "run.png").read_text() == "old png"


def test_failure_between_files_keeps_the_old_set(tmp_path):
    a, b = tmp_path / "a.csv", tmp_path / "a.png"
    a.write_text("old a")
    b.write_text("old b")

    def fail(tmp):
        raise RuntimeError("plot failed")

    with pytest.raises(RuntimeError, match="plot failed"):
        atomic_write_all({a: lambda tmp: tmp.write_text("new a"), b: fail})
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.csv", "a.png"]
    assert a.read_text() == "old a" and b.read_text() == "old b"
    assert atomic_write_all({a: lambda t: t.write_text("A"), b: lambda t: t.write_text("B")})
    assert a.read_text() == "A" and b.read_text() == "B"


_SIGTERM_BETWEEN_RENAMES = r"""
import os, signal, sys
from pathlib import Path
from rt70.guards.atomic import atomic_write_all
from rt70.cli.session import stop_signals

real_replace = os.replace
def replace_then_sigterm(src, dst):  # SIGTERM right after the first rename
    real_replace(src, dst)
    os.kill(os.getpid(), signal.SIGTERM)
os.replace = replace_then_sigterm
d = Path(sys.argv[1])
with stop_signals(143):
    atomic_write_all({d / "a.csv": lambda t: t.write_text("new"),
                      d / "a.png": lambda t: t.write_text("new")})
    print("not reached: SIGTERM is delivered once the renames are done")
"""


def test_sigterm_during_the_renames_is_deferred_until_both_are_done(tmp_path):
    for name in ("a.csv", "a.png"):
        (tmp_path / name).write_text("old")
    proc = subprocess.run(
        [sys.executable, "-c", _SIGTERM_BETWEEN_RENAMES, str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert proc.returncode == 143, proc.stderr
    assert proc.stdout == ""
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.csv", "a.png"]
    assert {(tmp_path / n).read_text() for n in ("a.csv", "a.png")} == {"new"}


def test_simulate_writes_the_set(tmp_path, capsys):
    out = tmp_path / "run.npz"
    assert main(["simulate", "double_pendulum", "--t-end", "0.05", "--out", str(out)]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.npz", "run.png", "run.units.json"]
    assert f"wrote {out}" in capsys.readouterr().out


# --- 5. a closed standard output --------------------------------------------------------------


@pytest.mark.slow
@pytest.mark.parametrize(
    "args", [["modes", "rt70_elevation"], ["validate", "--json", "--samples", "1", "rt70"]]
)
def test_closed_stdout_is_no_traceback(args):
    proc = subprocess.Popen(
        [sys.executable, "-m", "rt70", *args],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env={**os.environ, "MPLBACKEND": "Agg"},
    )
    proc.stdout.close()  # the reader is gone before rt70 prints anything (``| head -0``)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == EXIT_BROKEN_PIPE, err
    assert err == b""


# --- 6. models simulate and modes refuse cleanly -----------------------------------------------


def _bushing(stiffness: str, rpy: str = "0 0 0") -> str:
    return (
        f'<rt70:bushing name="b" stiffness="{stiffness}" damping="0 0 0 0 0 0">'
        f'<rt70:frame1 link="world" rpy="{rpy}"/><rt70:frame2 link="l2"/></rt70:bushing>'
    )


HOSTILE = {
    "no_dof": (chain_urdf(["fixed"]), "no degree of freedom"),
    "massless_leaf": (chain_urdf(["revolute"], massless=(1,)), "coordinate(s) j1 move no mass"),
    "massless_tip": (
        chain_urdf(["revolute", "revolute"], massless=(2,)),
        "coordinate(s) j2 move no mass",
    ),
    "huge_stiffness": (
        chain_urdf(["revolute", "revolute"]).replace(
            "</robot>", _bushing("1e308 " * 6) + "</robot>"
        ),
        "",
    ),
    "gimbal_lock_bushing": (
        chain_urdf(["revolute", "revolute"]).replace(
            "</robot>", _bushing("1 1 1 1 1 1", "0 1.5707963267948966 0") + "</robot>"
        ),
        "gimbal lock",
    ),
}


@pytest.mark.parametrize("name", HOSTILE)
@pytest.mark.parametrize("command", ["simulate reference", "simulate textbook", "modes"])
def test_hostile_model_is_one_error_line(name, command, tmp_path, capsys):
    text, message = HOSTILE[name]
    path = tmp_path / f"{name}.urdf"
    path.write_text(text, encoding="utf-8")
    cmd, *side = command.split()
    argv = [cmd, str(path)] + (["--side", side[0], "--t-end", "0.1"] if side else [])
    assert main(argv) == 2
    line = one_error_line(capsys.readouterr().err)
    assert name in line and message in line


def test_simulate_rejects_bad_python_input():
    scene = load_scene("double_pendulum")
    with pytest.raises(
        ShapeError, match=r"initial state q0: expected shape \(2,\), got shape \(3,\)"
    ):
        simulate(scene, (0, 0.1), (np.zeros(3), np.zeros(2)))
    with pytest.raises(NonFiniteError, match="initial state qd0"):
        simulate(scene, (0, 0.1), (np.zeros(2), np.array([0.0, np.inf])))
    with pytest.raises(ShapeError, match=r"inputs\(t, q, qd\): expected shape \(2,\)"):
        simulate(scene, (0, 0.1), inputs=lambda t, q, qd: np.zeros(3))
    with pytest.raises(Rt70Error, match="t_eval"):
        simulate(scene, (0, 0.1), t_eval=np.array([0.0, 0.2]))
    with pytest.raises(Rt70Error, match="rtol"):
        simulate(scene, (0, 0.1), rtol=0.0)


def test_simulation_that_blows_up_stops_with_a_clean_error():
    """A NaN input force mid-run: the integration stops with the time, not a traceback."""
    scene = load_scene("double_pendulum")

    def inputs(t, q, qd):
        return np.full(2, np.nan if t > 0.01 else 0.0)

    with pytest.raises(SimulationError, match=r"integration stopped at t = 0\.01"):
        simulate(scene, (0, 0.1), inputs=inputs)


def test_output_suffix_is_checked_from_python():
    scene = load_scene("double_pendulum")
    result = simulate(scene, (0, 0.01))
    with pytest.raises(OutputError, match="must end in .csv or .npz"):
        result.save("/tmp/x.txt")


# --- 7. shapes and non-finite states from Python, both sides -----------------------------------


@pytest.fixture(scope="module")
def scene():
    return load_scene(ALL_JOINTS)


def _textbook_calls(scene):
    m, d = scene.textbook, scene.textbook_data
    return {
        "dynamics.mass_matrix": lambda q, qd: dynamics.mass_matrix(m, d, q),
        "dynamics.bias_force": lambda q, qd: dynamics.bias_force(m, d, q, qd),
        "dynamics.gravity_force": lambda q, qd: dynamics.gravity_force(m, d, q),
        "dynamics.forward_dynamics": lambda q, qd: dynamics.forward_dynamics(
            m, d, q, qd, np.zeros(m.nv)
        ),
        "forces.spring_damper_force": lambda q, qd: forces.spring_damper_force(m, d, q, qd),
        "dynamics.kinetic_energy": lambda q, qd: dynamics.kinetic_energy(m, d, q, qd),
        "forces.spring_potential": lambda q, qd: forces.spring_potential(m, d, q),
        "structured.mass_matrix": lambda q, qd: structured.mass_matrix(
            m, structured.BatchData(m), q
        ),
        "structured.bias_force": lambda q, qd: structured.bias_force(
            m, structured.BatchData(m), q, qd
        ),
    }


def _reference_calls(scene):
    m, d = scene.reference, scene.reference_data
    return {
        "reference.mass_matrix": lambda q, qd: reference.mass_matrix(m, d, q),
        "reference.bias_force": lambda q, qd: reference.bias_force(m, d, q, qd),
        "reference.gravity_force": lambda q, qd: reference.gravity_force(m, d, q),
        "reference.forward_dynamics": lambda q, qd: reference.forward_dynamics(m, d, q, qd),
        "reference.spring_damper_force": lambda q, qd: reference.spring_damper_force(m, d, q, qd),
        "reference.kinetic_energy": lambda q, qd: reference.kinetic_energy(m, d, q, qd),
        "reference.spring_potential": lambda q, qd: reference.spring_potential(m, d, q),
    }


def test_every_public_function_names_a_wrong_shape(scene):
    n = scene.textbook.nv
    calls = {**_textbook_calls(scene), **_reference_calls(scene)}
    for name, call in calls.items():
        call(np.zeros(n), np.zeros(n))  # the right shape works
        for bad in (np.zeros(n + 1), np.zeros((n, 1)), np.zeros(0)):
            with pytest.raises(ShapeError, match=rf"q: expected shape \({n},\), got shape"):
                call(bad, np.zeros(n))
        if "qd" in name or name.endswith(("bias_force", "forward_dynamics", "damper_force")):
            with pytest.raises(ValueError, match=rf"^qd: expected shape \({n},\)"):  # compat
                call(np.zeros(n), np.zeros(n - 1))
    with pytest.raises(ShapeError, match=r"Q: expected shape \(K, \d+\), got shape \(3,\)"):
        structured.mass_matrix_batch(
            scene.textbook, structured.BatchData(scene.textbook), np.zeros(3)
        )


@pytest.mark.parametrize("side", ["textbook", "reference"])
@pytest.mark.parametrize("value", [np.nan, np.inf, -np.inf], ids=["nan", "inf", "-inf"])
def test_non_finite_state_is_the_same_error_on_both_sides(scene, side, value):
    n = scene.textbook.nv
    calls = _textbook_calls(scene) if side == "textbook" else _reference_calls(scene)
    bad = np.zeros(n)
    bad[-1] = value
    for call in calls.values():
        with pytest.raises(NonFiniteError, match="^q contains NaN or infinite"):
            call(bad, np.zeros(n))
    with pytest.raises(NonFiniteError, match="^qp contains"):
        reference.deformations(
            scene.reference, scene.reference_data, np.full(scene.reference.pin_model.nq, value)
        )
