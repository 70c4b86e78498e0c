"""``rt70 plant --drives [--loop open|closed]``: the servo plant with the scene's own drives.

The structure linearised at the drive-held equilibrium with every ``<rt70:drive>`` on it
(gear sector included; :func:`rt70.control.scene_loop.driven_plant`), the armature
voltages in; with ``--loop closed`` each axis's declared (or tuned) PI cascade closed
(references in, :func:`rt70.control.scene_loop.closed_loop`); with ``--loop open --at
position|rate`` that loop broken on every drive (the loop transfer ``L = −e/w``). The
result is python-control's ``StateSpace`` with named signals and units, written as
``.npz`` or ``.mat``. Used by :mod:`rt70.cli.plant`.
"""

from __future__ import annotations

import argparse
import json

from rt70.errors import Rt70Error

#: Units of the signals by name suffix (``<drive>_<suffix>``, or an output's name).
SIGNAL_UNITS = {
    "voltage": "V",
    "encoder": "rad",
    "current": "A",
    "motor_speed": "rad/s",
    "reference": "rad",
    "e_p": "rad",
    "e_v": "rad/s",
    "pointing_correction": "arcsec",
    "focal_offset": "mm",
}


def unit_of(name: str, drives: list[str], loop: str = "position") -> str:
    """The unit of a signal ``<drive>_<suffix>`` or ``<output>:<component>``.

    Parameters
    ----------
    name : str
        The signal.
    drives : list of str
        The drives' names (the prefixes).
    loop : {"position", "rate"}
        The loop a ``<drive>_w`` input breaks: it has that loop's error's unit.
    """
    for d in drives:
        if name.startswith(f"{d}_"):
            suffix = name[len(d) + 1 :]
            return SIGNAL_UNITS[
                {"position": "e_p", "rate": "e_v"}[loop] if suffix == "w" else suffix
            ]
    return SIGNAL_UNITS[name.split(":")[0]]


def run_drives(
    args: argparse.Namespace, scene, pointing: tuple[float, float], held: dict, outputs: list
):
    """Build, print and write the plant with drives (module docstring).

    Parameters
    ----------
    args : argparse.Namespace
        ``rt70 plant``'s options (``loop``, ``at``, ``json``, ``out``).
    scene : rt70.model.scene.Scene
        The scene, with its drives.
    pointing : (float, float)
        The elevation and azimuth, degrees.
    held : dict of str to float
        Its held axis coordinates (:func:`rt70.model.antenna.pointing`).
    outputs : list of rt70.model.outputs.Output
        The mirror outputs beside the drives' own (``rt70 plant``'s, zenith keyhole
        applied).
    """
    import control
    import numpy as np

    from rt70.control.scene_loop import ERRORS, closed_loop, driven_plant
    from rt70.telescope.drive_equilibrium import drive_held_linearization

    if not scene.description.drives:
        raise Rt70Error(f"{scene.name}: --drives/--loop need the scene's <rt70:drive> elements")
    lm = drive_held_linearization(scene, held)
    elevation, azimuth = pointing
    if args.loop is None:
        sys_, what = driven_plant(scene, lm, outputs), "open loops: the voltages in"
    else:
        from rt70.telescope.scene_servo import scene_servos

        servos = scene_servos(scene)
        if args.loop == "closed":
            sys_, what = closed_loop(scene, lm, {}, outputs, servos), "every loop closed"
        else:
            full = closed_loop(scene, lm, {}, [], servos, open_loop=args.at)
            names = [d.name for d in scene.description.drives]
            errors = [f"{d}_{ERRORS[args.at]}" for d in names]
            ws = [f"{d}_w" for d in names]
            sub = full[errors, ws]
            sys_ = control.ss(
                sub.A, sub.B, -sub.C, -sub.D, inputs=ws, outputs=errors,
                states=list(sub.state_labels),
            )  # fmt: skip
            what = f"the {args.at} loop broken on every drive: L = -e/w"
    drives = [d.name for d in scene.description.drives]
    info = {
        "scene": scene.name,
        "pointing": {"elevation_deg": elevation, "azimuth_deg": azimuth},
        "plant": what,
        "states": list(sys_.state_labels),
        "inputs": list(sys_.input_labels),
        "outputs": list(sys_.output_labels),
        "input_units": {n: unit_of(n, drives, args.at) for n in sys_.input_labels},
        "output_units": {n: unit_of(n, drives, args.at) for n in sys_.output_labels},
        "poles_max_real": float(np.max(np.real(sys_.poles()))),
    }
    _write(args, scene, sys_, info)
    if args.json:
        print(json.dumps(info, indent=2))
        return 0
    print(
        f"{scene.name}: plant with its drives at elevation {elevation:g}°, azimuth "
        f"{azimuth:g}° ({what}): {sys_.nstates} states, {sys_.ninputs} inputs, "
        f"{sys_.noutputs} outputs; largest pole real part {info['poles_max_real']:.3g} 1/s"
    )
    print("  inputs:  " + ", ".join(f"{n} [{u}]" for n, u in info["input_units"].items()))
    print("  outputs: " + ", ".join(f"{n} [{u}]" for n, u in info["output_units"].items()))
    if args.out:
        print(f"wrote {args.out}")
    return 0


def _write(args: argparse.Namespace, scene, sys_, info: dict) -> None:
    """Check the plant is finite; with ``--out``, write it (.npz or .mat)."""
    from rt70.cli import options

    arrays = {"A": sys_.A, "B": sys_.B, "C": sys_.C, "D": sys_.D}
    options.check_finite(arrays, f"{scene.name}: plant")
    if args.out:
        write_plant(args.out, arrays, info)


def write_plant(out: str, arrays: dict, info: dict) -> None:
    """Write A, B, C, D with the signals' names and units, atomically: ``.npz`` or ``.mat``.

    The ``.mat`` file (MATLAB 5, ``scipy.io.savemat``) holds the matrices, the names as
    cell arrays (``states``, ``inputs``, ``outputs``), the units likewise
    (``input_units``, ``output_units``, when known) and ``description`` (the JSON info).

    Parameters
    ----------
    out : str
        The file, ``.npz`` or ``.mat``.
    arrays : dict
        ``A``, ``B``, ``C``, ``D``.
    info : dict
        The names (``states``, ``inputs``, ``outputs``) and what else ``--json`` prints.
    """
    from pathlib import Path

    import numpy as np

    from rt70.guards.atomic import atomic_write

    labels = {k: np.array(info[k], dtype=object) for k in ("states", "inputs", "outputs")}
    for key in ("input_units", "output_units"):
        if key in info:
            labels[key] = np.array(
                [info[key][n] for n in info[key.split("_")[0] + "s"]], dtype=object
            )
    if Path(out).suffix == ".mat":
        import scipy.io

        text = json.dumps({k: v for k, v in info.items() if k not in ("states",)}, default=str)
        content = {**arrays, **labels, "description": text}
        atomic_write(out, lambda tmp: scipy.io.savemat(tmp, content, appendmat=False))
    else:
        plain = {k: np.array(v, dtype=str) for k, v in labels.items()}
        atomic_write(out, lambda tmp: np.savez(tmp, **arrays, **plain))
