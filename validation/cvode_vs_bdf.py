"""SUNDIALS CVODE against scipy's BDF on the RT-70 10 s transient (issue 13, item 2).

The structural benchmark (listing's start state, axes free) over 10 s, sampled at 201
times; the error is the largest distance over time and bodies between each body's
centre of mass (Pinocchio's joints, ``oMi · lever``) and that of a tight reference
(CVODE at rtol 1e-10, checked against scipy BDF at 1e-9). For each method and rtol it
prints the error, the integration's wall time, the solver's statistics and the time
split of ``SimulationResult.timing``. What decided that BDF stays the default.

    python validation/cvode_vs_bdf.py [--rtols 1e-5 1e-6 1e-7 1e-8] [--adams]
"""

from __future__ import annotations

import argparse

import numpy as np
import pinocchio as pin

from rt70.model.scene import load_scene
from rt70.scenes.rt70_state import listing_initial_state
from rt70.simulation.simulate import simulate

T = np.linspace(0.0, 10.0, 201)


def centres_of_mass(model, data, q: np.ndarray) -> np.ndarray:
    """Ground positions of every body's centre of mass, (n_t, n_bodies, 3)."""
    out = []
    for qi in q:
        pin.forwardKinematics(model, data, qi)
        out.append([data.oMi[j].act(model.inertias[j].lever) for j in range(1, model.njoints)])
    return np.array(out)


def main() -> None:
    """Run the comparison and print one line per run."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rtols", type=float, nargs="+", default=[1e-5, 1e-6, 1e-7, 1e-8])
    parser.add_argument("--adams", action="store_true", help="also CVODE_ADAMS (slow here)")
    args = parser.parse_args()
    scene = load_scene("rt70")
    x0 = listing_initial_state(scene)
    model = scene.reference.pin_model
    data = model.createData()

    def run(method: str, rtol: float):
        r = simulate(scene, (0.0, 10.0), x0, method=method, rtol=rtol, t_eval=T)
        return r, centres_of_mass(model, data, r.q)

    ref, com_ref = run("CVODE", 1e-10)
    check, com_check = run("BDF", 1e-9)
    gap = np.linalg.norm(com_check - com_ref, axis=2).max()
    print(f"reference CVODE 1e-10: {ref.wall_time_s:.2f} s; scipy BDF 1e-9 within {gap:.1e} m")
    methods = ("BDF", "CVODE", "CVODE_ADAMS") if args.adams else ("BDF", "CVODE")
    for rtol in args.rtols:
        for method in methods:
            r, com = run(method, rtol)
            err = np.linalg.norm(com - com_ref, axis=2).max()
            split = ", ".join(f"{k} {v:.3f} s" for k, v in r.timing.items())
            print(
                f"{method:11s} rtol {rtol:.0e}: centre-of-mass error {err:.2e} m, "
                f"{r.wall_time_s:.2f} s, {r.nfev} evaluations, {r.njev} Jacobians, "
                f"{r.nlu} LU ({split})"
            )


if __name__ == "__main__":
    main()
