"""The ``rt70`` command line.

Exit codes: :data:`rt70.cli.options.EXIT_CODES` (the epilog of ``rt70 --help``); ``bench``
prints each target as met or not and exits 0 either way (timings are the machine's, not
a verdict). Input read with a caveat (:class:`~rt70.errors.Rt70Warning`) prints one
``rt70: warning: ...`` line on stderr each. Robots of example-robot-data that rt70
cannot load are listed as ``not loaded: <name>: <reason>`` lines, no error by themselves.

Every option is checked before any work starts (:mod:`rt70.cli.options`); SIGTERM becomes a
normal exit, so outputs being written are cleaned up (:mod:`rt70.guards.atomic`).

Numerical trouble is an error, never a stray warning beside a result: inside a command
every ``RuntimeWarning`` (numpy's overflow, invalid value, division by zero; scipy's
``LinAlgWarning`` and the Lyapunov solver's marginal eigenvalues) is raised and printed
as the one ``rt70: error:`` line, exit 2 (:func:`rt70.cli.options.warning_guards`); code
that expects such values says so with ``np.errstate`` and checks them. The solvers'
warnings join the run's message, and every integration but ``bench``'s has an evaluation
budget: a run its method cannot integrate stops with one line (:mod:`rt70.simulation.integrators`).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import warnings

from rt70.cli import cart as cli_cart
from rt70.cli import impact as cli_impact
from rt70.cli import options
from rt70.cli import pointing as cli_pointing
from rt70.cli import reactions as cli_reactions
from rt70.cli import simulate as cli_simulate
from rt70.cli import sweep as cli_sweep
from rt70.cli.options import EXIT_BROKEN_PIPE, EXIT_CODES, EXIT_INTERRUPTED, EXIT_TERMINATED
from rt70.errors import Rt70Error, SingularConfigurationError


def _validate(args: argparse.Namespace) -> int:
    from rt70.crosscheck.robots import UNEXPECTED, survey
    from rt70.crosscheck.validate import cross_check, format_table
    from rt70.model.scene import URDF_DIR, load_scene, require_coordinates, scene_names

    targets = args.targets or scene_names()
    if not targets:
        raise Rt70Error(f"no target to check: no scene files in {URDF_DIR}")
    balance = args.balance_inertia
    scenes, not_loaded = [], {}
    for t in targets:  # read everything first: bad input exits 2
        if t == "robots" or t.startswith("robot:"):  # example-robot-data (rt70.crosscheck.robots)
            names = None if t == "robots" else [t.removeprefix("robot:")]
            loaded, failed = survey(names, balance_inertia=balance)
            scenes += loaded
            not_loaded.update(failed)
        else:
            scenes.append(load_scene(t, balance_inertia=balance))
    bug = any(reason.startswith(UNEXPECTED) for reason in not_loaded.values())
    if not scenes:  # every robot asked for failed to load: nothing was checked
        reasons = "; ".join(f"{name}: {why}" for name, why in not_loaded.items())
        if bug:
            print(f"rt70: no target could be checked, a bug in rt70: {reasons}", file=sys.stderr)
            return 1
        raise Rt70Error(f"no target could be checked ({reasons})")
    for scene in scenes:  # build both sides first: a model rt70 refuses exits 2
        scene.reference  # noqa: B018  Pinocchio's guards first: cheaper than the mass check
        scene.textbook  # noqa: B018
        require_coordinates(scene)
    records = [r for scene in scenes for r in cross_check(scene, args.samples, args.seed)]
    if args.json:
        print(json.dumps([r.as_dict() for r in records], indent=2))
    else:
        print(format_table(records, args.tolerance))
        print(
            f"\n{len(scenes)} target(s), {args.samples} random states each, seed {args.seed}; "
            f"tolerance {args.tolerance:g} relative to the reference's max-norm."
        )
    for name, reason in not_loaded.items():  # reported, not an error by itself
        print(f"not loaded: {name}: {reason}", file=sys.stderr if args.json else sys.stdout)
    return 0 if all(r.passed(args.tolerance) for r in records) and not bug else 1


def _bench(args: argparse.Namespace) -> int:
    from pathlib import Path

    if args.what == "simulate":
        from rt70.reports import simulation_targets, work_precision, work_precision_results

        say = lambda msg: print(f"  {msg}", file=sys.stderr, flush=True)  # noqa: E731
        rows = work_precision.run(quick=args.quick, progress=say)
        print(work_precision_results.format_table(rows))
        for check in simulation_targets.check(rows, quick=args.quick, progress=say):
            print(check.line())
        for path in work_precision_results.write_results(rows, Path(args.out)):
            print(f"wrote {path}")
        return 0

    from rt70.reports import bench

    sizes = (10, 20, 50) if args.quick else (10, 20, 50, 100, 200, 400)
    rounds = 3 if args.quick else 7
    rows = bench.run(
        sizes=sizes,
        K=args.K,
        rounds=rounds,
        progress=lambda msg: print(f"  {msg}", file=sys.stderr, flush=True),
    )
    print(bench.format_report(rows))
    for path in bench.write_results(rows, Path(args.out)):
        print(f"wrote {path}")
    return 0


def _modes(args: argparse.Namespace) -> int:
    import numpy as np

    from rt70.linear import linearize as lin
    from rt70.linear import modal, mode_table
    from rt70.model.scene import load_scene
    from rt70.textbook.massless import require_diagonal

    scene = load_scene(args.scene)
    has_axes, elevation, azimuth, held = _pointing(args, scene, "modes")
    constraints = None
    try:
        with np.errstate(over="ignore", invalid="ignore"):  # overflow is reported, not warned
            if scene.description.loops:  # on the manifold Φ(q) = 0 (docs/constrained-modes.md)
                result, shapes, model, damped, constraints = _loop_modes(args, scene, held)
            else:
                q0 = lin.equilibrium(scene, held)
                model = lin.linearize(scene, q0, locked=tuple(held) if args.lock_axes else ())
                if scene.description.drives and not args.lock_axes:  # motors held: locked rotor
                    model = lin.locked_rotor(scene, model)
    except SingularConfigurationError as exc:  # a state on the way: name the scene
        raise SingularConfigurationError(f"{scene.name}: {exc}") from None
    drives = bool(scene.description.drives) and not args.lock_axes
    if constraints is None:
        require_diagonal(model.M, model.coordinates, f"{scene.name}: ")
        result = modal.modes(model.M, model.K, model.D)
        shapes = result.shapes
        damped = modal.damped_modes(model.M, model.K, model.D)
    rows = mode_table.mode_rows(result, shapes, model.M, model.coordinates)
    damped_summary = mode_table.damped_summary(result, damped)
    options.check_finite({"modes": rows, "damped": damped_summary}, f"{scene.name}: modes")
    if args.json:
        out = {
            "scene": scene.name,
            "held": held,
            "locked_rotor": drives,
            **({"constraints": constraints} if constraints is not None else {}),
            "modes": rows,
            "damped": damped_summary,
        }
        print(json.dumps(out, indent=2))
        return 0
    where = f", elevation {elevation:g}°, azimuth {azimuth:g}°" if has_axes else ""
    axes = " (axes locked)" if args.lock_axes and held else ""
    if drives:
        names = ", ".join(d.name for d in scene.description.drives)
        axes = f" (locked rotor: the motors of {names} held, their reducers hold the axes)"
    closed = ""
    if constraints is not None:
        closed = (
            f", on the manifold of {constraints['loop_rows']} loop-closure row(s) "
            f"(rank {constraints['rank']})"
        )
    print(f"{scene.name}: {len(rows)} modes at static equilibrium{where}{closed}{axes}")
    print(f"{'mode':>4} {'f, Hz':>10} {'ξ':>8}  {'kind':<8} dominant coordinate (energy)")
    for r in rows:
        zeta = "" if r["zeta"] is None else f"{r['zeta']:.4f}"
        freq = f"{r['freq_hz']:.4f}" if r["freq_hz"] is not None else "—"
        print(f"{r['mode']:>4} {freq:>10} {zeta:>8}  {r['kind']:<8} {r['dominant']}")
    print(
        "ξ = (VᵀDV)ᵢᵢ/2ωᵢ of the undamped modes"
        + ("" if result.proportional else " (approximate: the damping is not proportional)")
        + f"; the damped system has {len(damped.oscillatory)} oscillatory pairs and "
        f"{len(damped.real)} real eigenvalues (creeping motions: overdamped, rigid, unstable)"
    )
    hint = "; --lock-axes lets the drives hold it" if held and not args.lock_axes else ""
    for r in rows:
        if r["kind"] == "unstable":
            print(
                f"mode {r['mode']} is unstable (negative stiffness, divergence rate "
                f"{r['divergence_rate']:.4g} 1/s): gravity's moment about {r['dominant']} "
                "grows faster than any spring resists it — the part it swings is not balanced "
                f"about that free axis{hint}"
            )
        elif r["kind"] == "rigid":
            print(
                f"mode {r['mode']} is a rigid-body motion along {r['dominant']}: nothing holds "
                f"it (no spring, no drive, no gravity moment){hint}"
            )
    return 0


def _loop_modes(args: argparse.Namespace, scene, held: dict) -> tuple:
    """Modes of a closed-chain scene on its manifold (textbook side; docs/constrained-modes.md).

    From the mechanism's closed start, or a closed state at rest
    (:func:`rt70.simulation.closed_chains.closed_rest`); the stable equilibrium (Newton
    descending where the stiffness is negative). Returns modes, shapes, model, damped modes,
    constraints.
    """
    from rt70.linear import constrained_scene as cs
    from rt70.scenes.loop_scenes import start_state
    from rt70.simulation.closed_chains import closed_rest
    from rt70.textbook import loops

    start = start_state(scene)
    q = start[0] if start is not None else closed_rest(scene)[0]
    for name, value in held.items():
        q[scene.textbook.coordinate_names.index(name)] = value
    model = cs.constrained_linearize(
        scene,
        loops.loop_residual,
        loops.loop_jacobian,
        held,
        args.lock_axes,
        q_start=q,
        descend=True,
    )
    modes, shapes, damped, constraints = cs.spectrum(model)
    return modes, shapes, model, damped, constraints


#: Above this elevation (degrees) the pointing corrections are not given (zenith keyhole).
ZENITH_KEYHOLE_DEG = 89.0


def _add_pointing_arguments(parser: argparse.ArgumentParser, default: str = "zenith") -> None:
    """``--elevation`` and ``--azimuth`` of the RT-70 (read back by :func:`_pointing`)."""
    parser.add_argument(
        "--elevation",
        type=options.elevation,
        help=f"RT-70 elevation, degrees, 0 (horizon) to 90 (zenith); default {default}",
    )
    parser.add_argument(
        "--azimuth", type=options.angle_deg, help="RT-70 azimuth, degrees (default 0)"
    )


def _pointing(args: argparse.Namespace, scene, what: str) -> tuple[bool, float, float, dict]:
    """The RT-70 pointing asked for: (has axes, elevation, azimuth, held coordinates)."""
    from rt70.scenes import rt70_state

    names = scene.textbook.coordinate_names
    if not names:
        raise Rt70Error(f"{scene.name}: the model has no degree of freedom: no {what}")
    axes = (rt70_state.AZIMUTH_COORDINATE, rt70_state.ELEVATION_COORDINATE)
    has_axes = all(axis in names for axis in axes)
    if (args.elevation is not None or args.azimuth is not None) and not has_axes:
        raise Rt70Error(
            f"{scene.name}: --elevation/--azimuth need the RT-70 pointing axes ({', '.join(axes)})"
        )
    elevation = 90.0 if args.elevation is None else args.elevation
    azimuth = 0.0 if args.azimuth is None else args.azimuth
    held = rt70_state.rt70_pointing(elevation, azimuth) if has_axes else {}
    return has_axes, elevation, azimuth, held


def _plant(args: argparse.Namespace) -> int:
    import numpy as np

    from rt70.linear import linearize as lin
    from rt70.linear import modal
    from rt70.linear import plant as pl
    from rt70.model.outputs import optical_point_outputs
    from rt70.model.scene import load_scene

    method = args.method or "balanced"
    if args.method is not None and args.reduce is None:
        raise Rt70Error("--method needs --reduce N")
    if method == "modal" and args.reduce is not None and args.reduce % 2:
        raise Rt70Error(
            f"--reduce {args.reduce}: modal truncation keeps whole modes, 2 states each"
        )
    scene = load_scene(args.scene)
    has_axes, elevation, azimuth, held = _pointing(args, scene, "plant")
    names = scene.textbook.coordinate_names
    if has_axes:  # the drives' torques in; the axis angles and the optical points out
        inputs = [pl.CoordinateInput(f"torque:{a}", a) for a in held]
        outputs = [pl.CoordinateOutput(f"angle:{a}", a) for a in held]
        outputs += optical_point_outputs(scene)
        if elevation < ZENITH_KEYHOLE_DEG:  # at the zenith Δα, Δβ are undefined (4.160)
            from rt70.scenes.rt70_optics import rt70_mirror_outputs

            mirror = rt70_mirror_outputs(scene, elevation, azimuth)
            outputs += [o for o in mirror if o.name in ("focal_offset", "pointing_correction")]
    else:  # a generalised force on, and the value of, every coordinate
        inputs = [pl.CoordinateInput(f"force:{n}", n) for n in names]
        outputs = [pl.CoordinateOutput(n, n) for n in names]
    try:
        with np.errstate(over="ignore", invalid="ignore"):
            q0 = lin.equilibrium(scene, held)
            ss = pl.plant(scene, q0, inputs, outputs)
    except SingularConfigurationError as exc:
        raise SingularConfigurationError(f"{scene.name}: {exc}") from None
    # from K v = ω² M v, not from eig(A): a rigid mode's double pole at 0 splits by
    # rounding into ±√ε-sized poles that would look unstable
    so = ss.second_order
    spectrum = modal.modes(so.M, so.K)
    unstable, rigid = int(spectrum.negative.sum()), int(spectrum.rigid.sum())
    info = {
        "scene": scene.name,
        "pointing": {"elevation_deg": elevation, "azimuth_deg": azimuth} if has_axes else None,
        "states": list(ss.state_names),
        "inputs": list(ss.input_names),
        "outputs": list(ss.output_names),
        "unstable_modes": unstable,
        "rigid_modes": rigid,
        "units": "inputs N or N·m; angles rad, points m, focal_offset mm, "
        "pointing_correction arcsec (Δα, Δβ); states m, rad and their rates",
    }
    if args.reduce is not None:  # modal or balanced truncation, and what it costs
        from rt70.linear import reduce as rd

        full = ss
        with options.option_at_fault(f"{scene.name}: --reduce {args.reduce}"):
            red = (
                rd.modal_truncation(ss, args.reduce // 2)
                if method == "modal"
                else rd.balanced_truncation(ss, args.reduce)
            )
        ss, err = red.ss, rd.hinf_error(full, red.ss)
        info["states"] = list(ss.state_names)
        info["reduced"] = {
            "method": method,
            "order": red.order,
            "full_order": full.n_states,
            "hinf_error": err.peak,
            "hinf_error_relative": err.relative,
            "peak_hz": err.freq_hz,
            "bound_2sum_hsv": red.bound,
        }
    arrays = {"A": ss.A, "B": ss.B, "C": ss.C, "D": ss.D}
    options.check_finite({**info, **arrays}, f"{scene.name}: plant")
    if args.out:
        from rt70.guards.atomic import atomic_write

        labels = {k: np.array(info[k]) for k in ("states", "inputs", "outputs")}
        atomic_write(args.out, lambda tmp: np.savez_compressed(tmp, **arrays, **labels))
    if args.json:
        print(json.dumps(info, indent=2))
        return 0
    where = f" at elevation {elevation:g}°, azimuth {azimuth:g}°" if has_axes else ""
    print(
        f"{scene.name}: linear plant{where}: {ss.n_states} states, {ss.n_inputs} inputs, "
        f"{ss.n_outputs} outputs; {unstable} unstable and {rigid} rigid mode(s) "
        "(the loops the drives must close)"
    )
    print("  inputs:  " + ", ".join(ss.input_names))
    print("  outputs: " + ", ".join(ss.output_names))
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
    return 0


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``rt70`` command (errors: one line, exit 2)."""
    parser = options.Parser(
        prog="rt70",
        description="Models of flexible structures, cross-checked against Pinocchio.",
        epilog="exit codes: " + "; ".join(f"{code} {what}" for code, what in EXIT_CODES.items()),
    )
    parser.add_argument("--version", action=options.PrintVersion)
    sub = parser.add_subparsers(dest="command", required=True)
    val = sub.add_parser(
        "validate",
        help="cross-check the textbook algorithm against Pinocchio",
        description="Compare mass matrix, bias, gravity, spring/damper forces, forward "
        "dynamics and energies of the textbook algorithm and Pinocchio on random states.",
    )
    val.add_argument(
        "targets",
        nargs="*",
        metavar="TARGET",
        help="scene name, URDF path, 'robots' (every robot of example-robot-data that "
        "loads) or 'robot:NAME' (default: every scene in urdf/)",
    )
    val.add_argument(
        "--samples", type=options.positive_int, default=10, help="random states per target"
    )
    val.add_argument("--seed", type=options.seed, default=0, help="random seed (≥ 0)")
    val.add_argument(
        "--tolerance", type=options.non_negative_float, default=1e-10, help="relative tolerance"
    )
    val.add_argument("--json", action="store_true", help="print the records as JSON")
    val.add_argument(
        "--balance-inertia",
        action="store_true",
        help="repair rotational inertias of moving links that are not positive definite or "
        "break the triangle inequality (principal moments set to their mean, as MuJoCo's "
        "balanceinertia) instead of refusing them; each repair is reported",
    )
    val.set_defaults(func=_validate)
    ben = sub.add_parser(
        "bench",
        help="benchmark the textbook mass matrix against pin.crba (ratios, one run)",
        description="Per-call and batched textbook A(q) against pin.crba on rt70, ur5, panda "
        "and talos_full, and the growth of its cost on serial chains and balanced trees; "
        "writes CSV and a log-log plot.",
    )
    ben.add_argument(
        "what",
        nargs="?",
        default="mass-matrix",
        choices=("mass-matrix", "simulate"),
        help="mass-matrix (default) or simulate (the work-precision report)",
    )
    ben.add_argument("--K", type=options.batch_size, default=1000, help="batch size")
    ben.add_argument("--quick", action="store_true", help="small sizes, few rounds (a smoke run)")
    ben.add_argument(
        "--out",
        default="rt70-results",
        help="directory for CSV and PNG output (default: rt70-results in the current "
        "directory; validation/*.py write the committed validation/results)",
    )
    ben.set_defaults(func=_bench)
    mod = sub.add_parser(
        "modes",
        help="eigenfrequencies and mode shapes at static equilibrium",
        description="Linearise a scene at its static equilibrium under gravity (the "
        "RT-70 at a given pointing, held there) and print the eigenfrequencies of "
        "K v = ω² M v. A scene with <rt70:drive> elements (rt70_servo) gives its "
        "locked-rotor spectrum: the motors held, the reducers' stiffness holding the axes. "
        "Without drives (rt70, the listing) the axes are free unless --lock-axes.",
    )
    mod.add_argument("scene", metavar="SCENE", help="scene name or URDF path")
    _add_pointing_arguments(mod)
    mod.add_argument(
        "--lock-axes",
        action="store_true",
        help="remove the azimuth and elevation coordinates (drives infinitely stiff)",
    )
    mod.add_argument("--json", action="store_true", help="print JSON")
    mod.set_defaults(func=_modes)
    pla = sub.add_parser(
        "plant",
        help="the linear plant (state space) with named inputs and outputs",
        description="Linearise a scene at its static equilibrium (the RT-70 at a pointing, "
        "its axes held) and print the state space's named inputs and outputs: for the "
        "RT-70 the axis torques in, the axis angles and the optical points out; for other "
        "scenes a force on and the value of every coordinate. --out writes A, B, C, D and "
        "the names (.npz); in Python, rt70.linear.plant.to_control gives python-control's "
        "StateSpace.",
    )
    pla.add_argument("scene", metavar="SCENE", help="scene name or URDF path")
    _add_pointing_arguments(pla)
    pla.add_argument("--json", action="store_true", help="print JSON")
    pla.add_argument("--out", help="write A, B, C, D and the names to FILE.npz")
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
    pla.set_defaults(func=_plant)
    cli_pointing.add_parser(sub, _add_pointing_arguments)
    cli_reactions.add_parser(sub)
    cli_simulate.add_parser(sub, _add_pointing_arguments)
    cli_sweep.add_parser(sub)
    cli_cart.add_parser(sub)
    cli_impact.add_parser(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run the command line; return the exit code."""
    argv = sys.argv[1:] if argv is None else argv
    args = build_parser().parse_args(argv)  # bad options: one line, exit 2 (options.Parser)
    guards = options.warning_guards(args.command)  # module docstring
    with (
        options.stop_signals(EXIT_TERMINATED),
        options.checked_stdout(),  # '> file' on a full disk: one line, exit 2
        warnings.catch_warnings(),
        guards,
    ):
        try:
            options.check_outputs(args)  # before any work: a bad output path exits 2 at once
            code = args.func(args)
            sys.stdout.flush()  # a closed pipe shows here, inside the try, not at shutdown
            return code
        except Rt70Error as exc:
            print(f"rt70: error: {exc}", file=sys.stderr)
            return 2
        except RuntimeWarning as exc:  # numpy's floating-point warnings, scipy's LinAlgWarning
            print(f"rt70: error: {options.numerical_failure(argv, exc)}", file=sys.stderr)
            return 2
        except BrokenPipeError:
            # the reader went away (``| head``); Python flushes stdout again at exit:
            # point it at /dev/null (the Python docs' recipe for SIGPIPE)
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, sys.stdout.fileno())
            return EXIT_BROKEN_PIPE
        except KeyboardInterrupt:
            print("rt70: interrupted", file=sys.stderr)
            return EXIT_INTERRUPTED


if __name__ == "__main__":
    sys.exit(main())
