"""The robots of example-robot-data as cross-check targets.

example-robot-data v6 ships its URDF files (and no Python module) under
``<prefix>/cmeel.prefix/share/example-robot-data/robots`` of the environment it is
installed in. This module finds that directory without importing any Pinocchio-specific
loader, names every URDF file in it (:data:`ROBOTS`, with the names of
example-robot-data's own loaders where there is one), loads a robot as a
:class:`~rt70.model.scene.Scene` and surveys which robots both sides can load
(``docs/robots.md``).
"""

from __future__ import annotations

import importlib.metadata
import re
import site
import sysconfig
from pathlib import Path

import numpy as np

from rt70.errors import Rt70Error, SceneError
from rt70.model.scene import Scene, load_scene, require_coordinates
from rt70.textbook import dynamics
from rt70.textbook.massless import require_diagonal

#: Distribution that ships the robots.
DISTRIBUTION = "example-robot-data"

#: The error when no installation prefix has the robots: they are rt70's ``robots`` extra.
NOT_INSTALLED = "the robots of example-robot-data are not installed: pip install 'rt70[robots]'"

#: Location of the robots inside an installation prefix (cmeel layout of the wheel).
ROBOTS_SUBDIR = Path("cmeel.prefix", "share", "example-robot-data", "robots")

#: Robot name → URDF path relative to :func:`robots_dir`, one entry per URDF file of
#: example-robot-data 6.0.0. Names are those of example-robot-data's loaders
#: (``robots_loader.py``) where a loader reads the file; the last five are derived.
ROBOTS: dict[str, str] = {
    "a1": "a1_description/urdf/a1.urdf",
    "alex_nub_hands": "alex_description/urdf/alex_nub_hands.urdf",
    "alex_psyonic_hands": "alex_description/urdf/alex_psyonic_hands.urdf",
    "alex_sake_hands": "alex_description/urdf/alex_sake_hands.urdf",
    "alexander": "alexander_description/urdf/alexander_v1.lowerBodyOnly.urdf",
    "allegro_left_hand": "allegro_hand_description/urdf/allegro_left_hand.urdf",
    "allegro_right_hand": "allegro_hand_description/urdf/allegro_right_hand.urdf",
    "anymal": "anymal_b_simple_description/robots/anymal.urdf",
    "anymal_kinova": "anymal_b_simple_description/robots/anymal-kinova.urdf",
    "anymal_c": "anymal_c_simple_description/urdf/anymal.urdf",
    "asr_twodof": "asr_twodof_description/urdf/TwoDofs.urdf",
    "b1": "b1_description/urdf/b1.urdf",
    "b1_z1": "b1_description/urdf/b1-z1.urdf",
    "baxter": "baxter_description/urdf/baxter.urdf",
    "bolt": "bolt_description/robots/bolt.urdf",
    "borinot": "borinot_description/urdf/borinot_flying_arm_2.urdf",
    "centauro": "centauro_description/urdf/centauro.urdf",
    "double_pendulum": "double_pendulum_description/urdf/double_pendulum.urdf",
    "double_pendulum_continuous": (
        "double_pendulum_description/urdf/double_pendulum_continuous.urdf"
    ),
    "double_pendulum_simple": "double_pendulum_description/urdf/double_pendulum_simple.urdf",
    "finger_edu": "finger_edu_description/robots/finger_edu.urdf",
    "g1": "g1_description/urdf/g1_29dof_rev_1_0.urdf",
    "g1_with_hands": "g1_description/urdf/g1_29dof_with_hand_rev_1_0.urdf",
    "go1": "go1_description/urdf/go1.urdf",
    "go2": "go2_description/urdf/go2.urdf",
    "hector": "hector_description/robots/quadrotor_base.urdf",
    "hextilt": "hextilt_description/urdf/hextilt_flying_arm_5.urdf",
    "human": "human_description/robots/human.urdf",
    "hyq": "hyq_description/robots/hyq_no_sensors.urdf",
    "icub": "icub_description/robots/icub.urdf",
    "icub_reduced": "icub_description/robots/icub_reduced.urdf",
    "iris": "iris_description/robots/iris_simple.urdf",
    "kinova": "kinova_description/robots/kinova.urdf",
    "laikago": "laikago_description/urdf/laikago.urdf",
    "panda": "panda_description/urdf/panda.urdf",
    "panda_collision": "panda_description/urdf/panda_collision.urdf",
    "pr2": "pr2_description/urdf/pr2.urdf",
    "quadruped": "quadruped_description/urdf/quadruped.urdf",
    "romeo": "romeo_description/urdf/romeo.urdf",
    "simple_humanoid": "simple_humanoid_description/urdf/simple_humanoid.urdf",
    "simple_humanoid_classical": "simple_humanoid_description/urdf/simple_humanoid_classical.urdf",
    "so100": "so_arm_description/urdf/so100.urdf",
    "so101": "so_arm_description/urdf/so101.urdf",
    "solo8": "solo_description/robots/solo.urdf",
    "solo12": "solo_description/robots/solo12.urdf",
    "talos": "talos_data/robots/talos_reduced.urdf",
    "talos_box": "talos_data/robots/talos_reduced_box.urdf",
    "talos_arm": "talos_data/robots/talos_left_arm.urdf",
    "talos_full": "talos_data/robots/talos_full_v2.urdf",
    "talos_full_box": "talos_data/robots/talos_full_v2_box.urdf",
    "tiago": "tiago_description/robots/tiago.urdf",
    "tiago_dual": "tiago_description/robots/tiago_dual.urdf",
    "tiago_no_hand": "tiago_description/robots/tiago_no_hand.urdf",
    "tiago_pro": "tiago_pro_description/robots/tiago_pro.urdf",
    "ur3": "ur_description/urdf/ur3_robot.urdf",
    "ur3_gripper": "ur_description/urdf/ur3_gripper.urdf",
    "ur3_limited": "ur_description/urdf/ur3_joint_limited_robot.urdf",
    "ur5": "ur_description/urdf/ur5_robot.urdf",
    "ur5_gripper": "ur_description/urdf/ur5_gripper.urdf",
    "ur5_limited": "ur_description/urdf/ur5_joint_limited_robot.urdf",
    "ur10": "ur_description/urdf/ur10_robot.urdf",
    "ur10_limited": "ur_description/urdf/ur10_joint_limited_robot.urdf",
    "xarm7": "xarm_description/urdf/xarm7.urdf",
    "z1": "z1_description/urdf/z1.urdf",
    # no loader reads these files: derived names
    "iris_rotors": "iris_description/robots/iris.urdf",
    "romeo_small": "romeo_description/urdf/romeo_small.urdf",
    "romeo_laas_small": "romeo_description/urdf/romeo_laas_small.urdf",
    "talos_reduced_corrected": "talos_data/robots/talos_reduced_corrected.urdf",
    "ur3_empty": "ur_description/urdf/ur3.urdf",
}

#: Prefix of a survey reason for an exception that is not an :class:`Rt70Error` (a bug).
UNEXPECTED = "unexpected "


def _candidates() -> list[Path]:
    """Possible installation prefixes of example-robot-data, most specific first."""
    out = []
    try:
        out.append(Path(str(importlib.metadata.distribution(DISTRIBUTION).locate_file(""))))
    except importlib.metadata.PackageNotFoundError:
        pass
    paths = sysconfig.get_paths()
    out += [Path(paths[key]) for key in ("purelib", "platlib") if key in paths]
    out += [Path(p) for p in site.getsitepackages()]
    user = site.getusersitepackages()
    if user:
        out.append(Path(user))
    return out


def robots_dir() -> Path:
    """The ``robots`` directory of the installed example-robot-data.

    Raises
    ------
    Rt70Error
        If example-robot-data (v6, the cmeel wheel; rt70's ``robots`` extra) is not
        installed: :data:`NOT_INSTALLED`.
    """
    for prefix in _candidates():
        candidate = prefix / ROBOTS_SUBDIR
        if candidate.is_dir():
            return candidate
    raise Rt70Error(NOT_INSTALLED)


def robot_path(name: str) -> Path:
    """The URDF file of robot ``name``.

    Raises
    ------
    SceneError
        If ``name`` is not a key of :data:`ROBOTS`.
    """
    if name not in ROBOTS:
        raise SceneError(f"{name}: no such robot (known: {', '.join(sorted(ROBOTS))})")
    return robots_dir() / ROBOTS[name]


def load_robot(name: str, balance_inertia: bool = False) -> Scene:
    """Read robot ``name`` as a :class:`~rt70.model.scene.Scene` named after the robot.

    Only the URDF is read and validated here; the two sides are built on first use
    (:attr:`Scene.textbook`, :attr:`Scene.reference`). ``balance_inertia`` is passed to
    :func:`~rt70.model.scene.load_scene`.
    """
    scene = load_scene(robot_path(name), balance_inertia=balance_inertia)
    return Scene(name, scene.path, scene.text, scene.description)


class CoordinateMismatch(Exception):
    """The two sides disagree on the robot's coordinates: a bug in rt70, not bad input.

    Deliberately not an :class:`Rt70Error`: :func:`survey` reports it as unexpected.
    """


def _reason(exc: BaseException, path: Path) -> str:
    """One line: the exception type and message, without the leading file path.

    Pinocchio's C++ messages lose their ``From file: ... at line: N`` preamble.
    """
    msg = " ".join(str(exc).split())
    msg = re.sub(r"^From file: .*? at line: \d+ message: ", "", msg)
    for prefix in (f"{path}: ", f"{path.name}: "):
        msg = msg.removeprefix(prefix)
    return f"{type(exc).__name__}: {msg}"


def _check_coordinates(scene: Scene) -> None:
    """Both sides have the same generalised coordinates (names and number)."""
    tb, ref = scene.textbook.coordinate_names, scene.reference.coordinate_names
    if sorted(tb) != sorted(ref) or scene.textbook.nv != scene.reference.nv:
        only_tb = sorted(set(tb) - set(ref))
        only_ref = sorted(set(ref) - set(tb))
        raise CoordinateMismatch(
            f"textbook nv={scene.textbook.nv}, reference nv={scene.reference.nv}"
            + (f"; textbook only: {', '.join(only_tb)}" if only_tb else "")
            + (f"; reference only: {', '.join(only_ref)}" if only_ref else "")
        )


def _try_both_sides(scene: Scene, rng: np.random.Generator) -> None:
    """Build both sides, check their coordinates, evaluate one mass matrix on each.

    The textbook's forward dynamics is evaluated too: a singular mass matrix (a
    coordinate that moves no mass) makes the robot unusable for the cross-check.
    """
    from rt70 import reference

    model, data, ref = scene.textbook, scene.textbook_data, scene.reference
    require_coordinates(scene)
    _check_coordinates(scene)
    q, qd = rng.uniform(-0.5, 0.5, model.nv), rng.uniform(-1.0, 1.0, model.nv)
    A = dynamics.mass_matrix(model, data, q)
    reference.mass_matrix(ref, scene.reference_data, q)
    require_diagonal(A, model.coordinate_names, "")
    dynamics.forward_dynamics(model, data, q, qd, np.zeros(model.nv))


def survey(
    names: list[str] | None = None, seed: int = 0, balance_inertia: bool = False
) -> tuple[list[Scene], dict[str, str]]:
    """Try to load each robot (default: all of :data:`ROBOTS`) on both sides.

    Returns the scenes that load, in the order of ``names``, and ``{name: reason}``
    for the others. A robot fails with the message of the :class:`Rt70Error` raised
    while reading it, building either side, evaluating one mass matrix on each side or
    the textbook's forward dynamics (a singular mass matrix). Any other exception — a
    :class:`CoordinateMismatch` between the sides included — is a bug in rt70,
    recorded with a reason starting with :data:`UNEXPECTED`
    (``"unexpected <Type>: message"``) for the caller to report.

    Parameters
    ----------
    names : list of str, optional
        Keys of :data:`ROBOTS` to try, in this order (default all).
    seed : int
        Seed of the random states each robot is evaluated at.
    balance_inertia : bool
        Repair inertias that are not physical instead of refusing them
        (:func:`load_robot`).

    Raises
    ------
    SceneError
        If a name is not a key of :data:`ROBOTS` (bad input, not a robot that fails).
    """
    names = list(ROBOTS) if names is None else list(names)
    paths = {name: robot_path(name) for name in names}  # unknown names: SceneError
    rng = np.random.default_rng(seed)
    loaded: list[Scene] = []
    failed: dict[str, str] = {}
    for name in names:
        try:
            scene = load_robot(name, balance_inertia)
            _try_both_sides(scene, rng)
        except Rt70Error as exc:
            failed[name] = _reason(exc, paths[name])
        except Exception as exc:  # reported as a bug, never dropped: see the docstring
            failed[name] = UNEXPECTED + _reason(exc, paths[name])
        else:
            loaded.append(scene)
    return loaded, failed
