"""Build the rt70 scene URDF files from the book's data.

Every scene is a function returning the URDF text (the RT-70 listing's in
:mod:`rt70.scenes.rt70_scenes`, the chapter-2 models and mechanisms in
:mod:`rt70.scenes.book_scenes`, the closed chains in :mod:`rt70.scenes.loop_scenes`, the
two other antennas in :mod:`rt70.scenes.antenna_presets`, the flexible members in
:mod:`rt70.scenes.modal_scenes`);
:data:`SCENES` maps scene names to them and :func:`write_all` writes ``<name>.urdf``
files. The output is deterministic (:mod:`rt70.scenes.urdf_writer`: fixed element and
attribute order, two-space indentation, numbers written as the shortest text that reads
back as the same float, and a final newline). The extension elements follow
``docs/urdf-extensions.md``.

Run ``python -m rt70.scenes.generate [DIR]`` to regenerate the files (default: the
repository's ``urdf/`` directory).
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable, Sequence
from functools import partial
from pathlib import Path

from rt70.guards.atomic import atomic_write_text
from rt70.scenes.antenna import antenna_urdf
from rt70.scenes.antenna_dish import DISH_FILE, antenna_12m_dish_body, antenna_12m_dish_scene
from rt70.scenes.antenna_presets import PRESETS
from rt70.scenes.book_scenes import (
    double_pendulum_scene,
    gear_reducer_scene,
    rt70_azimuth_el90_scene,
    rt70_azimuth_scene,
    rt70_elevation_scene,
    three_masses_scene,
    two_body_gravity_scene,
)
from rt70.scenes.loop_scenes import crank_slider_scene, four_bar_scene
from rt70.scenes.modal_scenes import TRUSS_FILE, slewing_truss_scene, truss_arm
from rt70.scenes.rt70_mirror import RT70_DISH_FILE, rt70_mirror_body, rt70_mirror_scene
from rt70.scenes.rt70_scenes import (
    rt70_flexible_scene,
    rt70_jack_scene,
    rt70_scene,
    rt70_servo_scene,
)
from rt70.urdf.modal_file import ModalArrays, write_modal_file

#: Default output directory: ``urdf/`` at the repository root.
DEFAULT_DIRECTORY = Path(__file__).resolve().parents[2] / "urdf"


#: Scene name → function returning the scene's URDF text.
SCENES: dict[str, Callable[[], str]] = {
    "rt70": rt70_scene,
    "rt70_servo": rt70_servo_scene,
    "rt70_jack": rt70_jack_scene,
    "rt70_flexible": rt70_flexible_scene,
    "rt70_elevation": rt70_elevation_scene,
    "rt70_azimuth": rt70_azimuth_scene,
    "rt70_azimuth_el90": rt70_azimuth_el90_scene,
    "double_pendulum": double_pendulum_scene,
    "three_masses": three_masses_scene,
    "two_body_gravity": two_body_gravity_scene,
    "gear_reducer": gear_reducer_scene,
    "four_bar": four_bar_scene,
    "crank_slider": crank_slider_scene,
    **{name: partial(antenna_urdf, spec) for name, spec in PRESETS.items()},
    "slewing_truss": slewing_truss_scene,
    "rt70_mirror": rt70_mirror_scene,
    "antenna_12m_dish": antenna_12m_dish_scene,
}

#: The modal body files the scenes name (``rt70-modal/1``), by file name.
MODAL_FILES: dict[str, Callable[[], ModalArrays]] = {
    TRUSS_FILE: truss_arm,
    RT70_DISH_FILE: rt70_mirror_body,
    DISH_FILE: antenna_12m_dish_body,
}


def write_all(directory: Path) -> list[Path]:
    """Write every scene as ``<name>.urdf`` into ``directory``, and the modal body files.

    Each file is written to a temporary file in the same directory and moved into place
    with :func:`os.replace`, so a reader never sees a partial file.

    Parameters
    ----------
    directory : Path
        Output directory; created if missing.

    Returns
    -------
    list of Path
        The written files, in the order of :data:`SCENES`, then :data:`MODAL_FILES`.
    """
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    written = []
    for name, build in SCENES.items():
        path = directory / f"{name}.urdf"
        atomic_write_text(path, build())
        written.append(path)
    for name, body in MODAL_FILES.items():
        written.append(write_modal_file(directory / name, body()))
    return written


def main(argv: Sequence[str] | None = None) -> int:
    """Regenerate the scene files (command-line entry point).

    Parameters
    ----------
    argv : sequence of str, optional
        Arguments; default ``sys.argv[1:]``. One optional positional argument: the
        output directory (default :data:`DEFAULT_DIRECTORY`).

    Returns
    -------
    int
        Exit status 0.
    """
    parser = argparse.ArgumentParser(
        prog="python -m rt70.scenes.generate",
        description="Regenerate the rt70 scene URDF files from the book's data.",
    )
    parser.add_argument(
        "directory",
        nargs="?",
        type=Path,
        default=DEFAULT_DIRECTORY,
        help=f"output directory (default: {DEFAULT_DIRECTORY})",
    )
    args = parser.parse_args(argv)
    for path in write_all(args.directory):
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
