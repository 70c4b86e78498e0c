"""``rt70 simulate``: integrate a scene's equations of motion with an energy audit.

A scene with the RT-70 axes that its drives can hold runs a servo scenario
(:mod:`rt70.telescope.scenarios`); any other scene the structural benchmark
(:func:`rt70.simulation.simulate.simulate`). The trajectory is written atomically as CSV
or NPZ with a plot beside it.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable

from rt70.cli import options
from rt70.errors import ResourceError, Rt70Error

#: The RT-70 listing as printed, and its control object (a hint for the first).
LISTING, SERVO_SCENE = "rt70", "rt70_servo"


def _simulate(args: argparse.Namespace) -> int:
    from pathlib import Path

    from rt70.model.scene import load_scene
    from rt70.scenes.rt70_state import start_state
    from rt70.simulation.simulate import simulate

    if args.free_axes and (
        args.scenario
        or args.elevation is not None
        or args.azimuth is not None
        or args.drives
        or args.friction
    ):
        raise Rt70Error(
            "--free-axes runs the structural benchmark: no "
            "--scenario/--elevation/--azimuth/--drives/--friction"
        )
    scene = load_scene(args.scene)
    if args.drives == "scene":
        from rt70.telescope.scene_servo import check_scene_drives

        check_scene_drives(scene)
    scenario = _servo_scenario(args, scene)
    if scenario is not None:
        return _simulate_scenario(args, scene, scenario)
    if args.drives or args.friction:
        raise Rt70Error(f"{scene.name}: --drives/--friction need a servo scenario (RT-70 axes)")
    try:
        result = simulate(
            scene,
            (0.0, 10.0 if args.t_end is None else args.t_end),
            start_state(scene),
            side=args.side,
            method=args.method or _default_method(scene),
            rtol=args.rtol,
            progress=args.progress or sys.stderr.isatty(),
        )
    except ResourceError as exc:  # Pinocchio's Data too large: the textbook side may do
        if args.side != "reference":
            raise
        raise ResourceError(f"{exc}; {_refusal_hint(scene)}") from None
    side = "compiled kernels" if result.side == "compiled" else args.side
    print(
        f"{scene.name}: {result.method} ({side}), rtol {args.rtol:g}, "
        f"0 … {result.t[-1]:g} s: {'ok' if result.success else 'FAILED: ' + result.message}"
    )
    _print_solver(result)
    print(
        f"  energy: T0 = {result.kinetic[0]:.6g} J, dissipated {result.dissipated[-1]:.6g} J, "
        f"balance drift {result.relative_drift:.2e} of {result.balance_scale:.6g} J"
        + ("  [FLAGGED: more than the tolerance explains]" if result.drift_flagged else "")
    )
    if result.constraint_residual.size:  # closed chains (rt70.simulation.closed_chains)
        print(f"  constraints: max |Φ| = {result.constraint_residual.max():.2e} m (Baumgarte)")
    if args.out:
        figure = None
        if not args.no_plot:
            from rt70.plotting.simulation import simulation_figure

            figure = simulation_figure(result)
        _write_simulation(Path(args.out), result, figure)
    return 0 if result.success else 1


def _servo_scenario(args: argparse.Namespace, scene):
    """The servo scenario to run on ``scene`` or None (:func:`rt70.telescope.scenarios.choose`)."""
    from rt70.telescope import scenarios

    if args.free_axes:
        return None
    sc, hint = scenarios.choose(scene, args.scenario, args.elevation, args.azimuth, args.t_end)
    if hint:
        print(f"{scene.name}: {hint}")
    if hint and scene.name == LISTING:
        print(
            f"{scene.name}: the listing as printed has no drives, and drives of the book's "
            f"torque could not hold it (docs/rt70-errata.md item 12); 'rt70 simulate "
            f"{SERVO_SCENE}' runs the telescope held by its servo"
        )
    return sc


def _default_method(scene) -> str:
    """BDF; the generalized-α method on the compiled kernels for a large scene they cover.

    (:func:`rt70.linear.compiled.kernels_for`: from ``LARGE_NV`` coordinates on, where
    Pinocchio's ``Data`` and the dense Jacobian of 2 nv states grow as nv³ and nv².)
    """
    from rt70.linear.compiled import kernels_for
    from rt70.simulation.compiled_run import METHOD

    return "BDF" if kernels_for(scene) is None else METHOD


def _refusal_hint(scene) -> str:
    """What a refused reference-side simulation can do instead."""
    from rt70.textbook.motion_kernel import MotionData

    if MotionData.of(scene.textbook) is not None and not scene.description.loops:
        return "'--method generalized-alpha' integrates it on the compiled kernels, in O(nv) memory"
    return "'--side textbook' does without Pinocchio (its dense right-hand side is slow)"


def _simulate_scenario(args: argparse.Namespace, scene, sc) -> int:
    """Run a servo scenario and print what it measured (:mod:`rt70.telescope.scenarios`)."""
    from pathlib import Path

    from rt70.telescope import scenarios
    from rt70.telescope.scene_servo import choose_drives

    drives, label = choose_drives(scene, args.drives, args.friction, args.side)
    run = scenarios.run_scenario(
        scene,
        sc,
        drives=drives,
        rtol=args.rtol,
        side=args.side,
        method=args.method,
        progress=args.progress or sys.stderr.isatty(),
    )
    result = run.result
    tuning = scenarios.tuning_text(scenarios.declared_tuning(scene))
    print(
        f"{scene.name}: {sc.name} at elevation {sc.elevation_deg:g}°, azimuth "
        f"{sc.azimuth_deg:g}°, {label} and servo holding ({tuning}); "
        f"{result.method} ({args.side}), rtol {args.rtol:g}, 0 … {sc.t_end:g} s: ok"
    )
    _print_solver(result)
    for line in scenarios.summary_lines(run):
        print("  " + line)
    if args.out:
        figure = None
        if not args.no_plot:
            from rt70.plotting.servo import servo_figure

            figure = servo_figure(run)
        _write_simulation(Path(args.out), result, figure)
    return 0


def _print_solver(result) -> None:
    # with output times asked for (t_eval) scipy does not keep the step count: -1
    steps = f"{result.n_steps} steps, " if result.n_steps >= 0 else ""
    lu = f", {result.nlu} LU" if result.nlu >= 0 else ""  # CVODE does not report it: -1
    print(
        f"  {steps}{result.nfev} evaluations, {result.njev} Jacobians{lu}; "
        f"{result.wall_time_s:.3f} s wall, {result.real_time_factor:.1f}× real time"
    )
    split = ", ".join(f"{k} {v:.3f} s" for k, v in result.timing.items())
    print(f"  time split: {split}")


def _write_simulation(out, result, figure) -> None:
    """The trajectory and its figure (``.png`` beside it), written together atomically."""
    from rt70.guards.atomic import atomic_write_all
    from rt70.simulation.result import units_path

    writers = {out: result.writer(out)}
    if figure is not None:
        writers[out.with_suffix(".png")] = lambda tmp: figure.savefig(tmp, dpi=110)
    writers[units_path(out)] = result.units_writer(out)
    for path in atomic_write_all(writers):  # the trajectory and its plot appear together
        print(f"  wrote {path}")


def add_parser(
    sub: argparse._SubParsersAction, add_pointing_arguments: Callable[..., None]
) -> None:
    """Add ``rt70 simulate`` to the command line's subparsers.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The subparsers of ``rt70``.
    add_pointing_arguments : callable
        Adds ``--elevation``/``--azimuth`` to a parser (shared with ``rt70 modes``).
    """
    from rt70.simulation.request import ALL_METHODS  # not the simulation: --help stays light

    sim = sub.add_parser(
        "simulate",
        help="integrate the equations of motion with an energy audit",
        description="Simulate a scene and report solver statistics and the energy "
        "balance; optionally write the trajectory (CSV or NPZ, atomically) and a plot. A "
        "scene with the RT-70 axes that its drives can hold (rt70_servo) runs a servo "
        "scenario (hold by default, elevation 45°): settling, overshoot, torque, pointing "
        "error in arc seconds. Other scenes, rt70 (the listing as printed) and "
        "--free-axes run the structural benchmark (the listing's initial state for rt70).",
    )
    sim.add_argument("scene", metavar="SCENE", help="scene name or URDF path")
    sim.add_argument(
        "--t-end",
        type=options.positive_float,
        help="end time, s (default 10; a scenario's own: hold 60, steps 40/25, track 40)",
    )
    sim.add_argument(
        "--scenario",
        choices=("hold", "step-azimuth", "step-elevation", "track"),
        help="servo scenario of a scene with the RT-70 axes (default hold where the drives "
        "can hold the scene, e.g. rt70_servo): hold, a 1° step in azimuth or elevation, "
        "sidereal tracking (15″/s in azimuth)",
    )
    add_pointing_arguments(sim, default="45")
    sim.add_argument(
        "--free-axes",
        action="store_true",
        help="no drives: the structural benchmark from the listing's start state (the "
        "default for rt70, the listing as printed, which its drives cannot hold)",
    )
    sim.add_argument(
        "--drives",
        choices=("scene", "coordinate"),
        help="drive model of a servo scenario: the scene's <rt70:drive> elements, the "
        "elevation acting through its gear sector, encoders on the axes (default where the "
        "scene has them, e.g. rt70_servo), or torques on the axis coordinates",
    )
    sim.add_argument(
        "--friction",
        action="store_true",
        help="add the book's dry friction on both axes to a servo scenario",
    )
    sim.add_argument(
        "--method",
        choices=ALL_METHODS,
        help="integrator: a solve_ivp method, CVODE / CVODE_ADAMS (SUNDIALS), "
        "generalized-alpha on the compiled kernels, in O(nv) memory and work per step, or "
        "compiled-BDF: scipy's BDF with its loop compiled with the equations of a passive "
        "scene (default BDF; generalized-alpha from 200 coordinates on where the kernels "
        "cover the model; CVODE for the servo scenarios)",
    )
    options.add_side_argument(sim, what="q̈ and its Jacobian")
    sim.add_argument(
        "--rtol", type=options.rtol, default=1e-6, help="relative tolerance, 0 < rtol < 1"
    )
    sim.add_argument(
        "--out",
        help="output file, .csv or .npz (the unit of every column in NAME.units.json and a "
        ".png plot beside it)",
    )
    sim.add_argument("--no-plot", action="store_true", help="do not write the plot")
    sim.add_argument("--progress", action="store_true", help="progress bar on stderr")
    sim.set_defaults(func=_simulate)
