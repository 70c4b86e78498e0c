"""``rt70 plant``: the linear plant of a scene, with named inputs and outputs, and its reductions.

The plant: :mod:`rt70.linear.plant` (for the RT-70 the axis torques in; the axis angles,
the optical points, the focal offset and the pointing corrections out); its reductions
by modal or balanced truncation and their H∞ error: :mod:`rt70.linear.reduce` (docs:
'Reduced plants of the RT-70', docs/plant-reduction.md).
"""

from __future__ import annotations

import argparse
import json

from rt70.cli import options
from rt70.errors import Rt70Error, SingularConfigurationError

#: Above this elevation (degrees) the pointing corrections are not given (zenith keyhole).
ZENITH_KEYHOLE_DEG = 89.0

#: The units of the plant's signals, as ``--json`` reports them.
UNITS = (
    "inputs N or N·m; angles rad, points m, focal_offset mm, "
    "pointing_correction arcsec (Δα, Δβ); states m, rad and their rates"
)


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add ``rt70 plant`` to the command line's subparsers ``sub``; return its parser."""
    pla = sub.add_parser(
        "plant",
        help="the linear plant (state space) with named inputs and outputs",
        description="Linearise a scene at its static equilibrium (the RT-70 at a pointing, "
        "its axes held) and print the state space's named inputs and outputs: for the "
        "RT-70 the axis torques in, the axis angles and the optical points out; for other "
        "scenes a force on and the value of every coordinate. --drives: the structure with "
        "its <rt70:drive> elements, the armature voltages in; --loop closed|open: their "
        "declared servos closed, or one loop broken. --out writes A, B, C, D and the names "
        "(.npz, or .mat for MATLAB with the units); in Python, rt70.plant "
        "gives python-control's StateSpace.",
    )
    pla.add_argument("scene", metavar="SCENE", help="scene name or URDF path")
    options.add_pointing_arguments(pla)
    pla.add_argument("--json", action="store_true", help="print JSON")
    pla.add_argument(
        "--out", help="write A, B, C, D and the names to FILE.npz or FILE.mat (MATLAB)"
    )
    pla.add_argument(
        "--drives",
        action="store_true",
        help="the structure with its drives (voltage inputs, gear sectors included)",
    )
    pla.add_argument(
        "--loop",
        choices=("open", "closed"),
        help="with the drives: every servo closed (references in), or one loop broken",
    )
    pla.add_argument(
        "--at",
        choices=("position", "rate"),
        default="position",
        help="with --loop open: the loop broken on every drive (default position)",
    )
    pla.add_argument(
        "--reduce",
        type=options.positive_int,
        metavar="N",
        help="reduce to N states and print the H∞ error (--out writes the reduced plant)",
    )
    pla.add_argument(
        "--method",
        choices=("modal", "balanced"),
        help="with --reduce: modal truncation with static correction, or balanced "
        "truncation by Hankel singular values (default)",
    )
    pla.set_defaults(func=run)
    return pla


def run(args: argparse.Namespace) -> int:
    """Build the plant at the static equilibrium, reduce it if asked, write and print it."""
    import numpy as np

    from rt70.linear import linearize as lin
    from rt70.linear import modal
    from rt70.linear import plant as pl
    from rt70.model.scene import load_scene

    method = _check_reduction(args)
    if args.loop is not None or args.drives:
        if args.reduce is not None:
            raise Rt70Error("--reduce works on the structure's plant, not with --drives/--loop")
        if args.at != "position" and args.loop != "open":
            raise Rt70Error("--at needs --loop open")
    scene = load_scene(args.scene)
    has_axes, elevation, azimuth, held = options.asked_pointing(args, scene, "plant")
    if args.loop is not None or args.drives:
        from rt70.cli.plant_drives import run_drives

        if not has_axes:
            from rt70.model.antenna import mount_of

            mount_of(scene)  # one line naming the element
        outputs = _mirror_outputs(scene, elevation, azimuth)
        return run_drives(args, scene, (elevation, azimuth), held, outputs)
    inputs, outputs = _signals(scene, has_axes, elevation, azimuth, held)
    try:
        with np.errstate(over="ignore", invalid="ignore"):
            q0 = lin.equilibrium(scene, held)
            ss = pl.plant_matrices(scene, q0, inputs, outputs)
    except SingularConfigurationError as exc:
        raise SingularConfigurationError(f"{scene.name}: {exc}") from None
    # from K v = ω² M v, not from eig(A): a rigid mode's double pole at 0 splits by
    # rounding into ±√ε-sized poles that would look unstable
    so = ss.second_order
    unstable, rigid = modal.unheld_counts(so.M, so.K)
    info = {
        "scene": scene.name,
        "pointing": {"elevation_deg": elevation, "azimuth_deg": azimuth} if has_axes else None,
        "states": list(ss.state_labels),
        "inputs": list(ss.input_labels),
        "outputs": list(ss.output_labels),
        "unstable_modes": unstable,
        "rigid_modes": rigid,
        "units": UNITS,
    }
    if args.reduce is not None:  # modal or balanced truncation, and what it costs
        ss = _reduce(args, scene, method, ss.state_space(), info)
    _write(args, scene, ss, info)
    if args.json:
        print(json.dumps(info, indent=2))
        return 0
    where = f" at elevation {elevation:g}°, azimuth {azimuth:g}°" if has_axes else ""
    _print_text(args, f"{scene.name}: linear plant{where}", ss, info)
    return 0


def _check_reduction(args: argparse.Namespace) -> str:
    """The reduction method (``--method``, default balanced), checked against ``--reduce``."""
    method = args.method or "balanced"
    if args.method is not None and args.reduce is None:
        raise Rt70Error("--method needs --reduce N")
    if method == "modal" and args.reduce is not None and args.reduce % 2:
        raise Rt70Error(
            f"--reduce {args.reduce}: modal truncation keeps whole modes, 2 states each"
        )
    return method


def _signals(scene, has_axes: bool, elevation: float, azimuth: float, held: dict) -> tuple:
    """``(inputs, outputs)`` of the plant.

    With a ``<rt70:mount>``: the torques on its axes in; the axis angles and the optical
    points out, and, when the scene declares ``<rt70:optics>`` and the pointing is below
    :data:`ZENITH_KEYHOLE_DEG`, the pointing corrections (and the focal offset of a
    secondary). Otherwise a generalised force on, and the value of, every coordinate.
    """
    from rt70.linear import plant as pl
    from rt70.model.outputs import optical_point_outputs

    if not has_axes:
        names = scene.textbook.coordinate_names
        inputs = [pl.CoordinateInput(f"force:{n}", n) for n in names]
        return inputs, [pl.CoordinateOutput(n, n) for n in names]
    inputs = [pl.CoordinateInput(f"torque:{a}", a) for a in held]
    outputs = [pl.CoordinateOutput(f"angle:{a}", a) for a in held]
    outputs += optical_point_outputs(scene)
    return inputs, outputs + _mirror_outputs(scene, elevation, azimuth)


def _mirror_outputs(scene, elevation: float, azimuth: float) -> list:
    """The focal offset and pointing corrections, when the scene declares ``<rt70:optics>``.

    None above :data:`ZENITH_KEYHOLE_DEG`: at the zenith Δα, Δβ are undefined (4.160).
    A scene with a reflecting surface adds its outputs (docs/surface.md): the best fit's
    focus shift, axis tilt and beam deviation, and the residual of every surface node.
    """
    outputs = _surface_outputs(scene)
    if scene.description.optics is None or elevation >= ZENITH_KEYHOLE_DEG:
        return outputs
    from rt70.model.antenna import pointing_outputs

    wanted = ("focal_offset", "pointing_correction")
    return [o for o in pointing_outputs(scene, elevation, azimuth) if o.name in wanted] + outputs


def _surface_outputs(scene) -> list:
    """The reflecting surface's outputs ``surface_*``, or none without a surface."""
    from rt70.model.surface_outputs import has_surface, reflector_surface, surface_outputs

    if not has_surface(scene):
        return []

    wanted = ("focus_shift", "axis_tilt", "beam_deviation", "residual")
    outs = surface_outputs(reflector_surface(scene), "surface")
    return [o for o in outs if o.name.removeprefix("surface_") in wanted]


def _reduce(args: argparse.Namespace, scene, method: str, full, info: dict):
    """The plant reduced to ``--reduce`` states; its order and H∞ error go into ``info``."""
    from rt70.linear import reduce as rd

    with options.option_at_fault(f"{scene.name}: --reduce {args.reduce}"):
        red = (
            rd.modal_truncation(full, args.reduce // 2)
            if method == "modal"
            else rd.balanced_truncation(full, args.reduce)
        )
    ss, err = red.ss, rd.hinf_error(full, red.ss)
    info["states"] = list(ss.state_labels)
    info["reduced"] = {
        "method": method,
        "order": red.order,
        "full_order": full.nstates,
        "hinf_error": err.peak,
        "hinf_error_relative": err.relative,
        "peak_hz": err.freq_hz,
        "bound_2sum_hsv": red.bound,
    }
    return ss


def _write(args: argparse.Namespace, scene, ss, info: dict) -> None:
    """Check the plant is finite; with ``--out``, write A, B, C, D and the names (.npz)."""
    arrays = {"A": ss.A, "B": ss.B, "C": ss.C, "D": ss.D}
    options.check_finite({**info, **arrays}, f"{scene.name}: plant")
    if args.out:
        from rt70.cli.plant_drives import write_plant

        write_plant(args.out, arrays, info)


#: The text summary names this many signals of a kind, then counts the rest (--json: all).
LISTED = 24


def _listed(labels: list[str]) -> str:
    """The signals' names, the first :data:`LISTED` of a long list and how many more."""
    if len(labels) <= LISTED:
        return ", ".join(labels)
    more = len(labels) - LISTED
    return ", ".join(labels[:LISTED]) + f", … and {more} more (--json or --out lists all)"


def _print_text(args: argparse.Namespace, title: str, ss, info: dict) -> None:
    """The plant's summary: its size, unstable and rigid modes, signals, reduction."""
    print(
        f"{title}: {ss.nstates} states, {ss.ninputs} inputs, "
        f"{ss.noutputs} outputs; {info['unstable_modes']} unstable and "
        f"{info['rigid_modes']} rigid mode(s) (the loops the drives must close)"
    )
    print("  inputs:  " + _listed(ss.input_labels))
    print("  outputs: " + _listed(ss.output_labels))
    if args.reduce is not None:
        r = info["reduced"]
        bound = "" if r["bound_2sum_hsv"] is None else f" (bound 2Σσ {r['bound_2sum_hsv']:.3g})"
        print(
            f"  reduced by {r['method']} truncation to {r['order']} states: H∞ error "
            f"{r['hinf_error']:.3g}{bound}, {r['hinf_error_relative']:.2e} of ‖G‖∞, "
            f"peak at {r['peak_hz']:.3g} Hz (in the outputs' units per input unit)"
        )
    if args.out:
        print(f"wrote {args.out}")
