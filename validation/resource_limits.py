"""Measure the limits behind rt70.guards.resources: memory of both sides, Pinocchio's parser depth.

Every measurement runs in a fresh subprocess (a model that is too large, or a parser
that segfaults, cannot take this script down):

- memory: growth of the anonymous resident set at its peak (``VmHWM`` less the
  file-backed pages) while building a ReferenceModel and its ReferenceData, of one
  call of every dense textbook function on a fresh Data, and of the textbook's mass
  check (``rt70.textbook.massless``), for serial chains of
  revolute, planar and floating joints; printed beside the estimates of
  ``rt70.guards.resources`` with a least-squares fit ``a nv³ + b nv² + c`` of the reference side;
- parser depth: the deepest chain of fixed joints Pinocchio's URDF parser survives, by
  bisection, on the main thread (the process's stack limit, ``ulimit -s``); and that a
  chain ``rt70.guards.resources.PARSER_MAX_DEPTH`` deep parses in a thread with
  ``rt70.guards.resources.PARSER_STACK_BYTES`` (one run: the parser's time grows with the
  square of the frames, about 4.5 minutes for 40 000 levels).

    python validation/resource_limits.py [--quick]

Takes a few minutes and up to about 4.5 GB of memory (``--quick``: seconds, 0.5 GB).
"""

from __future__ import annotations

import argparse
import json
import resource
import subprocess
import sys

import numpy as np

_MEMORY_CHILD = r"""
import json, sys
import numpy as np
from rt70.model.scene import scene_from_text
from rt70.scenes.synthetic import serial_chain

def status():  # resident memory: peak (VmHWM), anonymous, file-backed (libraries), shared
    with open("/proc/self/status") as f:
        keys = ("VmHWM", "Rss")
        return {l.split(":")[0]: int(l.split()[1]) * 1024 for l in f if l.startswith(keys)}

side, n, joint = sys.argv[1], int(sys.argv[2]), sys.argv[3]
scene = scene_from_text(serial_chain(n, joint_types=(joint,)), "chain")
desc = scene.description
if side == "reference":
    from rt70.reference import ReferenceData, ReferenceModel
    base = status()
    ref = ReferenceModel(desc, scene.text)
    ReferenceData(ref)
    nv, nb = ref.pin_model.nv, ref.pin_model.njoints
elif side == "massless":
    from rt70.textbook.massless import check_moves_mass
    from rt70.textbook.model import build_model
    m = build_model(desc)
    base = status()
    check_moves_mass(m, "chain")
    nv, nb = m.n_full, m.nb
else:
    from rt70.textbook import dynamics, forces
    from rt70.textbook.data import Data
    m = scene.textbook
    base = status()
    d = Data(m)
    q, qd = np.zeros(m.nv), np.full(m.nv, 0.1)
    dynamics.mass_matrix(m, d, q)
    dynamics.bias_force(m, d, q, qd)
    dynamics.gravity_force(m, d, q)
    Qc, Qd = forces.spring_damper_force(m, d, q, qd)
    dynamics.forward_dynamics(m, d, q, qd, Qc + Qd)
    dynamics.kinetic_energy(m, d, q, qd)
    dynamics.gravity_potential(m, d, q)
    forces.spring_potential(m, d, q)
    nv, nb = m.n_full, m.nb
end = status()
# growth of anonymous memory at the peak (library pages read back in do not count);
# VmHWM, not ru_maxrss, which keeps the parent's peak across fork and exec
growth = end["VmHWM"] - end["RssFile"] - end["RssShmem"] - base["RssAnon"]
print(json.dumps({"nv": nv, "nb": nb, "peak": growth}))
"""

_PARSER_CHILD = r"""
import sys
import pinocchio as pin
from rt70.guards.resources import run_with_stack

n, where = int(sys.argv[1]), sys.argv[2]
inertial = ('<inertial><mass value="1"/>'
            '<inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial>')
parts = ['<robot name="deep">', '<link name="l0"/>']
for i in range(1, n):
    parts.append(f'<link name="l{i}">{inertial}</link>')
    parts.append(f'<joint name="j{i}" type="fixed"><parent link="l{i-1}"/>'
                 f'<child link="l{i}"/></joint>')
parts.append("</robot>")
text = "\n".join(parts)
parse = lambda: pin.buildModelFromXML(text)
model = parse() if where == "main" else run_with_stack(parse)
print(model.nframes)
"""


def measure(side: str, n: int, joint: str) -> dict:
    out = subprocess.run(
        [sys.executable, "-c", _MEMORY_CHILD, side, str(n), joint],
        capture_output=True,
        text=True,
        check=True,
    )
    return json.loads(out.stdout)


def parses(depth: int, where: str) -> bool:
    proc = subprocess.run(
        [sys.executable, "-c", _PARSER_CHILD, str(depth), where], capture_output=True, text=True
    )
    return proc.returncode == 0


def parser_limit(where: str, lo: int, hi: int) -> tuple[int, int]:
    """Deepest chain that parses and shallowest that crashes (within 1 %)."""
    assert parses(lo, where) and not parses(hi, where), (lo, hi)
    while hi - lo > max(10, lo // 100):
        mid = (lo + hi) // 2
        lo, hi = (mid, hi) if parses(mid, where) else (lo, mid)
    return lo, hi


def main() -> int:
    from rt70.guards import resources

    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="small sizes only")
    args = parser.parse_args()

    ref_cases = [("revolute", n) for n in (25, 50, 100, 150)]
    ref_cases += [("planar", 30), ("floating", 10), ("floating", 20)]
    tb_cases = [("revolute", n) for n in (100, 200, 400)] + [("floating", 50)]
    if not args.quick:
        ref_cases += [("revolute", n) for n in (200, 250, 300, 350)]
        ref_cases += [("planar", 60), ("floating", 40), ("floating", 50)]
        tb_cases += [("revolute", 600), ("revolute", 800), ("floating", 100)]

    print("reference side (ReferenceModel and ReferenceData: Pinocchio model, two Data)")
    print(f"{'joint':>9} {'nv':>5} {'peak MB':>10} {'estimate MB':>12} {'est/peak':>9}")
    rows = []
    for joint, n in ref_cases:
        r = measure("reference", n, joint)
        est = resources.reference_peak_bytes(r["nv"], r["nb"])
        rows.append((r["nv"], r["peak"]))
        print(
            f"{joint:>9} {r['nv']:>5} {r['peak'] / 1e6:>10.1f} {est / 1e6:>12.1f} "
            f"{est / r['peak']:>9.3f}",
            flush=True,
        )
    nv, peak = np.array(rows, dtype=float).T
    big = nv >= 100  # below, allocator granularity dominates
    if big.sum() > 4:  # a fit of three coefficients needs more points than --quick has
        coef, *_ = np.linalg.lstsq(
            np.column_stack([nv[big] ** 3, nv[big] ** 2, np.ones(big.sum())]),
            peak[big],
            rcond=None,
        )
        print(
            f"least-squares fit (nv >= 100): peak = {coef[0]:.1f} nv³ + {coef[1]:.0f} nv² "
            f"+ {coef[2] / 1e6:.1f} MB"
        )

    print("\ntextbook side (dense Data and one call of every dense function)")
    print(f"{'joint':>9} {'nb':>5} {'n':>5} {'peak MB':>10} {'estimate MB':>12} {'est/peak':>9}")
    for joint, n in tb_cases:
        r = measure("textbook", n, joint)
        est = resources.textbook_peak_bytes(r["nb"], r["nv"])
        print(
            f"{joint:>9} {r['nb']:>5} {r['nv']:>5} {r['peak'] / 1e6:>10.1f} "
            f"{est / 1e6:>12.1f} {est / r['peak']:>9.3f}",
            flush=True,
        )

    print("\ntextbook side's mass check (rt70.textbook.massless.check_moves_mass)")
    print(f"{'joint':>9} {'nb':>5} {'n':>5} {'peak MB':>10} {'estimate MB':>12} {'est/peak':>9}")
    massless_cases = [("revolute", 500), ("revolute", 1000), ("floating", 100)]
    if not args.quick:
        massless_cases += [("revolute", 2000), ("revolute", 3000), ("planar", 1000)]
    for joint, n in massless_cases:
        r = measure("massless", n, joint)
        est = resources.massless_peak_bytes(r["nb"], r["nv"])
        print(
            f"{joint:>9} {r['nb']:>5} {r['nv']:>5} {r['peak'] / 1e6:>10.1f} "
            f"{est / 1e6:>12.1f} {est / r['peak']:>9.3f}",
            flush=True,
        )

    stack = resource.getrlimit(resource.RLIMIT_STACK)[0]
    print("\nPinocchio URDF parser, chain of fixed joints")
    if stack != resource.RLIM_INFINITY:
        lo, hi = parser_limit("main", 500, 8 * stack // 2048)
        print(
            f"main thread, stack {stack / 2**20:.0f} MiB: parses {lo} levels, segfaults at "
            f"{hi} ({stack / hi:.0f} bytes per level)",
            flush=True,
        )
    if not args.quick:  # the parser is quadratic in the frames: minutes at this depth
        size, depth = resources.PARSER_STACK_BYTES, resources.PARSER_MAX_DEPTH
        ok = parses(depth, "thread")
        print(
            f"parser thread, stack {size / 2**20:.0f} MiB: {depth} levels (the deepest tree "
            f"rt70 hands to the parser) {'parse' if ok else 'CRASH'}"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
