"""``rt70 modes``: eigenfrequencies and mode shapes of a scene at its static equilibrium.

The linearisation: :mod:`rt70.linear.linearize`; the modes: :mod:`rt70.linear.modal` and
their table :mod:`rt70.linear.mode_table`; a scene with ``<rt70:loop>`` closures on its
manifold Φ(q) = 0 (:mod:`rt70.linear.constrained_scene`; docs: 'Modes of a constrained
scene', docs/constrained-modes.md).
"""

from __future__ import annotations

import argparse
import json

from rt70.cli import options
from rt70.errors import SceneError, SingularConfigurationError


def _count(text: str) -> int | str:
    """``--count``: a positive integer, or ``all``."""
    if text == "all":
        return text
    try:
        return options.positive_int(text)
    except argparse.ArgumentTypeError:
        raise argparse.ArgumentTypeError(
            f"expected a number of modes (1 or more) or 'all', got {text!r}"
        ) from None


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add ``rt70 modes`` to the command line's subparsers ``sub``; return its parser."""
    from rt70.linear.lowest_modes import DENSE_MAX, LOWEST

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
    options.add_pointing_arguments(mod)
    mod.add_argument(
        "--lock-axes",
        action="store_true",
        help="remove the azimuth and elevation coordinates (drives infinitely stiff)",
    )
    mod.add_argument(
        "--count",
        type=_count,
        metavar="N|all",
        help="the N modes nearest zero (the lowest), found by shift-invert Lanczos; default "
        f"all up to {DENSE_MAX} coordinates, the lowest {LOWEST} above",
    )
    mod.add_argument("--json", action="store_true", help="print JSON")
    mod.add_argument(
        "--plot",
        metavar="FILE",
        help="draw the modes on the structure, a 3-D panel each: FILE.png, .pdf or .svg, "
        "or FILE.gif animated through a cycle",
    )
    mod.add_argument(
        "--plot-modes",
        type=options.positive_int,
        default=6,
        metavar="N",
        help="how many modes --plot draws, the lowest elastic first (default 6)",
    )
    mod.set_defaults(func=run)
    return mod


def run(args: argparse.Namespace) -> int:
    """Linearise the scene at its static equilibrium and print its modes (text or JSON)."""
    from rt70.linear import mode_table
    from rt70.model.scene import load_scene

    scene = load_scene(args.scene)
    has_axes, elevation, azimuth, held = options.asked_pointing(args, scene, "modes")
    result, shapes, model, damped, constraints, partial = _spectrum(args, scene, held)
    drives = bool(scene.description.drives) and not args.lock_axes
    rows = mode_table.mode_rows(result, shapes, model.M, model.coordinates, args.json)
    if isinstance(args.count, int):
        rows = rows[: args.count]
    n = result.n if partial is None else partial["modes"]
    damped_summary = mode_table.damped_summary(result, damped, n)
    options.check_finite({"modes": rows, "damped": damped_summary}, f"{scene.name}: modes")
    if args.plot is not None:
        _plot(args, scene, model, result, shapes)
    if args.json:
        out = {
            "scene": scene.name,
            "held": held,
            "locked_rotor": drives,
            **({"constraints": constraints} if constraints is not None else {}),
            **({"lowest_of": partial} if partial is not None else {}),
            "modes": rows,
            "damped": damped_summary,
            "units": {
                "held": "rad (m for a prismatic coordinate)",
                "freq_hz": "Hz",
                "divergence_rate": "1/s",
                "zeta": "1",
                "shape": "mass-normalised: each coordinate's unit per sqrt(kg·m²)",
                "real_eigenvalues": "1/s",
            },
        }
        print(json.dumps(out, indent=2))
        return 0
    where = f", elevation {elevation:g}°, azimuth {azimuth:g}°" if has_axes else ""
    what = f"{_how_many(rows, partial)} at static equilibrium{where}{_manifold(constraints)}"
    print(f"{scene.name}: {what}{_axes(args, scene, held, drives)}")
    _print_table(rows, result, damped, n)
    _print_unheld(rows, held, args.lock_axes, partial)
    return 0


def _how_many(rows: list[dict], partial: dict | None) -> str:
    """The title's count: every mode, or the lowest found of how many."""
    if partial is None:
        return f"{len(rows)} modes"
    return f"the {len(rows)} lowest of {partial['modes']} modes (--count N|all for others)"


#: Frames of one cycle in an animated mode plot.
ANIMATION_FRAMES = 24


def _plot(args: argparse.Namespace, scene, model, result, shapes) -> None:
    """Draw the lowest elastic modes on the structure into ``args.plot`` (atomically).

    ``shapes`` are the modes over ``model.coordinates`` (on a closed chain's manifold, its
    tangent directions: drawn to first order, the loops opening by the square of the
    drawn amplitude).
    """
    from pathlib import Path

    import numpy as np

    from rt70.guards.atomic import atomic_write
    from rt70.linear.mode_shapes import draw_modes
    from rt70.plotting.structure import animate_structure_modes, plot_structure_modes

    elastic = np.flatnonzero(~result.rigid)[: args.plot_modes]
    if elastic.size == 0:
        raise SceneError(f"{scene.name}: no elastic mode to draw")
    labels = [f"mode {k + 1}, {result.freq_hz[k]:.4g} Hz" for k in elastic]
    out = Path(args.plot)
    animated = out.suffix.lower() == ".gif"
    phases = np.linspace(0.0, 2 * np.pi, ANIMATION_FRAMES, endpoint=False)
    lines, rest, drawn = draw_modes(
        scene, model.q0, model.coordinates, shapes[:, elastic], labels, phases
    )
    title = f"{scene.name}: mode shapes on the structure (grey: at rest)"
    if animated:
        animation = animate_structure_modes(lines, rest, drawn, title)
        atomic_write(out, lambda tmp: animation.save(tmp, writer="pillow", fps=12))
    else:
        fig = plot_structure_modes(lines, rest, drawn, title)
        fmt = out.suffix.lower().lstrip(".")
        atomic_write(out, lambda tmp: fig.savefig(tmp, dpi=110, format=fmt))
    print(f"wrote {out}")


def _spectrum(args: argparse.Namespace, scene, held: dict) -> tuple:
    """``(modes, shapes, model, damped modes, constraints)`` at the static equilibrium.

    The tree held at the pointing (the axes locked with ``--lock-axes``; with drives and
    free axes, the locked-rotor model), or a closed-chain scene on its manifold
    (:func:`_loop_modes`; ``constraints`` is None for a tree).
    """
    import numpy as np

    from rt70.linear import linearize as lin
    from rt70.linear import modal
    from rt70.linear.damped_lowest import damped_spectrum
    from rt70.linear.lowest_modes import lowest_modes
    from rt70.textbook.massless import require_diagonal

    constraints = partial = None
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
    if constraints is None:
        require_diagonal(model.M, model.coordinates, f"{scene.name}: ")
        n = model.M.shape[0]
        count = _wanted(args.count, n)
        if count is None:
            result = modal.modes(model.M, model.K, model.D)
        else:
            result, unstable = lowest_modes(model.M, model.K, model.D, count)
            partial = {"modes": n, "unstable": unstable}
        shapes = result.shapes
        damped = damped_spectrum(model.M, model.K, model.D, result)
    if partial is None and isinstance(args.count, int) and args.count < result.n:
        partial = {"modes": result.n, "unstable": int(result.negative.sum())}
    return result, shapes, model, damped, constraints, partial


def _wanted(count: int | str | None, n: int) -> int | None:
    """How many modes the Lanczos solver finds; None: every mode, by the dense ``eigh``.

    Every mode when asked (``all``), by default up to
    :data:`rt70.linear.lowest_modes.DENSE_MAX` coordinates, and
    when ARPACK cannot find that many (more than n − 2); the table then shows ``--count``.
    """
    from rt70.linear.lowest_modes import DENSE_MAX, LOWEST

    if count == "all" or (count is None and n <= DENSE_MAX):
        return None
    count = LOWEST if count is None else int(count)
    return None if count > n - 2 else count


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


def _manifold(constraints: dict | None) -> str:
    """The title's note of the loop-closure rows the modes are constrained by, if any."""
    if constraints is None:
        return ""
    return (
        f", on the manifold of {constraints['loop_rows']} loop-closure row(s) "
        f"(rank {constraints['rank']})"
    )


def _axes(args: argparse.Namespace, scene, held: dict, drives: bool) -> str:
    """The title's note of what holds the axes: locked, or the drives' locked rotors."""
    if drives:
        names = ", ".join(d.name for d in scene.description.drives)
        return f" (locked rotor: the motors of {names} held, their reducers hold the axes)"
    return " (axes locked)" if args.lock_axes and held else ""


def _print_table(rows: list[dict], result, damped, n: int) -> None:
    """The modes' table and the line on the damping and the damped system's eigenvalues.

    ``n`` is the number of modes of the model (more than the rows when some were found).
    """
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
        + _found(damped, n)
    )


def _found(damped, n: int) -> str:
    """The note of a damped spectrum found in part (rt70.linear.damped_lowest)."""
    found = len(damped.eigenvalues)
    return "" if found == 2 * n else f" among its {found} eigenvalues nearest zero (of {2 * n})"


def _print_unheld(rows: list[dict], held: dict, lock_axes: bool, partial: dict | None) -> None:
    """One line per unstable or rigid mode: what it is and what would hold it.

    With modes found in part, also the unstable modes beyond them (counted by inertia).
    """
    hint = "; --lock-axes lets the drives hold it" if held and not lock_axes else ""
    beyond = (
        0 if partial is None else partial["unstable"] - sum(r["kind"] == "unstable" for r in rows)
    )
    if beyond > 0:
        print(
            f"{beyond} more unstable mode(s) lie beyond the modes shown (counted by the "
            f"inertia of K − σM; --count all lists every mode){hint}"
        )
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
