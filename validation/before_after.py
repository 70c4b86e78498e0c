"""Simulation speed of this checkout against an earlier revision, measured in one run.

Checks the earlier revision out into a temporary git worktree and runs the same
measurements with each version's code on ``PYTHONPATH`` (this environment's packages,
BLAS/OpenMP pinned to one thread), alternating before/after each round, best of the
rounds:

- ``simulate(rt70, 10 s)`` from the listing's state, axes free, BDF at rtol 1e-6 (the
  default of ``rt70 simulate rt70 --t-end 10`` on both): integration wall time, steps,
  evaluations; and the same with ``--method`` (after only, e.g. LSODA);
- the right-hand side (the reference side's backend's ``accelerations``) and its Jacobian per
  call, against ``pin.aba`` / ``pin.computeABADerivatives`` in the same process;
- the servo closed: ``rt70_servo``'s step-elevation scenario, 10 s, LSODA rtol 1e-6;
- the whole command ``python -m rt70 simulate rt70 --t-end 10 --no-plot`` (wall).

Run: ``python validation/before_after.py [--before REV] [--rounds N] [--method M]
[--rtol R]`` (default REV 8664442, the start of issue 13; about 2 minutes). Writes
validation/results/before_after.md.
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from rt70.guards.atomic import atomic_write_text
from rt70.reports.provenance import command_line, headed, run_header

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "validation" / "results" / "before_after.md"

CHILD = r"""
import json, sys, time
import numpy as np
from rt70.reports.threads import single_threaded
with single_threaded():
    import pinocchio as pin
    try:  # the package in folders by domain
        from rt70.simulation import simulate as sim
        from rt70.simulation.backends import BACKENDS
        from rt70.model.scene import load_scene
        from rt70.telescope import scenarios
        from rt70.telescope.scene_servo import choose_drives
        REFERENCE = "reference"
    except ImportError:  # the flat layout of the earlier revisions
        from rt70 import simulate as sim
        from rt70.simulate import BACKENDS
        from rt70.scene import load_scene
        from rt70 import scenarios
        from rt70.scene_servo import choose_drives
        REFERENCE = "pinocchio"
    from rt70.scenes.rt70_state import listing_initial_state
    method, rtol = sys.argv[1], float(sys.argv[2])
    scene = load_scene("rt70")
    q, qd = listing_initial_state(scene)
    out = {}
    r = sim.simulate(scene, (0.0, 10.0), (q, qd), method="BDF", rtol=1e-6)
    out["bdf"] = [r.wall_time_s, r.n_steps, r.nfev, r.njev]
    if method != "BDF":
        r = sim.simulate(scene, (0.0, 10.0), (q, qd), method=method, rtol=rtol)
        out["method"] = [r.wall_time_s, r.n_steps, r.nfev, r.njev]
    side = BACKENDS[REFERENCE](scene)
    ref, rd = scene.reference, scene.reference_data
    tau = np.zeros(ref.pin_model.nv)
    calls = {
        "rhs": lambda: side.accelerations(q, qd, None),
        "aba": lambda: pin.aba(ref.pin_model, rd.pin_data, q, qd, tau),
        "jac": lambda: side.jacobian(q, qd, None),
        "abaderiv": lambda: pin.computeABADerivatives(ref.pin_model, rd.pin_data, q, qd, tau),
    }
    for name, f in calls.items():
        f()
        n = 100 if name in ("jac", "abaderiv") else 400
        best = 1e9
        for _ in range(5):
            t = time.perf_counter()
            for _ in range(n):
                f()
            best = min(best, (time.perf_counter() - t) / n)
        out[name] = best
    servo = load_scene("rt70_servo")
    sc = scenarios.scenario("step-elevation", 45.0, 0.0, 10.0)
    drives, _ = choose_drives(servo, None)
    run = scenarios.run_scenario(servo, sc, drives=drives, method="LSODA", rtol=1e-6)
    out["servo"] = [run.result.wall_time_s, run.result.nfev]
print(json.dumps(out))
"""


def _measure(path: Path, method: str, rtol: float) -> dict:
    env = dict(os.environ, PYTHONPATH=str(path), OMP_NUM_THREADS="1")
    done = subprocess.run(
        [sys.executable, "-c", CHILD, method, repr(rtol)],
        env=env, capture_output=True, text=True, check=True, cwd=tempfile.gettempdir(),
    )  # fmt: skip
    return json.loads(done.stdout.strip().splitlines()[-1])


def _command(path: Path) -> float:
    env = dict(os.environ, PYTHONPATH=str(path))
    start = time.perf_counter()
    subprocess.run(
        [sys.executable, "-m", "rt70", "simulate", "rt70", "--t-end", "10", "--no-plot"],
        env=env, capture_output=True, check=True, cwd=tempfile.gettempdir(),
    )  # fmt: skip
    return time.perf_counter() - start


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--before", default="8664442")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--method", default="LSODA")
    parser.add_argument("--rtol", type=float, default=1e-6)
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        old = Path(tmp) / "before"
        subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "-q", "--detach", str(old),
                        args.before], check=True)  # fmt: skip
        try:
            runs = {"before": [], "after": []}
            commands = {"before": [], "after": []}
            for k in range(args.rounds):
                for label, path in (("before", old), ("after", ROOT)):
                    print(f"round {k + 1}: {label}", file=sys.stderr, flush=True)
                    runs[label].append(_measure(path, args.method, args.rtol))
                    commands[label].append(_command(path))
        finally:
            subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(old)],
                           check=False)  # fmt: skip
    best = {
        label: {
            key: min((r[key] for r in rs), key=lambda v: v[0] if isinstance(v, list) else v)
            for key in rs[0]
        }
        for label, rs in runs.items()
    }
    b, a = best["before"], best["after"]
    lines = [
        "# Before and after: simulation speed against an earlier revision",
        "",
        f"Before: {args.before}; after: this checkout. `python validation/before_after.py` "
        f"({args.rounds} rounds alternating, best of each; BLAS pinned to one thread).",
        "",
        "| quantity | before | after | after / before |",
        "|---|---|---|---|",
    ]

    def row(name: str, x: float, y: float, unit: str, scale: float = 1.0) -> None:
        lines.append(f"| {name} | {x * scale:.3g} {unit} | {y * scale:.3g} {unit} | {y / x:.2f} |")

    row("RT-70 10 s, BDF rtol 1e-6: integration", b["bdf"][0], a["bdf"][0], "s")
    lines.append(f"| steps / evaluations / Jacobians | {b['bdf'][1]} / {b['bdf'][2]} / "
                 f"{b['bdf'][3]} | {a['bdf'][1]} / {a['bdf'][2]} / {a['bdf'][3]} | |")  # fmt: skip
    if "method" in a:
        m = a["method"]
        lines.append(f"| RT-70 10 s, {args.method} rtol {args.rtol:g}: integration | "
                     f"{b.get('method', [float('nan')])[0]:.3g} s | {m[0]:.3g} s | |")  # fmt: skip
    row("right-hand side per call", b["rhs"], a["rhs"], "µs", 1e6)
    lines.append(f"| right-hand side / pin.aba | {b['rhs'] / b['aba']:.2f} | "
                 f"{a['rhs'] / a['aba']:.2f} | |")  # fmt: skip
    row("Jacobian per call", b["jac"], a["jac"], "µs", 1e6)
    lines.append(f"| Jacobian / pin.computeABADerivatives | {b['jac'] / b['abaderiv']:.2f} | "
                 f"{a['jac'] / a['abaderiv']:.2f} | |")  # fmt: skip
    row("rt70_servo step-elevation 10 s, LSODA 1e-6: integration", b["servo"][0],
        a["servo"][0], "s")  # fmt: skip
    row("whole command `rt70 simulate rt70 --t-end 10`", min(commands["before"]),
        min(commands["after"]), "s")  # fmt: skip
    text = "\n".join(lines) + "\n"
    print(text)
    atomic_write_text(OUT, headed(text, run_header(command_line())))
    print(f"wrote {OUT}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
