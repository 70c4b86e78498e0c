"""Cost of reading and building a scene against its number of bushings or joints.

Two families, each at a few sizes (doubling), timed phase by phase in this process:

- ``bushings``: the double pendulum with N ``<rt70:bushing>`` elements between its two
  links; phases: read the URDF, build the textbook model, build the Pinocchio reference,
  one evaluation of every cross-checked quantity on both sides (``cross_check`` with
  one sample and no repeats);
- ``joints``: a star of N revolute joints on the root link, each with a
  ``<rt70:joint_spring>``; phases: read, build the textbook model.

Every phase should grow linearly: the last column is the time per element, which
should stay roughly constant as N doubles.

    python validation/bushing_scaling.py [--sizes 1000 2000 4000 ...]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

INERTIAL = (
    '<inertial><mass value="1"/>'
    '<inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial>'
)


def bushing_scene(n: int) -> str:
    """The double pendulum with n bushings between link1 and link2."""
    base = (ROOT / "urdf" / "double_pendulum.urdf").read_text(encoding="utf-8")
    bushings = "".join(
        f'<rt70:bushing name="b{i}" stiffness="1 1 1 1 1 1" damping="0.1 0.1 0.1 0.1 0.1 0.1">'
        f'<rt70:frame1 link="link1" xyz="0.{i % 10} 0 0"/><rt70:frame2 link="link2"/>'
        "</rt70:bushing>\n"
        for i in range(n)
    )
    return base.replace("</robot>", bushings + "</robot>")


def star_scene(n: int) -> str:
    """n revolute joints on the root link, each with a joint spring."""
    parts = ['<robot name="star" xmlns:rt70="urn:rt70:urdf-extensions:1">', '<link name="l0"/>']
    for i in range(1, n + 1):
        parts.append(f'<link name="l{i}">{INERTIAL}</link>')
        parts.append(
            f'<joint name="j{i}" type="revolute"><parent link="l0"/><child link="l{i}"/>'
            '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
        )
        parts.append(f'<rt70:joint_spring name="s{i}" joint="j{i}" stiffness="1"/>')
    parts.append("</robot>")
    return "\n".join(parts)


def timed(fn, *args):
    start = time.perf_counter()
    out = fn(*args)
    return out, time.perf_counter() - start


def build_textbook(scene):
    return scene.textbook_data


def build_reference(scene):
    return scene.reference_data  # the ReferenceModel and its Data


def evaluate(scene):
    from rt70.crosscheck.validate import cross_check

    return cross_check(scene, samples=1, seed=0, repeat=0)


def main() -> int:
    from rt70.model.scene import scene_from_text
    from rt70.textbook.model import build_model
    from rt70.urdf import read_urdf_string

    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[2000, 4000, 8000, 16000])
    args = parser.parse_args()

    print(f"{'bushings':>9} {'read s':>8} {'build s':>8} {'reference s':>12} {'evaluate s':>11}")
    for n in args.sizes:
        scene, t_read = timed(scene_from_text, bushing_scene(n), f"bushings_{n}")
        _, t_build = timed(build_textbook, scene)
        _, t_ref = timed(build_reference, scene)
        _, t_eval = timed(evaluate, scene)
        total = t_read + t_build + t_ref + t_eval
        print(
            f"{n:>9} {t_read:>8.3f} {t_build:>8.3f} {t_ref:>12.3f} {t_eval:>11.3f}"
            f"   {total / n * 1e6:.0f} µs per bushing",
            flush=True,
        )
    print(f"\n{'joints':>9} {'read s':>8} {'build s':>8}")
    for n in args.sizes:
        text = star_scene(n)
        desc, t_read = timed(read_urdf_string, text, "star")
        _, t_build = timed(build_model, desc)
        per_joint = (t_read + t_build) / n * 1e6
        print(f"{n:>9} {t_read:>8.3f} {t_build:>8.3f}   {per_joint:.0f} µs per joint", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
